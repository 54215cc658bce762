"""Rebuild ``labels.csv``: 72 labelled sensor readings across clear, cloudy and overcast skies.

Each reading is what the sun sensor sees (`hybridtrack.sensor.sensor_view`) on a synthetic day
(`hybridtrack.sky.synthetic`), labelled with the synthetic day's true ``sky`` at that minute.
Days: Lanzhou (2021) and Nanjing (2013), at a solstice and an equinox, one sunny, one cloudy, one
overcast and one mixed day each. Readings are drawn while the clear-sky GHI is above 100 W/m²
(the sensor's working day), 24 per class, by a seeded generator, so the same synthetic skies and
sensor model reproduce the file byte for byte::

    python examples/tuning/make_labels.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from hybridtrack.sensor import sensor_view
from hybridtrack.sky import synthetic

DAYS = [("lanzhou", "2021-06-21"), ("lanzhou", "2021-03-20"), ("nanjing", "2013-12-22"), ("nanjing", "2013-09-23")]
WEATHERS = ("sunny", "cloudy", "overcast", "mixed")
PER_CLASS = 24
SEED = 14


def readings() -> pd.DataFrame:
    """Every working-day minute of the chosen days, with the sensor's view and the true sky."""
    frames = []
    for k, (site, date) in enumerate(DAYS):
        for j, weather in enumerate(WEATHERS):
            frame = sensor_view(synthetic(site, date, weather=weather, seed=10 * k + j), seed=10 * k + j)
            day = frame[frame["ghi_clear"] > 100.0]
            frames.append(pd.DataFrame({"site": site, "time": day.index.strftime("%Y-%m-%dT%H:%M%z"),
                                        "intensity": day["intensity_ma"].round(1).to_numpy(),
                                        "variation": day["variation_ma"].round(1).to_numpy(),
                                        "weather": day["sky"].astype(str).to_numpy()}))
    return pd.concat(frames, ignore_index=True)


def labelled_set(seed: int = SEED) -> pd.DataFrame:
    """`PER_CLASS` readings of each sky class, drawn without replacement."""
    rng = np.random.default_rng(seed)
    pool = readings()
    picks = [group.iloc[rng.choice(len(group), PER_CLASS, replace=False)]
             for _, group in pool.groupby("weather", sort=True)]
    return pd.concat(picks).sort_values(["site", "time"]).reset_index(drop=True)


if __name__ == "__main__":
    out = Path(__file__).with_name("labels.csv")
    labelled_set().to_csv(out, index=False, columns=["intensity", "variation", "weather", "site", "time"])
    print(f"wrote {out}")
