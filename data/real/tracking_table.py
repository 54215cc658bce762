"""Tracking on the real records with the published sky inputs and with the default ones.

    python data/real/tracking_table.py

`simulate` does not yet take sky-input choices, so the relative inputs are passed through a
classifier whose `score` turns the photocurrent simulate hands it into the relative inputs
(`RelativeInputs`), exactly the call `simulate` is to make (docs/sky-validation.md).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import pandas as pd

from hybridtrack.fuzzy import FuzzyWeatherClassifier
from hybridtrack.io import read_weather
from hybridtrack.simulation import SimulationConfig, simulate
from hybridtrack.sites import Site
from hybridtrack.skyinputs import SkyInputConfig, fuzzy_config, sky_inputs

HERE = Path(__file__).parent


class RelativeInputs(FuzzyWeatherClassifier):
    """Scores the relative inputs of the photocurrent it is given, for one frame and site."""

    def __init__(self, frame: pd.DataFrame, site: Site, sensor, config: SkyInputConfig):
        super().__init__(fuzzy_config(config))
        self.frame, self.site, self.sensor, self.sky = frame, site, sensor, config

    def score(self, intensity, variation, **options):
        current = pd.Series(intensity, index=self.frame.index)
        inputs = sky_inputs(self.frame, self.site, self.sensor, self.sky, intensity=current)
        return super().score(inputs[0].to_numpy(), inputs[1].to_numpy(), **options)


def main() -> None:
    meta = tomllib.loads((HERE / "stations.toml").read_text())
    config = SimulationConfig()
    print("| record | inputs | energy capture | pointing error RMS (°) | p95 (°) | mode switches |")
    print("|---|---|---|---|---|---|")
    for file, spec in meta["files"].items():
        s = meta["stations"][spec["station"]]
        site = Site(spec["station"], s["latitude"], s["longitude"], s["altitude"], s["tz"])
        frame = read_weather(HERE / file).fillna(0.0)
        frame = frame[~frame.index.duplicated()]
        for name, classifier in (("published", None),
                                 ("relative (default)", RelativeInputs(frame, site, config.sensor, SkyInputConfig()))):
            summary = simulate(frame, site, config=config, classifier=classifier).summary
            error = summary["tracking_error_deg"]
            print(f"| {file} | {name} | {summary['energy_capture']:.4f} | {error['rms']:.3f} | {error['p95']:.3f} | "
                  f"{summary['mode_switches']} |")


if __name__ == "__main__":
    main()
