"""Whole fields: geometry over collectors, seeded imperfections, field runs against per-collector runs."""

import dataclasses
import threading
import time
import warnings
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pvlib
import pytest
from matplotlib.figure import Figure

from hybridtrack import HybridtrackError, simulate, simulate_field, sites
from hybridtrack.collectors import Collector, fresnel_angle, heliostat_normal, trough_angle
from hybridtrack.fields import (FresnelField, HeliostatField, ImperfectionSpread, TroughLoop, collector_columns,
                                run_collectors)
from hybridtrack.commissioning import warm_memory
from hybridtrack.simulation import SimulationConfig
from hybridtrack.sky import synthetic
from hybridtrack.sun import altitude_azimuth, solar_position
from hybridtrack.times import local_range
from hybridtrack.world import Imperfections

KUNMING_LATITUDE = 25 + 1 / 60
END_LOSS_NOON = [4.810, 5.217, 5.833, 6.600, 7.470, 8.413, 9.406, 10.435, 11.490, 12.565]


@pytest.fixture(scope="module")
def day():
    return synthetic("lanzhou", "2021-06-21", weather="mixed", seed=3)


@pytest.fixture(scope="module")
def sun():
    return solar_position(local_range("2021-03-20", "Asia/Shanghai", freq="15min"), "lanzhou")


def test_fresnel_field_geometry_is_each_rows_own(sun):
    field = FresnelField(row_distances=[-6.0, -2.0, 3.0, 7.5], receiver_height=8.0)
    table = field.targets(sun.altitude, sun.azimuth)
    for i, d in enumerate(field.row_distances):
        np.testing.assert_array_equal(table[:, i], fresnel_angle(sun.altitude, sun.azimuth, d, 8.0).to_numpy())
    np.testing.assert_array_equal(field.positions, [[-6, 0, 0], [-2, 0, 0], [3, 0, 0], [7.5, 0, 0]])


def test_fresnel_field_end_loss_per_row_matches_the_published_table():
    field = FresnelField(row_distances=np.arange(2.5, 25.01, 2.5), receiver_height=10.0)
    alt, az = altitude_azimuth(0.0, 0.0, KUNMING_LATITUDE)  # equinox solar noon at Kunming
    np.testing.assert_allclose(field.end_loss([alt], [az])[0], END_LOSS_NOON, atol=0.002)


def test_trough_loop_lies_on_one_axis_line(sun):
    loop = TroughLoop(count=3, collector_length=150.0, axis_azimuth=270.0)
    assert loop.kind == "trough-ew"
    np.testing.assert_allclose(loop.positions, [[0, 0, 0], [-150, 0, 0], [-300, 0, 0]], atol=1e-9)
    np.testing.assert_array_equal(loop.targets(sun.altitude, sun.azimuth)[:, 2],
                                  trough_angle(sun.altitude, sun.azimuth, 270.0).to_numpy())


@pytest.mark.parametrize("axis, kind", [(0.0, "trough-ns"), (180.0, "trough-ns"), (90.0, "trough-ew"),
                                        (270.0, "trough-ew"), (45.0, "trough"), (-100.0, "trough")])
def test_trough_loops_collectors_name_their_axis(axis, kind):
    """A loop on a 45° axis had reported its collectors as "trough-ns"."""
    loop = TroughLoop(count=2, axis_azimuth=axis)
    assert loop.kind == kind
    assert loop.collectors() == [Collector(kind, axis)] * 2


def test_a_trough_loop_on_a_slanted_axis_runs_as_what_it_is(day):
    """Scored and summarised as a "trough" on its own axis; its nominal targets are pvlib's tracker
    on that axis (ρ = 90° + θ, pvlib's axis pointing the other way)."""
    loop = TroughLoop(count=2, axis_azimuth=45.0, spread=ImperfectionSpread.none())
    result = simulate_field(day, "lanzhou", loop, seed=2, keep_log=False)
    assert result.summary["kind"] == "trough" and result.summary["collectors"] == 2
    sun = solar_position(day.index, "lanzhou")
    up = sun[sun.altitude > 0]
    pv = pvlib.tracking.singleaxis(90 - up.altitude, up.azimuth, axis_azimuth=225.0, backtrack=False, max_angle=180)
    np.testing.assert_allclose(loop.targets(up.altitude, up.azimuth), np.c_[pv.tracker_theta, pv.tracker_theta] + 90,
                               rtol=0, atol=1e-9)


def test_heliostat_field_aims_each_mirror_from_its_own_place(sun):
    field = HeliostatField(positions=[[0.0, -100.0, 0.0], [80.0, -60.0, 0.0], [-40.0, 120.0, 2.0]], aim=(0, 0, 100))
    normals = field.normals(sun.altitude, sun.azimuth)
    assert normals.shape == (len(sun), 3, 3)
    np.testing.assert_array_equal(normals[:, 2], heliostat_normal(sun.altitude, sun.azimuth, (40.0, -120.0, 98.0)))
    flat = HeliostatField(positions=[[0.0, -100.0], [80.0, -60.0]], aim=(0, 0, 100))
    np.testing.assert_array_equal(flat.positions[:, 2], [0.0, 0.0])
    own = HeliostatField(positions=[[0, -100], [80, -60]], aims=[[0, 0, 100], [3, 0, 95]])
    np.testing.assert_array_equal(own.relative_aims, [[0, 100, 100], [-77, 60, 95]])
    assert own.aim == (1.5, 0.0, 97.5)  # their mean, where the map draws the receiver
    for field in (own, flat, HeliostatField.rings(5)):  # both stored: replace hands them back, no second aim
        again = dataclasses.replace(field, spread=ImperfectionSpread.none())
        np.testing.assert_array_equal(again.aims, field.aims)
        assert again.aim == field.aim
    assert HeliostatField(positions=[[0, -100]]).aim == (0.0, 0.0, 100.0)


def test_replace_moves_a_shared_aim_point_or_the_mirrors():
    field = HeliostatField(positions=[[0, -100], [80, -60]], aim=(0, 0, 100))
    lower = dataclasses.replace(field, aim=(0.0, 0.0, 80.0))  # had been refused as a second aim point
    assert lower.aim == (0.0, 0.0, 80.0)
    np.testing.assert_array_equal(lower.relative_aims, [[0, 100, 80], [-80, 60, 80]])
    more = dataclasses.replace(field, positions=[[0, -100], [80, -60], [-80, -60]])  # had kept two aim points
    np.testing.assert_array_equal(more.relative_aims, [[0, 100, 100], [-80, 60, 100], [80, 60, 100]])
    own = HeliostatField(positions=[[0, -100], [80, -60]], aims=[[0, 0, 100], [3, 0, 95]])
    with pytest.raises(HybridtrackError, match="not both"):  # which of the two would be used?
        dataclasses.replace(own, aim=(0.0, 0.0, 80.0))
    # new aims for a field: its aim is the old aims' mean, so the refusal says to give aim=None
    with pytest.raises(HybridtrackError, match="give aim=None beside them"):
        dataclasses.replace(own, aims=[[0, 0, 90], [2, 0, 90]])
    spread = dataclasses.replace(field, aim=None, aims=[[0, 0, 90], [2, 0, 90]])
    assert spread.aim == (1.0, 0.0, 90.0)  # their mean, by hand
    np.testing.assert_array_equal(spread.relative_aims, [[0, 100, 90], [-78, 60, 90]])


