"""Sweeps: the grid, a run's row against a direct run, failures kept, the same table on 1 and 2 workers."""

import dataclasses
import datetime as dt
import re
import threading
import time

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from hybridtrack import HybridtrackError, simulate
from hybridtrack.cli import main
from hybridtrack.collectors import Collector
from hybridtrack.simulation import SimulationConfig
from hybridtrack.sky import synthetic
from hybridtrack.sweep import METRICS, Sweep, pareto_front, plot_tradeoff, _table, run_one, run_sweep

TINY = {"base": {"site": "lanzhou", "collector": "fresnel", "start": "2021-06-21", "days": 1, "freq": "15min"},
        "grid": {"drive.deadband": [0.1, 0.4, -1.0], "seed": [0, 1]}}


def test_a_sweep_round_trips_through_toml(tmp_path):
    data = {"base": {"site": "nanjing", "start": __import__("datetime").date(2013, 6, 21), "days": 2,
                     "config": {"drive": {"deadband": 0.3}}},
            "grid": {"controller.sun_model": ["plc", "spa"], "collector.aim": [[0.0, 20.0, 100.0]]},
            "plot": {"x": "travel_deg", "y": "energy_capture"}}
    sweep = Sweep.from_dict(data, source=str(tmp_path / "s.toml"))
    assert Sweep.from_toml(sweep.to_toml(tmp_path / "s.toml")) == sweep


def test_the_grid_is_every_combination_in_order():
    runs = Sweep.from_dict(TINY).runs()
    assert [(r["run"], r["drive.deadband"], r["seed"]) for r in runs] == [
        (0, 0.1, 0), (1, 0.1, 1), (2, 0.4, 0), (3, 0.4, 1), (4, -1.0, 0), (5, -1.0, 1)]


@pytest.mark.parametrize("data, message", [
    ({"grid": {"seed": [0]}, "runs": {}}, "runs: unknown table"),
    # one of the two was dropped without a word
    ({"base": {"drive.deadband": 0.2, "config": {"drive": {"deadband": 0.3}}}, "grid": {"seed": [0]}},
     "base.drive.deadband and \\[base.config\\] both set drive.deadband; give it once"),
    ({"base": {"config": {"seed": 4}}, "grid": {"drive.deadband": [0.1]}}, "\\[base.config\\] seed: each run's seed"),
    (None, "s.toml: the sweep must be a table, got None"),
    ({"base": "x", "grid": {"seed": [0]}}, "s.toml: \\[base\\] must be a table, got 'x'"),
    ({"grid": {"seed": [0]}, 1: {}}, "s.toml: the sweep: key 1 is not text"),
    ({"grid": {1: [0]}}, "s.toml: \\[grid\\]: key 1 is not text"),
    ({"base": {("site",): "x"}, "grid": {"seed": [0]}}, "s.toml: \\[base\\]: key \\('site',\\) is not text"),
    ({"grid": {}}, r"\[grid\] is empty"),
    ({"grid": {"seed": 3}}, "grid.seed: must be a non-empty list"),
    ({"grid": {"drive.deadbnd": [0.1]}}, "grid.drive.deadbnd: unknown key"),
    ({"grid": {"drive": [0.1]}}, "grid.drive: is a whole table"),
    ({"grid": {"planet": ["mars"]}}, "grid.planet: unknown key"),
    ({"base": {"colour": "red"}, "grid": {"seed": [0]}}, "base.colour: unknown key"),
    ({"base": {"config": {"drive": {"deadband": "wide"}}}, "grid": {"seed": [0]}}, "drive.deadband: must be a number"),
    ({"grid": {"seed": [0]}, "plot": {"y": "happiness"}}, "plot.y: 'happiness' is not a metric"),
    ({"grid": {"seed": [0]}, "plot": {"z": "rms"}}, "plot.z: unknown key"),
    ({"grid": {"seed": list(range(1000)), "days": list(range(1, 1001))}}, "makes 1,000,000 runs; at most 100,000"),
    # a base value every run would fail on is refused before a cluster starts, naming its key
    ({"base": {"site": "atlantis"}, "grid": {"seed": [0]}}, "s.toml: base.site: unknown site 'atlantis'"),
    ({"base": {"seed": [[1, 2]]}, "grid": {"days": [1]}}, r"base.seed: seed must be a whole number .* got \[\[1, 2\]\]"),
    ({"base": {"weather": "sunny,rainy"}, "grid": {"seed": [0]}}, "base.weather: unknown weather 'rainy'"),
    ({"base": {"days": 0}, "grid": {"seed": [0]}}, "base.days: days must be a whole number from 1 to 3660, got 0"),
    ({"base": {"strategy": "psychic"}, "grid": {"seed": [0]}}, "base.strategy: unknown strategy 'psychic'"),
    ({"base": {"collector": "dish"}, "grid": {"seed": [0]}}, "base.collector: unknown collector 'dish'"),
    ({"base": {"start": "2021-02-30"}, "grid": {"seed": [0]}}, "base.start: "),
    ({"base": {"freq": "soon"}, "grid": {"seed": [0]}}, "base.freq: "),
    ({"base": {"gusts_per_day": -1.0}, "grid": {"seed": [0]}}, "base.gusts_per_day: "),
    ({"base": {"drive.deadband": -1}, "grid": {"seed": [0]}}, "s.toml: base: drive: deadband .* = -1 is outside"),
    # ... checked as its runs check it: each of these started the cluster and failed every run
    ({"base": {"collector.row_distance": "x"}, "grid": {"seed": [0]}},
     "s.toml: base.collector.row_distance: collector: row_distance .* got 'x'"),
    ({"base": {"start": dt.datetime(2021, 6, 21, 10)}, "grid": {"seed": [0]}},
     "s.toml: base.start: date '2021-06-21T10:00:00' does not exist or is not YYYY-MM-DD"),
    ({"base": {"freq": "1ns"}, "grid": {"seed": [0]}}, "s.toml: base.freq: .* 86,400,000,000,000 steps of 1ns"),
    ({"base": {"days": 3660, "freq": "1s"}, "grid": {"seed": [0]}},  # 3660 days x 86,400 s
     "s.toml: base.days, base.freq: 2021-06-21 to 2031-06-28: 316,224,000 steps of 1s would need"),
    ({"base": {"days": 3, "weather": ["sunny", "cloudy"]}, "grid": {"seed": [0]}},
     "s.toml: base.days, base.weather: 2 weathers given for 3 days; give one per day"),
    ({"base": {"freq": ["1min"]}, "grid": {"seed": [0]}}, r"s.toml: base.freq: freq must be a step .* got \['1min'\]"),
    ({"base": {"weather": []}, "grid": {"seed": [0]}}, "s.toml: base.weather: weather is an empty list"),  # IndexError
    # the run key strategy (hybrid by default) had replaced these in every run, under their names in the table
    ({"grid": {"controller.strategy": ["sensor", "astronomical"]}},
     "s.toml: grid.controller.strategy: a run's strategy is the run key strategy; write strategy = ... in .grid."),
    ({"base": {"controller.strategy": "sensor"}, "grid": {"seed": [0]}}, "s.toml: base.controller.strategy: "),
    ({"base": {"config": {"controller": {"strategy": "sensor"}}}, "grid": {"seed": [0]}},
     r"s.toml: \[base.config.controller\] strategy: each run's strategy is the run key strategy"),
])
def test_bad_sweeps_are_refused_before_any_run(data, message):
    with pytest.raises(HybridtrackError, match=message):
        Sweep.from_dict(data, source="s.toml")


