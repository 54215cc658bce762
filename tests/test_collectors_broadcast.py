"""Geometry over many collectors at once: one call equals the per-collector loop and hand cases."""

import numpy as np
import pandas as pd
import pvlib
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.collectors import (
    THREE_POINT_SUPPORT, across_angle, fresnel_angle, fresnel_end_loss, heliostat_normal, jack_heights, normal_angles,
    receiver_angle, sun_vector, tracking_rate, trough_angle,
)
from hybridtrack.sun import altitude_azimuth, solar_position
from hybridtrack.times import local_range

KUNMING_LATITUDE = 25 + 1 / 60
DISTANCES = np.arange(2.5, 25.01, 2.5)
# published end losses at Kunming, equinox, h = 10 m: noon and 07:00 solar time
END_LOSS_NOON = [4.810, 5.217, 5.833, 6.600, 7.470, 8.413, 9.406, 10.435, 11.490, 12.565]
END_LOSS_0700 = [1.135, 1.232, 1.376, 1.558, 1.763, 1.985, 2.219, 2.462, 2.711, 2.965]


@pytest.fixture(scope="module")
def sun():
    return solar_position(local_range("2021-06-21", "Asia/Shanghai", freq="10min"), "lanzhou")


def test_end_loss_takes_every_row_distance_in_one_call():
    alt, az = altitude_azimuth(0.0, np.array([0.0, -75.0]), KUNMING_LATITUDE)  # equinox: noon and 07:00
    losses = fresnel_end_loss(alt[:, None], az[:, None], DISTANCES, 10.0)
    assert losses.shape == (2, len(DISTANCES))
    np.testing.assert_allclose(losses, [END_LOSS_NOON, END_LOSS_0700], atol=0.002)


def test_end_loss_broadcasts_receiver_heights_too(sun):
    rows = np.array([-7.5, 2.5, 10.0])
    heights = np.array([8.0, 10.0, 12.0])
    table = fresnel_end_loss(sun.altitude.to_numpy()[:, None], sun.azimuth.to_numpy()[:, None], rows, heights)
    for i, (d, h) in enumerate(zip(rows, heights)):
        np.testing.assert_array_equal(table[:, i], fresnel_end_loss(sun.altitude, sun.azimuth, d, h).to_numpy())


def test_fresnel_angles_of_a_field_equal_the_row_by_row_results(sun):
    rows = np.linspace(-12.0, 12.0, 9)
    table = fresnel_angle(sun.altitude.to_numpy()[:, None], sun.azimuth.to_numpy()[:, None], rows, 10.0)
    assert table.shape == (len(sun), len(rows))
    for i, d in enumerate(rows):
        np.testing.assert_array_equal(table[:, i], fresnel_angle(sun.altitude, sun.azimuth, d, 10.0).to_numpy())


def test_fresnel_angle_hand_cases():
    # sun at the zenith: the normal bisects 90° and the receiver direction atan2(h, -d)
    assert fresnel_angle(90.0, 0.0, [0.0, 10.0, -10.0], 10.0) == pytest.approx([90.0, 112.5, 67.5])
    assert receiver_angle([10.0, -10.0], [10.0, 10.0]) == pytest.approx([135.0, 45.0])
    assert isinstance(receiver_angle(5.0, 10.0), float)


def test_elementwise_broadcast_keeps_a_series_and_axes_per_collector(sun):
    up = sun[sun.altitude > 0]
    one_per_step = trough_angle(up.altitude, up.azimuth, np.zeros(len(up)))
    assert isinstance(one_per_step, pd.Series)
    pv = pvlib.tracking.singleaxis(90 - up.altitude, up.azimuth, axis_azimuth=180, backtrack=False, max_angle=90)
    np.testing.assert_allclose(one_per_step, 90 + pv.tracker_theta, atol=1e-9)
    axes = np.array([0.0, 30.0, 270.0])
    table = trough_angle(up.altitude.to_numpy()[:, None], up.azimuth.to_numpy()[:, None], axes)
    for i, axis in enumerate(axes):
        np.testing.assert_array_equal(table[:, i], trough_angle(up.altitude, up.azimuth, axis).to_numpy())


