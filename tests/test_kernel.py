"""The compiled kernel (hybridtrack.kernel) against the readable reference controller and world:
identical modes, sensor statuses, sky and events, angles and every other number to 1e-9."""

import ast
import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import hybridtrack.kernel as kernel
from hybridtrack import simulate
from hybridtrack.control import STRATEGIES
from hybridtrack.errors import HybridtrackError
from hybridtrack.faults import SCENARIOS
from hybridtrack.simulation import FAULTS, SimulationConfig
from hybridtrack.sky import synthetic
from hybridtrack.skyinputs import SkyInputConfig
from hybridtrack.sun import solar_position
from hybridtrack.world import Imperfections

COLLECTORS = ("trough-ns", "trough-ew", "fresnel", "heliostat")
TOLERANCE = 1e-9


def both(frame, site, *, config=None, **options):
    """The same run on the reference loop and on the kernel."""
    config = config or SimulationConfig()
    return [simulate(frame, site, config=dataclasses.replace(config, engine=engine), **options)
            for engine in ("reference", "compiled")]


def assert_same_numbers(reference, compiled, where):
    reference, compiled = np.asarray(reference, float), np.asarray(compiled, float)
    assert reference.shape == compiled.shape, where
    assert np.array_equal(np.isnan(reference), np.isnan(compiled)), where
    assert np.allclose(reference, compiled, rtol=0.0, atol=TOLERANCE, equal_nan=True), \
        f"{where}: {np.nanmax(np.abs(reference - compiled))}"


def assert_same_run(reference, compiled):
    """Every log column, every event, the summary and the memory the run carries over."""
    assert list(reference.log.columns) == list(compiled.log.columns)
    for column in reference.log.columns:
        ours, theirs = reference.log[column], compiled.log[column]
        if ours.dtype.kind in "fc":
            assert_same_numbers(ours, theirs, column)
        else:
            assert ours.astype(object).equals(theirs.astype(object)), column
    pd.testing.assert_frame_equal(reference.events, compiled.events)
    assert_same_summary(reference.summary, compiled.summary, "summary")
    assert_same_summary(reference.memory, compiled.memory, "memory")


def assert_same_summary(reference, compiled, where):
    if isinstance(reference, dict):
        assert set(reference) == set(compiled), where
        for key in reference:
            assert_same_summary(reference[key], compiled[key], f"{where}.{key}")
    elif isinstance(reference, (list, tuple, np.ndarray)) and np.asarray(reference).dtype.kind in "fiub":
        assert_same_numbers(reference, compiled, where)
    elif isinstance(reference, float):
        assert_same_numbers([reference], [compiled], where)
    else:
        assert reference == compiled, where


@pytest.fixture(scope="module")
def mixed_day():
    return synthetic("lanzhou", "2021-06-21", weather="mixed", seed=3, gusts_per_day=2.0)


def _strategies_on_collectors():
    """Every strategy on every collector; the default run keeps every strategy on the heliostat
    (two axes, the most of the controller) and the hybrid on each collector, the rest are slow."""
    for collector in COLLECTORS:
        for strategy in STRATEGIES:
            quick = collector == "heliostat" or strategy == "hybrid"
            yield pytest.param(strategy, collector, marks=() if quick else pytest.mark.slow,
                               id=f"{strategy}-{collector}")


@pytest.mark.parametrize("strategy,collector", list(_strategies_on_collectors()))
def test_every_strategy_on_every_collector_runs_the_same_compiled(mixed_day, strategy, collector):
    assert_same_run(*both(mixed_day, "lanzhou", strategy=strategy, collector=collector))


@pytest.mark.parametrize("collector", ["trough-ns", "heliostat"])
@pytest.mark.parametrize("fault", FAULTS)
def test_every_injected_fault_runs_the_same_compiled(mixed_day, fault, collector):
    n = len(mixed_day)
    window = (np.arange(n) >= 660) & (np.arange(n) < 780)
    axes = 2 if collector == "heliostat" else 1
    values = {
        "sensor": np.where(window, 0.1, np.nan), "sensor_dropout": window, "sensor_drift": np.where(window, 0.5, 0.0),
        "encoder": np.where(np.arange(n) == 700, 5.625, 0.0), "encoder_frozen": window,
        "clock": np.where(np.arange(n) >= 720, 600.0, 0.0)}[fault]
    if fault == "sensor" and axes == 2:
        values = np.column_stack([values, values])
    assert_same_run(*both(mixed_day, "lanzhou", collector=collector, faults={fault: values}))


