"""Fuzzy classifier throughput: the fast engine against scikit-fuzzy, in one process.

Run: ``python benchmarks/fuzzy.py [--repeats N]``. The fast engine classifies a year of
minutes (525,600 readings); scikit-fuzzy, far slower, runs on subsets (array mode and one
reading at a time), and rates are compared per reading. The fast engine's agreement with
scikit-fuzzy on the subset is printed with the table.
"""

from __future__ import annotations

import argparse

import numpy as np
from _timing import median_seconds, print_table

from hybridtrack.fuzzy import FuzzyWeatherClassifier

YEAR_OF_MINUTES = 525_600


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--array-subset", type=int, default=2000)
    parser.add_argument("--scalar-subset", type=int, default=300)
    args = parser.parse_args()
    clf = FuzzyWeatherClassifier()
    raw = np.random.default_rng(0).uniform([30.0, 0.0], [300.0, 180.0], size=(YEAR_OF_MINUTES, 2))
    array_part, scalar_part = raw[: args.array_subset], raw[: args.scalar_subset]

    fast = median_seconds(lambda: clf.classify(raw[:, 0], raw[:, 1]), args.repeats)
    array = median_seconds(lambda: clf.score(array_part[:, 0], array_part[:, 1], engine="skfuzzy"), 1)
    scalar = median_seconds(lambda: clf.score(scalar_part[:, 0], scalar_part[:, 1], engine="skfuzzy-scalar"), 1)

    rates = {"fast (numpy)": YEAR_OF_MINUTES / fast, "scikit-fuzzy, array inputs": len(array_part) / array,
             "scikit-fuzzy, one at a time": len(scalar_part) / scalar}
    readings = {"fast (numpy)": YEAR_OF_MINUTES, "scikit-fuzzy, array inputs": len(array_part),
                "scikit-fuzzy, one at a time": len(scalar_part)}
    rows = [[name, f"{readings[name]:,}", f"{rate:,.0f}", f"{YEAR_OF_MINUTES / rate:,.2f}",
             f"{rates['fast (numpy)'] / rate:,.0f}x"] for name, rate in rates.items()]
    print(f"classifying raw readings, published config, median of {args.repeats} runs for the fast engine")
    print_table(["engine", "readings timed", "readings/s", "s per year of minutes", "fast is"], rows)
    reference = clf.score(array_part[:, 0], array_part[:, 1], engine="skfuzzy")
    ours = clf.score(array_part[:, 0], array_part[:, 1])
    agree = (clf.label(ours) == clf.label(reference)).mean()
    print(f"\nparity on {len(array_part):,} readings: max |fast - scikit-fuzzy| = {np.nanmax(np.abs(ours - reference)):.2e}, "
          f"labels agree {agree:.1%}")


if __name__ == "__main__":
    main()