@pytest.mark.parametrize("make, message", [
    (lambda: HeliostatField(positions=[[0.0, np.nan]]), "heliostat 1: position is not finite"),
    (lambda: HeliostatField(positions=[[0, 0, 0, 0]]), r"\(N, 2\) or \(N, 3\)"),
    (lambda: HeliostatField(positions=[[1, 2], [0, 0]], aim=(0, 0, 0)), "heliostat 2: its aim point"),
    (lambda: HeliostatField(positions=[[1, 2]], aims=[[0, 0, 1], [0, 0, 2]]),
     "one \\(east, north, up\\) per heliostat, shape \\(1, 3\\); got shape \\(2, 3\\)"),
    # the one aim point was dropped for the aims without a word
    (lambda: HeliostatField(positions=[[1, 2]], aim=(0, 0, 50), aims=[[0, 0, 100]]), "give aim .* or aims .*not both"),
    (lambda: FresnelField(row_distances=[1.0, float("inf")]), "row distances must be finite"),
    (lambda: FresnelField(row_distances=[]), "non-empty"),
    (lambda: FresnelField(row_distances=[-1, 0, 1, 0.0]), "rows 2 and 4 are both at 0 m from the receiver line"),
    (lambda: HeliostatField(positions=[[10, 20], [30, 40], [10, 20]]), "heliostats 1 and 3 are both at 10, 20, 0 m"),
    # rings refused mirrors closer than 1 m; a positions file 0.5 m apart was taken
    (lambda: HeliostatField(positions=[[60, 0], [0, 60], [60.5, 0]]), "heliostats 1 and 3 are 0.5 m apart: closer"),
    (lambda: HeliostatField(positions=np.column_stack([np.arange(100_001.0), np.zeros(100_001)])),
     "at most 100,000 mirrors"),
    (lambda: FresnelField(receiver_height=-2), "receiver height must be finite and positive"),
    # a receiver on the mirrors (1e-300 m) and a row of no length had been taken: end loss 1, or 1.7e-303
    (lambda: FresnelField(receiver_height=1e-300), "^fresnel field: receiver height must be at least 0.1 m, got 1e-300$"),
    (lambda: FresnelField(receiver_height=0.01), "receiver height must be at least 0.1 m, got 0.01"),
    (lambda: FresnelField(row_length=1e-300), "^fresnel field: row length must be at least 1 m, got 1e-300$"),
    (lambda: Collector("fresnel", receiver_height=1e-300), r"receiver_height \(m\) must be at least 0.1 m above the rows"),
    (lambda: TroughLoop(count=0), "count must be a whole number"),
    (lambda: TroughLoop(count=2.5), "count must be a whole number"),
    (lambda: ImperfectionSpread(encoder_offset=-0.1), "encoder_offset must be a finite number >= 0"),
    (lambda: ImperfectionSpread(sensor_bias=float("nan")), "sensor_bias must be a finite number >= 0"),
    # aims that are not three numbers had leaked numpy's broadcasting error; a tiny spacing, a MemoryError
    (lambda: HeliostatField(aim=(0, 0)), r"aim must be three numbers \(east, north, up\)"),
    (lambda: HeliostatField(aim=(0, 0, 1, 2)), "aim must be three numbers"),
    (lambda: HeliostatField(aim="abc"), "aim must be three numbers"),
    (lambda: HeliostatField.rings(3, aim=(0, 0)), "aim must be three numbers"),
    (lambda: HeliostatField.rings(3, spacing=1e-9), "spacing must be at least 1 m"),
    # aims a heliostat cannot serve had run (capture 0), or failed in the run without naming the mirror
    (lambda: HeliostatField(positions=[[0, -100], [0, -50]], aim=(0, 0, -50)),
     r"heliostat 1: its aim point is not above the mirror \(-50 m up from it, at least 0\.1 m\)"),
    (lambda: HeliostatField(positions=[[0, -100, 0], [0, -50, 120]]), "heliostat 2: its aim point is not above"),
    (lambda: HeliostatField(positions=[[0, -100], [-4000, 0]], aim=(4500, 0, 100)),
     "heliostat 2: its aim point is more than 5000 m from the mirror"),
    # text and True/False had been read as numbers
    (lambda: FresnelField(row_distances=[True, False]), "row distances must be numbers"),
    (lambda: FresnelField(receiver_height="10"), "receiver height must be numbers"),
    (lambda: FresnelField(axis_azimuth=True), "axis azimuth must be numbers"),
    (lambda: HeliostatField(positions=[["1", "2"]]), r"\(N, 2\) or \(N, 3\)"),
    (lambda: HeliostatField(positions=[[True, False]]), r"\(N, 2\) or \(N, 3\)"),
    # one True among numbers had been read as 1
    (lambda: HeliostatField(positions=[[50, True]]), r"positions must be numbers"),
    (lambda: HeliostatField(positions=[[50, 0], [0, 60]], aim=(True, False, 100)), "aim must be three numbers"),
    (lambda: FresnelField(row_distances=[True, 0.5]), "row distances must be numbers"),
    (lambda: FresnelField(row_distances=[1.0, 1.0000001]), "rows 1 and 2 are 1.00000000058e-07 m apart: closer than 0.1 m"),
    # a frame's repr had run the message over several lines
    (lambda: HeliostatField(positions=pd.DataFrame({"east": [1.0, None], "north": [3.0, 4.0]}).astype("Float64")),
     r"^heliostat 2: position is not finite$"),
    (lambda: HeliostatField(positions=pd.DataFrame({"east": ["1", "2"], "north": [3.0, 4.0]})),
     r"^heliostat positions must be numbers, \(N, 2\) or \(N, 3\) metres, got east north 0 1 3.0 1 2 4.0$"),
    (lambda: HeliostatField(positions=[[1, 2]], aims=[["0", "0", "1"]]), "one \\(east, north, up\\) per heliostat"),
    # a spread of another type had been accepted, to fail at run time with an AttributeError
    (lambda: FresnelField(spread=None), "FresnelField: spread must be an ImperfectionSpread, got NoneType"),
    (lambda: TroughLoop(spread={"encoder_offset": 0.1}), "TroughLoop: spread must be an ImperfectionSpread"),
    (lambda: HeliostatField(spread=0.2), "HeliostatField: spread must be an ImperfectionSpread, got float"),
    # each length was bounded, the line was not: 100,000 collectors had reached 100,000 km
    (lambda: TroughLoop(count=100_000, collector_length=1000.0), "reach 9.9999e\\+07 m along the axis, beyond 5000 m"),
    # had said "must be a non-empty list of numbers" of a setting that takes one number
    (lambda: FresnelField(receiver_height=[10, 11]), r"receiver height must be one number for the whole field, got \[10, 11\]"),
    (lambda: TroughLoop(collector_length=np.array([150.0, 140.0])), "collector length must be one number"),
    # had said "must be numbers" of numbers: none of them
    (lambda: HeliostatField(positions=np.zeros((0, 2))), "^heliostat positions are empty: a field needs at least one mirror$"),
    (lambda: HeliostatField(positions=[]), "heliostat positions are empty"),
])
def test_bad_fields_are_refused_with_what_is_wrong(make, message):
    with pytest.raises(HybridtrackError, match=message):
        make()