def test_one_altitude_broadcasts_against_many_azimuths(sun):
    """A scalar altitude against an array of azimuths had raised numpy's ValueError ('all input
    arrays must have the same shape') in every function; pvlib's tracker is the reference."""
    azimuths = np.array([60.0, 120.0, 200.0, 300.0])
    np.testing.assert_allclose(sun_vector(30.0, azimuths), sun_vector(np.full(4, 30.0), azimuths), rtol=0, atol=0)
    np.testing.assert_allclose(sun_vector(30.0, 90.0), [np.cos(np.radians(30.0)), 0.0, 0.5], rtol=0, atol=1e-16)
    pv = pvlib.tracking.singleaxis(np.full(4, 60.0), azimuths, axis_azimuth=180, backtrack=False, max_angle=90)
    np.testing.assert_allclose(trough_angle(30.0, azimuths), 90 + pv["tracker_theta"], rtol=0, atol=1e-9)
    assert fresnel_angle(30.0, azimuths, 5.0, 10.0).shape == fresnel_end_loss(30.0, azimuths, 5.0, 10.0).shape == (4,)
    assert heliostat_normal(30.0, azimuths, (0.0, 20.0, 100.0)).shape == (4, 3)


SCALARS = [30.0, 30, np.float64(30.0), np.array(30.0)]  # a Python float and int, numpy's float and a 0-d array


@pytest.mark.parametrize("alt", SCALARS)
def test_every_function_gives_a_numpy_float_for_one_number_and_arrays_for_arrays(alt):
    """They had given a 0-d array (trough_angle, fresnel_end_loss, across_angle), a numpy.float64
    (fresnel_angle) or a Python float (receiver_angle). References: pvlib's tracker, hand cases."""
    from hybridtrack.collectors import within_turn

    az = 120.0 if isinstance(alt, float) else np.array(120.0) if isinstance(alt, np.ndarray) else 120
    pv = pvlib.tracking.singleaxis(60.0, 120.0, axis_azimuth=180, backtrack=False, max_angle=90)
    lean = np.degrees(np.arctan2(np.cos(np.radians(30.0)) * np.sin(np.radians(120.0)), 0.5))  # across ⊥ zenith
    singles = {
        "trough_angle": (trough_angle(alt, az), 90.0 + np.ravel(pv["tracker_theta"])[0]),
        "fresnel_angle": (fresnel_angle(90.0, 0.0, alt / 3.0, 10.0), 112.5),  # zenith sun, receiver at 135°
        "receiver_angle": (receiver_angle(alt / 3.0, 10.0), 135.0),
        "fresnel_end_loss": (fresnel_end_loss(90.0 - alt, 180.0, 0.0, 10.0), 10.0 / np.tan(np.radians(60.0))),
        "across_angle": (across_angle(sun_vector(alt, az), 0.0), 90.0 - lean),
        "within_turn": (within_turn(-alt), 330.0),
        "normal_angles azimuth": (normal_angles([1.0, 0.0, 1.0])[0], 90.0),
        "normal_angles elevation": (normal_angles([1.0, 0.0, 1.0])[1], 45.0),
    }
    for name, (got, expected) in singles.items():
        assert type(got) is np.float64, name
        assert got == pytest.approx(expected, abs=1e-9), name
    assert sun_vector(alt, az).shape == heliostat_normal(alt, az, (0.0, 20.0, 100.0)).shape == (3,)
    np.testing.assert_allclose(jack_heights([0.0, 0.0, 1.0]), [0.0, 0.0, 0.0])  # a level mirror: jacks at 0
    assert jack_heights([0.0, 0.0, 1.0]).shape == (3,)
    assert type(trough_angle([alt], [az])) is np.ndarray and trough_angle([alt], [az]).shape == (1,)
    assert type(trough_angle(alt, az, [0.0, 90.0])) is np.ndarray  # one sun, two axes
    assert type(receiver_angle([10.0], 10.0)) is np.ndarray and type(within_turn([-30.0])) is np.ndarray
    assert normal_angles([[1.0, 0.0, 1.0]])[1].shape == (1,)
    assert isinstance(trough_angle(pd.Series([30.0]), pd.Series([120.0])), pd.Series)