@pytest.mark.parametrize("text, message", [
    ("", r"s.toml: the sweep file is empty; a sweep file needs a \[grid\] table at least"),  # "leave it out for the defaults"
    ("[base]\nseed = 1\n", r"s.toml: \[grid\] is missing; give at least one key"),  # "[grid] is empty"
    ("[grid]\n", r"s.toml: \[grid\] is empty; give at least one key"),
])
def test_an_empty_sweep_file_or_grid_is_told_what_it_needs(tmp_path, text, message):
    path = tmp_path / "s.toml"
    path.write_text(text)
    with pytest.raises(HybridtrackError, match=message):
        Sweep.from_toml(path)


@pytest.mark.parametrize("key, value, message", [
    ("days", [1], "HybridtrackError: grid.days = [1]: days must be a whole number from 1 to 3660, got [1]"),
    ("freq", ["1min"], "HybridtrackError: grid.freq = ['1min']: freq must be a step such as '1min' or '10s', "
                       "got ['1min']"),
    ("weather", "sunny,cloudy", "HybridtrackError: grid.weather = 'sunny,cloudy': 2 weathers given for 1 days; "
                                "give one per day"),
    ("strategy", "psychic", "HybridtrackError: grid.strategy = 'psychic': unknown strategy 'psychic'"),
    ("collector.row_distance", "x", "HybridtrackError: grid.collector.row_distance = 'x': collector: row_distance"),
    ("start", dt.date(2262, 6, 1), "HybridtrackError: grid.start = 2262-06-01: date '2262-06-01' is outside"),
])
def test_a_bad_grid_value_fails_its_run_naming_its_key(key, value, message):
    """A list where days or freq is one value failed its run with "unhashable type: 'list'"; the
    error had not said the grid gave the value."""
    assert run_one(Sweep.from_dict(TINY).base, {"run": 0, key: value})["error"].startswith(message)


@pytest.mark.parametrize("base, run, named", [
    # neither alone: 3 days of mixed weather and 2 of sunny,cloudy are each fine; together refused
    ({"days": 2}, {"days": 3, "weather": "sunny,cloudy"}, "grid.days = 3, grid.weather = 'sunny,cloudy': "
                                                          "2 weathers given for 3 days"),
    # the base's weather is wrong for the grid's days: the days are what the grid gave
    ({"weather": ["sunny", "cloudy"]}, {"days": 3}, "grid.days = 3: 2 weathers given for 3 days"),
    # the seed is not to blame, though it came from the grid too
    ({}, {"seed": 4, "drive.deadband": 20}, "grid.drive.deadband = 20: s.toml: drive: deadband (degrees) = 20 is "
                                            "outside [0, 10]"),
    # a base value refused whatever the grid gives is the base's, not the grid's
    ({"collector.row_distance": "x"}, {"collector": "fresnel"}, "collector: row_distance (m) must be a finite"),
])
def test_a_failed_runs_error_names_the_grid_values_it_came_from_and_no_others(base, run, named):
    error = run_one({"freq": "30min", **base, "config": {}}, {"run": 7, **run}, "s.toml")["error"]
    assert error.startswith(f"HybridtrackError: {named}")


def test_a_sweep_with_one_bad_grid_value_runs_the_others_and_names_it(tmp_path, capsys):
    """grid."drive.deadband" = [0.1, -1]: the bad run's error had not said which grid value it was."""
    path = tmp_path / "s.toml"
    path.write_text("[base]\nfreq = '30min'\n[grid]\n\"drive.deadband\" = [0.1, -1]\nseed = [0, 1]\n")
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--workers", "1"]) == 0
    table = pd.read_parquet(tmp_path / "out" / "runs.parquet")
    assert table["error"].isna().tolist() == [True, True, False, False] and table["rms"][:2].notna().all()
    want = f"HybridtrackError: grid.drive.deadband = -1: {path}: drive: deadband (degrees) = -1 is outside [0, 10]"
    assert table["error"][2] == table["error"][3] == want
    printed = capsys.readouterr().out
    assert f"  run 2: {want}\n  run 3: {want}\n" in printed


@pytest.mark.parametrize("grid", [
    'drive.deadband = [0.1, 0.4]\nseed = [0, 1]\n',  # TOML's dotted key, unquoted
    '"drive.deadband" = [0.1, 0.4]\nseed = [0, 1]\n',
    'seed = [0, 1]\n[grid.drive]\ndeadband = [0.1, 0.4]\n',  # a sub-table: the same key
])
def test_a_dotted_grid_key_unquoted_or_as_a_table_is_the_same_key(tmp_path, grid):
    """TOML reads drive.deadband = [...] unquoted as a table drive holding deadband: it was refused
    as "grid.drive: is a whole table; name one of its fields", though it names one."""
    path = tmp_path / "s.toml"
    path.write_text("[base]\ncollector = 'fresnel'\n'collector.row_distance' = -4.0\nimperfections.encoder_offset = 0.05\n"
                    "[grid]\n" + grid)
    sweep = Sweep.from_toml(path)
    assert sorted(sweep.grid.items()) == [("drive.deadband", [0.1, 0.4]), ("seed", [0, 1])]
    assert {k: v for k, v in sweep.base.items() if k != "config"} == {
        "collector": "fresnel", "collector.row_distance": -4.0, "imperfections.encoder_offset": 0.05}
    assert Sweep.from_toml(sweep.to_toml(tmp_path / "back.toml")).to_dict() == sweep.to_dict()


def test_a_key_given_both_dotted_and_as_a_table_is_refused():
    with pytest.raises(HybridtrackError, match=r"s.toml: grid.drive.deadband: given twice"):
        Sweep.from_dict({"grid": {"drive.deadband": [0.1], "drive": {"deadband": [0.2]}}}, source="s.toml")


@pytest.mark.parametrize("key, values, message", [
    ("seed", [0, 1, 0], "grid.seed: 0 is given twice .values 1 and 3.; each value makes its runs once"),
    ("drive.deadband", [0.1, 0.2, 0.10], "grid.drive.deadband: 0.1 is given twice .values 1 and 3."),
    ("drive.deadband", [1, 0.5, 1.0], "grid.drive.deadband: 1.0 is given twice .values 1 and 3."),
    ("weather", [["sunny", "cloudy"], ["sunny", "cloudy"]], r"grid.weather: \['sunny', 'cloudy'\] is given twice"),
])
def test_a_grid_value_given_twice_is_refused(key, values, message):
    """seed = [0, 1, 0] ran seed 0 twice: two identical rows, the mean over seeds weighted to it."""
    with pytest.raises(HybridtrackError, match=message):
        Sweep.from_dict({"grid": {key: values}}, source="s.toml")


def test_values_alike_only_to_python_are_not_refused_as_repeats():
    """True == 1 in Python, but a seed of true is refused by its run and 1 is not: two runs."""
    assert len(Sweep.from_dict({"grid": {"seed": [1, True], "drive.deadband": [float("nan"), float("nan")]}}).runs()) == 4


@pytest.mark.parametrize("plot, message", [
    ({"x": "rms", "y": "rms"}, "s.toml: plot.x and plot.y are both 'rms'; a trade-off needs two metrics"),
    ({"x": "rms"}, "s.toml: plot.x and plot.y are both 'rms' .y by default.; a trade-off needs two metrics"),
])
def test_a_trade_off_of_a_metric_against_itself_is_refused(plot, message):
    with pytest.raises(HybridtrackError, match=message):
        Sweep.from_dict({"grid": {"seed": [0]}, "plot": plot}, source="s.toml")


