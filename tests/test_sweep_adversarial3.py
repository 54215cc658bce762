"""Adversarial pass 3 over sweeps: each test holds a defect found and fixed."""

from __future__ import annotations

import datetime as dt

import pytest

from hybridtrack import HybridtrackError
from hybridtrack.sweep import Sweep, run_one


@pytest.mark.parametrize("freq", ["2h", "1D", "61min"])
def test_a_base_step_longer_than_an_hour_is_refused_before_any_run(freq):
    """A run replays its controller at steps of an hour or finer; a base freq of 2 h (1 D: one
    step a day) had been taken, to fail every run once the cluster was up."""
    with pytest.raises(HybridtrackError, match=f"s.toml: base.freq: step '{freq}' is longer than a run's longest, "
                                               "1 h"):
        Sweep.from_dict({"base": {"freq": freq}, "grid": {"seed": [0]}}, source="s.toml")


def test_an_hourly_step_is_taken_and_a_longer_grid_step_fails_its_run_only():
    Sweep.from_dict({"base": {"freq": "1h"}, "grid": {"seed": [0]}}, source="s.toml")
    row = run_one({"config": {}}, {"run": 3, "freq": "2h"}, "s.toml")
    assert row["error"].startswith("HybridtrackError: grid.freq = '2h': step '2h' is longer than")


@pytest.mark.parametrize("key, values, message", [
    ("start", [dt.date(2021, 6, 21), "2021-06-21"], "grid.start: '2021-06-21' is 2021-06-21 again .values 1 and 2."),
    ("freq", ["30min", "60min", "1h"], "grid.freq: '1h' is '60min' again .values 2 and 3."),
    ("site", ["lanzhou", "nanjing", "Lanzhou"], "grid.site: 'Lanzhou' is 'lanzhou' again .values 1 and 3."),
    ("weather", ["sunny", ["sunny"]], r"grid.weather: \['sunny'\] is 'sunny' again .values 1 and 2."),
    ("weather", ["sunny,cloudy", ["sunny", "cloudy"]], r"grid.weather: \['sunny', 'cloudy'\] is 'sunny,cloudy' again .values 1 and 2."),
])
def test_two_grid_values_a_run_reads_alike_are_refused_as_repeats(key, values, message):
    """A date and its text, '60min' and '1h', a site's name in capitals had each made the same
    runs twice: two rows alike in all but their number, a mean over them counted double."""
    with pytest.raises(HybridtrackError, match=message + ": their runs are the same; each value makes its runs once"):
        Sweep.from_dict({"base": {"days": 2}, "grid": {key: values}}, source="s.toml")


def test_values_that_read_differently_or_that_their_runs_refuse_are_not_repeats():
    grid = {"freq": ["30min", "30s"], "site": ["lanzhou", "nanjing"], "seed": [1, True],
            "start": ["2021-06-21", "2021-6-21x"]}
    assert len(Sweep.from_dict({"grid": grid}, source="s.toml").runs()) == 16