def scenario_runs(name):
    scenario = SCENARIOS[name]
    frame, faults, changes, _ = scenario.build(scenario.site)
    config = SimulationConfig()
    for part, values in changes.items():
        config = dataclasses.replace(config, **{part: dataclasses.replace(getattr(config, part), **values)})
    return both(frame, scenario.site, collector=scenario.collector, config=config, faults=faults or None)


@pytest.mark.parametrize("name", ["sensor-drift", "encoder-creep", "encoder-frozen-gust", "clock-creep", "wind-stuck",
                                  "heliostat-wrap"])
def test_fault_scenarios_run_the_same_compiled(name):
    assert_same_run(*scenario_runs(name))


@pytest.mark.parametrize("reading", [-5.0, np.inf])
def test_an_unreadable_wind_and_a_timed_stow_from_a_reckoned_position_run_the_same_compiled(mixed_day, reading):
    """A wind reading no anemometer gives stows with its own reason; an encoder frozen overnight
    misses the morning's first move, and a gust's timed stow is measured from where that move left it."""
    n = len(mixed_day)
    wind = np.clip(mixed_day["wind_speed"].to_numpy(), 0.0, 11.0)
    wind[600:610] = reading
    wind[700:720] = 25.0
    frozen = (np.arange(n) >= 180) & (np.arange(n) < 1380)
    assert_same_run(*both(mixed_day.assign(wind_speed=wind), "lanzhou", faults={"encoder_frozen": frozen}))
    assert_same_run(*both(mixed_day.assign(wind_speed=wind), "lanzhou"))


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SCENARIOS))
def test_every_fault_scenario_runs_the_same_compiled(name):
    assert_same_run(*scenario_runs(name))


def test_a_warm_start_and_a_cold_one_both_run_the_same_compiled(mixed_day):
    for warm in (True, False):
        assert_same_run(*both(mixed_day, "lanzhou", warm_start=warm))


def test_nights_in_bulk_or_scan_by_scan_run_the_same_compiled(mixed_day):
    bulk = simulate(mixed_day, "lanzhou", config=SimulationConfig(engine="compiled"))
    scans = simulate(mixed_day, "lanzhou", config=SimulationConfig(engine="compiled"), bulk_nights=False)
    assert_same_run(bulk, scans)


@pytest.mark.parametrize("collector", ["fresnel", "heliostat"])
def test_a_run_without_fit_columns_scores_and_ends_the_same_as_the_reference(mixed_day, collector):
    """A field's collector that keeps no log runs without the mount fit at each scan: its scores,
    events and carried memory are still the reference loop's."""
    from hybridtrack.simulation import track

    runs = {engine: track(mixed_day, "lanzhou", collector=collector, fit_columns=engine == "reference",
                          config=SimulationConfig(engine=engine)) for engine in ("reference", "compiled")}
    lean, full = runs["compiled"], runs["reference"]
    assert lean.out.fit.shape == (len(mixed_day), 0) and full.out.fit.shape[1] > 0
    assert_same_summary(full.scores(full.events()), lean.scores(lean.events()), "scores")
    pd.testing.assert_frame_equal(full.events(), lean.events())
    assert_same_summary(full.memory(), lean.memory(), "memory")
    assert_same_numbers(full.world.angles, lean.world.angles, "angles")


def test_the_kernel_reports_progress_over_every_scan(mixed_day):
    done = []
    simulate(mixed_day, "lanzhou", config=SimulationConfig(engine="compiled"), progress=done.append)
    assert sum(done) == len(mixed_day)


def test_the_engine_round_trips_through_toml_and_unknown_ones_are_refused(tmp_path):
    config = SimulationConfig(engine="reference")
    assert SimulationConfig.from_toml(config.to_toml(tmp_path / "run.toml")) == config
    with pytest.raises(HybridtrackError, match="engine"):
        SimulationConfig(engine="fortran")