@pytest.mark.parametrize("key, suggestion", [
    ("drive.deadbnd", "did you mean drive.deadband?"),
    ("seeds", "did you mean seed?"),
    ("collector.row_distanc", "did you mean collector.row_distance?"),
])
def test_a_grid_key_that_is_a_typo_names_the_real_one(key, suggestion):
    with pytest.raises(HybridtrackError, match=f"s.toml: grid.{re.escape(key)}: unknown key; {re.escape(suggestion)}"):
        Sweep.from_dict({"grid": {key: [0.1]}}, source="s.toml")


def test_a_base_value_the_grid_overrides_is_refused_as_given_twice_not_judged_as_a_run():
    """days = 0 in [base] beside a grid of days had been taken and never used (no run reads it); it
    is refused as set twice, before it is judged as a value a run would fail on."""
    with pytest.raises(HybridtrackError, match="base.days and grid.days both set days"):
        Sweep.from_dict({"base": {"days": 0, "site": "atlantis"}, "grid": {"days": [1], "site": ["lanzhou"]}})


def test_a_runs_row_is_that_run_and_a_failure_is_a_row():
    sweep = Sweep.from_dict(TINY)
    runs = sweep.runs()
    row = run_one(sweep.base, runs[3])
    frame = synthetic("lanzhou", "2021-06-21", weather="mixed", freq="15min", seed=1)
    config = dataclasses.replace(SimulationConfig(), seed=1,
                                 drive=dataclasses.replace(SimulationConfig().drive, deadband=0.4))
    direct = simulate(frame, "lanzhou", collector=Collector("fresnel"), strategy="hybrid", config=config).summary
    assert row["error"] is None and row["drive.deadband"] == 0.4 and row["seed"] == 1
    assert row["rms"] == direct["tracking_error_deg"]["rms"] and row["moves"] == direct["moves"]
    failed = run_one(sweep.base, runs[4])
    assert failed["error"].startswith("HybridtrackError:") and "deadband" in failed["error"]
    assert all(failed[m] is None for m in METRICS)
    geometry = run_one({**sweep.base, "collector.row_distance": -4.0}, {"run": 0, "seed": 0})
    assert geometry["error"] is None and geometry["collector.row_distance"] == -4.0
    for seed in (1.5, True):  # not truncated to seed 1's run
        assert "seed must be a whole number" in run_one(sweep.base, {"run": 0, "seed": seed})["error"]


def test_a_grid_of_mixed_types_makes_a_table_parquet_can_hold(tmp_path):
    """[0.1, "wide"] is two runs, one failing; the table keeps both values, as text."""
    rows = [run_one(Sweep.from_dict(TINY).base, {"run": k, "drive.deadband": v}) for k, v in enumerate([0.1, "wide"])]
    table = _table(rows)
    table.to_parquet(tmp_path / "runs.parquet", index=False)
    assert list(pd.read_parquet(tmp_path / "runs.parquet")["drive.deadband"]) == ["0.1", "wide"]
    assert table["error"].isna().tolist() == [True, False]
    grid = Sweep.from_dict({**TINY, "grid": {"controller.lead": [True, "x"]}})
    flags = _table([run_one(grid.base, {"run": k, "controller.lead": v}) for k, v in enumerate([True, "x"])])
    assert list(flags["controller.lead"]) == ["true", "x"]  # as the sweep's TOML wrote it, not Python's 'True'
    assert flags["error"].isna().tolist() == [True, False]
    nested = [[True, False], "x", {"a": True}]  # within lists and tables too (helper-32)
    grid = Sweep.from_dict({**TINY, "grid": {"controller.lead": nested}})
    cells = _table([run_one(grid.base, {"run": k, "controller.lead": v}) for k, v in enumerate(nested)])
    assert list(cells["controller.lead"]) == ["true,false", "x", "{a = true}"]


def test_a_seed_beyond_64_bits_fails_its_run_and_the_table_keeps_every_digit(tmp_path):
    """seed = [0, 1e20]: pyarrow cannot store 10**20 as an integer and the whole table was lost."""
    huge = 10**20
    rows = [run_one(Sweep.from_dict(TINY).base, {"run": k, "seed": seed}) for k, seed in enumerate([0, huge])]
    table = _table(rows)
    table.to_parquet(tmp_path / "runs.parquet", index=False)
    back = pd.read_parquet(tmp_path / "runs.parquet")
    assert list(back["seed"]) == ["0", "100000000000000000000"]
    assert back["error"].isna().tolist() == [True, False] and "seed must be a whole number" in back["error"][1]
    assert back["rms"][0] == rows[0]["rms"]


def test_pareto_front_hand_case():
    table = pd.DataFrame({"moves": [10, 20, 30, 15, 40], "rms": [0.5, 0.3, 0.1, 0.6, 0.1],
                          "energy_capture": [0.9, 0.95, 0.97, 0.99, 0.96]})
    assert list(pareto_front(table, "moves", "rms").index) == [0, 1, 2]
    assert list(pareto_front(table, "moves", "energy_capture").index) == [0, 3]  # 15 moves at 0.99 beats 20 and 30


@pytest.mark.parametrize("call, message", [
    (lambda table: pareto_front(table, "moves", "p95"), "pareto_front: the table has no column 'p95'; its columns: "
                                                        "moves, rms, site"),
    (lambda table: pareto_front(table, "site", "rms"), "pareto_front: column 'site' holds .*, not numbers"),
    (lambda table: pareto_front(table.to_dict(), "moves", "rms"), "pareto_front: the table must be a pandas DataFrame"),
    (lambda table: plot_tradeoff(table, "rms", "max"), "plot_tradeoff: the table has no column 'max'"),
    (lambda table: plot_tradeoff(table, colour="seed"), "plot_tradeoff: colour: the table has no column 'seed'"),
    (lambda table: run_sweep("abc"), "run_sweep: sweep must be a Sweep .* got 'abc'"),
])
def test_the_api_refuses_what_it_cannot_use_naming_the_argument(call, message):
    """These raised KeyError, TypeError and AttributeError; a colour not in the table was ignored unsaid."""
    table = pd.DataFrame({"moves": [10, 20], "rms": [0.5, 0.3], "site": ["lanzhou", "nanjing"]})
    with pytest.raises(HybridtrackError, match=message):
        call(table)


def test_the_table_is_the_same_on_one_and_two_workers_and_failures_are_kept():
    sweep = Sweep.from_dict(TINY)
    one = run_sweep(sweep, workers=1, progress=False)
    two = run_sweep(sweep, workers=2, progress=False)
    pd.testing.assert_frame_equal(one, two)
    assert list(one["run"]) == list(range(6))
    assert one["error"].notna().tolist() == [False, False, False, False, True, True]
    assert one.loc[one["error"].isna(), "rms"].notna().all()
    assert isinstance(plot_tradeoff(one, "moves", "rms", colour="drive.deadband"), Figure)


