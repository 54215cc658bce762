"""A heliostat's sun sensor, on the mirror, reads angles in its own frame, and the controller
turns them back into axis degrees.

Across the sensor's face an azimuth-axis miss Δaz at elevation e is the angle asin(cos e · sin Δaz),
about Δaz · cos e; along it the elevation miss is atan2(sin e, cos e · cos Δaz) less the mirror's
elevation (docs/world.md, "The sensor's frame"). The sensor had read raw azimuth-axis degrees: at
Lanzhou on the solstice at 30-minute steps it said 26.7° "out of view" (field of view 10°) where
the target was 0.45° from its axis, and the sensor-only heliostat lost the sun at the zenith pass.

Every expected value is computed by hand (small angles, right triangles on the sphere) or from the
installation's budget, never from an earlier run.
"""

import math

import numpy as np
import pandas as pd
import pytest

from hybridtrack.collectors import Collector
from hybridtrack.control.sensing import COSINE_FLOOR, axis_offset
from hybridtrack.kernel import controller as kernel_controller
from hybridtrack.kernel import world as kernel_world
from hybridtrack.metrics import TRACKING_MODES
from hybridtrack.sensor import SensorModel, sensor_frame
from hybridtrack.simulation import SimulationConfig, _drives, simulate
from hybridtrack.sky import synthetic
from hybridtrack import sites
from hybridtrack.world import Imperfections, World

from test_heliostat_coarse_steps import OPEN_LOOP_BUDGET
from test_kernel import assert_same_run

FIELD_OF_VIEW = SensorModel().field_of_view


# -- the sensor's frame (world) --------------------------------------------------------------------

def test_an_azimuth_miss_at_60_degrees_up_is_half_of_it_across_the_face():
    across, along = sensor_frame(2.0, 60.0, 60.0)
    assert across == pytest.approx(2.0 * math.cos(math.radians(60.0)), abs=2e-4)  # 1.0°, asin's third order
    # tan φ = tan 60° / cos 2°: φ - 60° ≈ sin 60° cos 60° (1 - cos 2°) = 2.64e-4 rad, 0.0151° higher
    assert along == pytest.approx(0.0151, abs=1e-4)


def test_near_the_zenith_a_large_azimuth_miss_is_a_small_angle_across_the_face():
    across, along = sensor_frame(26.7, 89.0, 89.0)
    assert 26.7 * math.cos(math.radians(89.0)) == pytest.approx(0.466, abs=1e-3)  # the small-angle value
    assert across == pytest.approx(0.449, abs=1e-3)  # asin(0.017452 · 0.44932) = 0.4493°
    assert abs(across) < FIELD_OF_VIEW and abs(along) < FIELD_OF_VIEW  # in view, not 26.7° out of it


def test_without_an_azimuth_miss_the_sensor_reads_the_elevation_miss_alone():
    across, along = sensor_frame(0.0, 50.0, 48.5)
    assert across == 0.0
    assert along == pytest.approx(1.5, abs=1e-12)


def test_a_sun_just_past_the_zenith_is_a_few_degrees_off_in_the_sensor_however_far_round_its_azimuth():
    # mirror at 89.05° up facing azimuth 98.9°, sun at 87.26° up in azimuth 261.9°: 163° of azimuth,
    # but 0.95° and 2.74° from the zenith, 163° apart there: a small triangle's third side,
    # sqrt(0.95² + 2.74² - 2 · 0.95 · 2.74 · cos 163°) = 3.66°, nearly all along the face
    across, along = sensor_frame(261.9 - 98.9, 87.26, 89.05)
    assert math.hypot(across, along) == pytest.approx(3.66, abs=0.01)
    assert abs(across) < 1.0 and along > 3.5


def _heliostat_world(kind="heliostat"):
    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", freq="30min", seed=1)
    config = SimulationConfig()
    collector = Collector(kind)
    return World(frame, sites.get("lanzhou"), collector, config.imperfections, config.sensor,
                 _drives(collector, config), 1, {})


