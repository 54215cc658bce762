"""The world's per-scan step compiled: `hybridtrack.world.World.observe`, `.move` and `.rest`
restated over arrays for numba, with the same names.

What the world computes for the whole frame at once (the true sun, the sensor's scene, the
noise draws) stays in `World`; `WorldArrays` carries it here. The world's moving state is where
each axis truly stands (`actual`) and the encoder's last reading. The world writes the
controller's observation; it never reads the controller's state (`hybridtrack.kernel.controller`).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..world import HARD_STOP_MARGIN
from .jit import kernel

__all__ = ["WorldArrays", "WorldState", "world_observe", "world_move", "world_rest"]

#: The world's frame-wide arrays (per axis first where per axis) and its sensor's and drives' constants.
WorldArrays = namedtuple("WorldArrays", [
    "truth", "beam", "aureole", "patch", "patch_offset", "diffuse", "noise", "current_noise", "coarse_noise",
    "recorded", "has_recorded", "wind", "minutes", "true_sky",
    "sensor_fault", "sensor_drift", "sensor_dropout", "encoder_fault", "encoder_frozen",
    "bias", "field_of_view", "direct_threshold", "sensor_noise", "coarse_field_of_view", "coarse_accuracy",
    "dark_current", "responsivity", "diffuse_share", "current_noise_ma",
    "encoder_offset", "resolution", "low", "high", "circular", "pointing", "has_pointing"])
#: Where each axis stands, the encoder's last reading, and the angle of every scan (axes, N).
WorldState = namedtuple("WorldState", ["actual", "last_encoder", "angles"])


@kernel
def _miss(w, state, a, i):
    difference = w.truth[a, i] - state.actual[a]
    if w.circular[a]:
        difference = (difference + 180.0) % 360.0 - 180.0
    return difference


@kernel
def sensor_frame(azimuth_miss, target_elevation, elevation):
    """`hybridtrack.sensor.sensor_frame`."""
    d, e = math.radians(azimuth_miss), math.radians(target_elevation)
    across = math.degrees(math.asin(math.cos(e) * math.sin(d)))
    along = math.degrees(math.atan2(math.sin(e), math.cos(e) * math.cos(d))) - elevation
    return across, (along + 180.0) % 360.0 - 180.0


@kernel
def _offsets(w, state, i, offsets):
    """World._offsets: fill `offsets`."""
    azimuth_miss = _miss(w, state, 0, i)
    if offsets.shape[0] == 1:
        offsets[0] = azimuth_miss + w.bias
    else:
        across, along = sensor_frame(azimuth_miss, w.truth[1, i], state.actual[1])
        offsets[0], offsets[1] = across + w.bias, along + w.bias


@kernel
def _encoder(w, state, a, i):
    if w.encoder_frozen[i] and not math.isnan(state.last_encoder[a]):
        return state.last_encoder[a]
    resolution = w.resolution[a]
    value = np.rint((state.actual[a] + w.encoder_offset) / resolution) * resolution  # encoder_reading
    value += w.encoder_fault[a, i]
    state.last_encoder[a] = value
    return value


@kernel
def read_pointing(w, i, offsets, reported):
    """`hybridtrack.sensor.read_pointing`: fill `reported`; return the "sun present" output."""
    axes = offsets.shape[0]
    worst = abs(offsets[0]) if axes == 1 else max(abs(offsets[0]), abs(offsets[1]))
    spot0 = offsets[0] + w.patch_offset[0, i]
    spread = abs(spot0)
    if axes == 2:
        spread = max(spread, abs(offsets[1] + w.patch_offset[1, i]))
    sun_light = w.beam[i] * math.cos(math.radians(worst)) + w.aureole[i] if worst <= w.field_of_view else 0.0
    patch_light = w.patch[i] if spread <= w.field_of_view else 0.0
    light = sun_light + patch_light
    if not light >= w.direct_threshold:
        reported[:] = math.nan
        return False
    sigma = w.sensor_noise * 1000.0 / light
    for a in range(axes):
        spot = offsets[a] + w.patch_offset[a, i]
        reported[a] = (sun_light * offsets[a] + patch_light * spot) / light + sigma * w.noise[a, i]
    return True


@kernel
def read_photocurrent(w, offset, i):
    """`hybridtrack.sensor.read_photocurrent`."""
    off = abs(offset)
    direct = w.beam[i] * math.cos(math.radians(off)) if off <= w.coarse_field_of_view else 0.0
    current = w.dark_current + w.responsivity * (direct + w.diffuse_share * w.diffuse[i])
    return max(current + w.current_noise_ma * w.current_noise[i], 0.0)


@kernel
def coarse_offset(w, offset, i, a):
    """`hybridtrack.sensor.coarse_offset`."""
    if w.beam[i] >= w.direct_threshold and abs(offset) <= w.coarse_field_of_view:
        return offset + w.coarse_accuracy * w.coarse_noise[a, i]
    return math.nan


@kernel
def _sensor_faults(w, i, reported, obs, obs_axes):
    for a in range(reported.shape[0]):
        value = reported[a]
        if not math.isnan(w.sensor_fault[a, i]):
            value = w.sensor_fault[a, i]
            obs[2] = 1.0
        value += w.sensor_drift[i]
        if w.sensor_dropout[i]:
            value = math.nan
        obs_axes[a, 1] = value


@kernel(inline=True)
def world_observe(w, state, i, obs, obs_axes, offsets, reported):
    """World.observe: fill the observation of scan `i` (`obs`: t, wind, valid, intensity, true sky;
    `obs_axes`: encoder, offset, coarse per axis); `offsets` and `reported` are scratch."""
    axes = state.actual.shape[0]
    _offsets(w, state, i, offsets)
    if w.has_pointing:  # as recorded: what the logger's sensor said
        valid = True
        for a in range(axes):
            reported[a] = w.pointing[a, i]
            if math.isnan(reported[a]):
                valid = False
        obs[2] = 1.0 if valid else 0.0
    else:
        obs[2] = 1.0 if read_pointing(w, i, offsets, reported) else 0.0
    _sensor_faults(w, i, reported, obs, obs_axes)
    obs[0], obs[1] = w.minutes[i], w.wind[i]
    worst = 0.0
    for a in range(axes):
        obs_axes[a, 0] = _encoder(w, state, a, i)
        obs_axes[a, 2] = coarse_offset(w, offsets[a], i, a)
        worst = max(worst, abs(offsets[a]))
    obs[3] = w.recorded[i] if w.has_recorded else read_photocurrent(w, worst, i)
    obs[4] = w.true_sky[i]


@kernel
def world_move(w, state, i, moves):
    """World.move: drive each axis; the hard stops hold it; record the angle at `i`."""
    for a in range(moves.shape[0]):
        low, high = w.low[a] - HARD_STOP_MARGIN, w.high[a] + HARD_STOP_MARGIN
        state.actual[a] = min(max(state.actual[a] + moves[a], low), high)
        state.angles[a, i] = state.actual[a]


@kernel
def world_rest(state, i, j):
    """World.rest: scans `i` to `j` - 1 with nothing moving."""
    for a in range(state.actual.shape[0]):
        state.angles[a, i:j] = state.actual[a]