def test_trough_hand_case_sun_along_and_across_the_axis():
    # sun low in the east at 30°: a north-south trough faces it at 30°; an east-west axis sees it along itself
    assert trough_angle(30.0, 90.0, [0.0, 90.0]) == pytest.approx([30.0, 90.0])


def test_heliostat_normals_of_m_mirrors_at_t_steps_in_one_call(sun):
    aims = np.array([[0.0, 20.0, 100.0], [30.0, -40.0, 95.0], [-60.0, 10.0, 102.0], [5.0, 80.0, 99.0]])
    alt, az = sun.altitude.to_numpy(), sun.azimuth.to_numpy()
    normals = heliostat_normal(alt[:, None], az[:, None], aims)
    assert normals.shape == (len(sun), len(aims), 3)
    azimuth, elevation = normal_angles(normals)
    jacks = jack_heights(normals)
    assert azimuth.shape == (len(sun), len(aims)) and jacks.shape == (len(sun), len(aims), 3)
    for m, aim in enumerate(aims):
        one = heliostat_normal(alt, az, aim)
        np.testing.assert_array_equal(normals[:, m], one)
        np.testing.assert_array_equal(jacks[:, m], jack_heights(one, THREE_POINT_SUPPORT))
        np.testing.assert_array_equal(elevation[:, m], normal_angles(one)[1])


def test_heliostat_hand_cases():
    # sun at the zenith: aim straight up keeps the mirror flat; aim due north on the horizon tilts it 45°
    n = heliostat_normal(90.0, 0.0, [[0.0, 0.0, 50.0], [0.0, 100.0, 0.0]])
    np.testing.assert_allclose(n, [[0.0, 0.0, 1.0], [0.0, np.sqrt(0.5), np.sqrt(0.5)]], atol=1e-12)
    assert heliostat_normal(45.0, 180.0, (0.0, 20.0, 100.0)).shape == (3,)  # one sun, one mirror: one normal
    night = heliostat_normal(np.array([[-5.0], [30.0]]), np.array([[90.0], [120.0]]), [[0, 1, 1], [1, 0, 1]])
    assert np.isnan(night[0]).all() and np.isfinite(night[1]).all()


@pytest.mark.parametrize("call, message", [
    (lambda: fresnel_end_loss(50.0, 180.0, [1.0, np.nan], 10.0), "row distance d must be finite"),
    (lambda: fresnel_angle(50.0, 180.0, [1.0, 2.0], [10.0, -1.0]), "receiver height h must be positive"),
    (lambda: fresnel_angle(50.0, 180.0, 1.0, 10.0, [0.0, np.inf]), "axis azimuth must be finite"),
    (lambda: trough_angle(50.0, 180.0, ["north"]), "axis azimuth must be numbers"),
    (lambda: heliostat_normal(50.0, 180.0, [[0, 0, 1], [0, 0, 0]]), "aim point must be three finite"),
    (lambda: heliostat_normal(50.0, 180.0, [[0, 0, 1, 2]]), "aim point must be three finite"),
])
def test_bad_collector_parameters_are_refused_with_their_name(call, message):
    with pytest.raises(HybridtrackError, match=message):
        call()


THREE_SUNS = np.array([30.0, 45.0, 60.0]), np.array([120.0, 180.0, 240.0])


