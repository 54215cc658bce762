"""The compiled pass of a collector's angles (`hybridtrack.mountpass`) against numpy's path
(`angles_on_mount(..., engine="numpy")`, its reference), bit for bit where numpy's elementary
functions are the C library's; and where the pass leaves a path to the reference (a vector on
the horizon, an infinite or zero vector).

On a machine with AVX-512, numpy takes `arcsin`, `arccos`, `arctan2` (and, by its build, more)
from its SIMD library (Intel's SVML), which rounds differently from the C library numba calls:
there the two paths are held to the same NaNs and to 1e-12 (angles in degrees; 6e-14° the most
seen, 2026-11-29)."""

import math

import numpy as np
import pandas as pd
import pytest

from hybridtrack import sites
from hybridtrack.collectors import Collector, sun_vector
from hybridtrack.errors import HybridtrackError
from hybridtrack.fields import FresnelField, HeliostatField
from hybridtrack.mounting import angles_on_mount, mount_targets, mounting_rotation, pointing_vectors
from hybridtrack.sun import solar_position

COLLECTORS = {"trough-ns": Collector("trough-ns"), "trough-ew": Collector("trough-ew"),
              "trough-30": Collector("trough", axis_azimuth=30.0), "fresnel-west": FresnelField().collectors()[2],
              "fresnel-east": FresnelField().collectors()[17], "heliostat": HeliostatField.rings(2).collectors()[1]}


def _sun():
    """A year's sun path every 53 minutes: nights and days of every season, some NaN."""
    index = pd.date_range("2021-01-01", "2021-12-31", freq="53min", tz="UTC")
    position = solar_position(index, sites.get("lanzhou"), "spa")
    altitude, azimuth = position["altitude"].to_numpy(copy=True), position["azimuth"].to_numpy(copy=True)
    altitude[::97] = np.nan
    return altitude, azimuth


def _numpy_rounds_as_libm() -> bool:
    """Whether numpy's trigonometry gives the C library's bits on this machine (each function the
    passes call, over the range they call it on)."""
    x = np.linspace(-0.999, 0.999, 4001)
    y = np.linspace(-3.0, 3.0, 4001)[::-1]
    pairs = [(np.arcsin(x), map(math.asin, x)), (np.arccos(x), map(math.acos, x)), (np.sin(y), map(math.sin, y)),
             (np.cos(y), map(math.cos, y)), (np.arctan2(x, y), map(math.atan2, x, y)),
             (np.hypot(x, y), map(math.hypot, x, y))]
    return all(np.array_equal(numpys, list(libms)) for numpys, libms in pairs)


#: Bit for bit where numpy rounds as the C library does (AVX2 machines); see the module's note.
BITS = _numpy_rounds_as_libm()


def _as_numpys(got, expected):
    """The pass's result against numpy's path: its bits, or on AVX-512 its NaNs and 1e-12."""
    assert got.shape == expected.shape
    if BITS:
        assert np.array_equal(got.view(np.int64), expected.view(np.int64))  # NaN's bits too
    else:
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected))
        np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-12)


@pytest.mark.parametrize("name", COLLECTORS)
@pytest.mark.parametrize("night", [False, True])
@pytest.mark.parametrize("mount", [None, (0.3, -0.2, 0.1), (-4.0, 3.0, -2.5)])
def test_compiled_angles_are_numpys_bit_for_bit(name, night, mount):
    collector = COLLECTORS[name]
    altitude, azimuth = _sun()
    rotation = None if mount is None else mounting_rotation(mount[0], mount[1], collector.axis, mount[2])
    vectors = pointing_vectors(altitude, azimuth, collector, night=night)
    expected = angles_on_mount(vectors, collector, rotation, engine="numpy")
    assert np.isfinite(expected).any() and np.isnan(expected).any()
    _as_numpys(angles_on_mount(vectors, collector, rotation, engine="compiled"), expected)
    _as_numpys(angles_on_mount(vectors, collector, rotation), expected)
    given = None if collector.kind == "heliostat" else vectors
    expected = mount_targets(altitude, azimuth, collector, rotation, vectors=given, night=night, engine="numpy")
    _as_numpys(mount_targets(altitude, azimuth, collector, rotation, vectors=given, night=night,
                             engine="compiled"), expected)
    if collector.kind == "heliostat":  # its normals made in the pass from the sun's unit vectors
        sun = sun_vector(np.abs(altitude) if night else altitude, azimuth)
        _as_numpys(mount_targets(altitude, azimuth, collector, rotation, sun=sun, night=night), expected)


