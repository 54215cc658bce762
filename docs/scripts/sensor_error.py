"""Draw the sun sensor's pointing error against the ratio of direct to diffuse light.

Run: ``python docs/scripts/sensor_error.py`` (writes ``docs/images/sensor-error.png``). For
seeded mixed and cloudy days at both sites, the sensor is held exactly on the sun and the
error is what it reports (noise switched off): the pull of the bright cloud patch alone.
"""

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from hybridtrack import sites
from hybridtrack.sensor import SensorModel, read_pointing, sensor_scene
from hybridtrack.sky import synthetic
from hybridtrack.sun import solar_position


def pull_errors(site: str, date: str, weather: str, seed: int, model: SensorModel):
    frame = synthetic(site, date, weather=weather, seed=seed)
    position = solar_position(frame.index, sites.get(site), "spa")
    scene = sensor_scene(frame, position, model, clear_dni=frame["dni_clear"], clear_dhi=frame["dhi_clear"],
                         rng=np.random.default_rng(seed))
    up = np.flatnonzero(position["altitude"].to_numpy() > 10)
    ratio, error = [], []
    for i in up:
        reading, valid = read_pointing([0.0], scene.beam[i], scene.aureole[i], scene.patch[i],
                                       [scene.patch_offset[i, 0]], [0.0], model)
        if valid:
            ratio.append(scene.beam[i] / max(scene.diffuse[i], 1.0))
            error.append(abs(reading[0]))
    return np.array(ratio), np.array(error)


def main() -> None:
    model = SensorModel(noise=0.0)
    ratio, error = [], []
    for site, year in (("lanzhou", 2021), ("nanjing", 2013)):
        for date in (f"{year}-03-20", f"{year}-06-21", f"{year}-09-23", f"{year}-12-21"):
            for weather in ("mixed", "cloudy"):
                for seed in (1, 2, 3):
                    r, e = pull_errors(site, date, weather, seed, model)
                    ratio.append(r)
                    error.append(e)
    ratio, error = np.concatenate(ratio), np.concatenate(error)
    figure = Figure(figsize=(8, 4.5), layout="constrained")
    ax = figure.subplots()
    ax.scatter(ratio, np.maximum(error, 1e-4), s=3, alpha=0.25, color="C0", label="one minute")
    edges = np.logspace(np.log10(max(ratio.min(), 0.05)), np.log10(ratio.max()), 16)
    which = np.digitize(ratio, edges)
    centres, medians, p95 = [], [], []
    for k in range(1, len(edges)):
        chosen = error[which == k]
        if len(chosen) >= 20:
            centres.append(np.sqrt(edges[k - 1] * edges[k]))
            medians.append(np.median(chosen))
            p95.append(np.percentile(chosen, 95))
    ax.plot(centres, medians, color="black", label="median")
    ax.plot(centres, p95, color="C3", label="95th percentile")
    ax.axhline(0.5, color="grey", linestyle=":", label="0.5° (trough acceptance scale)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(1e-4, 10)
    ax.set_xlabel("DNI / DHI")
    ax.set_ylabel("sensor pointing error, ° (held on the sun, noise off)")
    ax.set_title(f"Cloud pull against DNI/DHI ({len(error):,} valid minutes, both sites, mixed and cloudy)",
                 fontsize=10)
    ax.legend(loc="upper right", fontsize=8)
    out = Path(__file__).resolve().parents[1] / "images" / "sensor-error.png"
    figure.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