@pytest.mark.parametrize("call, message", [
    (lambda: trough_angle(*THREE_SUNS, [0.0, 90.0]),
     r"trough_angle: the shapes altitude \(3,\), azimuth \(3,\), axis_azimuth \(2,\) do not broadcast together "
     r"\(a sun position of shape \(T, 1\) against"),
    (lambda: fresnel_angle(*THREE_SUNS, [-4.0, 4.0], 8.0), r"fresnel_angle: the shapes .* d \(2,\), h \(\)"),
    (lambda: fresnel_end_loss(*THREE_SUNS, [-4.0, 4.0], 8.0), r"fresnel_end_loss: the shapes .* d \(2,\)"),
    (lambda: heliostat_normal(*THREE_SUNS, [[0, 100, 100], [50, 90, 100]]),
     r"aim_points without their x, y, z axis \(2,\) do not broadcast"),
    (lambda: receiver_angle([1.0, 2.0], [1.0, 2.0, 3.0]), r"receiver_angle: the shapes d \(2,\), h \(3,\) do not "
                                                           r"broadcast together$"),
    (lambda: normal_angles(np.ones((3, 2))), r"normals must be \(east, north, up\) vectors.*got shape \(3, 2\)"),
    (lambda: jack_heights(np.ones((3, 2))), r"jack_heights: normals must be"),
])
def test_collector_parameters_of_shapes_that_do_not_broadcast_are_named(call, message):
    """numpy's ValueError (or an IndexError) named no parameter and was no HybridtrackError."""
    with pytest.raises(HybridtrackError, match=message):
        call()


@pytest.mark.parametrize("call, message", [
    (lambda: trough_angle("abc", 90.0), r"trough_angle: altitude must be numbers \(degrees\), got 'abc'"),
    (lambda: trough_angle(None, 90.0), "altitude must be numbers"),  # had been NaN, without a word
    (lambda: trough_angle(True, False), "altitude must be numbers"),  # had been read as 1 and 0
    (lambda: trough_angle(["10"], ["90"]), "altitude must be numbers"),
    (lambda: fresnel_angle(10 + 1j, 120.0, 5.0, 10.0), "fresnel_angle: altitude must be numbers"),
    (lambda: trough_angle(200.0, 90.0), r"altitude must be within \[-90, 90\] degrees .* got 200"),  # gave 200
    (lambda: fresnel_end_loss(np.inf, 120.0, 5.0, 10.0), "altitude must be finite degrees"),
    (lambda: heliostat_normal(30.0, "south", [0, 20, 100]), "heliostat_normal: azimuth must be numbers"),
    (lambda: fresnel_end_loss(30.0, 120.0, 5.0, -10.0), "receiver height h must be positive"),  # gave +10 m's
    (lambda: trough_angle(pd.Series([10.0, 20.0], index=[0, 1]), pd.Series([90.0, 120.0], index=[1, 0])),
     "altitude and azimuth are Series on different indexes"),  # paired by position, labelled by altitude's
])
def test_a_sun_position_that_is_no_angle_is_refused_by_name(call, message):
    with pytest.raises(HybridtrackError, match=message):
        call()


def test_a_fields_geometry_takes_one_position_as_a_path_of_one_step_and_refuses_ragged_paths():
    from hybridtrack.fields import FresnelField, HeliostatField

    assert FresnelField().targets(30.0, 120.0).shape == (1, 20)  # numpy's IndexError before
    assert HeliostatField().normals(30.0, 120.0).shape == (1, 3, 3)
    with pytest.raises(HybridtrackError, match=r"the same length; got shapes \(2,\) and \(1,\)"):
        FresnelField(row_distances=[-2.0, 2.0]).targets([30.0, 40.0], [120.0])  # the azimuth had been reused


def test_tracking_rates_of_a_field_are_each_columns_own(sun):
    rows = [-6.0, 0.0, 6.0]
    angles = pd.DataFrame(fresnel_angle(sun.altitude.to_numpy()[:, None], sun.azimuth.to_numpy()[:, None], rows, 10.0),
                          index=sun.index, columns=["west", "middle", "east"])
    rates = tracking_rate(angles)
    assert list(rates.columns) == ["west", "middle", "east"] and rates.index.equals(sun.index)
    for column, d in zip(rates.columns, rows):
        np.testing.assert_array_equal(rates[column], tracking_rate(fresnel_angle(sun.altitude, sun.azimuth, d, 10.0)))
    # hand case: an angle growing 15° an hour turns at 0.25°/min
    hours = pd.date_range("2021-06-21 08:00", periods=5, freq="1h", tz="UTC")
    np.testing.assert_allclose(tracking_rate(pd.DataFrame({"a": 15.0 * np.arange(5)}, index=hours)), 0.25)


