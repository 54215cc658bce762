"""Render the report pictures in docs/images/: a 1-day, a 7-day and a 365-day run.

    python docs/make_images.py
"""

from __future__ import annotations

from pathlib import Path

import hybridtrack
from hybridtrack.io import read_weather
from hybridtrack.report import plot_days, save_figure
from hybridtrack.sky import synthetic

OUT = Path(__file__).with_name("images")
DATA = Path(__file__).resolve().parents[1] / "data"


def main() -> None:
    day = hybridtrack.simulate(synthetic("lanzhou", "2021-06-21", weather="mixed", seed=5, gusts_per_day=2.0),
                               "lanzhou", collector="fresnel")
    save_figure(day.plot(), OUT / "report-1day.png")
    week = hybridtrack.simulate(synthetic("nanjing", "2013-07-01", "2013-07-07", weather="climate", seed=2,
                                          gusts_per_day=0.5), "nanjing", collector="trough-ns")
    save_figure(week.plot(), OUT / "report-7day.png")
    save_figure(plot_days(week), OUT / "days-7day.png")
    year = hybridtrack.simulate(synthetic("lanzhou", "2021-01-01", "2021-12-31", weather="climate", freq="5min",
                                          seed=1, gusts_per_day=0.3), "lanzhou", collector="trough-ns")
    save_figure(year.plot(), OUT / "report-365day.png")
    save_figure(year.plot(day="2021-03-20"), OUT / "report-365day-one-day.png")
    record = read_weather(DATA / "nanjing-2013-cloudy.csv", site="nanjing", freq="1min")
    save_figure(hybridtrack.simulate(record, "nanjing").plot(), OUT / "report-4-typical-days.png")
    print(f"wrote the pictures to {OUT}")


if __name__ == "__main__":
    main()
