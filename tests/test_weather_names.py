"""Weather names in any case, everywhere they are read: the canonical lower-case name is the one
run and recorded (`hybridtrack.sky.weather_name`), as site names and a file's sky labels are read.

Each was refused before ("unknown weather 'Sunny'"): by ``--weather``, a sweep's base and grid
(each grid run failing as a row), ``ablate --weather`` and ``synthetic`` from Python.
"""

from __future__ import annotations

import pandas as pd
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.ablation import AblationPlan
from hybridtrack.cli import main
from hybridtrack.sky import synthetic
from hybridtrack.streaming import synthetic_days
from hybridtrack.sweep import Sweep, run_one


def test_synthetic_takes_a_weather_in_any_case_and_records_its_name():
    """'Overcast' makes the very frame 'overcast' makes, and its attrs name 'overcast'."""
    given = synthetic("lanzhou", "2021-06-21", "2021-06-22", weather=[" Overcast", "SUNNY"], freq="30min", seed=3)
    canonical = synthetic("lanzhou", "2021-06-21", "2021-06-22", weather=["overcast", "sunny"], freq="30min", seed=3)
    pd.testing.assert_frame_equal(given, canonical)
    assert given.attrs["weather"] == {"2021-06-21": "overcast", "2021-06-22": "sunny"}
    assert synthetic("lanzhou", "2021-06-21", weather="Climate", freq="30min").attrs["weather"]["2021-06-21"] in \
        ("sunny", "cloudy", "overcast", "mixed")


@pytest.mark.parametrize("weather, message", [
    ("Foggy", "unknown weather 'Foggy'; choose from sunny, cloudy, overcast, mixed, climate or a per-day list"),
    (["Sunny", "Climate"], "unknown day weather 'Climate'; choose from sunny, cloudy, overcast, mixed"),
])
def test_an_unknown_weather_is_refused_as_written_with_the_names_known(weather, message):
    with pytest.raises(HybridtrackError, match=message):
        synthetic("lanzhou", "2021-06-21", "2021-06-22", weather=weather, freq="30min")


def test_the_command_line_runs_and_heads_the_canonical_weather(tmp_path, capsys):
    assert main(["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--days", "2", "--weather", "Sunny, OVERCAST",
                 "--freq", "30min"]) == 0
    assert capsys.readouterr().out.startswith("lanzhou, 2021-06-21 (2 days, sunny,overcast), trough-ns, hybrid\n")
    assert main(["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--weather", "Foggy"]) == 2
    assert capsys.readouterr().err == ("hybridtrack: error: --weather: unknown weather 'Foggy'; choose from sunny, "
                                       "cloudy, overcast, mixed, climate or a per-day list\n")


def test_a_sweeps_weather_in_any_case_is_run_and_recorded_by_its_canonical_name(tmp_path):
    data = {"base": {"site": "lanzhou", "start": "2021-06-21", "days": 1, "freq": "30min", "weather": "Sunny"},
            "grid": {"seed": [0]}}
    assert Sweep.from_dict(data).base["weather"] == "sunny"
    data = {"base": {"site": "lanzhou", "start": "2021-06-21", "days": 2, "freq": "30min"},
            "grid": {"weather": ["Overcast,SUNNY", ["Cloudy", "mixed"]]}}
    sweep = Sweep.from_dict(data)
    assert sweep.grid["weather"] == ["overcast,sunny", ["cloudy", "mixed"]]
    assert sweep.to_dict()["grid"]["weather"] == ["overcast,sunny", ["cloudy", "mixed"]]  # sweep.toml
    row = run_one(sweep.base, sweep.runs()[0])
    assert row["error"] is None and row["weather"] == "overcast,sunny"


def test_a_sweeps_weather_given_twice_in_two_cases_is_a_repeat_and_an_unknown_one_fails_its_run():
    with pytest.raises(HybridtrackError, match=r"grid.weather: 'sunny' is 'Sunny' again \(values 1 and 2\)"):
        Sweep.from_dict({"grid": {"weather": ["Sunny", "sunny"]}}, source="s.toml")
    with pytest.raises(HybridtrackError, match="s.toml: base.weather: unknown weather 'Foggy'; choose from sunny"):
        Sweep.from_dict({"base": {"weather": "Foggy"}, "grid": {"seed": [0]}}, source="s.toml")
    sweep = Sweep.from_dict({"base": {"freq": "30min"}, "grid": {"weather": ["Foggy"]}})
    assert sweep.grid["weather"] == ["Foggy"]  # kept as written, for its run to refuse by name
    assert run_one(sweep.base, sweep.runs()[0])["error"] == (
        "HybridtrackError: grid.weather = 'Foggy': unknown weather 'Foggy'; choose from sunny, cloudy, overcast, "
        "mixed, climate or a per-day list")


def test_ablate_and_a_streamed_run_take_a_weather_in_any_case():
    assert AblationPlan(weather=("Sunny", " MIXED ")).weather == ("sunny", "mixed")
    with pytest.raises(HybridtrackError, match="ablate: weather names 'sunny' twice"):
        AblationPlan(weather=("Sunny", "sunny"))
    with pytest.raises(HybridtrackError, match="ablate: unknown weather 'Foggy'; choose from sunny, cloudy, overcast, "
                                               "mixed"):
        AblationPlan(weather=("Foggy",))
    assert synthetic_days("lanzhou", "2021-06-21", weather="Sunny", freq="30min").describe.startswith(
        "2021-06-21 to 2021-06-21, sunny (synthetic")
