"""Print the agreement tables of docs/sky-validation.md from the excerpts in this folder.

    python data/real/agreement_table.py

Each day is typed by its own reference (beam ratio over the classifier's window, sun above
10°): "clear" if at least 80 % of its samples are sunny, "overcast" if at least 80 % are
overcast, "broken" otherwise.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from dataclasses import replace

import numpy as np
import pandas as pd

from hybridtrack.io import read_weather
from hybridtrack.sites import Site
from hybridtrack.skyinputs import SkyInputConfig, classify_sky, clear_sky
from hybridtrack.skyvalidation import validate_sky

HERE = Path(__file__).parent
SYSTEMS = {"relative (default)": SkyInputConfig(), "published": SkyInputConfig.published()}
DEFAULT = SkyInputConfig()
VARIANTS = {
    "default": DEFAULT,
    "complete rule table": replace(DEFAULT, rules="complete"),
    "2 min smoothing": replace(DEFAULT, smoothing="2min"),
    "5 min smoothing": replace(DEFAULT, smoothing="5min"),
    "full_variation 0.67 (published ranges)": replace(DEFAULT, full_variation=0.667),
    "full_variation 0.35": replace(DEFAULT, full_variation=0.35),
    "full_variation 0.25": replace(DEFAULT, full_variation=0.25),
    "relative_floor 0 (k read as it is)": replace(DEFAULT, relative_floor=0.0),
    "no low-sun rule": replace(DEFAULT, min_altitude=-5.0),
    "absolute, complete rules": replace(SkyInputConfig.published(), rules="complete"),
    "published": SkyInputConfig.published(),
}


def _site(meta: dict, name: str) -> Site:
    spec = meta["stations"][name]
    return Site(name, spec["latitude"], spec["longitude"], spec["altitude"], spec["tz"])


def _day_type(reference: pd.Series) -> str:
    shares = reference.value_counts(normalize=True)
    for label, name in (("sunny", "clear"), ("overcast", "overcast")):
        if shares.get(label, 0.0) >= 0.8:
            return name
    return "broken"


def _pct(value: float) -> str:
    return "–" if pd.isna(value) else f"{100 * value:.1f}"


def _consistency(meta: dict, config: SkyInputConfig) -> float:
    """Label agreement of the 1-minute Payerne records and their own 5-minute means, sun above 10°."""
    frame = pd.concat([read_weather(HERE / f) for f, spec in meta["files"].items() if spec["station"] == "payerne"])
    site = _site(meta, "payerne")
    coarse = frame.resample("5min", label="right", closed="right").mean().dropna()
    fine, rough = classify_sky(frame, site, config=config)["sky"], classify_sky(coarse, site, config=config)["sky"]
    up = coarse.index[clear_sky(coarse.index, site)["apparent_elevation"] > 10]
    return float((fine.reindex(up) == rough.reindex(up)).mean())


def variants(meta: dict) -> None:
    """The choices of the default, each undone in turn."""
    frames = {f: (read_weather(HERE / f), _site(meta, spec["station"])) for f, spec in meta["files"].items()}
    multi = [f for f, spec in meta["files"].items() if spec["kind"] == "multi-day"]
    print("| inputs | worst multi-day record | mean of multi-day records | worst day | sunny precision (pooled) "
          "| worst record's sunny precision | clear called overcast | sun 5-10°, agreement | 1 min vs 5 min labels |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, config in VARIANTS.items():
        results = {f: validate_sky(frame, site, config=config, min_altitude=5.0) for f, (frame, site) in frames.items()}
        rows = pd.concat([r.samples for r in results.values()])
        above = rows[rows["elevation"] > 10]
        low = rows[(rows["elevation"] > 5) & (rows["elevation"] <= 10) & rows["beam_window_sky"].notna()]
        scores = {f: validate_sky(*frames[f], config=config) for f in multi}
        overall = [scores[f].overall["beam_window"] for f in multi]
        worst_day = min(validate_sky(*frames[f], config=config).days["beam_window"].min() for f in frames)
        called = above[(above["sky"] == "sunny") & above["beam_window_sky"].notna()]
        worst_precision = np.nanmin([validate_sky(*frames[f], config=config).overall["sunny_precision"]
                                     for f in frames])
        clear_overcast = int(((above["beam_window_sky"] == "sunny") & (above["sky"] == "overcast")).sum())
        print(f"| {name} | {_pct(min(overall))} | {_pct(np.mean(overall))} | {_pct(worst_day)} | "
              f"{_pct((called['beam_window_sky'] == 'sunny').mean())} | {_pct(worst_precision)} | {clear_overcast} | "
              f"{_pct((low['sky'] == low['beam_window_sky']).mean())} | {_pct(_consistency(meta, config))} |")


def main() -> None:
    meta = tomllib.loads((HERE / "stations.toml").read_text())
    per_file, pooled = [], {name: [] for name in SYSTEMS}
    for file, spec in meta["files"].items():
        frame, site = read_weather(HERE / file), _site(meta, spec["station"])
        row = {"record": file, "kind": spec["kind"]}
        for system, config in SYSTEMS.items():
            result = validate_sky(frame, site, config=config)
            o = result.overall
            row[system] = (f"{_pct(o['beam_window'])} (min day {_pct(result.days['beam_window'].min())}), "
                           f"sunny prec. {_pct(o['sunny_precision'])}, clear→overcast {o['clear_called_overcast']}, "
                           f"detect_clearsky {_pct(o['clearsky_agreement'])}")
            counted = result.samples[result.samples["counted"]].copy()
            counted["station"] = spec["station"]
            local = counted.index.tz_convert(site.tz).date
            counted["day_type"] = counted.groupby(local)["beam_window_sky"].transform(_day_type)
            pooled[system].append(counted)
        per_file.append(row)
    print("| record | kind | " + " | ".join(SYSTEMS) + " |")
    print("|---|---|" + "---|" * len(SYSTEMS))
    for row in per_file:
        print(f"| {row['record']} | {row['kind']} | " + " | ".join(row[s] for s in SYSTEMS) + " |")
    print()
    print("| station | day type | samples | " + " | ".join(SYSTEMS) + " |")
    print("|---|---|---|" + "---|" * len(SYSTEMS))
    groups = {s: pd.concat(frames).groupby(["station", "day_type"]) for s, frames in pooled.items()}
    first = next(iter(SYSTEMS))
    for key, rows in groups[first]:
        cells = []
        for system in SYSTEMS:
            g = groups[system].get_group(key)
            known = g["beam_window_sky"].notna()
            cells.append(_pct((g["sky"][known] == g["beam_window_sky"][known]).mean()))
        print(f"| {key[0]} | {key[1]} | {int(rows['beam_window_sky'].notna().sum())} | " + " | ".join(cells) + " |")
    print()
    variants(meta)


if __name__ == "__main__":
    main()