def test_auto_takes_the_reference_path_for_what_the_kernel_does_not_run(mixed_day):
    filterpy = SimulationConfig(controller=dataclasses.replace(SimulationConfig().controller, kalman="filterpy"))
    assert kernel.unsupported(filterpy) and not kernel.uses_kernel(filterpy, kernel.COMPILE_PAYS_AT)
    assert kernel.uses_kernel(SimulationConfig(), kernel.COMPILE_PAYS_AT)
    with pytest.raises(HybridtrackError, match="fast"):
        kernel.uses_kernel(dataclasses.replace(filterpy, engine="compiled"))


def test_auto_takes_the_kernel_only_where_it_is_quicker(monkeypatch, mixed_day):
    """Compiled in this process: always; loaded from the disk cache: from LOAD_PAYS_AT scans;
    compiled afresh: from COMPILE_PAYS_AT scans; otherwise the reference (the same results)."""
    config, day = SimulationConfig(), len(mixed_day)
    simulate(mixed_day, "lanzhou", config=dataclasses.replace(config, engine="compiled"))
    assert kernel.compiled() and kernel.cached()  # a compiled run leaves the loop in numba's disk cache
    assert kernel.uses_kernel(config, day)
    monkeypatch.setattr(kernel, "compiled", lambda: False)
    monkeypatch.setattr(kernel, "cached", lambda: True)
    assert not kernel.uses_kernel(config, day) and kernel.uses_kernel(config, kernel.LOAD_PAYS_AT)
    monkeypatch.setattr(kernel, "cached", lambda: False)
    assert not kernel.uses_kernel(config, kernel.COMPILE_PAYS_AT - 1)
    assert kernel.uses_kernel(config, kernel.COMPILE_PAYS_AT)
    assert kernel.uses_kernel(dataclasses.replace(config, engine="compiled"), day)
    assert not kernel.uses_kernel(dataclasses.replace(config, engine="reference"), kernel.COMPILE_PAYS_AT)


def test_a_fresh_install_runs_a_day_on_auto_without_compiling(tmp_path):
    script = (
        "import hybridtrack.kernel as kernel\n"
        "from hybridtrack import simulate\n"
        "from hybridtrack.kernel.loop import run_scans\n"
        "from hybridtrack.sky import synthetic\n"
        "assert not kernel.cached()\n"
        "simulate(synthetic('lanzhou', '2021-06-21', weather='mixed', seed=1), 'lanzhou')\n"
        "print(len(run_scans.signatures))\n")
    env = dict(os.environ, PYTHONPATH=str(Path(kernel.__file__).parents[2]), NUMBA_CACHE_DIR=str(tmp_path))
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == "0"


def test_the_compiled_controller_imports_nothing_of_the_world():
    source = Path(kernel.__file__).parent / "controller.py"
    for node in ast.walk(ast.parse(source.read_text())):
        if isinstance(node, ast.ImportFrom):
            module = node.module or ""
            named = module.split(".")[-1]
            assert not module.startswith("..") and named not in ("world", "sensor", "sky", "simulation"), module
            assert node.level < 2 or module.split(".")[0] == "control", module


def test_without_numba_the_package_runs_the_reference_with_one_warning():
    script = (
        "import sys, warnings\n"
        "sys.modules['numba'] = None\n"
        "warnings.simplefilter('always')\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    from hybridtrack import simulate\n"
        "    from hybridtrack.sky import synthetic\n"
        "    from hybridtrack.fuzzy import FuzzyWeatherClassifier\n"
        "    frame = synthetic('lanzhou', '2021-06-21 10:00', '2021-06-21 12:00', weather='sunny', seed=1)\n"
        "    simulate(frame, 'lanzhou', bulk_nights=False)\n"
        "    simulate(frame, 'lanzhou')\n"
        "    FuzzyWeatherClassifier().score(246.0, 27.0)\n"
        "ours = [str(w.message) for w in caught if 'numba' in str(w.message)]\n"
        "print(len(ours))\n")
    env = dict(os.environ, PYTHONPATH=str(Path(kernel.__file__).parents[2]))
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == "1"


def replaced(**parts):
    """A config with some of its parts' fields changed: ``controller={"lead": False}``."""
    config = SimulationConfig()
    for part, values in parts.items():
        current = getattr(config, part)
        config = dataclasses.replace(config, **{part: dataclasses.replace(current, **values) if isinstance(values, dict)
                                                else values})
    return config