@pytest.mark.parametrize("night", [False, True])
def test_compiled_heliostat_normals_are_numpys_bit_for_bit(night):
    """A heliostat's mirror normals under a year's sun vectors, in one pass, against numpy's
    bisector over its length (NaN where the sun is down), and by hand: the sun at the zenith
    and the aim point at the horizon tilt the normal 45°."""
    from hybridtrack.collectors import heliostat_normal

    altitude, azimuth = _sun()
    sun = sun_vector(np.abs(altitude) if night else altitude, azimuth)
    for aim in [(0.0, 20.0, 100.0), (-35.0, -80.0, 60.0)]:
        got = heliostat_normal(np.abs(altitude) if night else altitude, azimuth, aim, sun=sun)
        unit = np.asarray(aim) / np.linalg.norm(aim)
        bisector = sun + unit
        expected = np.where(((np.abs(altitude) if night else altitude) < 0.0)[:, None], np.nan,
                            bisector / np.linalg.norm(bisector, axis=-1, keepdims=True))
        _as_numpys(got, expected)
    np.testing.assert_allclose(heliostat_normal([90.0], [0.0], (0.0, 10.0, 0.0), sun=[[0.0, 0.0, 1.0]]),
                               [[0.0, np.sqrt(0.5), np.sqrt(0.5)]], rtol=0, atol=1e-15)


def test_a_trough_on_a_known_sun_reads_pvlibs_tracker_through_the_pass():
    """An independent reference beside numpy's path: pvlib's single-axis tracker (trough
    convention: 90° + its rotation) on a north-south axis."""
    import pvlib

    altitude, azimuth = np.array([10.0, 35.0, 62.0, 20.0]), np.array([95.0, 130.0, 200.0, 260.0])
    got = angles_on_mount(sun_vector(altitude, azimuth), Collector("trough-ns"), engine="compiled")
    pv = pvlib.tracking.singleaxis(90 - altitude, azimuth, axis_azimuth=180, backtrack=False, max_angle=180)
    np.testing.assert_allclose(got[:, 0], 90 + np.asarray(pv["tracker_theta"]), rtol=0, atol=1e-9)


def test_a_vector_on_the_horizon_takes_the_reference_path():
    """A vector with an up component of exactly zero along the axis gives 90° (the reference's
    rule for no part across the axis), with the pass as without it."""
    vectors = np.array([[0.0, 1.0, 0.0], [0.3, 0.5, 0.8], [1.0, 0.0, 0.0]])
    got = angles_on_mount(vectors, Collector("trough-ns"), engine="compiled")
    _as_numpys(got, angles_on_mount(vectors, Collector("trough-ns"), engine="numpy"))
    assert got[0, 0] == 90.0 and got[2, 0] == 0.0


@pytest.mark.parametrize("name", ["trough-ns", "heliostat"])
def test_an_infinite_vector_is_refused_by_name_either_way(name):
    vectors = np.array([[0.3, 0.5, 0.8], [np.inf, 0.0, 0.5]])
    messages = []
    for engine in ("numpy", "compiled"):
        with pytest.raises(HybridtrackError) as refused:
            angles_on_mount(vectors, COLLECTORS[name], engine=engine)
        messages.append(str(refused.value))
    assert messages[0] == messages[1] and "finite" in messages[0]


def test_a_zero_normal_is_refused_either_way():
    for engine in ("numpy", "compiled"):
        with pytest.raises(HybridtrackError, match="zero vector"):
            angles_on_mount(np.array([[0.0, 1.0, 1.0], [0.0, 0.0, 0.0]]), Collector("heliostat"), engine=engine)


def test_an_unknown_engine_is_refused_by_name():
    with pytest.raises(HybridtrackError, match="unknown engine 'fast'"):
        angles_on_mount(np.array([[0.0, 1.0, 1.0]]), Collector(), engine="fast")
    with pytest.raises(HybridtrackError, match="mount_targets: unknown engine"):
        mount_targets([30.0], [120.0], Collector(), engine=None)


def test_without_numba_the_reference_path_runs_and_compiled_is_refused():
    import subprocess
    import sys
    from pathlib import Path

    import hybridtrack

    script = ("import sys\nsys.modules['numba'] = None\n"
              "from hybridtrack.collectors import Collector\n"
              "from hybridtrack.errors import HybridtrackError\n"
              "from hybridtrack.mounting import angles_on_mount\n"
              "print(angles_on_mount([[0.0, 0.6, 0.8]], Collector())[0, 0])\n"
              "try:\n    angles_on_mount([[0.0, 0.6, 0.8]], Collector(), engine='compiled')\n"
              "except HybridtrackError as error:\n    print(error)\n")
    env = {"PYTHONPATH": str(Path(hybridtrack.__file__).parents[1]), "PATH": ""}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    first, second = done.stdout.strip().splitlines()
    assert float(first) == pytest.approx(np.degrees(np.arctan2(0.8, 0.0)))
    assert "needs numba" in second