@pytest.mark.parametrize("make", [
    lambda: HeliostatField(positions=[[-8.2, -60.0], [-7.2, -60.0]]),  # 1 m apart as written
    lambda: HeliostatField.rings(6, first_radius=1.0, spacing=1.0),  # a hexagon of 1 m sides: 2 sin(30°) = 1
    lambda: FresnelField(row_distances=[0.2, 0.3]),  # 0.1 m apart as written
])
def test_collectors_exactly_the_least_spacing_apart_are_taken(make):
    """Decimals exactly at the limit had been refused as "1 m apart: closer than 1 m": -7.2 - -8.2
    is 0.9999999999999991 in binary floating point."""
    make()


def test_imperfection_draws_are_seeded_per_collector_and_spread_as_asked():
    spread = ImperfectionSpread(axis_azimuth_error=0.2, sensor_noise=0.05)
    mean = Imperfections()
    many = spread.draw(mean, 4000, seed=7)
    assert spread.draw(mean, 3, seed=7) == many[:3]  # collector i's draw does not depend on the field's size
    assert spread.draw(mean, 3, seed=8) != many[:3]
    azimuth = np.array([m.axis_azimuth_error for m in many])
    assert azimuth.mean() == pytest.approx(mean.axis_azimuth_error, abs=4 * 0.2 / np.sqrt(4000))
    assert azimuth.std() == pytest.approx(0.2, rel=0.05)
    assert all(m.sensor_noise >= 0 for m in many)
    assert {m.clock_error for m in many} == {mean.clock_error}  # no spread: every collector gets the config's
    with pytest.raises(HybridtrackError, match="axis_tilt_error = 10000.0 is beyond the imperfection's own limit"):
        ImperfectionSpread(axis_tilt_error=1e4)  # refused at the door: no collector could be that far off
    wide = ImperfectionSpread(axis_tilt_error=9.0)  # 1σ = 9°: some draw passes the 10° limit
    first = next(i for i in range(100) if abs(mean.axis_tilt_error + 9.0 * np.random.default_rng(
        [0, i]).standard_normal(len(dataclasses.fields(Imperfections)))[1]) > 10)  # collector i's second draw: tilt
    with pytest.raises(HybridtrackError, match=rf"^collector {first + 1}: the drawn imperfections"):
        wide.draw(mean, 100, seed=0)  # counted from 1, as the field's names are (it said 'collector 43' for H44)
    with pytest.raises(HybridtrackError, match=rf"^H{first + 1}: the drawn imperfections"):
        wide.draw(mean, 100, seed=0, names=[f"H{i + 1}" for i in range(100)])


def test_a_field_run_is_each_collectors_own_run(day):
    field = FresnelField(row_distances=[-4.0, 6.0])
    config = SimulationConfig()
    result = simulate_field(day, "lanzhou", field, seed=11, config=config)
    drawn = field.spread.draw(config.imperfections, 2, 11)
    for i, (name, collector) in enumerate(zip(field.names, field.collectors())):
        alone = simulate(day, "lanzhou", collector=collector, sky_seed=11, config=dataclasses.replace(
            config, imperfections=drawn[i], seed=int(np.random.SeedSequence([11, i]).generate_state(1)[0])))
        row = result.collectors.loc[name]
        assert row["rms"] == alone.summary["tracking_error_deg"]["rms"]
        assert row["moves"] == alone.summary["moves"] and row["energy_capture"] == alone.summary["energy_capture"]
        assert row["axis_azimuth_error"] == drawn[i].axis_azimuth_error
        np.testing.assert_array_equal(result.dataset["angle"].sel(collector=name).to_numpy(), alone.log["angle"])
        codes = result.dataset["mode"].sel(collector=name).to_numpy()
        meanings = result.dataset["mode"].attrs["flag_meanings"].split()
        assert list(np.asarray(meanings)[codes]) == list(alone.log["mode"].astype(str))
    assert len(result.events) > 0 and set(result.events["collector"]) == set(field.names)


def test_the_field_stood_under_one_sky_the_day_before(day, monkeypatch):
    """The clear day before the run (the warm start's) is drawn once, from the field's seed, for
    every collector, as the run's own frame is one sky; each collector's sensor noise on it is
    still its own (a row alone under that day, with its own seed, ends with the same memory)."""
    import hybridtrack.sky as sky

    drawn, synthetic_day = [], sky.synthetic
    monkeypatch.setattr(sky, "synthetic", lambda *a, **k: drawn.append(k["seed"]) or synthetic_day(*a, **k))
    field = FresnelField(row_distances=[-4.0, 2.0, 6.0])
    simulate_field(day, "lanzhou", field, seed=21, threads=2, keep_log=False)
    assert drawn == [21]
    seeds = [int(np.random.SeedSequence([21, i]).generate_state(1)[0]) for i in range(2)]
    memories = [warm_memory(sites.get("lanzhou"), field.collectors()[0], SimulationConfig(seed=s), day.index[0],
                            sky_seed=21)["offsets"] for s in seeds]
    assert drawn == [21, 21, 21] and memories[0] != memories[1]  # one sky, each sensor's own noise


@pytest.mark.parametrize("bad", [-1, 1.5, float("nan"), "1", True])
def test_a_sky_seed_that_is_no_seed_is_refused_by_name(day, bad):
    with pytest.raises(HybridtrackError, match="^sky_seed"):
        simulate(day, "lanzhou", sky_seed=bad)


def test_a_configs_seed_seeds_the_field_unless_seed_is_given():
    """A config's seed had been dropped without a word for seed=0 (the command line's --seed
    defaults to the --config file's seed, the API did not)."""
    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=3, freq="20min")
    field, config = FresnelField(row_distances=[-4.0, 6.0]), SimulationConfig(seed=7)
    for seed, expected in ((None, 7), (0, 0)):
        result = simulate_field(frame, "lanzhou", field, config=config, keep_log=False,
                                **({} if seed is None else {"seed": seed}))
        drawn = field.spread.draw(config.imperfections, 2, expected)
        assert list(result.collectors["encoder_offset"]) == [d.encoder_offset for d in drawn]


@pytest.mark.parametrize("field, strategy", [
    (FresnelField(row_distances=[-4.0, 6.0]), None), (TroughLoop(count=2), "astronomical-commissioned"),
    (HeliostatField(positions=[[0.0, -60.0], [30.0, -80.0]]), "hybrid"),
])
def test_a_field_without_its_log_scores_each_collector_as_its_whole_result_does(day, field, strategy):
    # keep_log=False scores from the pointing error, modes and angles alone (`Tracked.scores`),
    # without the log and the sky as the classifier saw it: the reference is the whole `Result`
    gusty = day.assign(wind_speed=np.where(np.arange(len(day)) % 300 < 20, 25.0, 3.0))  # wind stows too
    whole = simulate_field(gusty, "lanzhou", field, strategy=strategy, seed=5, keep_log=True)
    lean = simulate_field(gusty, "lanzhou", field, strategy=strategy, seed=5, keep_log=False)
    pd.testing.assert_frame_equal(lean.collectors, whole.collectors)
    pd.testing.assert_frame_equal(lean.events, whole.events)
    assert lean.summary == whole.summary
    assert whole.collectors["stow_events"].gt(0).all() and whole.collectors["rms"].gt(0).all()


