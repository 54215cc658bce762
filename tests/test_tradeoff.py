"""The drive's deadband and scan period against pointing error and moves a day."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError, sites
from hybridtrack.cli import main
from hybridtrack.collectors import Collector
from hybridtrack.simulation import SimulationConfig
from hybridtrack.tradeoff import SUBSTEPS, TradeoffPlan, held_error, tradeoff

#: Degrees: how much a sunny day's RMS moves with the seed alone at one deadband (standard
#: deviation 0.002-0.004° over seeds 1-5 at Lanzhou in June, deadbands 0.1° and 0.4°).
RMS_NOISE = 0.005


def test_more_deadband_moves_less_and_points_no_better_on_a_sunny_day():
    plan = TradeoffPlan(deadbands=(0.1, 0.2, 0.4, 0.8), sites=("lanzhou",), seasons=("summer",))
    runs = tradeoff(plan).runs.sort_values("deadband")
    assert np.all(np.diff(runs["moves_per_day"]) < 0)
    for metric in ("rms", "held_rms"):
        assert np.all(np.diff(runs[metric]) > -RMS_NOISE), metric


def test_the_held_error_is_the_ramp_of_a_sun_running_away_between_scans():
    """A collector put exactly on its target at every scan, the target moving `step` a scan: in
    between it lags by step·k/SUBSTEPS at the k-th sample, whatever the light."""
    index = pd.date_range("2021-06-21 10:00", periods=61, freq="2min", tz="Asia/Shanghai")
    step = 0.5
    target = 40.0 + step * np.arange(len(index))
    log = pd.DataFrame({"target_true": target, "angle": target, "mode": "sensor", "dni": 900.0}, index=index)
    result = SimpleNamespace(log=log, site=sites.get("lanzhou"), collector=Collector("trough-ns"),
                             config=SimulationConfig())
    rms, p95 = held_error(result)
    lags = step * np.arange(SUBSTEPS) / SUBSTEPS
    assert rms == pytest.approx(np.sqrt(np.mean(lags**2)))
    assert p95 == pytest.approx(lags[-1])


def test_ablate_tradeoff_writes_its_table_and_plot(tmp_path, capsys):
    out = tmp_path / "trade"
    assert main(["ablate", "--tradeoff", "--sites", "nanjing", "--seasons", "winter", "--weather", "sunny",
                 "--seeds", "1", "--deadbands", "0.2,0.8", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "held_rms" in text and "moves_per_day" in text
    table = pd.read_csv(out / "table.csv")
    assert list(table["deadband"]) == [0.2, 0.8]
    assert (out / "tradeoff.png").stat().st_size > 0


@pytest.mark.parametrize("flags,message", [(["--deadbands", "0.1,x"], "--deadbands"),
                                           (["--deadbands", "0.1,nan"], "finite"),
                                           (["--deadbands", "20"], "deadband"),
                                           (["--periods", "1h"], "period")])
def test_bad_tradeoff_grids_are_refused(flags, message, capsys):
    assert main(["ablate", "--tradeoff", *flags]) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("options, message", [
    # a float raised TypeError; a text was run letter by letter ("period '1' is outside 10 s to 30 min")
    ({"deadbands": 0.1}, r"tradeoff: deadbands must be a list of degrees such as \(0.1, 0.4\), got 0.1"),
    ({"periods": "1min"}, r"tradeoff: periods must be a list of steps such as \('1min', '5min'\), got '1min'"),
    ({"periods": (60,)}, r"tradeoff: period 60 is not a step such as '1min' or '10s'"),
    ({"periods": ("1T",)}, r"tradeoff: period '1T' is not a step"),  # pandas takes it, the synthetic sky did not
    # each ran its days twice, as two rows of runs, and the table's mean over them counted them double
    ({"deadbands": (0.1, 0.4, 0.10)}, r"tradeoff: deadband 0.1 is given twice"),
    ({"periods": ("1min", "60s")}, r"tradeoff: period '60s' is given twice \(as '1min' and '60s'\)"),
])
def test_a_plan_that_is_not_a_grid_of_distinct_values_is_refused(options, message):
    with pytest.raises(HybridtrackError, match=message):
        TradeoffPlan(**options)


def test_a_plan_takes_lists_as_well_as_tuples():
    plan = TradeoffPlan(deadbands=[0.1, 0.4], periods=["1min", "90s"], sites=("lanzhou",), seasons=("summer",))
    assert [(d["period"]) for d in plan.days()] == ["1min", "90s"] and plan.deadbands == (0.1, 0.4)
