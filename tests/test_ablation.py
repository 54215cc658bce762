"""The ablation's numbers by hand: why a closed loop lost energy, the table's pooling, and the
same runs whatever the number of worker processes.

The headline tests (tests/test_world_controller.py) compare policies with one another; these hold
the attribution and the table to their definitions (hybridtrack.ablation's docstring)."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hybridtrack.ablation import AblationPlan, AblationResult, _metrics, ablate
from hybridtrack.collectors import Collector


@pytest.mark.parametrize("unit", ["ns", "us", "s"])
def test_the_lost_energy_is_put_down_to_pull_or_to_a_lost_sun_by_hand(unit):
    # a north-south trough (θ½ = 1°), 1-minute steps; η(e) = 1 / (1 + e⁴)
    #   step mode          status        DNI  error  lost = DNI (1 − η)         counted as
    #   0    sensor        ok            800  1.0    800 · 1/2      = 400       pull (followed)
    #   1    sensor        outlier       600  2.0    600 · 16/17    = 564.706   pull (read, gated out)
    #   2    sensor        low light     500  1.0    500 · 1/2      = 250       lost sun
    #   3    search        not read      400  nan    400 · 1        = 400       lost sun (no error: all lost)
    #   4    astronomical  not read      300  1.0    300 · 1/2      = 150       neither
    #   5    stow_wind     not read      900  30.0   not tracking   = 0
    # total 1764.706; pull (400 + 564.706) / total = 0.54667; lost sun (250 + 400) / total = 0.36833
    # any resolution of the stamps (a µs index, pandas 3's default for date_range and
    # read_weather's, had given lost_kwh 1000 times too small)
    index = pd.date_range("2021-06-21 12:00", periods=6, freq="1min", tz="Asia/Shanghai", unit=unit)
    log = pd.DataFrame({"dni": [800.0, 600.0, 500.0, 400.0, 300.0, 900.0],
                        "mode": ["sensor", "sensor", "sensor", "search", "astronomical", "stow_wind"],
                        "sensor_status": ["ok", "outlier", "low light", "not read", "not read", "not read"],
                        "error": [1.0, 2.0, 1.0, np.nan, 1.0, 30.0]}, index=index)
    summary = {"tracking_error_deg": {"rms": 0.5, "p95": 0.9}, "energy_capture": 0.8,
               "mode_share": {"sensor": 0.5}}
    row = _metrics(SimpleNamespace(summary=summary, log=log, collector=Collector("trough-ns")))
    total = 400 + 600 * 16 / 17 + 250 + 400 + 150
    assert row["pull_loss_share"] == pytest.approx((400 + 600 * 16 / 17) / total, rel=1e-12)
    assert row["lost_sun_loss_share"] == pytest.approx((250 + 400) / total, rel=1e-12)
    # W/m² over 1-minute steps: Σ lost × 1/60 h / 1000 = kWh/m²
    assert row["lost_kwh"] == pytest.approx(total / 60 / 1000, rel=1e-12)
    assert (row["rms"], row["p95"], row["energy"], row["sensor_share"]) == (0.5, 0.9, 0.8, 0.5)


def test_the_table_pools_the_shares_by_the_energy_each_run_lost():
    runs = pd.DataFrame({"policy": ["sensor", "sensor", "sensor"], "rms": [0.2, 0.4, 0.9], "p95": [0.3, 0.5, 1.2],
                         "energy": [0.99, 0.97, 0.90], "pull_loss_share": [1.0, 0.5, np.nan],
                         "lost_sun_loss_share": [0.0, 0.25, np.nan], "lost_kwh": [1.0, 3.0, 0.0]})
    table = AblationResult(runs).table
    row = table.loc["sensor"]
    assert row["rms mean"] == pytest.approx(0.5) and row["rms worst"] == 0.9  # (0.2 + 0.4 + 0.9) / 3
    assert row["energy mean"] == pytest.approx(2.86 / 3) and row["energy worst"] == 0.90  # 0.99 + 0.97 + 0.90
    # pooled over the runs that lost energy: (1.0 · 1 + 0.5 · 3) / 4 = 0.625; (0 · 1 + 0.25 · 3) / 4 = 0.1875
    assert row["pull loss share"] == pytest.approx(0.625) and row["lost-sun loss share"] == pytest.approx(0.1875)
    assert row["rms 95% low"] <= row["rms mean"] <= row["rms 95% high"]


def test_the_runs_are_the_same_in_one_process_or_two():
    """Every day is seeded: the worker processes are a fast path whose reference is one process."""
    plan = AblationPlan(sites=("lanzhou",), seasons=("summer", "winter"), seeds=(1,), collectors=("trough-ns",),
                        policies=("hybrid", "sensor"))
    one, two = ablate(plan, workers=1).runs, ablate(plan, workers=2).runs
    assert len(one) == 4
    pd.testing.assert_frame_equal(one, two)