def test_the_world_gives_a_heliostats_sensor_its_own_frame_and_the_bias_on_top():
    world = _heliostat_world()
    world.actual = [200.0 - 26.7, 89.0]
    across, along = world._offsets([[200.0], [89.0]], 0)
    bias = world.sensor.bias
    assert across - bias == pytest.approx(0.449, abs=1e-3)
    assert along - bias == pytest.approx(math.degrees(math.atan(math.tan(math.radians(89.0))
                                                                 / math.cos(math.radians(26.7)))) - 89.0, abs=1e-9)


def test_a_single_axis_collector_reads_its_miss_as_before():
    """A trough's sensor turns with its one axis: its reading is the axis's miss plus the bias,
    to the bit."""
    world = _heliostat_world("trough-ns")
    world.actual = [12.25]
    assert world._offsets([[40.5]], 0) == [40.5 - 12.25 + world.sensor.bias]


@pytest.mark.parametrize("miss,target,elevation", [(2.0, 60.0, 60.0), (26.7, 89.0, 89.0), (163.0, 87.26, 89.05),
                                                   (-5.0, 30.0, 28.0), (0.0, 45.0, 45.0)])
def test_the_kernels_sensor_frame_is_the_references(miss, target, elevation):
    assert kernel_world.sensor_frame(miss, target, elevation) == pytest.approx(
        sensor_frame(miss, target, elevation), abs=1e-12)


# -- the controller's conversion back ----------------------------------------------------------------

def test_at_60_degrees_up_the_controller_doubles_an_azimuth_reading():
    offset, measures = axis_offset([1.0, 0.0], 0, [180.0, 60.0])
    assert offset == pytest.approx(1.0 / math.cos(math.radians(60.0)), abs=2e-3)  # 2°
    assert measures


def test_the_controller_recovers_the_axis_misses_its_sensor_saw():
    """With its encoders where the axes stand, the conversion is the sensor frame's exact inverse."""
    sensed = list(sensor_frame(2.0, 60.0, 59.0))
    assert axis_offset(sensed, 0, [100.0, 59.0])[0] == pytest.approx(2.0, abs=1e-9)
    assert axis_offset(sensed, 1, [100.0, 59.0])[0] == pytest.approx(1.0, abs=1e-9)


def test_near_the_zenith_the_controller_divides_by_the_floor_and_does_not_calibrate_from_it():
    sensed = list(sensor_frame(26.7, 89.0, 89.0))
    offset, measures = axis_offset(sensed, 0, [173.3, 89.0])
    assert COSINE_FLOOR == pytest.approx(0.0872, abs=1e-4)  # cos 85°
    assert offset == pytest.approx(0.449 / 0.0872, abs=0.02)  # 5.15° of the 26.7°: steered toward the sun
    assert not measures


def test_a_sun_past_the_zenith_turns_the_azimuth_the_half_turn():
    sensed = list(sensor_frame(261.9 - 98.9, 87.26, 89.05))
    azimuth, _ = axis_offset(sensed, 0, [98.9, 89.05])
    elevation, measures = axis_offset(sensed, 1, [98.9, 89.05])
    assert azimuth > 90.0  # round the back, the way the sun went: not a few degrees the other way
    assert elevation == pytest.approx(87.26 - 89.05, abs=1e-9)  # asin(cos c · sin φ) is the sun's elevation
    assert measures


def test_a_single_axis_reading_and_missing_readings_pass_as_they_are():
    assert axis_offset([0.37], 0, [12.0]) == (0.37, True)
    assert math.isnan(axis_offset([math.nan, 0.5], 0, [180.0, 60.0])[0])
    assert math.isnan(axis_offset([0.5, math.nan], 1, [180.0, 60.0])[0])
    # no elevation reading: the encoder's elevation alone is the divisor
    assert axis_offset([1.0, math.nan], 0, [180.0, 60.0])[0] == pytest.approx(2.0, abs=2e-3)


