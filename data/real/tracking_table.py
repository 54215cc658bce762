"""Tracking on the real records with the published sky inputs and with the default ones.

    python data/real/tracking_table.py

The controller's sky watch takes its inputs from `SimulationConfig.sky`: the default relative
inputs, or `SkyInputConfig.published()` (docs/sky-validation.md). The records carry no wind, so
they are replayed as `hybridtrack replay` does: tracking through (`wind_missing = "track"`).
"""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

from hybridtrack.io import read_weather
from hybridtrack.simulation import SimulationConfig, simulate
from hybridtrack.sites import Site
from hybridtrack.skyinputs import SkyInputConfig

HERE = Path(__file__).parent


def main() -> None:
    meta = tomllib.loads((HERE / "stations.toml").read_text())
    controller = dataclasses.replace(SimulationConfig().controller, wind_missing="track")
    print("| record | inputs | energy capture | pointing error RMS (°) | p95 (°) | mode switches |")
    print("|---|---|---|---|---|---|")
    for file, spec in meta["files"].items():
        s = meta["stations"][spec["station"]]
        site = Site(spec["station"], s["latitude"], s["longitude"], s["altitude"], s["tz"])
        frame = read_weather(HERE / file).fillna(0.0)
        frame = frame[~frame.index.duplicated()]
        for name, sky in (("published", SkyInputConfig.published()), ("relative (default)", SkyInputConfig())):
            summary = simulate(frame, site, config=SimulationConfig(controller=controller, sky=sky)).summary
            error = summary["tracking_error_deg"]
            print(f"| {file} | {name} | {summary['energy_capture']:.4f} | {error['rms']:.3f} | {error['p95']:.3f} | "
                  f"{summary['mode_switches']} |")


if __name__ == "__main__":
    main()