def test_sweep_command_writes_the_table_and_the_plot(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text('[base]\nsite = "nanjing"\nstart = 2021-03-20\nfreq = "20min"\n'
                    '[grid]\nstrategy = ["hybrid", "astronomical"]\n[plot]\ny = "energy_capture"\n')
    out = tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1"]) == 0
    printed = capsys.readouterr().out
    assert "2 runs over strategy" in printed and "Pareto front of moves against energy_capture" in printed
    table = pd.read_parquet(out / "runs.parquet")
    assert list(table["strategy"]) == ["hybrid", "astronomical"] and table["start"].iloc[0] == "2021-03-20"
    assert np.all(table["steps"] == 72) and (out / "tradeoff.png").stat().st_size > 0
    assert Sweep.from_toml(out / "sweep.toml").grid == {"strategy": ["hybrid", "astronomical"]}


@pytest.mark.parametrize("content, flags, message", [
    ("[grid]\nseed = [0]\n", ["--workers", "0"], "workers must be a whole number"),
    ("[grid]\nseed = [0]\n", ["--workers", "1", "--scheduler", "tcp://127.0.0.1:1"], "not both"),
    # distributed's TLS and UCX connectors raise TypeError without their setup: it was a traceback
    ("[grid]\nseed = [0]\n", ["--scheduler", "tls://127.0.0.1:1"], "cannot reach the Dask scheduler at tls://"),
    ("[grid]\nseed = [0]\n", ["--scheduler", ""], "scheduler must be an address"),  # an unset $VAR: not a local cluster
    ("[grid]\nseed = [0]\n", ["--scheduler", "ucx://127.0.0.1:1"], "cannot reach the Dask scheduler at ucx://"),
    ("[grid\n", [], "not valid TOML"),
    ("[grid]\nwind = [1]\n", [], "grid.wind: unknown key"),
    ("[base]\nstart = 2021-06-21T10:00:00\n[grid]\nseed = [0]\n", ["--workers", "1"],
     "s.toml: base.start: date '2021-06-21T10:00:00' does not exist"),
    ("[base]\nfreq = '30min'\n[grid]\nstart = ['2021-02-30']\n", ["--workers", "1"],
     "every run failed; run 0: HybridtrackError: grid.start = '2021-02-30': date '2021-02-30' does not exist"),
])
def test_bad_sweep_input_is_one_line_and_status_2(tmp_path, capsys, content, flags, message):
    path = tmp_path / "s.toml"
    path.write_text(content)
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), *flags]) == 2
    error = [line for line in capsys.readouterr().err.splitlines() if "hybridtrack" in line]  # not the progress bar
    assert len(error) == 1 and error[0].strip().startswith("hybridtrack: error:") and message in error[0]
    assert list(tmp_path.iterdir()) == [path] or list((tmp_path / "out").iterdir())  # no empty --out left behind


@pytest.mark.parametrize("flags, message", [
    # these were refused by distributed once the run count had been printed above the refusal
    (["--scheduler", "nonsense://x"], "scheduler 'nonsense://x': a Dask scheduler's address is such as "
                                      "'tcp://host:8786'; nonsense:// is not one a scheduler is reached by"),
    (["--scheduler", "tcp://"], "scheduler 'tcp://' is not an address: a Dask scheduler's address is such as"),
    # no client is made for what is no address, or where nothing answers: one that failed to start
    # had been closed by Python's collector at the command's end, 20 s later and with a traceback
    (["--scheduler", "tcp://:abc"], "scheduler 'tcp://:abc' is not an address: a Dask scheduler's address"),
    (["--scheduler", "inproc://x"], "scheduler 'inproc://x' is not an address: a Dask scheduler's address is"),
    (["--scheduler", "tcp://127.0.0.1:1"], "cannot reach the Dask scheduler at tcp://127.0.0.1:1: "),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "give either --scheduler or --workers, not both"),
    (["--workers", "0"], "--workers must be a whole number within [1, 1,024], got 0"),
    (["--scheduler", ""], "--scheduler must be an address such as 'tcp://host:8786', got ''"),
])
def test_where_the_runs_go_is_checked_before_anything_is_printed(tmp_path, capsys, flags, message):
    """The run count ("s.toml: 2 runs over seed") had been printed above the refusal."""
    path = tmp_path / "s.toml"
    path.write_text("[base]\nfreq = '30min'\n[grid]\nseed = [0, 1]\n")
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), *flags]) == 2
    printed = capsys.readouterr()
    assert printed.out == "" and printed.err.startswith(f"hybridtrack: error: {message}")
    assert printed.err.count("\n") == 1 and printed.err.endswith("\n")
    assert not (tmp_path / "out").exists()


def test_a_run_whose_task_dies_is_a_row_and_the_sweep_goes_on(monkeypatch):
    """A worker killed mid-run (out of memory, a signal) raises at the client; the run is still a row."""
    from dask.distributed import LocalCluster

    import hybridtrack.sweep as sweep_module

    real = sweep_module.run_one

    def dying(base, spec, *given):  # run_one's source and the sweep's steps
        if spec["run"] == 1:
            raise MemoryError("the worker ran out of memory")
        return real(base, spec, *given)

    monkeypatch.setattr(sweep_module, "run_one", dying)
    sweep = Sweep.from_dict({"base": {"freq": "30min"}, "grid": {"seed": [0, 1, 2]}})
    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        table = run_sweep(sweep, scheduler=cluster.scheduler_address, progress=False)
    assert list(table["run"]) == [0, 1, 2] and list(table["seed"]) == [0, 1, 2]
    assert table["error"].isna().tolist() == [True, False, True]
    assert table.loc[1, "error"] == "MemoryError: the worker ran out of memory" and pd.isna(table.loc[1, "rms"])


_FIRST_DONE, _RELEASED = threading.Event(), threading.Event()
_RUN_ONE = run_one  # the real one, which the test replaces in its module


def _the_first_run_alone(base, spec, *given):
    """run_one for the first run to come; the others wait until the test lets them go."""
    if not _FIRST_DONE.is_set():
        row = _RUN_ONE(base, spec, *given)
        _FIRST_DONE.set()
        return row
    _RELEASED.wait(30)
    return _RUN_ONE(base, spec, *given)


def test_runs_left_when_the_schedulers_last_worker_leaves_are_failed_rows_not_a_hang(monkeypatch):
    """A remote worker killed mid-sweep (its machine gone, no nanny to restart it): the runs left
    waited for a worker for ever. After WORKERS_GONE_AFTER seconds with none they are rows that
    say why, and the runs that finished are kept."""
    from dask.distributed import LocalCluster

    import hybridtrack.cluster as cluster_module
    import hybridtrack.sweep as sweep_module

    monkeypatch.setattr(cluster_module, "WORKERS_GONE_AFTER", 1.0)
    monkeypatch.setattr(sweep_module, "run_one", _the_first_run_alone)
    _FIRST_DONE.clear()
    _RELEASED.clear()
    sweep = Sweep.from_dict({"base": {"freq": "30min"}, "grid": {"seed": [0, 1, 2, 3]}})
    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        def last_worker_leaves():
            _FIRST_DONE.wait(60)
            time.sleep(1.0)  # the client fetches the first result from the worker before it leaves
            threading.Thread(target=cluster.scale, args=(0,), daemon=True).start()
            time.sleep(0.5)
            _RELEASED.set()

        threading.Thread(target=last_worker_leaves, daemon=True).start()
        table = run_sweep(sweep, scheduler=cluster.scheduler_address, progress=False)
    assert list(table["run"]) == [0, 1, 2, 3]
    assert table["error"].notna().sum() >= 2 and table["rms"].notna().sum() >= 1  # the first run, at least
    assert table.loc[table["error"].isna(), "rms"].notna().all()
    gone = table["error"].dropna()
    assert gone.str.startswith("WorkersGone: the Dask scheduler has had no worker for 1 s").all()
    assert table.loc[table["error"].notna(), "rms"].isna().all()