@pytest.mark.parametrize("field, computed", [
    (FresnelField(row_distances=[-4.0, 2.0, 6.0]), (3, 1)),  # pointing (world, plan), the sun's unit vectors
    # each row's incidence on its own mirror starts from; derivatives
    (TroughLoop(count=3), (3, 1)),
    # the sun's unit vectors once for the world and once for the plan; each mirror's derivatives its own
    (HeliostatField(positions=[[0.0, -60.0], [30.0, -80.0], [-30.0, -80.0]]), (2, 3)),
])
def test_rows_on_one_axis_line_share_their_geometry_and_heliostats_keep_their_own(monkeypatch, field, computed):
    """Under one sun, the sun's direction (the world's and the plan's) and its incidence on the
    aperture are computed once for a field's troughs on one axis line, and so are the mount fit's
    derivatives (and a Fresnel field's rows' pointing and derivatives); a heliostat's pointing and
    a Fresnel row's incidence turn on its own aim point or place under the receiver, so each of
    those is its own, but the sun's unit vectors they start from are shared. (The clear day before the
    run, a day's scans, is not counted here: `test_the_field_stood_under_one_sky_the_day_before`.)"""
    import hybridtrack.control.plan as plan
    import hybridtrack.mounting as mounting

    frame = synthetic("lanzhou", "2021-06-21", "2021-06-22", weather="mixed", seed=3)  # two days: not a warm start
    suns, derivatives = [], []
    sun_vector, vector_jacobian = mounting.sun_vector, plan.vector_jacobian
    monkeypatch.setattr(mounting, "sun_vector", lambda alt, az: suns.append(np.size(alt)) or sun_vector(alt, az))
    monkeypatch.setattr(plan, "vector_jacobian", lambda vectors, collector, lit: derivatives.append(len(lit))
                        or vector_jacobian(vectors, collector, lit=lit))
    simulate_field(frame, "lanzhou", field, threads=2, keep_log=False)
    assert (suns.count(len(frame)), derivatives.count(len(frame))) == computed


def test_collectors_with_their_own_clocks_and_sites_share_no_sky(day):
    """Shared work is keyed on what it depends on: collectors whose controllers' clocks and site
    coordinates differ get their own plan and clear sky (here two collectors on two threads, each
    equal to its own run alone)."""
    field = TroughLoop(count=2, spread=ImperfectionSpread(clock_error=20.0, latitude_error=0.3))
    config = SimulationConfig()
    result = simulate_field(day, "lanzhou", field, seed=5, config=config, threads=2)
    drawn = field.spread.draw(config.imperfections, 2, 5)
    assert drawn[0].clock_error != drawn[1].clock_error and drawn[0].latitude_error != drawn[1].latitude_error
    for i, (name, collector) in enumerate(zip(field.names, field.collectors())):
        alone = simulate(day, "lanzhou", collector=collector, sky_seed=5, config=dataclasses.replace(
            config, imperfections=drawn[i], seed=int(np.random.SeedSequence([5, i]).generate_state(1)[0])))
        np.testing.assert_array_equal(result.dataset["angle"].sel(collector=name).to_numpy(), alone.log["angle"])
        np.testing.assert_array_equal(result.dataset["target"].sel(collector=name).to_numpy(), alone.log["target"])
        assert result.collectors.loc[name, "rms"] == alone.summary["tracking_error_deg"]["rms"]


@pytest.mark.parametrize("engine", ["compiled", "reference"])
def test_a_field_on_one_thread_or_three_is_the_same_field(day, engine):
    field = FresnelField(row_distances=[-6.0, -2.0, 1.0, 5.0])
    config = SimulationConfig(engine=engine)
    one = simulate_field(day, "lanzhou", field, seed=8, threads=1, config=config)
    three = simulate_field(day, "lanzhou", field, seed=8, threads=3, config=config)
    pd.testing.assert_frame_equal(one.collectors, three.collectors)
    assert one.summary == three.summary
    pd.testing.assert_frame_equal(one.events, three.events)
    assert one.dataset.equals(three.dataset)


@pytest.mark.parametrize("threads, extra, message", [
    (0, {}, "threads must be a whole number within"),
    (2.0, {}, "threads must be a whole number"),
    (2, {"workers": 1}, "give one or the other"),
    (1, {"workers": 1}, "give one or the other"),
    (1, {"scheduler": "tcp://127.0.0.1:1"}, "give one or the other"),
])
def test_bad_thread_counts_are_refused(day, threads, extra, message):
    with pytest.raises(HybridtrackError, match=message):
        simulate_field(day, "lanzhou", TroughLoop(count=2), threads=threads, **extra)


def test_the_default_threads_fit_the_memory_and_the_engine(day, monkeypatch):
    """Each thread holds a run: where the memory holds only one, the field runs on one thread
    rather than being refused, and an explicit count that does not fit is refused. The reference
    loop holds Python's lock, so its runs default to one thread."""
    from hybridtrack import budget
    from hybridtrack.fields import _thread_count

    steps = len(day)
    monkeypatch.setattr(budget, "available_memory", lambda: int(2 * budget.BYTES_PER_STEP * steps * 1.5))
    assert _thread_count(None, day, 4, False, dask=False) == 1
    with pytest.raises(HybridtrackError, match="on 2 threads"):
        _thread_count(2, day, 4, False, dask=False)
    monkeypatch.setattr(budget, "available_memory", lambda: 2**40)
    assert _thread_count(None, day, 1, False, dask=False) == 1
    assert _thread_count(None, day, 4, False, dask=True) == 1
    assert _thread_count(None, day, 4, False, dask=False, compiled=False) == 1  # the reference loop holds the GIL
    assert _thread_count(3, day, 4, False, dask=False, compiled=False) == 3  # as asked
    monkeypatch.setattr(budget, "available_memory", lambda: int(2 * budget.BYTES_PER_STEP * steps * 1.5))
    assert _thread_count(1024, day, 1, False, dask=False) == 1  # one collector: 1,023 threads would idle, not hold runs


def test_field_figures_weigh_each_collector_by_the_light_it_is_offered(day):
    result = simulate_field(day, "lanzhou", HeliostatField(), seed=2, keep_log=False)
    table = result.collectors
    weight = table["offered"] / table["offered"].sum()
    assert result.summary["energy_capture"] == pytest.approx(float((weight * table["energy_capture"]).sum()), abs=1e-5)
    assert result.summary["rms"] == pytest.approx(float(np.sqrt((weight * table["rms"] ** 2).sum())), abs=1e-5)
    assert result.summary["moves"] == table["moves"].sum()
    assert result.summary["rms_worst_collector"] == table["rms"].idxmax()
    assert result.dataset is None
    assert list(table.columns) == collector_columns(HeliostatField())


def test_heliostat_rings_are_spaced_and_staggered():
    field = HeliostatField.rings(300, first_radius=50.0, spacing=10.0)
    xy = field.positions[:, :2]
    gaps = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1)) + np.diag(np.full(len(xy), np.inf))
    assert len(xy) == 300 and gaps.min() >= 10.0 - 1e-9
    radii = np.hypot(*xy.T)
    assert radii.min() == pytest.approx(50.0) and set(np.round(radii, 6)) <= {50.0 + 10.0 * k for k in range(10)}