@pytest.mark.parametrize("name", COLLECTORS)
@pytest.mark.parametrize("lit_only", [False, True])
def test_compiled_derivatives_are_numpys_bit_for_bit(name, lit_only):
    """The mount fit's derivatives of the plan's targets (`vector_jacobian`) in one pass against
    numpy's path, over a year's scans followed below the horizon, some NaN: with the plan's lit
    scans (zero elsewhere) and without."""
    from hybridtrack.control.mountfit import vector_jacobian

    collector = COLLECTORS[name]
    altitude, azimuth = _sun()
    vectors = pointing_vectors(altitude, azimuth, collector, night=True)
    vectors[5] = [0.0, 0.0, 1.0]  # the zenith: a heliostat's azimuth gradient divides by zero there
    lit = np.isfinite(vectors).all(axis=1) & (np.arange(len(vectors)) % 5 != 0) if lit_only else None
    expected = vector_jacobian(vectors, collector, lit=lit, engine="numpy")
    assert np.isfinite(expected).all() and (expected != 0).any()
    _as_numpys(vector_jacobian(vectors, collector, lit=lit), expected)


def test_a_heliostats_compiled_pointing_error_is_numpys_bit_for_bit():
    """The angle between the normal a heliostat stands at and its true normal, in one pass,
    against the numpy path over a year's sun (NaN where the sun is down), with the axes off
    their targets by up to a few degrees, some past the zenith; and by hand: 3° of elevation
    alone is 3°, 90° of azimuth at the horizon is 90°."""
    from types import SimpleNamespace

    from hybridtrack.simulation import _pointing_error

    collector = COLLECTORS["heliostat"]
    altitude, azimuth = _sun()
    truth = mount_targets(altitude, azimuth, collector, mounting_rotation(0.3, -0.2, collector.axis, 0.1))
    rng = np.random.default_rng(4)
    angles = np.nan_to_num(truth.T, nan=45.0) + rng.normal(0.0, 2.0, (2, len(truth)))
    angles[1, :50] = 90.5  # past the zenith
    world = SimpleNamespace(truth=truth, angles=angles)
    expected = _pointing_error(collector, world, engine="numpy")
    assert np.isnan(expected).any() and np.nanmax(expected) > 1.0
    _as_numpys(_pointing_error(collector, world), expected)
    by_hand = SimpleNamespace(truth=np.array([[180.0, 40.0], [0.0, 0.0]]), angles=np.array([[180.0, 90.0], [43.0, 0.0]]))
    np.testing.assert_allclose(_pointing_error(collector, by_hand), [3.0, 90.0], rtol=0, atol=1e-12)


def test_derivatives_and_errors_refuse_what_does_not_fit_by_name():
    """A `lit` mask of another length or of indices had been read past its end by the pass (rows
    taken as lit at random); wrong shapes had raised numpy's IndexError. The pointing error's
    pass declines angles of another length, and float32, which numpy's path keeps."""
    from types import SimpleNamespace

    from hybridtrack.control.mountfit import vector_jacobian
    from hybridtrack.simulation import _pointing_error

    vectors, collector = np.tile([0.3, 0.2, 0.93], (1000, 1)), Collector("trough-ns")
    for lit in (np.ones(3, bool), np.array([0, 5]), np.ones(1000)):
        with pytest.raises(HybridtrackError, match="vector_jacobian: lit must be one True or False a scan"):
            vector_jacobian(vectors, collector, lit=lit)
    for bad in (vectors[:, :2], vectors[None], "up"):
        with pytest.raises(HybridtrackError, match="vector_jacobian: vectors must be"):
            vector_jacobian(bad, collector)
    with pytest.raises(HybridtrackError, match="unknown engine"):
        vector_jacobian(vectors, collector, engine="fast")
    helio = COLLECTORS["heliostat"]
    truth = np.tile([180.0, 40.0], (10, 1))
    with pytest.raises(IndexError):  # the numpy path's own error, as before: an internal function
        _pointing_error(helio, SimpleNamespace(truth=truth, angles=np.zeros((2, 5))))
    single = SimpleNamespace(truth=truth.astype(np.float32), angles=np.full((2, 10), 41.0, np.float32))
    _as_numpys(_pointing_error(helio, single), _pointing_error(helio, single, engine="numpy"))
