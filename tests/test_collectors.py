"""Collector geometry against pvlib, the published figures and the law of reflection."""

import numpy as np
import pandas as pd
import pvlib
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.collectors import (
    THREE_POINT_SUPPORT, Collector, fresnel_angle, fresnel_end_loss, heliostat_normal, jack_heights,
    normal_angles, sun_vector, tracking_rate, trough_angle,
)
from hybridtrack.sun import altitude_azimuth, cooper_declination, solar_position
from hybridtrack.times import local_range

KUNMING_LATITUDE = 25 + 1 / 60
DISTANCES = np.arange(2.5, 25.01, 2.5)
END_LOSS_NOON = [4.810, 5.217, 5.833, 6.600, 7.470, 8.413, 9.406, 10.435, 11.490, 12.565]
END_LOSS_0700 = [1.135, 1.232, 1.376, 1.558, 1.763, 1.985, 2.219, 2.462, 2.711, 2.965]


def sun_on(date, site="nanjing", freq="1min", **window):
    return solar_position(local_range(date, "Asia/Shanghai", freq=freq, **window), site)


@pytest.mark.parametrize("date", ["2013-03-20", "2013-06-21", "2013-12-22"])
def test_trough_angle_is_90_plus_pvlib_singleaxis(date):
    sun = sun_on(date)
    rho = trough_angle(sun.altitude, sun.azimuth)
    pv = pvlib.tracking.singleaxis(90 - sun.altitude, sun.azimuth, axis_azimuth=180, backtrack=False, max_angle=90)
    up = sun.altitude > 0
    np.testing.assert_allclose(rho[up], 90 + pv.tracker_theta[up], atol=1e-9)
    assert rho[~up].isna().all()
    assert rho[up].between(0, 180).all()


def test_trough_angle_matches_the_published_formula():
    alt, az = np.array([20.0, 45.0, 70.0]), np.array([100.0, 230.0, 170.0])
    gamma_s = np.radians(az - 180)  # from south
    published = np.degrees(np.arctan(np.sin(0 - gamma_s) / np.tan(np.radians(alt))))  # from zenith, east +
    np.testing.assert_allclose(trough_angle(alt, az), 90 - published, atol=1e-12)


def test_east_west_axis_tracks_north_south_with_y_for_x():
    alt, az = np.array([30.0, 60.0]), np.array([150.0, 200.0])
    s = sun_vector(alt, az)
    np.testing.assert_allclose(trough_angle(alt, az, "ew"), np.degrees(np.arctan2(s[:, 2], s[:, 1])))
    # an axis at azimuth 180 is the north-south axis turned round: the angle mirrors
    np.testing.assert_allclose(trough_angle(alt, az, 180.0), 180 - trough_angle(alt, az, 0.0))