def test_field_result_map_dataset_and_files(day, tmp_path):
    field = FresnelField(row_distances=[-5.0, 0.0, 5.0])
    result = simulate_field(day, "lanzhou", field, seed=0)
    assert list(result.collectors.columns) == collector_columns(field)
    assert isinstance(result.plot_map("energy_capture"), Figure)
    with pytest.raises(HybridtrackError, match="no collector metric 'shine'"):
        result.plot_map("shine")
    dataset = result.dataset
    assert dict(dataset.sizes) == {"collector": 3, "time": len(day)}
    np.testing.assert_array_equal(dataset["east"], [-5.0, 0.0, 5.0])
    assert pd.DatetimeIndex(dataset["time"].to_numpy()).tz_localize("UTC").equals(day.index.tz_convert("UTC"))
    assert 0 < result.summary["end_loss_share"] < 1 and (result.collectors["end_loss_m"] > 0).all()
    from hybridtrack.control import SENSOR_STATUS

    for name in ("mode", "sky", "sensor_status"):  # CF: one blank-separated word per flag value
        attrs = dataset[name].attrs
        assert len(attrs["flag_meanings"].split()) == len(attrs["flag_values"]), name
    assert dataset["sensor_status"].attrs["flag_meanings"].split() == [s.replace(" ", "_") for s in SENSOR_STATUS]
    assert {name: dataset[name].attrs.get("units") for name in ("angle", "error", "intensity_ma", "dni", "wind_speed")} \
        == {"angle": "degree", "error": "degree", "intensity_ma": "mA", "dni": "W m-2", "wind_speed": "m s-1"}
    written = result.save(tmp_path / "field")
    assert {p.name for p in written.values()} == {"collectors.csv", "events.csv", "summary.json", "field_map.png",
                                                  "log.nc"}
    assert "<b>FresnelField</b>" in result._repr_html_()
    assert repr(result).startswith("<FieldResult: FresnelField of 3 at lanzhou, hybrid, 1,440 steps from 2021-06-21")


def test_a_saved_heliostat_field_keeps_every_position_and_aim_point_to_the_last_digit(day, tmp_path):
    """collectors.csv had rounded to six figures (a mirror 1234.5678 m east was written 1234.57) and
    left the aim points out; it is now a positions file that builds the same field again."""
    import xarray as xr

    from hybridtrack.cli.field import read_positions

    positions = [[1234.5678, -987.6543, 0.25], [50.123456789, 60.0, 1.5]]
    aims = [[0.0, 0.0, 100.0], [0.0, 5.0, 90.0]]
    field = HeliostatField(positions=positions, aims=aims)
    result = simulate_field(day.iloc[600:660], "lanzhou", field, seed=0)
    written = result.save(tmp_path / "field")
    read, read_aims = read_positions(str(written["collectors"]))  # the metrics' columns are named as not read
    np.testing.assert_array_equal(read, positions)
    np.testing.assert_array_equal(read_aims, aims)
    with xr.open_dataset(written["log"]) as log:
        np.testing.assert_array_equal(log["aim_north"], [0.0, 5.0])
        assert {place: log[place].attrs.get("units") for place in ("east", "north", "up", "aim_up")} \
            == {"east": "m", "north": "m", "up": "m", "aim_up": "m"}


def test_a_heliostat_map_stars_each_aim_point_and_says_when_nothing_was_scored(day):
    """The map had starred the aims' mean, (0, 2.5) for aims at (0, 0) and (0, 5): neither mirror's."""
    field = HeliostatField(positions=[[0.0, 60.0], [0.0, -60.0]], aims=[[0.0, 0.0, 100.0], [0.0, 5.0, 90.0]])
    figure = simulate_field(day.iloc[600:660], "lanzhou", field, seed=0).plot_map("rms")
    stars = [line for line in figure.axes[0].lines if line.get_marker() == "*"]
    assert len(stars) == 1 and sorted(zip(stars[0].get_xdata(), stars[0].get_ydata())) == [(0.0, 0.0), (0.0, 5.0)]
    night = simulate_field(day.iloc[:60], "lanzhou", FresnelField(row_distances=[-3.0, 3.0]), seed=0).plot_map("rms")
    assert any("nothing was scored" in text.get_text() for text in night.axes[0].texts)


def test_simulate_field_refuses_what_is_not_a_field(day):
    with pytest.raises(HybridtrackError, match="field must be"):
        simulate_field(day, "lanzhou", "fresnel")
    with pytest.raises(HybridtrackError, match="seed must be"):
        simulate_field(day, "lanzhou", TroughLoop(count=1), seed=-1)
    with pytest.raises(HybridtrackError, match="naive"):
        simulate_field(day.tz_localize(None), "lanzhou", TroughLoop(count=1))
    with pytest.raises(HybridtrackError, match="config must be a SimulationConfig .* got dict"):
        simulate_field(day, "lanzhou", TroughLoop(count=1), config={"drive": {"deadband": 0.2}})


def test_the_offered_light_is_the_energy_on_a_perfect_trackers_aperture_whatever_the_step():
    """A north-south trough's offered light against pvlib's single-axis tracker: DNI on its
    aperture (cos of pvlib's angle of incidence) while the sun is up, in kWh/m², at 1 and 5 min."""
    import pvlib

    from hybridtrack import sites

    site = sites.get("lanzhou")
    offered = {}
    for freq in ("1min", "5min"):
        frame = synthetic(site, "2021-06-21", weather="sunny", seed=1, freq=freq)
        offered[freq] = simulate_field(frame, site, TroughLoop(count=1), keep_log=False).collectors["offered"].iloc[0]
        sun = pvlib.solarposition.get_solarposition(frame.index, site.latitude, site.longitude, site.altitude)
        aoi = pvlib.tracking.singleaxis(sun["apparent_zenith"], sun["azimuth"], axis_tilt=0, axis_azimuth=0,
                                        max_angle=90, backtrack=False)["aoi"].to_numpy()
        up = (sun["elevation"] > 0).to_numpy()
        beam = frame["dni"].to_numpy() * np.cos(np.radians(aoi))
        want = np.nansum(np.where(up, beam, 0.0)) * pd.Timedelta(freq) / pd.Timedelta(hours=1) / 1000.0
        assert offered[freq] == pytest.approx(want, rel=2e-3), freq
    assert offered["5min"] == pytest.approx(offered["1min"], rel=5e-3)