@pytest.mark.parametrize("config", [
    replaced(sky=SkyInputConfig.published()),
    replaced(sky={"low_sun": "unknown", "smoothing": None}),
    replaced(controller={"lead": False, "sun_model": "spa", "working_hours": ("07:00", "18:30")}),
    replaced(controller={"wind_missing": "track"}, imperfections=Imperfections.none()),
    replaced(drive={"deadband": 0.1, "encoder_bits": 16}, seed=7),
], ids=["published-sky", "no-smoothing-no-low-sun-label", "no-lead-spa-hours", "track-missing-wind", "fine-drive"])
@pytest.mark.parametrize("strategy", ["hybrid", "sensor"])
def test_other_configs_run_the_same_compiled(mixed_day, config, strategy):
    assert_same_run(*both(mixed_day, "lanzhou", config=config, strategy=strategy))


def test_a_recorded_photocurrent_and_a_frame_without_wind_or_diffuse_run_the_same_compiled(mixed_day):
    rng = np.random.default_rng(0)
    current = 30.0 + rng.uniform(0, 300, len(mixed_day))
    recorded = mixed_day.drop(columns=["wind_speed", "dhi"]).assign(photocurrent=current)
    config = replaced(controller={"wind_missing": "track"})
    for strategy in ("hybrid", "sensor"):
        assert_same_run(*both(recorded, "lanzhou", config=config, strategy=strategy))


def test_a_recorded_photocurrent_with_gaps_fits_the_mount_the_same_compiled(mixed_day):
    """hybrid-always fits the mount through the gaps, each reading weighed as at the sun threshold."""
    current = mixed_day.assign(photocurrent=simulate(mixed_day, "lanzhou").log["intensity_ma"].to_numpy())
    current.iloc[600:660, current.columns.get_loc("photocurrent")] = np.nan
    assert_same_run(*both(current, "lanzhou", strategy="hybrid-always"))


@pytest.mark.parametrize("policy,distrust", [("sensor", "60min"), ("model", "25min")])
def test_either_disagreement_policy_runs_the_same_compiled(policy, distrust):
    scenario = SCENARIOS["encoder-step"]
    frame, faults, _, _ = scenario.build(scenario.site)
    config = replaced(controller={"on_disagreement": policy, "distrust": distrust})
    runs = both(frame, scenario.site, collector=scenario.collector, config=config, faults=faults)
    assert runs[1].events["reason"].str.contains("sensor trusted" if policy == "sensor" else "25 min").any()
    assert_same_run(*runs)


@pytest.mark.parametrize("collector", ["trough-ns", "heliostat"])
def test_a_recorded_pointing_signal_runs_the_same_compiled(mixed_day, collector):
    rng = np.random.default_rng(2)
    n = len(mixed_day)
    recorded = mixed_day.assign(pointing=np.where(rng.random(n) < 0.2, np.nan, rng.normal(0.0, 0.3, n)))
    if collector == "heliostat":
        recorded = recorded.assign(pointing_2=rng.normal(0.0, 0.3, n))
    assert_same_run(*both(recorded, "lanzhou", collector=collector))


def test_the_clock_watch_alarms_the_same_compiled():
    """Both of the clock watch's alarms, worded by the kernel as the reference words them, and the
    summary's clock fit (a trough drifting a minute a day, a heliostat five minutes wrong: two
    sunny days, as its sensor's collimation error leaves one day's estimate under 4σ)."""
    drifting = replaced(imperfections={"clock_drift": 60.0, "clock_error": 0.0, "commissioned_days_ago": 0.0}, seed=1)
    runs = both(synthetic("lanzhou", "2021-06-21", "2021-06-23", weather="sunny", seed=1), "lanzhou",
                config=drifting, collector="trough-ns")
    assert any("clock drifting" in reason for reason in runs[1].events["reason"])
    assert "drift_s_per_day" in runs[1].summary["clock"]
    assert_same_run(*runs)
    wrong = replaced(imperfections={"clock_error": 300.0, "clock_drift": 0.0}, seed=1)
    runs = both(synthetic("delingha", "2018-06-21", "2018-06-22", weather="sunny", seed=1), "delingha",
                config=wrong, collector="heliostat")
    assert any("clock off by" in reason for reason in runs[1].events["reason"])
    assert_same_run(*runs)


