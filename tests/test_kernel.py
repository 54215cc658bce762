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


@pytest.mark.parametrize("collector", COLLECTORS)
@pytest.mark.parametrize("strategy", STRATEGIES)
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


@pytest.mark.parametrize("name", ["sensor-drift", "encoder-frozen-gust", "clock-creep", "wind-stuck",
                                  "heliostat-wrap"])
def test_fault_scenarios_run_the_same_compiled(name):
    assert_same_run(*scenario_runs(name))


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
    assert kernel.unsupported(filterpy) and not kernel.uses_kernel(filterpy)
    assert kernel.uses_kernel(SimulationConfig())
    with pytest.raises(HybridtrackError, match="fast"):
        kernel.uses_kernel(dataclasses.replace(filterpy, engine="compiled"))


def test_the_compiled_controller_imports_nothing_of_the_world():
    source = Path(kernel.__file__).parent / "controller.py"
    for node in ast.walk(ast.parse(source.read_text())):
        if isinstance(node, ast.ImportFrom):
            module = node.module or ""
            assert not module.startswith("..") and module.split(".")[-1] not in ("world", "sensor", "sky", "simulation"), \
                module
            assert node.level < 2 or module.split(".")[0] == "control", module


def test_without_numba_the_package_runs_the_reference_with_one_warning():
    script = (
        "import sys, warnings\n"
        "sys.modules['numba'] = None\n"
        "warnings.simplefilter('always')\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    from hybridtrack import simulate\n"
        "    from hybridtrack.sky import synthetic\n"
        "    frame = synthetic('lanzhou', '2021-06-21 10:00', '2021-06-21 12:00', weather='sunny', seed=1)\n"
        "    simulate(frame, 'lanzhou', bulk_nights=False)\n"
        "    simulate(frame, 'lanzhou')\n"
        "ours = [str(w.message) for w in caught if 'controller loop' in str(w.message)]\n"
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
    recorded = mixed_day.drop(columns=["wind_speed", "dhi"]).assign(photocurrent=30.0 + rng.uniform(0, 300, len(mixed_day)))
    config = replaced(controller={"wind_missing": "track"})
    for strategy in ("hybrid", "sensor"):
        assert_same_run(*both(recorded, "lanzhou", config=config, strategy=strategy))


def test_irregular_scans_run_the_same_compiled(mixed_day):
    keep = np.random.default_rng(1).random(len(mixed_day)) > 0.3
    assert_same_run(*both(mixed_day[keep], "lanzhou"))


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