@pytest.mark.parametrize("axis, along", [
    (0.0, [0.0, 360.0, -360.0, 720.0, 180.0, -180.0, 540.0]),
    (270.0, [90.0, -270.0, 450.0, 270.0, -90.0, 3690.0]),
    (45.0, [45.0, 225.0, -135.0, 405.0, -315.0]),
])
def test_a_sun_on_the_horizon_along_the_axis_gives_90_however_its_azimuth_is_written(axis, along):
    """It gave 0° or 180° by the rounding of sin 360° (0 against 360, 180 against -180). pvlib's
    tracker defines the angle just above the horizon on that line (tracker_theta 0: ρ 90°), and
    on the horizon off the line (±90°: ρ 0° or 180°); at exactly 0° its own answer is rounding."""
    along = np.array(along)
    np.testing.assert_array_equal(trough_angle(0.0, along, axis), 90.0)
    np.testing.assert_array_equal(trough_angle(-0.0, along, axis), 90.0)
    np.testing.assert_array_equal(fresnel_angle(0.0, along, 5.0, 10.0, axis),
                                  fresnel_angle(0.0, along[0], 5.0, 10.0, axis))
    low = pvlib.tracking.singleaxis(np.full(len(along), 90.0 - 1e-4), along, axis_azimuth=axis + 180.0,
                                    backtrack=False, max_angle=180.0)
    np.testing.assert_allclose(trough_angle(1e-4, along, axis), 90.0 + low["tracker_theta"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(trough_angle(0.0, along, axis), 90.0 + low["tracker_theta"], rtol=0, atol=1e-6)
    off = np.array([1.0, 30.0, 100.0, 181.0, 250.0, 330.0, -1.0]) + axis
    horizon = pvlib.tracking.singleaxis(np.full(len(off), 90.0), off, axis_azimuth=axis + 180.0, backtrack=False,
                                        max_angle=180.0)
    np.testing.assert_allclose(trough_angle(0.0, off, axis), 90.0 + horizon["tracker_theta"], rtol=0, atol=1e-9)


def test_mount_targets_follow_a_sun_on_the_horizon_along_the_axis_as_trough_angle_does():
    from hybridtrack.mounting import mount_targets

    az = np.array([0.0, 360.0, 180.0, -180.0, 90.0])
    np.testing.assert_array_equal(mount_targets(np.zeros(5), az, Collector())[:, 0], [90.0, 90.0, 90.0, 90.0, 0.0])


def peak_rate(date, start, end):
    sun = sun_on(date, freq="5s", start=start, end=end)
    return tracking_rate(trough_angle(sun.altitude, sun.azimuth)).max()


def test_nanjing_trough_rates_at_the_solstices():
    assert peak_rate("2013-12-22", "11:30", "12:40") == pytest.approx(0.398, abs=0.003)
    assert peak_rate("2013-06-21", "11:30", "12:40") == pytest.approx(0.232, abs=0.003)


def test_winter_solstice_noon_rate_is_the_years_largest():
    # the rate peaks at solar noon each day; sample every day's noon window at 30 s
    noons = pd.date_range("2013-01-01 11:50", "2013-12-31 11:50", freq="D", tz="Asia/Shanghai")
    times = pd.DatetimeIndex(np.concatenate([pd.date_range(t, periods=61, freq="30s") for t in noons]))
    sun = solar_position(times, "nanjing")
    angle = trough_angle(sun.altitude, sun.azimuth).to_numpy().reshape(len(noons), 61)
    daily_peak = pd.Series((np.diff(angle, axis=1) * 2).max(axis=1), index=noons.date)  # °/min
    assert str(daily_peak.idxmax()) == "2013-12-22"
    assert daily_peak.max() == pytest.approx(0.398, abs=0.003)


def test_end_loss_table_for_kunming_equinox():
    for hour_angle, row in ((0.0, END_LOSS_NOON), (-75.0, END_LOSS_0700)):
        alt, az = altitude_azimuth(0.0, hour_angle, KUNMING_LATITUDE)
        losses = [float(fresnel_end_loss(alt, az, d, 10.0)) for d in DISTANCES]
        np.testing.assert_allclose(losses, row, atol=0.002)


def test_end_loss_at_noon_is_f_cot_alpha_and_signs_the_end():
    alt, az = altitude_azimuth(0.0, 0.0, KUNMING_LATITUDE)
    assert float(fresnel_end_loss(alt, az, 5, 10)) == pytest.approx(np.hypot(5, 10) / np.tan(np.radians(alt)))
    # southern hemisphere: the sun is north at noon, the loss moves to the south end
    alt_s, az_s = altitude_azimuth(0.0, 0.0, -30.0)
    assert float(fresnel_end_loss(alt_s, az_s, 5, 10)) < 0
    assert np.isnan(fresnel_end_loss(-5.0, 90.0, 5, 10))


def test_december_loses_about_21_6_m_more_than_june():
    def noon_loss(day_of_year):
        alt, az = altitude_azimuth(cooper_declination(day_of_year), 0.0, KUNMING_LATITUDE)
        return float(fresnel_end_loss(alt, az, 0.0, 20.0))  # f = 20 m

    assert noon_loss(344) - noon_loss(162) == pytest.approx(21.6, abs=0.05)  # 10 Dec, 11 Jun


def test_fresnel_normal_bisects_sun_and_receiver():
    alt, az = np.array([25.0, 50.0, 80.0]), np.array([110.0, 180.0, 250.0])
    for d in (-7.5, 0.0, 7.5):
        angle = np.radians(fresnel_angle(alt, az, d, 10.0))
        normal = np.stack([np.cos(angle), np.sin(angle)], axis=1)  # (across, up)
        s = sun_vector(alt, az)
        sun = s[:, [0, 2]] / np.linalg.norm(s[:, [0, 2]], axis=1, keepdims=True)
        receiver = np.array([-d, 10.0]) / np.hypot(d, 10.0)
        np.testing.assert_allclose(np.sum(normal * sun, 1), normal @ receiver, atol=1e-12)
    # rows east and west of the receiver turn differently; a row under it is half the trough
    assert not np.allclose(fresnel_angle(alt, az, 7.5, 10), fresnel_angle(alt, az, -7.5, 10))
    np.testing.assert_allclose(fresnel_angle(alt, az, 0, 10), 0.5 * (trough_angle(alt, az) + 90))


def test_heliostat_reflects_the_sun_onto_the_aim_point():
    aim = np.array([0.0, 20.0, 100.0])
    sun = sun_on("2018-06-21", "delingha", "10min")
    up = sun[sun.altitude > 0]
    n = heliostat_normal(up.altitude, up.azimuth, aim)
    s = sun_vector(up.altitude, up.azimuth)
    reflected = 2 * np.sum(n * s, axis=1, keepdims=True) * n - s
    np.testing.assert_allclose(reflected, np.tile(aim / np.linalg.norm(aim), (len(up), 1)), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    azimuth, elevation = normal_angles(n)
    assert (elevation > 0).all() and ((azimuth >= 0) & (azimuth < 360)).all()


def test_jacks_rear_pair_equal_at_noon_and_mirror_morning_and_evening():
    aim = (0.0, 20.0, 100.0)
    hours = np.array([-60.0, -30.0, 0.0, 30.0, 60.0])
    alt, az = altitude_azimuth(23.44, hours, 37.352317)
    z = jack_heights(heliostat_normal(alt, az, aim), THREE_POINT_SUPPORT)
    noon = z[2]
    assert noon[1] == pytest.approx(noon[2], abs=1e-12)
    for morning, evening in ((0, 4), (1, 3)):
        assert z[morning][0] == pytest.approx(z[evening][0], abs=1e-12)
        assert z[morning][1] == pytest.approx(z[evening][2], abs=1e-12)
        assert z[morning][2] == pytest.approx(z[evening][1], abs=1e-12)
    # each jack head lies in the mirror plane through the centre
    n = heliostat_normal(alt, az, aim)
    points = np.concatenate([np.broadcast_to(THREE_POINT_SUPPORT, (5, 3, 2)), z[..., None]], axis=2)
    np.testing.assert_allclose(np.einsum("nkj,nj->nk", points, n), 0.0, atol=1e-12)


def test_published_jack_table_needs_an_unnormalised_receiver_vector():
    """docs/physics.md §3: the printed table adds (0, 20, 100) un-normalised; we keep the true law."""
    alt, az = altitude_azimuth(23.44, -45.0, 37.352317)
    ours = heliostat_normal(alt, az, (0, 20, 100))  # one position: one normal, (3,)
    s = sun_vector(alt, az)  # its [0] had been the east component alone, added to every coordinate
    swamped = s + np.array([0, 20, 100.0])
    swamped /= np.linalg.norm(swamped)
    assert np.degrees(np.arccos(np.clip(ours @ swamped, -1, 1))) > 10  # not a rounding matter


def test_collector_spec_gives_targets_for_each_kind():
    sun = sun_on("2021-06-21", "lanzhou", "10min")
    assert list(Collector("trough-ns").angles(sun.altitude, sun.azimuth)) == ["angle", "rate"]
    assert list(Collector("fresnel").angles(sun.altitude, sun.azimuth)) == ["angle", "rate", "end_loss"]
    assert list(Collector("heliostat").angles(sun.altitude, sun.azimuth)) == [
        "normal_azimuth", "normal_elevation", "jack_1", "jack_2", "jack_3"]
    ew = Collector("trough-ew").angles(sun.altitude, sun.azimuth)["angle"]
    np.testing.assert_allclose(ew, trough_angle(sun.altitude, sun.azimuth, "ew"))


@pytest.mark.parametrize("axis, kind", [(0.0, "trough-ns"), (180.0, "trough-ns"), (-180.0, "trough-ns"),
                                        (360.0, "trough-ns"), (-0.0, "trough-ns"), (90.0, "trough-ew"),
                                        (270.0, "trough-ew"), (-90.0, "trough-ew"), (45.0, "trough"),
                                        (1e-9, "trough"), (269.99, "trough"), (-135.0, "trough")])
def test_a_troughs_kind_names_its_axis_and_no_other(axis, kind):
    """A 45° trough had been a "trough-ns"; its targets are pvlib's tracker (ρ = 90° + θ, pvlib's
    axis pointing the other way) on that axis, whatever the kind's name."""
    from hybridtrack.collectors import trough_kind

    assert trough_kind(axis) == kind
    collector = Collector(kind, axis)
    assert collector.axis == axis
    for other in {"trough-ns", "trough-ew"} - {kind}:
        with pytest.raises(HybridtrackError, match=rf"axis_azimuth {axis:g} is no {other} axis .* it is a {kind} "):
            Collector(other, axis)
    sun = sun_on("2021-06-21", "lanzhou", "10min")
    up = sun[sun.altitude > 0]
    pv = pvlib.tracking.singleaxis(90 - up.altitude, up.azimuth, axis_azimuth=axis + 180.0, backtrack=False,
                                   max_angle=180.0)
    np.testing.assert_allclose(collector.angles(up.altitude, up.azimuth)["angle"], 90.0 + pv.tracker_theta,
                               rtol=0, atol=1e-9)


def test_a_trough_on_no_named_axis_needs_its_axis():
    from hybridtrack.collectors import trough_kind

    with pytest.raises(HybridtrackError, match="a trough needs its axis_azimuth"):
        Collector("trough")
    for axis in (np.nan, None, "0", np.array([0.0, 90.0])):  # no range to name: "within [-inf, inf]" had been said
        with pytest.raises(HybridtrackError, match=r"^trough_kind: axis_azimuth \(degrees from north\) must be a "
                                                   r"finite number, got "):
            trough_kind(axis)


@pytest.mark.parametrize("kwargs, message", [({"kind": "dish"}, "unknown collector 'dish'"),
                                             ({"kind": "fresnel", "receiver_height": 0}, "receiver_height"),
                                             ({"kind": "heliostat", "aim": (0, 0, 0)}, "aim point")])
def test_bad_collector_geometry_is_refused(kwargs, message):
    with pytest.raises(HybridtrackError, match=message):
        Collector(**kwargs)


def test_rotate_is_the_matrix_product_row_by_row():
    from hybridtrack.mounting import mounting_rotation, rotate

    vectors = np.random.default_rng(3).standard_normal((1000, 3))
    rotation = mounting_rotation(0.7, -1.3, 20.0, 0.4)
    np.testing.assert_allclose(rotate(vectors, rotation), vectors @ rotation.T, rtol=0, atol=1e-14)


@pytest.mark.parametrize("kind, geometry, message", [
    ("trough-ns", {"row_distance": 2.0}, "row_distance describes a fresnel collector, not a trough-ns"),
    ("heliostat", {"axis_azimuth": 10.0}, "axis_azimuth describes a trough-ns or trough-ew or trough or fresnel "
                                          "collector"),
    ("fresnel", {"aim": (0.0, 0.0, 50.0)}, "aim describes a heliostat collector, not a fresnel"),
])
def test_geometry_of_another_kind_is_refused_not_ignored(kind, geometry, message):
    """A trough given a row distance ran as if it had none (the CLI's --row-distance, a sweep's
    collector.row_distance grid gave identical runs)."""
    with pytest.raises(HybridtrackError, match=message):
        Collector(kind, **geometry)
    assert Collector(kind, row_distance=5.0, aim=[0, 20, 100]).kind == kind  # the defaults, however spelled


def test_within_turn_is_numpys_remainder_bit_for_bit():
    """The cheap turn (`within_turn`) gives numpy's own ``% 360`` on every kind of angle: inside a
    turn either side of zero, far outside it, at the edges, signed zeros, NaN and infinities."""
    from hybridtrack.collectors import within_turn

    rng = np.random.default_rng(7)
    edges = [-0.0, 0.0, -1e-20, -5e-324, -360.0, 360.0, -720.0, 720.0, 359.99999999999994, -359.99999999999994,
             180.0, -180.0, 1e300, -1e300, np.nan, np.inf, -np.inf]
    angles = np.concatenate([edges, rng.uniform(-360, 360, 10_000), rng.uniform(-1e4, 1e4, 10_000)])
    with np.errstate(invalid="ignore"):
        expected = angles % 360.0
    got = within_turn(angles)
    assert np.array_equal(got, expected, equal_nan=True)
    assert np.array_equal(np.signbit(got), np.signbit(expected))


@pytest.mark.parametrize("kind", ["trough-ns", "trough-ew"])
def test_mount_targets_and_incidence_take_one_sun_position_as_a_path_of_one_step(kind):
    """pvlib's single-axis tracker (no backtracking, no limit) is the reference: ρ = 90° + θ and
    the incidence its aoi. One position had raised a TypeError (len() of unsized object) and an
    IndexError."""
    from hybridtrack.mounting import incidence_cosine, mount_targets

    collector = Collector(kind)
    track = pvlib.tracking.singleaxis(90.0 - 30.0, 120.0, axis_azimuth=collector.axis + 180.0, max_angle=180.0,
                                      backtrack=False)
    np.testing.assert_allclose(mount_targets(30.0, 120.0, collector), 90.0 + np.ravel(track["tracker_theta"])[:, None])
    np.testing.assert_allclose(incidence_cosine(30.0, 120.0, collector), np.cos(np.radians(np.ravel(track["aoi"]))))


THREE = np.array([30.0, 45.0, 60.0]), np.array([120.0, 180.0, 240.0])


@pytest.mark.parametrize("call, message", [
    (lambda m: m.mount_targets(THREE[0], THREE[1][:2], Collector()),
     r"mount_targets takes a sun path: .* got shapes \(3,\) and \(2,\)"),  # numpy's IndexError
    (lambda m: m.mount_targets(THREE[0][:, None], THREE[1][:, None], Collector("heliostat")),
     r"mount_targets takes a sun path: .* got shapes \(3, 1\) and \(3, 1\)"),  # numpy's IndexError
    (lambda m: m.incidence_cosine(THREE[0][:, None], THREE[1][:, None], Collector()),
     r"incidence_cosine takes a sun path"),  # numpy's IndexError
    (lambda m: m.mount_targets(*THREE, "dish"), "unknown collector 'dish'"),  # AttributeError
    (lambda m: m.mount_targets(*THREE, "trough"), "a trough needs its axis_azimuth"),  # a kind of its own now
    (lambda m: m.incidence_cosine(*THREE, 5), "collector must be a kind's name"),  # AttributeError
    (lambda m: m.mount_targets("a", "b", Collector()), "mount_targets: altitude must be numbers"),  # ValueError
    (lambda m: m.mounting_rotation([0.1, 0.2], [0.0] * 3, 0.0),
     r"mounting_rotation: the shapes axis_azimuth_error \(2,\), axis_tilt_error \(3,\).* do not broadcast"),
    (lambda m: m.mounting_rotation([0.1, np.nan], 0.0, 0.0), "axis_azimuth_error"),  # a rotation of NaNs
    (lambda m: m.mounting_rotation(True, 0.0, 0.0), "axis_azimuth_error"),  # read as 1°
    (lambda m: m.mounting_rotation(0.1, None, 0.0), "axis_tilt_error"),  # numpy's TypeError
    (lambda m: m.mounting_rotation(0.1, 0.0, np.nan), "axis_azimuth"),  # a rotation of NaNs
    (lambda m: m.mount_targets(*THREE, Collector(), np.eye(2)),
     r"mount_targets: rotation must be a 3 x 3 matrix .* got shape \(2, 2\)"),  # numpy's ValueError
])
def test_mounting_refuses_what_is_no_sun_path_collector_or_angle_by_name(call, message):
    from hybridtrack import mounting

    with pytest.raises(HybridtrackError, match=message):
        call(mounting)


def test_mounts_broadcast_rotations_against_vectors_as_pvlibs_tilted_trackers():
    """mounting_rotation of an array of tilts is one rotation each, (N, 3, 3); angles_on_mount of
    the sun's vectors (T, 1, 3) on them is (T, N, 1), each pvlib's tracker on an axis tilted by
    that much (the far end up is pvlib's axis_tilt with the axis pointing the other way)."""
    from scipy.spatial.transform import Rotation

    from hybridtrack.mounting import angles_on_mount, mounting_rotation, rotate

    tilts = np.array([-4.0, 0.0, 2.0, 9.0])
    alt, az = np.array([20.0, 45.0, 70.0, 5.0]), np.array([100.0, 160.0, 250.0, 290.0])
    rotations = mounting_rotation(0.0, tilts, 0.0)
    assert rotations.shape == (4, 3, 3) and mounting_rotation(0.0, 2.0, 0.0).shape == (3, 3)
    got = angles_on_mount(sun_vector(alt, az)[:, None, :], Collector(), rotations)
    assert got.shape == (4, 4, 1)
    for i, tilt in enumerate(tilts):
        pv = pvlib.tracking.singleaxis(90 - alt, az, axis_tilt=tilt, axis_azimuth=180, backtrack=False, max_angle=180)
        np.testing.assert_allclose(got[:, i, 0], 90 + pv["tracker_theta"], rtol=0, atol=1e-9)
    # every parameter an array, against scipy's rotations about each axis (the turn, tilt and roll in order)
    turn, tilt, axis, roll = (np.array([0.3, -2.0]), np.array([1.0, 0.5]), np.array([0.0, 30.0]), np.array([-0.7, 4.0]))
    for i in range(2):
        b = np.radians(axis[i])
        about = [([0.0, 0.0, 1.0], turn[i]), ([np.cos(b), -np.sin(b), 0.0], tilt[i]),
                 ([np.sin(b), np.cos(b), 0.0], roll[i])]
        composed = np.eye(3)
        for direction, angle in about:
            composed = Rotation.from_rotvec(np.radians(angle) * np.array(direction)).as_matrix() @ composed
        np.testing.assert_allclose(mounting_rotation(turn, tilt, axis, roll)[i], composed.T, rtol=0, atol=1e-15)
    vectors = np.random.default_rng(2).standard_normal((5, 1, 3))
    np.testing.assert_allclose(rotate(vectors, rotations), (rotations @ vectors[..., None])[..., 0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(rotate(vectors[0, 0], rotations[1]), rotations[1] @ vectors[0, 0], rtol=0, atol=1e-15)


def test_one_vector_on_a_mount_gives_one_row_of_angles():
    """One (3,) vector had raised numpy's IndexError in angles_on_mount and einsum's ValueError in
    rotate. References: pvlib's tracker; a heliostat normal due north at 45° by hand."""
    from hybridtrack.mounting import angles_on_mount, mounting_rotation

    one = angles_on_mount(sun_vector(30.0, 120.0), Collector())
    pv = pvlib.tracking.singleaxis(60.0, 120.0, axis_azimuth=180, backtrack=False, max_angle=90)
    assert one.shape == (1,) and one[0] == pytest.approx(90 + np.ravel(pv["tracker_theta"])[0], abs=1e-9)
    assert angles_on_mount(sun_vector(30.0, 120.0), Collector(), mounting_rotation(0.0, 0.0, 0.0)) == \
        pytest.approx(one, abs=1e-12)
    np.testing.assert_allclose(angles_on_mount([0.0, 1.0, 1.0], Collector("heliostat")), [0.0, 45.0], atol=1e-12)
    assert angles_on_mount(np.zeros((0, 3)), Collector()).shape == (0, 1)


def test_one_sun_position_takes_its_one_vector():
    """One position is a path of one step, and its one vector (3,) the path's vectors (it had been
    refused as no (1, 3), or raised numpy's IndexError). Reference: pvlib's aoi and tracker."""
    from hybridtrack.mounting import incidence_cosine, mount_targets

    pv = pvlib.tracking.singleaxis(60.0, 120.0, axis_azimuth=180, backtrack=False, max_angle=90)
    s = sun_vector(30.0, 120.0)
    assert incidence_cosine(30.0, 120.0, Collector(), sun=s) == pytest.approx(np.cos(np.radians(np.ravel(pv["aoi"]))))
    np.testing.assert_allclose(mount_targets(30.0, 120.0, Collector(), vectors=s),
                               90 + np.ravel(pv["tracker_theta"])[:, None], rtol=0, atol=1e-9)
    helio = Collector("heliostat")
    np.testing.assert_allclose(mount_targets(30.0, 120.0, helio, sun=s), mount_targets(30.0, 120.0, helio),
                               rtol=0, atol=0)


THREE_UP = np.array([30.0, 45.0, 60.0]), np.array([120.0, 180.0, 240.0])


@pytest.mark.parametrize("call, message", [
    (lambda m: m.mount_targets(*THREE_UP, Collector("heliostat"), sun=np.ones((2, 3))),
     r"mount_targets: sun must be \(east, north, up\) vectors, shape \(3, 3\); got shape \(2, 3\)"),  # IndexError
    (lambda m: m.mount_targets(*THREE_UP, Collector("heliostat"), sun=np.ones(3)),
     r"mount_targets: sun must be .* shape \(3, 3\); got shape \(3,\)"),
    (lambda m: m.mount_targets(*THREE_UP, Collector(), vectors=np.ones((3, 2))),
     r"mount_targets: vectors must be .* shape \(3, 3\); got shape \(3, 2\)"),  # IndexError
    (lambda m: m.mount_targets(*THREE_UP, Collector(), night=True, vectors=np.ones((4, 3))),
     r"mount_targets: vectors must be .* got shape \(4, 3\)"),  # gave four rows for three steps
    (lambda m: m.mount_targets(*THREE_UP, Collector(), vectors="abc"), "mount_targets: vectors must be .* of numbers"),
    (lambda m: m.incidence_cosine(*THREE_UP, Collector("heliostat"), sun=np.ones((3, 2))),
     r"incidence_cosine: sun must be .* shape \(3, 3\); got shape \(3, 2\)"),  # numpy's ValueError
    (lambda m: m.pointing_vectors(*THREE_UP, Collector("heliostat"), sun=np.ones((2, 3))),
     r"heliostat_normal: sun must be .* shape \(3, 3\); got shape \(2, 3\)"),  # numpy's ValueError
    (lambda m: m.angles_on_mount(np.ones((3, 2)), Collector()),
     r"angles_on_mount: vectors must be .* shape \(\.\.\., 3\); got shape \(3, 2\)"),
    (lambda m: m.angles_on_mount([[0, 1, 1], [0, 1]], Collector()), "angles_on_mount: vectors must be .* of numbers"),
    (lambda m: m.rotate(np.ones((4, 3)), np.ones((2, 3, 3))),
     r"rotate: the shapes vectors without their x, y, z axis \(4,\), rotations without their 3 x 3 \(2,\) do not "
     "broadcast"),  # einsum's ValueError
    (lambda m: m.rotate(np.ones(3), np.eye(2)), r"rotate: rotation must be 3 x 3 .* got shape \(2, 2\)"),
    (lambda m: m.rotate(np.ones(2), np.eye(3)), r"rotate: vectors must be .* got shape \(2,\)"),
    (lambda m: m.rotate(5.0, np.eye(3)), r"rotate: vectors must be .* got shape \(\)"),
    (lambda m: m.rotate([1.0, 0.0, 0.0], "abc"), r"rotate: rotation must be 3 x 3 matrices of numbers.* got 'abc'"),
    (lambda m: m.mount_targets([30.0, 40.0], [120.0, 130.0], Collector("heliostat"), sun=sun_vector(30.0, 120.0)),
     r"mount_targets: sun must be .* shape \(2, 3\); got shape \(3,\)"),  # one vector is no path of two
    (lambda m: m.pointing_vectors("a", 120.0, Collector("heliostat")), "pointing_vectors: altitude must be numbers"),
    (lambda m: m.pointing_vectors("a", 120.0, Collector()), "sun_vector: altitude must be numbers"),  # numpy's
    (lambda m: m.pointing_vectors(30.0, 120.0, 5), "collector must be a kind's name"),  # AttributeError
    (lambda m: m.angles_on_mount([0.0, 0.0, 1.0], None), "collector must be a kind's name"),  # AttributeError
    (lambda m: m.mount_targets(30.0, 120.0, Collector("heliostat"), sun=[[0, 1, 1], [0, 1]]),
     r"mount_targets: sun must be .* of numbers, shape \(1, 3\)"),  # numpy's ValueError (ragged)
])
def test_mounting_refuses_vectors_of_the_wrong_shape_by_name(call, message):
    from hybridtrack import mounting

    with pytest.raises(HybridtrackError, match=message):
        call(mounting)


def test_within_turn_takes_a_number_or_a_list_and_refuses_what_is_no_angle():
    """A float raised an AttributeError ('bool' object has no attribute 'any') and a list a
    TypeError; Python's own remainder is the reference."""
    from hybridtrack.collectors import within_turn

    assert within_turn(-10.0) == -10.0 % 360.0 and within_turn(-400) == -400 % 360
    np.testing.assert_array_equal(within_turn([-10.0, 400.0, 720.0]), [-10.0 % 360.0, 400.0 % 360.0, 0.0])
    for angle in ("a", None, [True, False]):
        with pytest.raises(HybridtrackError, match="within_turn: angles must be numbers"):
            within_turn(angle)


@pytest.mark.parametrize("axis_azimuth", [0.0, 30.0, 90.0, 270.0])
def test_an_axis_azimuth_error_turns_the_true_axis_as_documented(axis_azimuth):
    """The true axis (the nominal axis taken from the mounting's frame to the world's) points at
    azimuth `axis_azimuth` − error (counterclockwise seen from above), its far end up by the tilt
    error: worked from the unit vectors east, north, up by hand."""
    from hybridtrack.mounting import mounting_rotation

    to_world = mounting_rotation(1.0, 0.5, axis_azimuth).T
    b = np.radians(axis_azimuth)
    east, north, up = to_world @ np.array([np.sin(b), np.cos(b), 0.0])
    assert np.degrees(np.arctan2(east, north)) % 360.0 == pytest.approx((axis_azimuth - 1.0) % 360.0, abs=1e-3)
    assert np.degrees(np.arcsin(up)) == pytest.approx(0.5, abs=1e-3)


def _traced_end_loss(alt, az, d, h, axis_azimuth):
    """An independent ray trace: a mirror normal across the axis that sends the sun to the receiver
    (its angle solved here by bisection of the two directions in the plane across the axis), the
    sun reflected by the law of reflection, and the ray followed up to the receiver's height:
    how far along the axis (towards `axis_azimuth`) it lands."""
    b = np.radians(axis_azimuth)
    along, across, up = np.array([np.sin(b), np.cos(b), 0.0]), np.array([np.cos(b), -np.sin(b), 0.0]), np.eye(3)[2]
    a, g = np.radians(alt), np.radians(az)
    s = np.array([np.cos(a) * np.sin(g), np.cos(a) * np.cos(g), np.sin(a)])
    sun_across = np.arctan2(s @ up, s @ across)  # the sun's direction in the plane across the axis
    to_receiver = np.arctan2(h, -d)
    theta = 0.5 * (sun_across + to_receiver)
    n = np.cos(theta) * across + np.sin(theta) * up
    ray = 2.0 * (s @ n) * n - s  # reflected: from the mirror outwards
    t = h / ray[2]
    np.testing.assert_allclose(d * 1.0 + t * (ray @ across), 0.0, atol=1e-9)  # it does meet the receiver line
    return t * (ray @ along)


@pytest.mark.parametrize("axis_azimuth", [0.0, 90.0, 180.0, 270.0, -90.0, 45.0, 360.0])
def test_end_loss_on_any_axis_is_where_the_reflected_ray_meets_the_receiver(axis_azimuth):
    """Only north-south rows had an end loss: an east-west Fresnel field was given none, without a
    word. On any axis it is where a ray traced by the law of reflection meets the receiver line."""
    for alt, az in ((25.0, 110.0), (50.0, 180.0), (80.0, 250.0), (10.0, 300.0), (60.0, 20.0)):
        for d in (-7.5, 0.0, 4.0):
            want = _traced_end_loss(alt, az, d, 10.0, axis_azimuth)
            assert float(fresnel_end_loss(alt, az, d, 10.0, axis_azimuth)) == pytest.approx(want, abs=1e-9)
    # a north-south row keeps its sign: positive past the north end when the sun is south
    assert fresnel_end_loss(50.0, 180.0, 0.0, 10.0) == pytest.approx(10.0 / np.tan(np.radians(50.0)))
    # and broadcasts its axes like any collector parameter: one column per axis
    table = fresnel_end_loss(np.array([30.0, 60.0])[:, None], np.array([120.0, 200.0])[:, None], 3.0, 10.0,
                             [0.0, 90.0])
    assert table.shape == (2, 2)
    assert table[1, 1] == pytest.approx(_traced_end_loss(60.0, 200.0, 3.0, 10.0, 90.0), abs=1e-9)


def test_an_east_west_fresnel_row_and_field_carry_their_end_loss():
    import pandas as pd

    from hybridtrack.fields import FresnelField, collector_columns

    times = pd.date_range("2021-06-21 10:00", periods=3, freq="1h", tz="UTC")
    alt, az = pd.Series([30.0, 50.0, 40.0], index=times), pd.Series([100.0, 170.0, 240.0], index=times)
    out = Collector("fresnel", axis_azimuth=90.0, row_distance=3.0).angles(alt, az)
    want = [_traced_end_loss(a, g, 3.0, 10.0, 90.0) for a, g in zip(alt, az)]
    np.testing.assert_allclose(out["end_loss"], want, atol=1e-9)
    field = FresnelField(row_distances=[-3.0, 3.0], axis_azimuth=90.0)
    np.testing.assert_allclose(field.end_loss(alt, az)[:, 1], want, atol=1e-9)
    assert collector_columns(field)[-2:] == ["end_loss_m", "end_loss_share"]


@pytest.mark.parametrize("axis", [0.0, 90.0, 30.0])
@pytest.mark.parametrize("d, h", [(0.0, 10.0), (4.0, 10.0), (-9.5, 10.0), (9.5, 4.0)])
def test_a_fresnel_rows_incidence_is_the_beams_on_its_own_mirror(axis, d, h):
    """The mirror's normal halfway between the sun and the receiver (`fresnel_angle`): pvlib's angle
    of incidence on a plane so tilted is the reference. The row's incidence had been a trough's,
    the same for every row, 9-18 % too high on outer rows (helper-38)."""
    from hybridtrack.mounting import incidence_cosine

    altitude = np.array([5.0, 20.0, 45.0, 70.0, 85.0, 30.0])
    azimuth = np.array([70.0, 100.0, 150.0, 190.0, 260.0, 300.0])
    rho = fresnel_angle(altitude, azimuth, d, h, axis)
    tilt = np.abs(90.0 - rho)
    facing = np.where(rho < 90.0, axis + 90.0, axis - 90.0) % 360.0
    aoi = pvlib.irradiance.aoi(tilt, facing, 90.0 - altitude, azimuth)
    collector = Collector("fresnel", axis_azimuth=axis, row_distance=d, receiver_height=h)
    np.testing.assert_allclose(incidence_cosine(altitude, azimuth, collector), np.cos(np.radians(aoi)), atol=1e-12)


def test_the_fresnel_end_loss_of_a_sun_on_the_horizon_is_a_length_and_a_row_beyond_reach_is_refused():
    """A sun at altitude 0 gave NaN where the angles give values; a row 1e308 m out overflowed to
    an infinite loss with numpy's RuntimeWarning (helper-38)."""
    f = np.hypot(2.0, 10.0)  # at 0° the ray runs f·|cos γ| / |sin γ| along the axis (γ from the axis)
    assert fresnel_end_loss(0.0, 100.0, 2.0, 10.0) == pytest.approx(-f * np.cos(np.radians(100.0)) /
                                                                     abs(np.sin(np.radians(100.0))))
    with pytest.raises(HybridtrackError, match="row distance d must be within 5000 m"):
        fresnel_end_loss(30.0, 180.0, 1e308, 1e308)


def test_tracking_rate_refuses_naive_stamps_as_every_time_input_does():
    """A naive local clock across a change of summer time reads an hour's step as two or none."""
    naive = pd.Series([10.0, 20.0, 30.0], index=pd.date_range("2021-06-21", periods=3, freq="h"))
    with pytest.raises(HybridtrackError, match="tz-aware"):
        tracking_rate(naive)
    aware = tracking_rate(naive.tz_localize("UTC"))
    np.testing.assert_allclose(aware.to_numpy(), [10.0 / 60.0] * 3)  # 10° an hour, by hand


def test_wrongly_shaped_aim_points_are_refused_in_one_line_naming_the_shape():
    """A thousand (east, north) pairs had been printed whole in the refusal, over seven lines."""
    with pytest.raises(HybridtrackError, match=r"shape \(3,\) or \(\.\.\., 3\); got an array of shape \(1000, 2\)$"):
        heliostat_normal(50.0, 180.0, np.ones((1000, 2)))


def test_end_loss_is_infinite_with_the_sun_on_the_horizon_straight_along_the_row():
    """sin 180° rounds to 1.2e-16: the ray along the row had been given 8.5e16 m, a finite length."""
    assert fresnel_end_loss(0.0, 180.0, 3.0, 10.0) == np.inf  # from the south: past the north end
    assert fresnel_end_loss(0.0, 0.0, 3.0, 10.0) == -np.inf
    low = 1e-9  # a sun just up along the axis: f cot(α), by hand
    assert fresnel_end_loss(low, 180.0, 3.0, 10.0) == pytest.approx(np.hypot(3.0, 10.0) / np.tan(np.radians(low)))