def test_a_rolled_heliostat_pedestal_runs_the_same_compiled(mixed_day):
    rolled = replaced(imperfections={"axis_roll_error": 0.4})
    runs = both(mixed_day, "lanzhou", config=rolled, collector="heliostat")
    plain = simulate(mixed_day, "lanzhou", collector="heliostat", config=replaced(engine="compiled"))
    assert not np.array_equal(runs[1].log["target_true"], plain.log["target_true"])  # the roll reaches the world
    assert any(column.startswith("fit_") for column in runs[1].log.columns)
    assert_same_run(*runs)


@pytest.mark.filterwarnings("ignore::hybridtrack.simulation.NightsLeftOutWarning")  # a gap into a morning, on purpose
def test_irregular_scans_run_the_same_compiled(mixed_day):
    keep = np.random.default_rng(1).random(len(mixed_day)) > 0.3
    assert_same_run(*both(mixed_day[keep], "lanzhou"))


@pytest.mark.parametrize("collector", ["trough-ns", "heliostat"])
def test_a_frame_without_its_nights_runs_the_same_compiled(collector):
    """Nights slept in the frame's gaps (`ControllerPlan.slept`), with the clock watch's evening
    verdict, on a trough and a heliostat."""
    days = synthetic("lanzhou", "2021-06-20", "2021-06-22", weather="mixed", seed=4)
    day_only = days[solar_position(days.index, "lanzhou")["altitude"].to_numpy() > -2.0]
    runs = both(day_only, "lanzhou", collector=collector)
    assert runs[1].events["reason"].str.contains("asleep through it").sum() == 2
    assert_same_run(*runs)


@pytest.mark.slow
@pytest.mark.parametrize("collector", ["trough-ns", "heliostat"])
def test_a_site_year_runs_the_same_compiled(collector):
    year = synthetic("nanjing", "2013-01-01", "2013-12-31", weather="climate", seed=1, gusts_per_day=0.5)
    assert_same_run(*both(year, "nanjing", collector=collector))


def test_a_changed_source_empties_the_kernels_cache(tmp_path):
    from hybridtrack.kernel import jit

    (tmp_path / "controller.run_scans-1.py311.nbi").write_text("stale")
    jit._empty_stale_cache(tmp_path)
    assert not list(tmp_path.glob("*.nbi")) and (tmp_path / "kernel-sources.sha256").read_text() == jit._sources_hash()
    (tmp_path / "controller.run_scans-1.py311.nbi").write_text("fresh")
    jit._empty_stale_cache(tmp_path)
    assert list(tmp_path.glob("*.nbi"))


# -- piece by piece: each compiled piece against the reference class it restates --------------------

def _reference_pair(frame, kind):
    """A reference world and controller of a hybrid `kind` at Lanzhou over `frame`, built as
    `simulate` builds them (without a warm start)."""
    from hybridtrack import sites
    from hybridtrack.collectors import Collector
    from hybridtrack.control import Controller, make_plan
    from hybridtrack.control.plan import east_park
    from hybridtrack.fuzzy import FuzzyWeatherClassifier
    from hybridtrack.simulation import _drives
    from hybridtrack.world import World, controller_clock, installed_site

    site, collector, config = sites.get("lanzhou"), Collector(kind), SimulationConfig()
    drives = _drives(collector, config)
    world = World(frame, site, collector, config.imperfections, config.sensor, drives, 0, {})
    plan = make_plan(controller_clock(frame.index, config.imperfections, {}), world.minutes,
                     installed_site(site, config.imperfections), collector, config.controller)
    controller = Controller(config.controller, drives, plan, FuzzyWeatherClassifier(), config.sky, 30.0,
                            east_park(collector))
    return world, controller


@pytest.fixture(scope="module")
def packed():
    """A reference controller of a hybrid heliostat, and its settings and state as the kernel has them."""
    from hybridtrack.kernel import bridge

    frame = synthetic("lanzhou", "2021-06-21 10:00", "2021-06-21 12:00", weather="sunny", seed=1)
    world, controller = _reference_pair(frame, "heliostat")
    return controller, bridge._settings(controller), bridge._state(controller, world.minutes)