def test_a_frame_of_mixed_steps_offers_the_light_of_its_days_apart():
    """A 15-minute day beside a 1-minute day: each stamp stands for its own step. The median step
    (1 min) had counted the 15-minute day's light a fifteenth (helper's finding: 13.74 kWh/m²
    offered for 12.89 + 12.88 apart); the field's energy, the daily table and the sky's daily
    summary now add up."""
    from hybridtrack.simulation import NightsLeftOutWarning
    from hybridtrack.sky import daily_summary

    first = synthetic("lanzhou", "2021-06-21", weather="sunny", freq="15min", seed=1)
    second = synthetic("lanzhou", "2021-06-22", weather="cloudy", freq="1min", seed=2)
    both = pd.concat([first, second])
    field = TroughLoop(count=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", NightsLeftOutWarning)  # a 15-min day's steps are its own, not gaps
        together = simulate_field(both, "lanzhou", field, keep_log=False).collectors["offered"].iloc[0]
    apart = [simulate_field(day, "lanzhou", field, keep_log=False).collectors["offered"].iloc[0]
             for day in (first, second)]
    assert together == pytest.approx(sum(apart), rel=1e-8)  # the sun on each frame: fast SPA to ~1e-10
    by_day = daily_summary(both, "lanzhou")["dni_kwh_m2"].to_numpy()
    alone = [daily_summary(day, "lanzhou")["dni_kwh_m2"].iloc[0] for day in (first, second)]
    np.testing.assert_allclose(by_day, alone, rtol=1e-12)
    assert alone[0] == pytest.approx(first["dni"].sum() * 0.25 / 1000.0, rel=1e-12)  # by hand: 15 min a stamp


def test_a_field_on_two_dask_workers_is_the_same_field(day):
    """Each collector's run depends only on its own draws, so where it runs changes nothing."""
    field = TroughLoop(count=5)
    here = simulate_field(day, "lanzhou", field, seed=4)
    there = simulate_field(day, "lanzhou", field, seed=4, workers=2)
    pd.testing.assert_frame_equal(here.collectors, there.collectors)
    assert here.summary == there.summary
    pd.testing.assert_frame_equal(here.events, there.events)
    assert here.dataset.equals(there.dataset)


@pytest.mark.parametrize("where", [{"workers": 1}, {"threads": 2}])
def test_a_collector_that_fails_fails_the_field_with_its_own_error_and_no_log(day, capfd, where):
    without_sky = day.drop(columns=["sky"])
    with pytest.raises(HybridtrackError, match="needs the frame's true 'sky' column"):
        simulate_field(without_sky, "lanzhou", TroughLoop(count=3), strategy="hybrid-oracle", **where)
    assert "Traceback" not in capfd.readouterr().err


def test_a_script_without_a_main_guard_is_told_why_its_workers_did_not_start(tmp_path):
    """Dask's worker processes import the running script again: a script that starts a parallel
    field at its top level cannot start them. It gets a HybridtrackError that says so, not
    distributed's "Nanny failed to start"."""
    import subprocess
    import sys

    script = tmp_path / "field_script.py"
    script.write_text("import hybridtrack as ht\n"
                      "from hybridtrack.fields import TroughLoop\n"
                      "from hybridtrack.sky import synthetic\n"
                      "day = synthetic('lanzhou', '2021-06-21', weather='sunny', freq='30min')\n"
                      "ht.simulate_field(day, 'lanzhou', TroughLoop(count=2), workers=1)\n")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    last = done.stderr.strip().splitlines()[-1]
    assert done.returncode != 0
    assert last.startswith("hybridtrack.errors.HybridtrackError: cannot start 1 local Dask workers"), last
    assert 'if __name__ == "__main__":' in last


def test_a_heliostat_dataset_keeps_each_angle_with_its_azimuth_twin_and_nothing_else(day):
    """Every kept angle's azimuth axis comes with it; the log's other azimuth columns (the fit's, the
    sensor's sun) had come too, without their elevation twins."""
    from hybridtrack.fields import LOG_VARIABLES

    dataset = simulate_field(day, "lanzhou", HeliostatField(positions=[[0.0, -100.0]])).dataset
    twins = {"target_true_azimuth", "target_azimuth", "angle_azimuth", "calibration_azimuth"}
    assert set(dataset.data_vars) == set(LOG_VARIABLES) | twins | {"dni", "wind_speed"}
    assert dataset["angle_azimuth"].attrs["units"] == "degree"


def test_a_field_on_a_frame_without_wind_says_so(day):
    """Without wind a controller stows (never a calm): the field's summary showed a day of zero
    energy and no reason."""
    calm_unknown = day.drop(columns=["wind_speed"])
    result = simulate_field(calm_unknown, "lanzhou", TroughLoop(count=2), seed=1, keep_log=False)
    assert result.summary["wind_data"] == "missing" and result.summary["energy_capture"] == 0.0
    assert simulate_field(day, "lanzhou", TroughLoop(count=2), seed=1, keep_log=False).summary["wind_data"] == "measured"


@pytest.mark.parametrize("call, message", [
    (lambda day: simulate_field(day, "lanzhou", TroughLoop(count=1), scheduler=123), "scheduler must be an address"),
    (lambda day: simulate_field(day, "lanzhou", TroughLoop(count=1), keep_log="yes"), "keep_log must be True or False"),
    (lambda day: simulate_field(day, "lanzhou", TroughLoop(count=1), keep_log=False).save(None),
     "the output folder must be a path, got None"),
    (lambda day: simulate_field(day, "lanzhou", TroughLoop(count=1), keep_log=False).save(" "),
     "the output folder must be a path, got ' '"),  # '' had written into the working folder
    (lambda day: simulate(day, "lanzhou", collector=5), "collector must be a kind's name"),
])
def test_api_arguments_of_the_wrong_kind_are_hybridtrack_errors(day, call, message):
    """Each was a TypeError or AttributeError from deep inside, or wrote where it was not asked to."""
    with pytest.raises(HybridtrackError, match=message):
        call(day)


def test_a_block_of_collectors_lost_on_dask_fails_the_field_in_one_line_not_a_hang(day, monkeypatch):
    """A worker killed too often (out of memory, a signal) loses its block: the field cannot be
    whole, so it is refused with a message that says what happened and what to do."""
    from dask.distributed import KilledWorker, LocalCluster

    import hybridtrack.fields as fields_module

    real = fields_module.run_collectors

    def killed(frame, runs, **job):
        if runs[0][0] == 0:
            raise KilledWorker("run_collectors", SimpleNamespace(address="tcp://127.0.0.1:1"), 3)
        return real(frame, runs, **job)

    monkeypatch.setattr(fields_module, "run_collectors", killed)
    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        with pytest.raises(HybridtrackError, match="a block of the field's collectors was lost on Dask "
                                                   r"\(KilledWorker: .*\); run the field again"):
            simulate_field(day, "lanzhou", TroughLoop(count=3), scheduler=cluster.scheduler_address)


_RELEASED = threading.Event()
_RUN_COLLECTORS = run_collectors  # the real one, which the test replaces in its module


def _waits_after_the_first_block(frame, runs, **job):
    """run_collectors for the first collector's block; the others wait until the test lets them go."""
    if runs[0][0] > 0:
        _RELEASED.wait(30)
    return _RUN_COLLECTORS(frame, runs, **job)


def test_a_field_whose_schedulers_last_worker_leaves_is_refused_not_waited_on(day, monkeypatch):
    """A remote worker gone mid-field (its machine lost, no nanny to restart it): the field waited
    for ever for the blocks left. After WORKERS_GONE_AFTER seconds with no worker it is refused."""
    from dask.distributed import LocalCluster

    import hybridtrack.cluster as cluster_module
    import hybridtrack.fields as fields_module

    monkeypatch.setattr(cluster_module, "WORKERS_GONE_AFTER", 1.0)
    monkeypatch.setattr(fields_module, "run_collectors", _waits_after_the_first_block)
    _RELEASED.clear()
    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        def last_worker_leaves():
            time.sleep(2.0)
            threading.Thread(target=cluster.scale, args=(0,), daemon=True).start()
            time.sleep(0.5)
            _RELEASED.set()

        threading.Thread(target=last_worker_leaves, daemon=True).start()
        # which of the two the client sees first depends on timing: either is one line, and no hang
        with pytest.raises(HybridtrackError, match="the Dask scheduler has had no worker for 1 s|"
                                                   "a block of the field's collectors was lost on Dask"):
            simulate_field(day, "lanzhou", TroughLoop(count=4), scheduler=cluster.scheduler_address)


def test_a_far_aim_point_is_refused_before_any_arithmetic_overflows():
    """The aim points' mean was taken before their distance was checked: 1e308 overflowed with a
    RuntimeWarning printed beside the refusal."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(HybridtrackError, match="its position or aim point lies beyond 5000 m"):
            HeliostatField(aim=(0.0, 0.0, 1e308))


@pytest.mark.parametrize("positions", [[[1e200, 60.0], [-10.0, 60.0]], [[0.0, 60.0, 0.0], [10.0, 60.0, 1e300]]])
def test_far_heliostats_are_refused_before_their_overlap_is_checked(positions):
    """Mirrors 1e155 m and more away raised scipy's floating-point overflow from the overlap
    check (a ValueError; helper-37): the distance is judged first."""
    with pytest.raises(HybridtrackError, match="its position or aim point lies beyond 5000 m"):
        HeliostatField(positions=positions)


def test_a_table_of_heliostat_positions_is_read_by_its_columns_names():
    """It was read by the columns' order: id, east, north put every mirror 100 m underground."""
    table = pd.DataFrame({"id": [1, 2], "North": [-100.0, -90.0], "east": [0.0, 50.0]})
    with pytest.warns(UserWarning, match="the table's id is not read"):
        field = HeliostatField(positions=table)
    np.testing.assert_array_equal(field.positions, [[0.0, -100.0, 0.0], [50.0, -90.0, 0.0]])
    with pytest.raises(HybridtrackError, match="a table needs columns 'east' and 'north' \\(and 'up'\\), m; it has x, y"):
        HeliostatField(positions=pd.DataFrame({"x": [1.0], "y": [2.0]}))


def test_a_table_of_positions_with_aim_points_is_refused_not_aimed_elsewhere():
    """A positions file's aim columns, which `hybridtrack field --positions` reads, had been dropped
    from a table: its mirrors aimed at (0, 0, 100) m, not at the file's 60 m."""
    table = pd.DataFrame({"east": [0.0, 50.0], "north": [-100.0, -90.0], "aim_east": [0.0, 0.0],
                          "aim_north": [0.0, 0.0], "aim_up": [60.0, 60.0]})
    with pytest.raises(HybridtrackError, match="aim_east, aim_north, aim_up are aim points.*without them.*aims="):
        HeliostatField(positions=table)
    field = HeliostatField(positions=table[["east", "north"]], aims=table[["aim_east", "aim_north", "aim_up"]])
    np.testing.assert_array_equal(field.relative_aims, [[0.0, 100.0, 60.0], [-50.0, 90.0, 60.0]])


def test_a_spread_takes_numpys_numbers_and_refuses_an_integer_past_any_float():
    spread = ImperfectionSpread(encoder_offset=np.float32(0.25), axis_tilt_error=np.int64(0))
    assert spread.encoder_offset == pytest.approx(0.25) and type(spread.axis_tilt_error) is float  # both had been refused
    with pytest.raises(HybridtrackError, match="is beyond the imperfection's own limit"):
        ImperfectionSpread(encoder_offset=10**400)  # numpy's TypeError


def test_a_field_map_of_a_metric_that_is_no_name_is_refused(day, tmp_path):
    result = simulate_field(day, "lanzhou", TroughLoop(count=2), keep_log=False)
    for call in (lambda: result.plot_map(["rms"]), lambda: result.save(tmp_path / "out", metric=["rms"])):
        with pytest.raises(HybridtrackError, match="no collector metric"):  # a TypeError: unhashable list
            call()


def test_a_table_of_aim_points_is_read_by_its_columns_names():
    """A table of aims was read by its columns' order: aim_north, aim_east, aim_up swapped every aim
    point's east and north without a word (positions were already read by name)."""
    positions = [[0.0, -100.0], [50.0, -90.0]]
    table = pd.DataFrame({"aim_north": [5.0, 6.0], "aim_up": [100.0, 90.0], "Aim_East": [1.0, 2.0]})
    field = HeliostatField(positions=positions, aims=table)
    # each aim point from its mirror, by hand: (aim_east - east, aim_north - north, aim_up)
    np.testing.assert_array_equal(field.relative_aims, [[1.0, 105.0, 100.0], [-48.0, 96.0, 90.0]])
    plain = pd.DataFrame({"up": [100.0, 90.0], "east": [1.0, 2.0], "north": [5.0, 6.0]})
    np.testing.assert_array_equal(HeliostatField(positions=positions, aims=plain).relative_aims, field.relative_aims)
    with pytest.raises(HybridtrackError, match="aim points: a table needs columns aim_east, aim_north, aim_up .*it "
                                               "has x, y, z"):
        HeliostatField(positions=positions, aims=pd.DataFrame({"x": [0.0, 0.0], "y": [0.0, 0.0], "z": [9.0, 9.0]}))
    with pytest.raises(HybridtrackError, match=r"one \(east, north, up\) per heliostat, shape \(2, 3\); got shape "
                                               r"\(1, 3\)"):
        HeliostatField(positions=positions, aims=[[0.0, 0.0, 100.0]])


def test_a_field_under_polar_night_keeps_its_metrics_numbers():
    """Where no step scored (the sun never rose) the metrics were None in object columns: the
    table's `rms` had no numeric mean and printed "None" beside the end loss's NaN."""
    site = sites.custom(-80.0, 0.0, "UTC")
    frame = synthetic(site, "2021-06-21", weather="mixed", seed=1, freq="30min")
    truth = pvlib.solarposition.get_solarposition(frame.index, -80.0, 0.0)
    assert (truth["elevation"] < 0).all()  # the reference: polar night all day
    result = simulate_field(frame, site, FresnelField(row_distances=[-1.0, 1.0]), keep_log=False)
    for column in ("rms", "p95", "max", "mean", "within_0_5_deg", "energy_capture"):
        assert result.collectors[column].dtype == float and result.collectors[column].isna().all(), column
    assert result.collectors["moves"].tolist() == [0, 0] and result.summary["rms"] is None


def test_an_east_west_fresnel_field_reports_its_end_loss(day):
    """It had no end_loss_m, end_loss_share nor field end loss, and --metric end_loss_share was refused."""
    field = FresnelField(row_distances=[-2.0, 2.0], axis_azimuth=90.0)
    result = simulate_field(day, "lanzhou", field, keep_log=False)
    assert list(result.collectors.columns) == collector_columns(field)
    # by hand: light-weighted |L_end| over the day, each step's L_end = f tan(θ) (docs/fields.md)
    # weighted by the beam on each row's own mirror: pvlib's incidence on the plane fresnel_angle tilts
    sun = solar_position(day.index, "lanzhou")  # the true sun as it appears (refracted), the world's
    up = (sun["apparent_altitude"] > 0) & (day["dni"] > 0)
    altitude, azimuth = sun["apparent_altitude"][up], sun["azimuth"][up]
    a, g = np.radians(altitude), np.radians(azimuth - 90.0)
    s_along = np.cos(a) * np.cos(g)
    loss = np.hypot(2.0, 10.0) * np.abs(s_along) / np.sqrt(1.0 - s_along**2)
    for row, d in enumerate(field.row_distances):
        rho = fresnel_angle(altitude.to_numpy(), azimuth.to_numpy(), d, 10.0, 90.0)
        aoi = pvlib.irradiance.aoi(np.abs(90.0 - rho), np.where(rho < 90.0, 180.0, 0.0), 90.0 - altitude, azimuth)
        beam = day["dni"][up] * np.cos(np.radians(aoi))
        assert result.collectors["end_loss_m"].iloc[row] == pytest.approx(np.sum(beam * loss) / beam.sum(), rel=1e-6)
    assert 0 < result.summary["end_loss_share"] < 1
    assert isinstance(result.plot_map("end_loss_share"), Figure)


def test_a_field_shows_its_figures_in_a_notebook_and_escapes_its_texts(day):
    """The notebook view had only the field's name and the table: none of its figures. And a site's
    name went into the page as markup: a site named '<script>...' ran as one."""
    site = sites.custom(36.1, 103.7, "Asia/Shanghai", name="<script>alert(1)</script>")
    result = simulate_field(day, site, TroughLoop(count=2), keep_log=False)
    html = result._repr_html_()
    assert "<script>" not in html and "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    for label, key in (("energy capture (field)", "energy_capture"), ("pointing error RMS (°, field)", "rms")):
        assert f"<th style='text-align:left'>{label}</th><td style='text-align:left'>{result.summary[key]:.4g}</td>" \
            in html
    assert "SCA 2" in html


def test_a_trough_loop_of_collectors_too_short_to_stand_apart_is_refused():
    """collector_length=1e-300 was taken: its collectors, one length apart, all stood at the origin
    (two collectors at one place, which every other field refuses)."""
    with pytest.raises(HybridtrackError, match="collector length must be at least 1 m .* got 1e-300"):
        TroughLoop(count=2, collector_length=1e-300)
    with pytest.raises(HybridtrackError, match="got 0.5"):
        TroughLoop(count=2, collector_length=0.5)
    np.testing.assert_array_equal(TroughLoop(count=2, collector_length=1.0).positions, [[0, 0, 0], [0, 1, 0]])


def test_a_field_saves_its_log_whatever_dasks_global_scheduler_says(day, tmp_path):
    """A Dask scheduler set to dask.distributed with no client open (a dask.yaml, DASK_SCHEDULER,
    a default client left unclosed; our sweep's clients had set it, the flaky order test_sweep.py
    then test_cli_field.py) had failed the save in xarray's netCDF writer: 'Requested
    dask.distributed scheduler but no Client active'. The log holds numpy arrays: no Dask at all."""
    import dask
    import xarray as xr

    result = simulate_field(day.iloc[600:660], "lanzhou", TroughLoop(count=2))
    with dask.config.set(scheduler="dask.distributed"):
        written = result.save(tmp_path / "field")
        assert dask.config.get("scheduler") == "dask.distributed"  # the caller's setting, as it was
    with xr.open_dataset(written["log"], engine="scipy") as saved:
        assert dict(saved.sizes) == {"collector": 2, "time": 60}


def test_the_engine_is_chosen_on_the_fields_scans_not_each_collectors(day, monkeypatch, engine_choices):
    """Where the kernel is neither compiled nor cached, ``auto`` compiles it from COMPILE_PAYS_AT
    scans: a field's collectors are counted together (each alone had run the reference loop, a
    20-row year 34 s a row against 0.6 s), and a field too short to pay runs the reference."""
    import hybridtrack.kernel as kernel

    engines = engine_choices
    monkeypatch.setattr(kernel, "COMPILE_PAYS_AT", 3 * len(day))
    simulate_field(day, "lanzhou", TroughLoop(count=3), keep_log=False, threads=1)
    assert engines == ["compiled"] * 6  # each collector's run and its warm-start day
    engines.clear()
    simulate_field(day, "lanzhou", TroughLoop(count=2), keep_log=False, threads=1)
    assert engines == ["auto"] * 4


@pytest.mark.parametrize("progress, compiles, said", [(True, True, True), (True, False, False), (False, True, False)])
def test_a_field_that_compiles_the_kernel_first_says_so_beside_its_bar(day, monkeypatch, capsys, progress, compiles,
                                                                       said):
    import hybridtrack.kernel as kernel

    monkeypatch.setattr(kernel, "compiles_first", lambda config, scans: compiles)
    simulate_field(day, "lanzhou", FresnelField(row_distances=[-2.0, 2.0]), keep_log=False, progress=progress)
    assert ("compiling the controller kernel" in capsys.readouterr().err) is said


def test_a_field_starts_no_more_dask_workers_than_it_has_collectors(day, monkeypatch):
    """--workers 64 for three rows had started 64 processes (2 min on two cores) for three runs."""
    import hybridtrack.cluster

    asked = []

    def fake_client(scheduler, workers, **_):
        asked.append(workers)
        raise HybridtrackError("stop here")

    monkeypatch.setattr(hybridtrack.cluster, "dask_client", fake_client)
    with pytest.raises(HybridtrackError, match="stop here"):
        simulate_field(day, "lanzhou", FresnelField(row_distances=[-4.0, 0.0, 4.0]), workers=64)
    assert asked == [3]


@pytest.mark.parametrize("table, what, name", [
    (pd.DataFrame([[0, 500, -80], [20, 600, -80]], columns=["east", "East ", "north"]), "positions", "east"),
    (pd.DataFrame([[0, -80, 5], [20, -80, 5]], columns=["east", "north", "north"]), "positions", "north"),
    (pd.DataFrame([[0, 0, 100, 7], [0, 0, 90, 7]], columns=["aim_east", "aim_north", "aim_up", "AIM_UP"]), "aims",
     "aim_up"),
])
def test_a_table_column_given_twice_is_refused_not_the_last_read(table, what, name):
    """The last of two columns of one name had been read: ``east, East`` took the second as east,
    ``east, north, north`` the second north as up, ``aim_up, AIM_UP`` the 7 m (helper-38)."""
    given = {"positions": table} if what == "positions" else {"positions": [[0.0, -80.0], [20.0, -80.0]], "aims": table}
    with pytest.raises(HybridtrackError, match=f"the table has the column '{name}' more than once"):
        HeliostatField(**given)


def test_a_tables_columns_not_read_are_named_in_a_warning():
    """An ``elevation`` beside ``east, north`` had put the mirrors at 0 m up without a word."""
    table = pd.DataFrame({"east": [0.0, 20.0], "north": [-80.0, -80.0], "elevation": [3.0, 3.0]})
    with pytest.warns(UserWarning, match=r"heliostat positions: the table's elevation is not read \(heliostat "
                                         r"positions reads east, north, up\)"):
        field = HeliostatField(positions=table)
    assert (field.positions[:, 2] == 0.0).all()


def test_a_fields_mirrors_cannot_be_moved_in_place_and_an_aim_on_the_mirror_is_refused():
    """A frozen field's positions had been writable (two mirrors put in one place ran), and an aim
    point 1e-300 m above the mirror ran, scoring 0.97 (helper-38)."""
    field = HeliostatField(positions=[[0.0, -60.0], [30.0, -80.0]], aims=[[0.0, 0.0, 80.0], [0.0, 0.0, 80.0]])
    for array in (field.positions, field.aims):
        with pytest.raises(ValueError, match="read-only"):
            array[1] = array[0]
    with pytest.raises(HybridtrackError, match=r"heliostat 1: its aim point is not above the mirror \(1e-300 m up "
                                               r"from it, at least 0\.1 m\)"):
        HeliostatField(positions=[[0.0, -60.0]], aim=(0.0, 0.0, 1e-300))
    targets = TroughLoop(count=3).targets(np.array([30.0, 40.0]), np.array([120.0, 150.0]))
    assert targets.shape == (2, 3) and targets.flags.writeable  # as the other fields' targets are
    import copy
    import pickle

    for again in (pickle.loads(pickle.dumps(field)), copy.deepcopy(field)):  # numpy's pickle gives writable arrays
        assert not again.positions.flags.writeable and not again.aims.flags.writeable
        np.testing.assert_array_equal(again.positions, field.positions)
        assert again.aim == field.aim