def test_a_scheduler_without_workers_is_refused_not_waited_on(monkeypatch):
    """A sweep sat at 0 runs for ever; a field ended in distributed's 'No valid workers found'."""
    from dask.distributed import LocalCluster

    import hybridtrack.cluster as cluster_module

    monkeypatch.setattr(cluster_module, "WORKER_WAIT", 0.5)
    sweep = Sweep.from_dict({"base": {"freq": "30min"}, "grid": {"seed": [0]}})
    with LocalCluster(n_workers=0, processes=False, dashboard_address=None) as cluster:
        with pytest.raises(HybridtrackError, match=f"the Dask scheduler at {cluster.scheduler_address} has no workers"):
            run_sweep(sweep, scheduler=cluster.scheduler_address, progress=False)


def test_the_example_sweep_is_valid_and_runs_one_of_its_runs():
    from pathlib import Path

    sweep = Sweep.from_toml(Path(__file__).resolve().parents[1] / "examples" / "sweep-deadband.toml")
    runs = sweep.runs()
    assert len(runs) == 25 and list(sweep.grid) == ["drive.deadband", "seed"] and (sweep.x, sweep.y) == ("moves", "rms")
    row = run_one({**sweep.base, "days": 1, "freq": "10min"}, runs[0], sweep.source)
    assert row["error"] is None and row["collector"] == "fresnel" and row["start"] == "2021-06-19"