def test_a_set_stop_event_ends_the_compiled_run_before_its_next_chunk():
    """What `simulate` sets on Ctrl-C while the loop runs beside it: the run stops at a chunk's
    end; without it every scan is run."""
    import threading

    from hybridtrack.kernel import bridge

    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=1)
    stopped = threading.Event()
    stopped.set()
    for stop, scans in ((stopped, 0), (threading.Event(), len(frame))):
        world, controller = _reference_pair(frame, "trough-ns")
        done = []
        bridge.run_compiled(world, controller, done.append, True, stop)
        assert sum(done) == scans


def test_the_sky_table_compiled_scores_as_the_reference(packed):
    from hybridtrack.kernel.controller import table_code, table_score

    controller, cfg, _ = packed
    table = controller.sky.table
    rng = np.random.default_rng(0)
    for intensity, variation in zip(rng.uniform(-50, 400, 2000), rng.uniform(-10, 250, 2000)):
        score = table_score(cfg, intensity, variation)
        assert score == table.score(intensity, variation)
        assert table_code(cfg, score) == table.code(score)
    assert np.isnan(table_score(cfg, np.nan, 1.0)) and table_code(cfg, np.nan) == table.code(np.nan)


def test_the_trailing_windows_compiled_keep_the_reference_range_and_mean(packed):
    from hybridtrack.control.skywatch import TrailingMean, TrailingRange
    from hybridtrack.kernel.controller import ABSOLUTE_HIGHS, ABSOLUTE_LOWS, trailing_mean, trailing_range

    _, _, state = packed
    state.window_ends[:] = 0
    rng = np.random.default_rng(1)
    times = np.cumsum(rng.choice([0.5, 1.0, 1.0, 7.0], 5000))
    values = np.where(rng.random(5000) < 0.1, np.nan, rng.normal(100.0, 30.0, 5000))
    spread, mean = TrailingRange(20.0), TrailingMean(3.0)
    for t, value in zip(times, values):
        expected = spread.add(t, value)
        ranged = trailing_range(state, ABSOLUTE_HIGHS, ABSOLUTE_LOWS, 20.0, t, value)
        assert ranged == pytest.approx(expected, nan_ok=True)
        assert trailing_mean(state, 3.0, t, value) == pytest.approx(mean.add(t, value), rel=0, abs=0, nan_ok=True)


def test_the_gate_and_kalman_filter_compiled_take_readings_as_the_reference(packed):
    from hybridtrack.control.sensing import SensorGate
    from hybridtrack.kernel.controller import P00, P01, P11, READY, X0, X1, gate_take

    controller, cfg, state = packed
    config = controller.config
    gate = SensorGate("fast", config.process_noise, controller.gates[0].filter.r, config.stuck_scans, config.gate,
                      config.reacquire, config.sensor_noise)
    state.gate[:] = 0
    rng = np.random.default_rng(2)
    for k in range(3000):
        z = 0.25 * k + rng.normal(0, 0.05) + (3.0 if rng.random() < 0.05 else 0.0)
        miss = rng.normal(0, 1.2) if rng.random() < 0.5 else np.nan
        dt = float(rng.choice([1.0, 1.0, 2.0]))
        scale = float(rng.choice([1.0, 1.0, 4.0, 131.6]))  # R as a heliostat's azimuth reading scales it
        assert gate_take(cfg, state, 0, z, dt, miss, 2.0, 0.25, scale) == gate.take(z, dt, miss, 2.0, 0.25, scale)
        if k % 500 == 0:
            gate.forget()
            state.gate[0, READY] = 0
    f = gate.filter
    assert state.kf[0, [X0, X1, P00, P01, P11]].tolist() == [f.x0, f.x1, f.p00, f.p01, f.p11]


