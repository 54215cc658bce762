"""Adversarial pass 3 over sweeps: each test holds a defect found and fixed."""

from __future__ import annotations

import pytest

from hybridtrack import HybridtrackError
from hybridtrack.sweep import Sweep, run_one


@pytest.mark.parametrize("freq", ["2h", "1D", "61min"])
def test_a_base_step_longer_than_an_hour_is_refused_before_any_run(freq):
    """A run replays its controller at steps of an hour or finer; a base freq of 2 h (1 D: one
    step a day) had been taken, to fail every run once the cluster was up."""
    with pytest.raises(HybridtrackError, match=f"s.toml: base.freq: freq '{freq}' is longer than a run's longest "
                                               "step, 1 h"):
        Sweep.from_dict({"base": {"freq": freq}, "grid": {"seed": [0]}}, source="s.toml")


def test_an_hourly_step_is_taken_and_a_longer_grid_step_fails_its_run_only():
    Sweep.from_dict({"base": {"freq": "1h"}, "grid": {"seed": [0]}}, source="s.toml")
    row = run_one({"config": {}}, {"run": 3, "freq": "2h"}, "s.toml")
    assert row["error"].startswith("HybridtrackError: grid.freq = '2h': freq '2h' is longer than")