def _stamps(count):
    return pd.date_range("2021-06-21 08:00", periods=count, freq="10min", tz="Asia/Shanghai")


@pytest.mark.parametrize("angles, message", [
    (lambda: pd.Series([0.0, 1.0, 4.0], index=_stamps(3)[[1, 0, 2]]), "time stamps that increase"),  # wrong rates
    (lambda: pd.Series([1.0, 2.0, 3.0], index=_stamps(3)[[0, 0, 1]]), "without repeats"),  # inf and nan
    (lambda: pd.Series([1.0, 2.0, 3.0], index=pd.DatetimeIndex([_stamps(1)[0], pd.NaT, _stamps(3)[2]])), "NaT"),
    (lambda: pd.Series(["a", "b", "c"], index=_stamps(3)), "angles as numbers"),  # numpy's ValueError
    (lambda: pd.DataFrame({"a": [1.0, 2.0], "b": ["x", "y"]}, index=_stamps(2)), "angles as numbers"),
])
def test_tracking_rate_refuses_stamps_out_of_order_and_angles_that_are_no_numbers(angles, message):
    with pytest.raises(HybridtrackError, match=message):
        tracking_rate(angles())


@pytest.mark.parametrize("aim, message", [(None, "must be three numbers"), (5.0, "must be three numbers"),
                                          ((0.0, 20.0), "must be three numbers"), ("abc", "must be a finite number")])
def test_a_heliostats_aim_that_is_no_point_is_refused_and_a_list_or_array_is_kept_as_a_tuple(aim, message):
    from hybridtrack.collectors import Collector

    with pytest.raises(HybridtrackError, match=f"collector: aim \\(m\\) {message}"):
        Collector("heliostat", aim=aim)
    listed = Collector("heliostat", aim=np.array([0.0, 20.0, 100.0]))  # an array made it unhashable
    assert listed == Collector("heliostat") and hash(listed) == hash(Collector("heliostat"))


@pytest.mark.parametrize("call, message", [
    (lambda: jack_heights([1.0, 0.0, 0.0]), r"normals must point up \(n_z > 0\)"),  # gave nan, inf, -inf
    (lambda: jack_heights("abc"), "normals must be \\(east, north, up\\) vectors of numbers"),
    (lambda: normal_angles([[0, 0, 1], [0, 1]]), "vectors of numbers"),  # ragged
    (lambda: __import__("hybridtrack.collectors").collectors.across_angle([1.0, 0.0], 0.0), "shape \\(..., 3\\)"),
    (lambda: __import__("hybridtrack.collectors").collectors.Collector("fresnel").angles(np.ones(2), np.ones(2)),
     "takes the sun path as two Series"),  # AttributeError: 'numpy.ndarray' object has no attribute 'index'
])
def test_vectors_and_paths_that_are_no_such_thing_are_refused_by_name(call, message):
    with pytest.raises(HybridtrackError, match=message):
        call()