def test_the_cusum_compiled_flags_as_the_reference():
    from hybridtrack.control.disagreement import DisagreementMonitor
    from hybridtrack.kernel.controller import (CUSUM_RUN, CUSUM_SUM, FLOAT_SLOTS, INT_SLOTS, ControllerState,
                                               disagreement_add)

    monitor, rng = DisagreementMonitor(), np.random.default_rng(3)
    unused = [np.zeros(1)] * (len(ControllerState._fields) - 2)
    compiled = ControllerState(np.zeros(FLOAT_SLOTS), np.zeros(INT_SLOTS, np.int64), *unused)
    alarms = 0
    for k in range(5000):
        residual = rng.normal(0.3 if (k // 400) % 2 else 0.0, 0.1)
        flagged = monitor.add(residual / 0.1, residual, 0.25)
        assert disagreement_add(compiled, residual / 0.1, residual, 0.25) == flagged
        alarms += flagged
        if flagged:
            monitor.reset()
            compiled.s[:], compiled.k[:] = 0.0, 0
        assert (compiled.k[CUSUM_RUN], compiled.s[CUSUM_SUM]) == (monitor.run, monitor.run_sum)
    assert alarms > 0


def test_the_mount_fit_compiled_updates_as_the_reference():
    from hybridtrack.control.mountfit import MountEstimator, pull_spread
    from hybridtrack.kernel.controller import (FLOAT_SLOTS, INT_SLOTS, LIGHT_LEVEL, ControllerState, fit_check,
                                               fit_excess_light, fit_forget, fit_update)
    from hybridtrack.kernel.controller import pull_spread as compiled_spread

    fit, rng = MountEstimator(2, 0.05), np.random.default_rng(4)
    theta, p, information, evidence = fit.theta.copy(), fit.p.copy(), fit.information.copy(), fit.evidence.copy()
    frozen, releases = True, 0
    unused = [np.zeros(1)] * (len(ControllerState._fields) - 2)
    compiled = ControllerState(np.full(FLOAT_SLOTS, np.nan), np.zeros(INT_SLOTS, np.int64), *unused)
    for k in range(400):
        derivatives, weight, residual = rng.normal(size=4), rng.uniform(0.2, 1.0), rng.normal(0, 0.3)
        ratio = np.nan if k % 50 == 7 else rng.choice([1.03, 1.1]) + rng.normal(0, 0.01)
        altitude = np.nan if k % 70 == 3 else rng.uniform(-2.0, 90.0)
        pull = weight * pull_spread(1.4, fit.excess_light(ratio), altitude)
        compiled_pull = weight * compiled_spread(1.4, fit_excess_light(compiled, ratio), altitude)
        assert compiled_pull == pull and compiled.s[LIGHT_LEVEL] == fit.level
        fit.forget(5.0)
        fit_forget(p, information, evidence, fit.memory, fit.prior, 5.0)
        fit.update(derivatives * weight, residual * weight, fit.r + pull * pull)
        fit_update(theta, p, information, evidence, fit.r + pull * pull, fit.clip, frozen, derivatives, weight,
                   residual * weight)
        if fit.updates % fit.check_every == 0:  # a release restarts both from the information form
            was = frozen
            condition, frozen = fit_check(theta, p, information, evidence, fit.prior, frozen)
            assert condition == pytest.approx(fit.condition, rel=1e-12) and frozen == fit.axis_frozen
            releases += was and not frozen
        assert np.array_equal(theta, fit.theta) and np.array_equal(p, fit.p)
        assert np.array_equal(information, fit.information) and np.array_equal(evidence, fit.evidence)
    assert releases >= 1


def test_the_ordered_sums_are_the_same_bits_compiled_and_a_matrix_product_in_numbers():
    from hybridtrack.control.mountfit import ordered_dot, ordered_matmul
    from hybridtrack.kernel.controller import _against_checkpoint, _mount_corrections
    from hybridtrack.kernel.controller import ordered_dot as compiled_dot

    rng = np.random.default_rng(9)
    for n in (3, 4):
        jacobian, theta = rng.normal(size=(50, 2, n)) * 10.0 ** rng.integers(-8, 3, size=(50, 2, n)), rng.normal(size=n)
        a, p = rng.normal(size=(n, n)), rng.normal(size=(n, n))
        mount = np.empty(2)
        for i in range(50):
            _mount_corrections(jacobian, theta, i, mount)
            assert np.array_equal(mount, ordered_dot(jacobian[i], theta))
            assert compiled_dot(jacobian[i, 0], theta) == ordered_dot(jacobian[i, 0], theta)
        np.testing.assert_allclose(ordered_dot(jacobian, theta), jacobian @ theta, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(ordered_matmul(a, p.T), a @ p.T, rtol=1e-12, atol=1e-12)
        row, cov = jacobian[0, 0], p @ p.T
        fitted, spread = _against_checkpoint(row, theta, cov, 0.01, 0.5)
        assert fitted == ordered_dot(row, theta)
        assert spread == np.sqrt(0.01 + 0.25 * float(ordered_dot(row, ordered_dot(cov, row))))
        assert spread == pytest.approx(np.sqrt(0.01 + 0.25 * row @ cov @ row), rel=1e-12)


def test_the_trailing_windows_queue_size_is_the_most_scans_a_window_holds():
    from hybridtrack.kernel.controller import most_in_window

    rng = np.random.default_rng(2)
    minutes = np.cumsum(rng.choice([0.5, 1.0, 1.0, 7.0, 60.0], 3000))
    for width in (0.25, 1.0, 3.0, 20.0, 600.0):
        start = np.searchsorted(minutes, minutes - width, side="right")
        assert most_in_window(minutes, width) == int(np.max(np.arange(len(minutes)) - start + 1))
    assert most_in_window(np.arange(10.0), 3.0) == 3  # (t − 3, t] at 1-minute scans: t − 2, t − 1 and t


def test_the_queues_hold_a_power_of_two_with_room_for_the_scan_being_added():
    """The queues mask their counts by their capacity, which must be a power of two."""
    from hybridtrack.kernel.bridge import _window_capacity

    minutes = np.arange(600.0)
    assert [_window_capacity(minutes, [w]) for w in (0.5, 1.0, 2.0, 6.0, 7.0, 30.0)] == [4, 4, 4, 8, 16, 32]
    assert _window_capacity(minutes, [6.0, 30.0]) == 32  # the widest window: 30 scans + 2


@pytest.mark.parametrize("days", [1.0, 40.0])  # within DRIFT_DAYS the drift is held; beyond it is fitted
def test_the_kernels_clock_fit_sums_its_normal_equations_to_the_references_answer(days):
    """The kernel keeps running sums of the clock fit's normal equations, its residuals' squares
    and their lag products, each reading summed once as it is counted (forming the design matrix
    every evening made a year quadratic); the reference forms the matrix. Two axes, readings in
    five-minute spells with gaps."""
    pytest.importorskip("numba")
    from hybridtrack.control.clockwatch import ClockWatch
    from hybridtrack.kernel import controller as kc

    rng = np.random.default_rng(5)
    times = np.arange(0.0, days * 1440.0, 5.0)
    count = min(400, len(times) // 2)
    t = np.sort(rng.choice(times, count, replace=False)).repeat(2)
    axis = np.tile([0, 1], count)
    rows = rng.standard_normal((2 * count, 5))  # four mount columns and the clock's
    values = 0.02 * np.cumsum(rng.standard_normal(2 * count)) + rows @ [0.1, -0.2, 0.05, 0.3, 0.01]
    watch = ClockWatch(4, 0.05)
    watch.rows = [(ti, ai, x, y) for ti, ai, x, y in zip(t, axis, rows, values)]
    expected, expected_std = watch.solve()
    n = watch.n
    moments, sums, last = np.zeros((4, n, n)), np.zeros((5, n + 1)), np.full(2, -1, np.int64)
    kc.clock_recount(t, axis, rows, values, moments, sums, last, len(t))
    estimate, std = kc.clock_solve(moments, sums, len(t), watch.span, np.diag(watch.prior_information), watch.r)
    np.testing.assert_allclose(estimate, expected, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(std, expected_std, rtol=1e-9)
    assert np.isinf(std[-1]) == (days < 1.5)


def test_a_recorded_photocurrent_or_a_heliostats_sensor_run_takes_the_kernel_already_compiled(mixed_day):
    """numba compiles the kernel once for each combination of its arrays' read-only flags: a
    frame's column is read-only and a computed array is not, so these two runs had compiled the
    kernel again (one to three minutes each) after a plain one."""
    from hybridtrack.kernel.loop import run_scans

    compiled = SimulationConfig(engine="compiled")
    simulate(mixed_day, "lanzhou", config=compiled)
    before = set(run_scans.signatures)
    recorded = mixed_day.drop(columns=["wind_speed", "dhi"]).assign(photocurrent=np.linspace(30.0, 330.0, len(mixed_day)))
    simulate(recorded, "lanzhou", config=dataclasses.replace(compiled, controller=dataclasses.replace(
        compiled.controller, wind_missing="track")))
    simulate(mixed_day, "lanzhou", config=compiled, collector="heliostat", strategy="sensor")
    assert set(run_scans.signatures) == before