@pytest.mark.parametrize("sensed,reading", [([1.0, 0.0], [180.0, 60.0]), ([0.449, 0.107], [173.3, 89.0]),
                                            ([0.8, 3.7], [98.9, 89.05]), ([math.nan, 0.5], [180.0, 60.0]),
                                            ([1.0, math.nan], [180.0, 60.0]), ([40.0, -20.0], [90.0, 30.0])])
@pytest.mark.parametrize("a", [0, 1])
def test_the_kernels_conversion_is_the_references(sensed, reading, a):
    ours = axis_offset(sensed, a, reading)
    theirs = kernel_controller.axis_offset(np.array(sensed), a, np.array(reading))
    assert theirs[1] == ours[1]
    assert theirs[0] == pytest.approx(ours[0], abs=1e-12, nan_ok=True)


# -- whole days ------------------------------------------------------------------------------------------

def _scored(result):
    log = result.log
    return log[log["mode"].isin(TRACKING_MODES) & (log["dni"] > 0) & log["error"].notna()]


def _sensor_only(freq, engine="reference"):
    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", freq=freq, seed=1)
    return simulate(frame, "lanzhou", collector="heliostat", strategy="sensor", config=SimulationConfig(engine=engine))


def test_a_sensor_only_heliostat_at_10_minutes_keeps_the_sun_in_view_through_the_zenith_pass():
    """It had lost the sun at the zenith pass (26.4° RMS, 68.7° worst). Now, once it has found the sun
    in the morning, it never lets it out of the fine field of view, and over the day it points
    within its open loop's budget."""
    scored = _scored(_sensor_only("10min"))
    found = scored.index[scored["mode"] == "sensor"][0]
    assert scored.loc[found:, "error"].max() < FIELD_OF_VIEW
    assert math.sqrt((scored["error"] ** 2).mean()) <= OPEN_LOOP_BUDGET


def test_a_sensor_only_heliostat_at_30_minutes_finds_the_sun_again_after_the_zenith_pass():
    """It had lost the sun at the zenith pass for the rest of the day (28.8° RMS, 70.6° worst): the
    coarse cells read raw azimuth degrees and never found it. Now the acquisition cells find it
    again within the afternoon: the last three hours point within the open loop's budget, in
    sensor mode."""
    scored = _scored(_sensor_only("30min"))
    evening = scored.loc[scored.index >= scored.index[-1] - pd.Timedelta(hours=3)]
    assert (evening["mode"] == "sensor").all()
    assert evening["error"].max() <= OPEN_LOOP_BUDGET


def test_a_sensor_only_heliostat_at_30_minutes_runs_the_same_compiled():
    """The zenith pass takes every branch of the conversion (floored, past the zenith, the coarse
    cells): the kernel follows the reference."""
    assert_same_run(_sensor_only("30min"), _sensor_only("30min", engine="compiled"))


def test_near_the_zenith_a_hybrid_steers_the_azimuth_by_its_model_not_by_a_floored_reading():
    """A floored azimuth reading (the target within 5° of the zenith) is a lower bound on the miss,
    not a measure of it: a controller with a calibrated model lets the model steer the pass. With a
    perfect sensor (no noise, no bias) the pass is then no worse than the rest of the day (0.037°
    against 0.056°); fed to the filter, the floored readings had made it the day's worst, 0.205°."""
    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", freq="1min", seed=1)
    perfect = Imperfections(sensor_bias=0.0, sensor_noise=0.0)
    scored = _scored(simulate(frame, "lanzhou", collector="heliostat",
                              config=SimulationConfig(engine="reference", imperfections=perfect)))
    high = scored["target_true"] > 85.0  # the mirror normal's true elevation
    assert high.sum() > 30  # the solstice pass at Lanzhou, 36° N
    assert (scored.loc[high, "sensor_status"] != "ok").all()
    assert scored.loc[high, "error"].max() <= scored.loc[~high, "error"].max()