def test_saving_with_something_that_is_not_a_sweep_writes_nothing(tmp_path):
    """save_sweep(table, None, ...) had written runs.parquet, then failed with an AttributeError."""
    from hybridtrack.sweep import save_sweep

    with pytest.raises(HybridtrackError, match="save_sweep: sweep must be a Sweep, got NoneType"):
        save_sweep(pd.DataFrame({"run": [0]}), None, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_a_plot_that_cannot_be_written_leaves_no_earlier_sweeps_files_beside_the_new_table(tmp_path, monkeypatch):
    """A --force sweep on a full disk left its new table beside the earlier sweep's sweep.toml and
    plot, which did not describe it."""
    import errno

    import hybridtrack.sweep as sweep_module
    from hybridtrack.sweep import save_sweep

    out = tmp_path / "out"
    out.mkdir()
    for name in ("runs.parquet", "sweep.toml", "tradeoff.png"):
        (out / name).write_text("the earlier sweep's\n")

    class FullDisk:
        def savefig(self, path, **options):
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(sweep_module, "plot_tradeoff", lambda *args, **kwargs: FullDisk())
    table = pd.DataFrame({"run": [0, 1], "seed": [0, 1], "rms": [0.1, 0.2], "moves": [3, 4]})
    with pytest.raises(HybridtrackError, match=r"tradeoff.png: cannot write \(No space left on device\); the runs "
                                               r"are in .*runs.parquet$"):
        save_sweep(table, Sweep.from_dict({"grid": {"seed": [0, 1]}}), out)
    assert sorted(p.name for p in out.iterdir()) == ["runs.parquet"]
    pd.testing.assert_frame_equal(pd.read_parquet(out / "runs.parquet"), table)


@pytest.mark.parametrize("stop", [KeyboardInterrupt(), ValueError("a plot matplotlib cannot draw")])
def test_a_plot_stopped_by_ctrl_c_or_an_error_leaves_no_earlier_sweeps_files_beside_the_new_table(tmp_path,
                                                                                                   monkeypatch, stop):
    """Only a HybridtrackError removed them: a Ctrl-C while 100,000 points were drawn, or any other
    error, left the earlier sweep's sweep.toml and plot beside the new table."""
    import hybridtrack.sweep as sweep_module
    from hybridtrack.sweep import save_sweep

    out = tmp_path / "out"
    out.mkdir()
    for name in ("runs.parquet", "sweep.toml", "tradeoff.png"):
        (out / name).write_text("the earlier sweep's\n")

    def stopped(*args, **kwargs):
        raise stop

    monkeypatch.setattr(sweep_module, "plot_tradeoff", stopped)
    table = pd.DataFrame({"run": [0, 1], "seed": [0, 1], "rms": [0.1, 0.2], "moves": [3, 4]})
    with pytest.raises(type(stop)):
        save_sweep(table, Sweep.from_dict({"grid": {"seed": [0, 1]}}), out)
    assert sorted(p.name for p in out.iterdir()) == ["runs.parquet"]
    pd.testing.assert_frame_equal(pd.read_parquet(out / "runs.parquet"), table)


@pytest.mark.parametrize("signal_name, status, said", [("SIGINT", 130, "interrupted"), ("SIGTERM", 143, "terminated")])
def test_ctrl_c_keeps_the_finished_runs_and_no_worker_prints_a_traceback(tmp_path, signal_name, status, said):
    """A terminal's Ctrl-C reaches the whole process group: each Dask worker printed distributed's
    KeyboardInterrupt traceback, and the runs already finished were lost with the folder. A SIGTERM
    (a batch scheduler's stop) was said as Ctrl-C, status 130."""
    import os
    import signal
    import subprocess
    import sys
    import time

    import tomli_w

    spec = {**TINY, "grid": {"seed": list(range(400))}}
    (tmp_path / "many.toml").write_text(tomli_w.dumps(spec))
    child = subprocess.Popen([sys.executable, "-m", "hybridtrack", "sweep", "many.toml", "--out", "out",
                              "--workers", "2"], cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             start_new_session=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    seen = b""
    deadline = time.monotonic() + 120
    while max(map(int, re.findall(rb" (\d+)/400", seen)), default=0) < 3 and time.monotonic() < deadline:
        chunk = os.read(child.stderr.fileno(), 4096)  # the progress bar, until it counts three runs done
        if not chunk:
            break
        seen += chunk
    os.killpg(child.pid, getattr(signal, signal_name))
    error = (seen + child.stderr.read()).decode()
    assert child.wait(timeout=60) == status and f"hybridtrack: {said}; " in error, error[-3000:]
    assert "Traceback" not in error and "KeyboardInterrupt" not in error
    finished = pd.read_parquet(tmp_path / "out" / "runs.partial.parquet")
    assert 3 <= len(finished) < 400 and finished["run"].is_unique and finished["error"].isna().all()
    assert error.rstrip().endswith(f"the {len(finished)} of 400 runs that had finished are in "
                                   f"{os.path.join('out', 'runs.partial.parquet')}")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["runs.partial.parquet"]


def test_a_forced_sweep_removes_the_partial_runs_of_an_interrupted_one(tmp_path, capsys):
    """'replaced (--force): out/runs.partial.parquet' was said, and the earlier sweep's partial runs
    stayed beside the new table (found by helper-2)."""
    import tomli_w

    out = tmp_path / "out"
    out.mkdir()
    pd.DataFrame({"run": [0], "seed": [7]}).to_parquet(out / "runs.partial.parquet")
    (tmp_path / "s.toml").write_text(tomli_w.dumps({"base": {"freq": "30min"}, "grid": {"seed": [0]}}))
    assert main(["sweep", str(tmp_path / "s.toml"), "--out", str(out), "--workers", "1", "--force"]) == 0
    assert "replaced (--force): " in capsys.readouterr().out
    assert sorted(p.name for p in out.iterdir()) == ["runs.parquet", "sweep.toml", "tradeoff.png"]


def test_a_sigterm_while_the_workers_start_is_held_until_the_cluster_can_be_closed(monkeypatch):
    """Raised amid distributed's start, it left tracebacks of a half-started cluster (found by helper-2)."""
    import os
    import signal

    import dask.distributed

    from hybridtrack import cluster as cluster_module

    closed = []

    class Starting:
        def __init__(self, **options):
            os.kill(os.getpid(), signal.SIGTERM)  # while the workers start
            assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN  # they start deaf to Ctrl-C

        def close(self):
            closed.append(True)

    class Stopped(Exception):
        pass

    def stop(signum, frame):
        raise Stopped

    monkeypatch.setattr(dask.distributed, "LocalCluster", Starting)
    previous = signal.signal(signal.SIGTERM, stop)
    try:
        with pytest.raises(Stopped):
            cluster_module.dask_client(None, 1)
        assert closed == [True] and signal.getsignal(signal.SIGTERM) is stop
    finally:
        signal.signal(signal.SIGTERM, previous)


def _distributed_log_level():
    import logging

    return logging.getLogger("distributed.batched").getEffectiveLevel()


def test_local_workers_log_nothing_below_critical_and_the_setting_is_put_back(monkeypatch):
    """silence_logs quieted this process and the nanny's log in a worker only: a worker's
    distributed.batched logged at INFO, and at a SIGTERM to the process group one printed
    "Batched Comm Closed" with a traceback (seen once in the suite under load)."""
    import logging
    import os

    from hybridtrack.cluster import close, dask_client

    monkeypatch.delenv("DASK_LOGGING__DISTRIBUTED", raising=False)
    client, cluster = dask_client(None, 1)
    try:
        assert set(client.run(_distributed_log_level).values()) == {logging.CRITICAL}
    finally:
        close(client, cluster)
    assert "DASK_LOGGING__DISTRIBUTED" not in os.environ


def _closing_after(signum, calls):
    """`close` as a Ctrl-C (or SIGTERM) pressed again while the cluster closes would meet it."""
    import signal

    from hybridtrack import sweep as module

    real = module.close

    def close(client, cluster):
        calls.append(signum)
        signal.raise_signal(signum)
        real(client, cluster)

    return close


@pytest.fixture
def ctrl_c_raises():
    """Ctrl-C as a terminal's command meets it (Python's default handler) for the test, whatever an
    earlier test in this process left (the default suite failed this module's Ctrl-C test twice on
    a fresh clone, never alone or with its module: the handler it found did not raise)."""
    import signal

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_a_ctrl_c_while_the_cluster_closes_keeps_every_finished_run(monkeypatch, ctrl_c_raises):
    """A second Ctrl-C, pressed while the local cluster closed after the first (5 in a row), raised
    a bare KeyboardInterrupt out of run_sweep's cleanup: the runs that had finished (5 of 40) were
    lost, no runs.partial.parquet was written, and the cluster was left half closed. One that came
    as the cluster closed after the last run lost a whole sweep's table."""
    import signal

    from hybridtrack import sweep as module

    calls = []
    monkeypatch.setattr(module, "close", _closing_after(signal.SIGINT, calls))
    sweep = Sweep.from_dict({"base": {"freq": "30min"}, "grid": {"seed": [0, 1]}})
    with pytest.raises(module.SweepInterrupted) as stopped:
        run_sweep(sweep, workers=1, progress=False)
    assert calls == [signal.SIGINT] and stopped.value.planned == 2
    assert list(stopped.value.table["run"]) == [0, 1] and stopped.value.table["error"].isna().all()


def test_a_ctrl_c_after_the_first_while_the_cluster_closes_keeps_the_runs_of_the_first(monkeypatch, ctrl_c_raises):
    import signal

    from hybridtrack import cluster as workers
    from hybridtrack import sweep as module

    real = workers.finished

    def first_then_ctrl_c(client, futures):
        for outcome in real(client, futures):
            yield outcome
            raise KeyboardInterrupt  # Ctrl-C once the first run is in

    calls = []
    monkeypatch.setattr(module, "finished", first_then_ctrl_c)
    monkeypatch.setattr(module, "close", _closing_after(signal.SIGINT, calls))
    sweep = Sweep.from_dict({"base": {"freq": "30min"}, "grid": {"seed": [0, 1]}})
    with pytest.raises(module.SweepInterrupted) as stopped:
        run_sweep(sweep, workers=1, progress=False)
    assert calls == [signal.SIGINT] and len(stopped.value.table) == 1 and stopped.value.planned == 2


def test_a_colour_of_many_text_values_is_a_colour_bar_not_a_legend_off_the_figure():
    """A sweep over 60 start dates (text) drew a legend of 60 entries, running off the figure, and
    matplotlib warned on stderr that the layout had collapsed."""
    import warnings

    starts = [str(dt.date(2021, 1, 1) + dt.timedelta(days=k)) for k in range(60)]
    table = pd.DataFrame({"moves": np.arange(120), "rms": np.linspace(1, 0.1, 120), "start": starts * 2,
                          "seed": [0] * 60 + [1] * 60, "error": pd.array([None] * 120, dtype="string")})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        figure = plot_tradeoff(table, "moves", "rms", colour="start")
        figure.canvas.draw()  # the layout is made here
    axes, bar = figure.axes
    legend = axes.get_legend()
    assert legend is None or len(legend.get_texts()) <= 12
    assert bar.get_ylabel() == "start (60 values)"
    assert [t.get_text() for t in bar.get_yticklabels()] == ["2021-01-01", "2021-03-01"]
    few = plot_tradeoff(table[table["start"] < "2021-01-04"], "moves", "rms", colour="start")
    assert [t.get_text() for t in few.axes[0].get_legend().get_texts()][:3] == [
        "start = 2021-01-01", "start = 2021-01-02", "start = 2021-01-03"]


def test_a_second_sweep_into_the_folder_a_sweep_is_writing_is_refused_before_it_runs(tmp_path, monkeypatch, capsys):
    """Two sweeps into one --out both passed the check of the empty folder; the one that finished
    second was refused its files (they existed now) after all its runs, or with --force wrote its
    table beside the other's sweep.toml and plot, in whatever order their writes fell."""
    from hybridtrack import sweep as module

    path = tmp_path / "s.toml"
    path.write_text("[grid]\nseed = [0]\n")
    out = str(tmp_path / "out")
    second = []

    def runs_while_another_starts(sweep, **options):
        if not second:
            second.append(None)
            second[0] = main(["sweep", str(path), "--out", out, "--workers", "1"])
        return _table([{"run": 0, "seed": 0, **{m: 1.0 for m in METRICS}, "error": None}])

    monkeypatch.setattr(module, "run_sweep", runs_while_another_starts)
    assert main(["sweep", str(path), "--out", out, "--workers", "1"]) == 0
    assert second == [2] and "another run is writing there now" in capsys.readouterr().err
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["runs.parquet", "sweep.toml", "tradeoff.png"]


def test_a_grid_made_with_numpy_is_taken_as_the_numbers_it_holds_and_round_trips(tmp_path):
    """seed = list(np.arange(3)) ran every run, then save_sweep raised TypeError (int64 is not TOML
    serializable) writing sweep.toml: a traceback, after the table, where a sweep file belongs."""
    sweep = Sweep.from_dict({"base": {"days": np.int64(1)}, "grid": {"seed": list(np.arange(3)),
                                                                      "collector.aim": [[np.int64(0), 20.0, 100.0]]}})
    assert sweep.grid["seed"] == [0, 1, 2] and all(type(v) is int for v in sweep.grid["seed"])
    assert type(sweep.base["days"]) is int and type(sweep.grid["collector.aim"][0][0]) is int
    assert Sweep.from_toml(sweep.to_toml(tmp_path / "s.toml")).to_dict() == sweep.to_dict()


@pytest.mark.parametrize("data, message", [
    ({"grid": {"seed": [0, None]}}, r"s.toml: grid.seed: None cannot be written in a sweep file"),
    ({"base": {"weather": object}, "grid": {"seed": [0]}}, r"s.toml: base.weather: <class 'object'> cannot be written"),
    ({"base": {"config": {"drive": {"deadband": np.float64(0.3), "period": None}}}, "grid": {"seed": [0]}},
     r"s.toml: base.config.drive.period: None cannot be written in a sweep file"),
    # a Series' repr had run over three lines (helper-37)
    ({"grid": {"seed": pd.Series([1, 2])}}, r"s.toml: grid.seed: 0 1 1 2 dtype: int64 cannot be written in a sweep"),
])
def test_a_value_a_sweep_file_cannot_hold_is_refused_before_any_run(data, message):
    with pytest.raises(HybridtrackError, match=message) as refused:
        Sweep.from_dict(data, source="s.toml")
    assert "\n" not in str(refused.value)


@pytest.mark.parametrize("workers, runs, started", [(None, 2, 2), (8, 3, 3), (1, 3, 1), (2, 5, 2)])
def test_a_local_cluster_starts_no_more_workers_than_the_sweep_has_runs(monkeypatch, workers, runs, started):
    """A 2-run sweep on a 64-core machine started 64 worker processes (each a Python with numba and
    pandas imported), 62 of them idle, and waited for all of them to start."""
    from hybridtrack import sweep as module

    asked = []

    class Stop(Exception):
        pass

    def dask_client(scheduler, count, **options):
        asked.append(count)
        raise Stop

    monkeypatch.setattr(module, "dask_client", dask_client)
    monkeypatch.setattr(module, "cores", lambda: 64)
    with pytest.raises(Stop):
        run_sweep(Sweep.from_dict({"grid": {"seed": list(range(runs))}}), workers=workers, progress=False)
    assert asked == [started]


def test_a_sweep_without_a_point_to_plot_says_so_not_pandas_empty_frame(tmp_path, capsys):
    """Every run failed: 'Pareto front of moves against rms (0 of 0 runs):' was followed by pandas'
    'Empty DataFrame / Columns: [...] / Index: []'."""
    path = tmp_path / "s.toml"
    path.write_text("[base]\nfreq = '30min'\n[grid]\n\"drive.deadband\" = [-1, 20]\n")
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--workers", "1"]) == 2
    printed = capsys.readouterr().out
    assert "Empty DataFrame" not in printed and "Index: []" not in printed
    assert "Pareto front of moves against rms: no run has both (2 runs failed)\n" in printed


def test_a_local_cluster_takes_no_more_workers_than_the_longest_runs_fit_in_memory(monkeypatch):
    """Each run was checked against the memory budget alone, so two workers could each hold a run
    that fit only once. Here a 1-minute day is 1,440 steps of `BYTES_PER_STEP` (2.9 MB) and a
    2-day run 5.8 MB; the budget is set to 12 MB, which holds two of the longest but not three."""
    import hybridtrack.budget as budget
    import hybridtrack.sweep as sweeps

    monkeypatch.setattr(budget, "memory_budget", lambda: 12_000_000)
    sweep = Sweep.from_dict({"base": {"freq": "1min"}, "grid": {"days": [1, 2], "seed": [0, 1, 2]}})
    runs = sweep.runs()
    assert 2 * 2880 * budget.BYTES_PER_STEP <= 12_000_000 < 3 * 2880 * budget.BYTES_PER_STEP
    assert sweeps._workers_that_fit(sweep, runs, 4, chosen=False) == 2
    assert sweeps._workers_that_fit(sweep, runs, 2, chosen=True) == 2
    with pytest.raises(HybridtrackError, match=r"3 workers would each hold a run of up to 2 days at 1min \(about "
                                               r"6 MB\), 17 MB together, over the 12 MB the runs may use; 2 fit"):
        sweeps._workers_that_fit(sweep, runs, 3, chosen=True)
    monkeypatch.setattr(budget, "memory_budget", lambda: 1_000_000)  # not one: each run's own check says so
    assert sweeps._workers_that_fit(sweep, runs, 2, chosen=False) == 1


def test_a_dask_client_of_ours_leaves_dasks_scheduler_setting_and_default_client_alone():
    """dask_client's clients were made Dask's default: while one was open Dask's global scheduler
    setting read 'dask.distributed', and one not closed in turn left it so, after which a field's
    save failed in xarray's netCDF writer ('Requested dask.distributed scheduler but no Client
    active'; seen after this file's tests, now and then). No client of ours is the default."""
    import dask
    from dask.distributed import LocalCluster, default_client

    from hybridtrack.cluster import close, dask_client

    before = dask.config.get("scheduler", None)
    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        client, _ = dask_client(cluster.scheduler_address, None)
        try:
            assert dask.config.get("scheduler", None) == before
            with pytest.raises(ValueError, match="No clients found"):
                default_client()
        finally:
            close(client, None)
    assert dask.config.get("scheduler", None) == before


def test_a_sweeps_runs_choose_the_engine_on_the_sweeps_steps(monkeypatch, engine_choices):
    """Where the kernel is neither compiled nor cached, ``auto`` compiles it once the sweep's runs
    together pay for it: each run's own steps had kept every run on the reference loop."""
    import hybridtrack.kernel as kernel
    from hybridtrack.sweep import _all_steps

    sweep = Sweep.from_dict(TINY)
    assert _all_steps(sweep, sweep.runs()) == 6 * 96
    engines = engine_choices
    monkeypatch.setattr(kernel, "COMPILE_PAYS_AT", 6 * 96)
    first = run_one(sweep.base, sweep.runs()[0], "s.toml", 6 * 96)
    alone = run_one(sweep.base, sweep.runs()[0], "s.toml", 96)
    assert engines == ["compiled"] * 2 + ["auto"] * 2  # each run and its warm-start day
    assert first == alone  # the same run either way


def test_a_grids_unreadable_days_or_step_fail_their_runs_not_the_sweep():
    """Sizing the cluster reads every run's days and step; one that cannot be read (``days = 0``,
    ``freq = "2h"``) had ended the whole sweep before it started, naming neither file nor key.
    Now it is left to its run, whose row names the grid's value."""
    from hybridtrack.sweep import _all_steps, _workers_that_fit

    for grid in ({"days": [1, 0]}, {"freq": ["15min", "2h", "abc"]}):
        base = {k: v for k, v in TINY["base"].items() if k not in grid}
        sweep = Sweep.from_dict({"base": base, "grid": grid}, source="s.toml")
        runs = sweep.runs()
        assert _workers_that_fit(sweep, runs, 2, chosen=True) == 2
        assert _all_steps(sweep, runs) == 96
        key, value = next(iter(grid)), grid[next(iter(grid))][1]
        assert run_one(sweep.base, runs[1], "s.toml")["error"].startswith(f"HybridtrackError: grid.{key} = {value!r}:")


@pytest.mark.parametrize("compiles", [True, False])
def test_a_sweep_that_compiles_the_kernel_first_says_so_before_its_bar_stands_still(monkeypatch, capsys, compiles):
    """A fresh install's first sweep sat at 0 % for about two minutes while each worker compiled
    the kernel, with no word of it."""
    import hybridtrack.kernel as kernel
    from hybridtrack.sweep import _say_if_compiling

    seen = []
    monkeypatch.setattr(kernel, "compiles_first", lambda config, scans: seen.append((config, scans)) or compiles)
    sweep = Sweep.from_dict(TINY)
    _say_if_compiling(sweep, sweep.runs(), 1440)
    said = capsys.readouterr().err
    assert seen and isinstance(seen[0][0], SimulationConfig) and seen[0][1] == 1440
    assert ("compiling the controller kernel" in said) is compiles


def test_compiles_first_is_the_kernel_taken_neither_compiled_nor_cached(monkeypatch):
    import hybridtrack.kernel as kernel

    config = SimulationConfig(engine="compiled")
    for compiled_here, cached_on_disk, expected in ((False, False, True), (True, False, False), (False, True, False)):
        monkeypatch.setattr(kernel, "compiled", lambda: compiled_here)
        monkeypatch.setattr(kernel, "cached", lambda: cached_on_disk)
        assert kernel.compiles_first(config, 10) is expected
    assert kernel.compiles_first(SimulationConfig(engine="reference"), 10**9) is False


@pytest.mark.parametrize("seeds", [[1], [1, 2]])
def test_the_plots_legend_names_the_pareto_front(seeds):
    """The front's red line is in the legend, with or without the mean over seeds (the legend had
    been drawn before the front, and only where there were seeds to average)."""
    table = pd.DataFrame([{"moves": 100 * (k + 1) + s, "rms": 0.3 / (k + 1) + 0.01 * s, "drive.deadband": 0.1 * k,
                           "seed": s, "error": None} for k in range(3) for s in seeds])
    figure = plot_tradeoff(table, "moves", "rms", colour="drive.deadband")
    legend = figure.axes[0].get_legend()
    assert legend is not None and "Pareto front" in [text.get_text() for text in legend.get_texts()]


def test_dasks_advice_about_a_large_graph_is_not_printed_beside_the_bar():
    """A grid of 100,000 runs makes an 11 MB graph, and Dask printed its five-line advice about it
    (a UserWarning) beside the progress bar (helper-37). Here its threshold is lowered to a byte,
    so that any graph would draw it."""
    import warnings

    import dask

    with dask.config.set({"distributed.admin.large-graph-warning-threshold": "1B"}), \
            warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run_sweep(Sweep.from_dict({**TINY, "grid": {"seed": [0, 1]}}), workers=1, progress=False)
    assert not [w for w in caught if "large graph" in str(w.message)]


@pytest.mark.parametrize("reply, message", [
    (None, "nothing answered as a scheduler in 1 s"),  # accepts, never answers: had hung for ever
    (b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n" * 4,  # another service: numpy's MemoryError
     r"something answers there, but not as a Dask scheduler \(its reply read as a message too large to hold\)"),
])
def test_a_port_that_is_no_dask_scheduler_is_refused_in_time(monkeypatch, capfd, reply, message):
    """A port that accepts and never answers had hung a sweep for ever (Dask's connect timeout does
    not bound the handshake); an HTTP proxy's reply ended in a 3 EiB MemoryError's traceback, then
    the half-made client's TimeoutError at exit (helper-39)."""
    import socket

    import hybridtrack.cluster as cluster_module

    monkeypatch.setattr(cluster_module, "ANSWER_SECONDS", 1.0)
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(4)
    held = []

    def serve():
        while True:
            try:
                connection, _ = server.accept()
            except OSError:
                return
            held.append(connection)
            if reply is not None:
                connection.sendall(reply)

    threading.Thread(target=serve, daemon=True).start()
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    try:
        started = time.monotonic()
        with pytest.raises(HybridtrackError, match=f"cannot reach the Dask scheduler at {address}: {message}"):
            cluster_module.dask_client(address, None)
        assert time.monotonic() - started < 15.0
    finally:
        server.close()
        for connection in held:
            connection.close()
    assert "Traceback" not in capfd.readouterr().err


@pytest.mark.parametrize("values, shown", [
    ([float("nan"), 9007199254740993], ["nan", "9007199254740993"]),  # the float nearest had been ...992.0
    ([1, 1.0], ["1", "1.0"]),
])
def test_whole_numbers_beside_floats_in_a_grid_column_keep_every_digit(values, shown):
    """A grid key of whole numbers beside a float had been one float64 column: the table named a
    run by a seed it was not given (helper-39). Such a column is the values as given, as text."""
    rows = [{"run": k, "seed": value, **{m: None for m in METRICS}, "error": None} for k, value in enumerate(values)]
    assert _table(rows)["seed"].tolist() == shown


@pytest.mark.parametrize("data, where", [
    ({"base": {"seed": 7}, "grid": {"seed": [0, 1]}}, "base.seed"),
    ({"base": {"drive.deadband": 0.2}, "grid": {"drive.deadband": [0.1]}}, "base.drive.deadband"),
    ({"base": {"config": {"drive": {"deadband": 0.3}}}, "grid": {"drive.deadband": [0.1, 0.2]}}, r"\[base.config\]"),
])
def test_a_key_set_by_the_base_and_the_grid_is_refused(data, where):
    """Every run took the grid's value, and the base's was dropped without a word (helper-39)."""
    key = next(iter(data["grid"]))
    with pytest.raises(HybridtrackError, match=rf"s\.toml: {where} and grid\.{key} both set {key}, and every run takes "
                                               r"the grid's value; give it once \(in \[grid\] to vary it\)"):
        Sweep.from_dict(data, source="s.toml")


def test_a_sweep_built_directly_is_checked_as_its_file_would_be(tmp_path):
    """Sweep(...) had skipped from_dict's checks: a numpy seed ended in a TypeError writing
    sweep.toml, a misspelt key ran every row to a failure, x = y was written and then refused."""
    built = Sweep(base={"site": "lanzhou"}, grid={"seed": [np.int64(0), np.int64(1)]})
    assert built.grid == {"seed": [0, 1]} and type(built.grid["seed"][0]) is int
    assert Sweep.from_toml(built.to_toml(tmp_path / "s.toml")) == built  # where it was read is not compared
    with pytest.raises(HybridtrackError, match="grid.drive.deadbnd: unknown key; did you mean drive.deadband"):
        Sweep(base={}, grid={"drive.deadbnd": [0.1]})
    with pytest.raises(HybridtrackError, match="plot.x and plot.y are both 'rms'"):
        Sweep(base={}, grid={"seed": [1]}, x="rms", y="rms")
    with pytest.raises(HybridtrackError, match=r"\[base\] must be a table, got None"):
        Sweep(base=None, grid={"seed": [1]})


def test_a_sweeps_sites_are_named_as_the_runs_name_them():
    """'Lanzhou' had been kept as written in the table, beside the ablation's 'lanzhou'; a name no
    site has is kept, for its runs to refuse by it."""
    assert Sweep(base={"site": "NANJING"}, grid={"seed": [1]}).base["site"] == "nanjing"
    assert Sweep(base={}, grid={"site": ["Lanzhou", "atlantis"]}).grid["site"] == ["lanzhou", "atlantis"]