def test_normal_angles_take_a_normal_of_any_length_and_refuse_none():
    """The arcsine of the up component alone read (0, 3, 2) as 90° elevation; its direction is
    atan(2/3) = 33.69° above north's horizon (hand-computed), and ten times it is the same."""
    azimuth, elevation = normal_angles([[0.0, 3.0, 2.0], [0.0, 30.0, 20.0], [-1.0, 0.0, -1.0]])
    np.testing.assert_allclose(elevation, [33.690067525979785, 33.690067525979785, -45.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(azimuth, [0.0, 0.0, 270.0], atol=1e-12)
    with pytest.raises(HybridtrackError, match="zero vector"):
        normal_angles([0.0, 0.0, 0.0])


RAGGED = [[10.0, 20.0], [30.0]]


@pytest.mark.parametrize("call, message", [
    (lambda: fresnel_angle(50.0, 180.0, "5", 10.0), "row distance d must be numbers"),  # had been read as 5 m
    (lambda: fresnel_angle(50.0, 180.0, True, 10.0), "row distance d must be numbers"),  # had been read as 1 m
    (lambda: fresnel_end_loss(50.0, 180.0, 5.0, ["10"]), "receiver height h must be numbers"),
    (lambda: receiver_angle(5.0, "10"), "receiver height h must be numbers"),
    (lambda: trough_angle(50.0, 180.0, ["90"]), "axis azimuth must be numbers"),  # had been read as 90°
    (lambda: heliostat_normal(50.0, 180.0, ["0", "20", "100"]), "aim point must be three finite"),  # was taken
    (lambda: heliostat_normal(50.0, 180.0, "abc"), "aim point must be three finite"),  # numpy's ValueError
    (lambda: heliostat_normal(50.0, 180.0, [[0, 20, 100], [0, 20]]), "aim point must be three finite"),  # ragged
    (lambda: trough_angle(RAGGED, 90.0), "trough_angle: altitude must be numbers"),  # numpy's ValueError
    (lambda: sun_vector(30.0, RAGGED), "sun_vector: azimuth must be numbers"),
    (lambda: heliostat_normal(RAGGED, 90.0, [0, 20, 100]), "heliostat_normal: altitude must be numbers"),
    (lambda: fresnel_angle(50.0, 180.0, [True, 2.0], 10.0), "row distance d must be numbers"),  # read as 1 m
    (lambda: trough_angle(50.0, 180.0, [0.0, True]), "axis azimuth must be numbers"),  # read as 1°
    (lambda: heliostat_normal(50.0, 180.0, [True, 0, 1]), "aim point must be three finite"),  # read as 1 m east
    (lambda: trough_angle([True, 30.0], [90.0, 90.0]), "trough_angle: altitude must be numbers"),  # read as 1°
])
def test_collector_parameters_and_sun_positions_that_are_no_numbers_are_refused_by_name(call, message):
    """Text and True are no metres or degrees: the sun position refused them, the collector's
    parameters read them as numbers; a ragged list raised numpy's ValueError."""
    with pytest.raises(HybridtrackError, match=message):
        call()


@pytest.mark.parametrize("call, message", [
    (lambda: normal_angles([np.inf, 0.0, 1.0]), "normal_angles: normals must be finite"),  # gave 90°, 0°
    (lambda: jack_heights([np.inf, 0.0, 1.0]), "jack_heights: normals must be finite"),  # gave nan, inf, -inf
    (lambda: across_angle([np.inf, 0.0, 1.0], 0.0), "across_angle: vectors must be finite"),  # gave 0°
    (lambda: across_angle(np.eye(3), [0.0, 90.0]),
     r"across_angle: the shapes vectors without their x, y, z axis \(3,\), axis_azimuth \(2,\) do not broadcast "
     "together"),  # numpy's
    (lambda: jack_heights([0.0, 0.0, 1.0], "ab"), "supports must be numbers"),  # numpy's ValueError
    (lambda: jack_heights([0.0, 0.0, 1.0], [[np.nan, 1.0]]), "supports must be finite"),  # gave NaN heights
    (lambda: across_angle([0.0, 0.0, 0.0], 0.0), "across_angle: a zero vector has no direction"),  # gave 0°
    (lambda: across_angle([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]], [0.0, 90.0]), "a zero vector"),  # gave [90°, 0°]
])
def test_vectors_and_supports_that_are_not_finite_or_do_not_broadcast_are_refused_by_name(call, message):
    with pytest.raises(HybridtrackError, match=message):
        call()


def test_across_angle_takes_one_axis_per_vector():
    """Hand cases: east is 0° across a north-south axis, the zenith 90°, west 180°; north is 0°
    across an east-west axis (azimuth 270°, its 0° faces north)."""
    vectors = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    np.testing.assert_allclose(across_angle(vectors, [0.0, 0.0, 0.0, 270.0]), [0.0, 90.0, 180.0, 0.0], atol=1e-12)
