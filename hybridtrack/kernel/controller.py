"""The controller compiled: `hybridtrack.control.Controller` restated over arrays for numba.

The readable controller (`hybridtrack.control`) is the reference and the documentation; this
module restates it function for function, with the same names, so that a reader can lay one
beside the other. Each piece keeps its state in its own arrays in `ControllerState` (the index
constants below name the slots of the shared scalar arrays) and is its own function:

=====================  ===================================================
reference               here
=====================  ===================================================
EncoderMonitor.read     `encoder_read`
WindGuard               `wind_watch`, `wind_heard`, `wind_update`, `wind_released`
SkyWatch                `trailing_mean`, `trailing_range`, `sky_update`
ClassifierTable         `table_score`, `table_code`
SensorGate + Kalman     `gate_judge`, `gate_take`, `kalman_*`
axis_offset             `axis_offset`
reading_scale           `reading_scale`
Calibrator.learn        `calibrator_learn`, `_start_day`
MountEstimator          `fit_forget`, `fit_update`, `fit_check`, `fit_solve`, `fit_excess_light`
pull_spread             `pull_spread`
DisagreementMonitor     `disagreement_add`
ClockWatch              `clock_add`, `clock_count`, `clock_solve`, `clock_verdict`
Controller.step         `controller_step` and its `_`-named helpers
Controller.rest         `controller_rest`
=====================  ===================================================

A new piece is a new function with its own state arrays, called from `controller_step` where the
reference calls it. The controller reads only its observation (`obs`, `obs_axes`), its plan and
its own state: nothing of the world (`hybridtrack.kernel.world`).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..control.clockwatch import ALARM_SIGMAS, CLOCK_TOLERANCE, DRIFT_DAYS, DRIFT_TOLERANCE, SPELL, SPELL_GAP
from ..control.controller import DUSK_MINUTES, FIT_EVERY, HELD_OFF_MINUTES, REFERENCE_LIGHT, SETTLE_UPDATES
from ..control.disagreement import ALLOWANCE, MIN_RUN, THRESHOLD
from ..control.modes import (ASTRONOMICAL, FAULT, IMPLAUSIBLE, INVALID, LOW_LIGHT, NOT_READ, OK, OUT_OF_VIEW,
                             OUTLIER, SEARCH, SENSOR, STOW_NIGHT, STOW_WIND, STUCK, SUNNY, UNKNOWN)
from ..control.mountfit import HORIZON, LEVEL_READINGS, LIGHT_TOLERANCE, MAX_CONDITION
from ..control.mountfit import spd_inverse as reference_spd_inverse  # compiled below
from ..control.sensing import axis_offset as reference_axis_offset  # compiled below
from ..control.sensing import reading_scale as reference_reading_scale  # compiled below
from ..control.wind import READABLE, STUCK_HOURS, STUCK_SPREAD
from . import events as ev
from .jit import kernel

__all__ = ["ControllerSettings", "ControllerPlanArrays", "ControllerState", "ControllerRecord", "EventLog",
           "controller_step", "controller_rest"]

#: What the controller is told (its config, its drives' datasheets, its classifier as a table).
ControllerSettings = namedtuple("ControllerSettings", [
    "uses_sensor", "uses_model", "calibrates", "sensor_only", "classifying", "trusts_always", "oracle", "lead",
    "dwell", "loss", "coast_for", "dusk_current", "plausibility", "disagreement", "follow_sensor", "distrust",
    "wind_stow", "wind_release", "wind_hold", "stow_when_missing", "encoder_confirm",
    "q", "r", "stuck_scans", "stuck_spread", "gate2", "reacquire", "tau", "max_rate",
    "has_fit", "fit_r", "prior", "fit_memory", "clip", "check_every", "pull_gain", "responsivity", "sun_threshold",
    "clock_r", "clock_prior", "clock_constant_seen",
    "sky_relative", "smoothing", "window", "min_altitude", "low_sun_absolute", "relative_floor", "full_variation",
    "dark", "table", "table_step", "table_last", "ranges", "edges", "codes",
    "deadband", "speed", "stow_speed", "low", "high", "stow", "resolution", "circular"])
#: The plan (`hybridtrack.control.plan.ControllerPlan`) as arrays; `alarm` marks its alarms' scans.
ControllerPlanArrays = namedtuple("ControllerPlanArrays", [
    "model", "awake", "slept", "clock_steps", "alarm", "clear_light", "altitude", "jacobian", "weight"])
#: Every piece's state. `s` (floats) and `k` (integers) hold the scalars named below.
ControllerState = namedtuple("ControllerState", [
    "s", "k", "encoder", "jumped", "kf", "gate", "stuck_angles", "stuck_expected", "stuck_fill",
    "calibration", "fitted_at", "blind_stow", "park", "moves", "travel", "mount",
    "theta", "p", "information", "checkpoint_offsets", "checkpoint_theta", "checkpoint_p",
    "checkpoint_information", "evidence", "checkpoint_evidence", "window_t", "window_v", "window_ends", "clock_t", "clock_axis", "clock_x", "clock_y",
    "clock_moments", "clock_sums", "clock_last"])
#: What the controller records per scan (`hybridtrack.control.controller.ControllerOutputs`).
ControllerRecord = namedtuple("ControllerRecord", [
    "mode", "status", "sky", "score", "intensity", "variation", "target", "reading", "calibration", "sun",
    "fit_value", "fit_std"])
#: Events as codes and up to three numbers (`hybridtrack.kernel.events`); `k[EVENTS]` counts them.
EventLog = namedtuple("EventLog", ["scan", "before", "after", "code", "value"])

# slots of ControllerState.s
(MODE_SINCE, INVALID_SINCE, PREVIOUS_T, DARK_SINCE, DISTRUSTED_UNTIL, FIT_SINCE, CALM_SINCE, FLAT_VALUE, FLAT_SINCE,
 MEAN_TOTAL, CONDITION, CUSUM_HIGH, CUSUM_LOW, CUSUM_SUM, SPELL_START, SPELL_LAST, LIGHT_LEVEL, HELD_OFF_SINCE,
 HELD_MISS) = range(19)
FLOAT_SLOTS = 19
# slots of ControllerState.k
(MODE, RESTING, WAS_AWAKE, FOUND_TODAY, BLIND_STOW, WIND_STUCK, EVENTS, HAS_CHECKPOINT, UPDATES, FROZEN,
 CHECKPOINT_UPDATES, CHECKPOINT_FROZEN, CUSUM_RUN, MOUNT_AT_SCAN, MOUNT_AT_UPDATES, CLOCK_ROWS, CLOCK_PENDING,
 CLOCK_RAISED, DRIFT_RAISED, HELD_OFF_RAISED) = range(20)
INT_SLOTS = 20
# the clock watch's running sums over its counted readings: rows of clock_moments (n x n each), of
# clock_sums (n each) and, after the n columns, its scalars; x a reading's row with its drift
# column, y its residual; a reading linked to the one before it on its axis (`_correlation_factor`)
# is c, that one p
XX, PP, CC, PC = range(4)
XY, PY_P, CY_C, PY_C, CY_P = range(5)
YY, YP_YP, YC_YC, YP_YC, LINKED = range(5)
# columns of ControllerState.encoder, .kf, .gate, .calibration
BELIEVED, LAST, COMMANDED = range(3)
X0, X1, P00, P01, P11 = range(5)
READY, REJECTED = range(2)
OFFSET, LEARNED = range(2)
# the trailing windows of the sky watch (rows of window_t, window_v, window_ends)
MEAN, ABSOLUTE_HIGHS, ABSOLUTE_LOWS, RELATIVE_HIGHS, RELATIVE_LOWS = range(5)
HEAD, TAIL = range(2)


# -- bookkeeping ----------------------------------------------------------------------------------

@kernel
def _event(i, before, after, code, value, other, state, log):
    n = state.k[EVENTS]
    log.scan[n] = i
    log.before[n] = before
    log.after[n] = after
    log.code[n] = code
    log.value[n, 0] = value
    log.value[n, 1] = other
    log.value[n, 2] = 0.0
    state.k[EVENTS] = n + 1


@kernel
def _switch(i, new, code, value, t, state, log):
    _event(i, state.k[MODE], new, code, value, 0.0, state, log)
    state.k[MODE] = new
    state.s[MODE_SINCE] = t


@kernel
def _alarm(i, code, value, other, state, log):
    _event(i, state.k[MODE], state.k[MODE], code, value, other, state, log)


@kernel
def _alarm3(i, code, value, other, third, state, log):
    """An alarm worded from three numbers."""
    _event(i, state.k[MODE], state.k[MODE], code, value, other, state, log)
    log.value[state.k[EVENTS] - 1, 2] = third


@kernel
def _turn(cfg, a, difference):
    if cfg.circular[a]:
        return (difference + 180.0) % 360.0 - 180.0
    return difference


@kernel
def _lead(rate, period, deadband):
    step = abs(rate) * period
    if not step > 0:
        return 0.0
    scans = math.ceil(deadband / step - 1e-9)
    return math.copysign(min(step * (scans - 1) / 2.0, deadband / 2.0), rate)


@kernel
def ordered_dot(x, y):
    """mountfit.ordered_dot of two vectors: Σₖ x[k] · y[k] added in turn, so the same bits."""
    total = x[0] * y[0]
    for k in range(1, y.shape[0]):
        total = total + x[k] * y[k]
    return total


@kernel
def _mount_corrections(jacobian, theta, i, mount):
    """Controller._mount_corrections of scan `i` into `mount`."""
    for a in range(mount.shape[0]):
        mount[a] = ordered_dot(jacobian[i, a], theta)


@kernel
def _correction(cfg, plan, state, i, a):
    """Controller._correction, with its cache of the fitted mount's correction by (scan, updates)."""
    offset = state.calibration[a, OFFSET]
    if not cfg.has_fit:
        return offset
    k = state.k
    if k[MOUNT_AT_SCAN] != i or k[MOUNT_AT_UPDATES] != k[UPDATES]:
        k[MOUNT_AT_SCAN], k[MOUNT_AT_UPDATES] = i, k[UPDATES]
        _mount_corrections(plan.jacobian, state.theta, i, state.mount)
    return state.mount[a] + offset


@kernel
def _record(cfg, plan, state, out, i, status, targets, reading):
    out.mode[i] = state.k[MODE]
    out.status[i] = status
    for a in range(targets.shape[0]):
        out.target[i, a] = targets[a]
        out.reading[i, a] = reading[a]
        out.calibration[i, a] = _correction(cfg, plan, state, i, a)
    for m in range(out.fit_value.shape[1]):  # none where the run keeps no fit columns
        out.fit_value[i, m] = state.theta[m]
        out.fit_std[i, m] = math.sqrt(max(state.p[m, m], 0.0))


@kernel
def _night_target(cfg, state, a):
    return state.park[a] if cfg.sensor_only else cfg.stow[a]


# -- the encoder monitor --------------------------------------------------------------------------

@kernel
def encoder_read(cfg, state, a, value, reckoned):
    """EncoderMonitor.read: (position, event code or 0, value, other, frozen)."""
    e = state.encoder
    previous = e[a, LAST]
    e[a, LAST] = value
    if math.isnan(e[a, BELIEVED]):
        e[a, BELIEVED] = value
        return value, 0, 0.0, 0.0, False
    resolution = cfg.resolution[a]
    commanded = e[a, COMMANDED]
    expected = e[a, BELIEVED] + commanded
    if reckoned:
        e[a, BELIEVED] = expected
        return expected, 0, 0.0, 0.0, False
    tolerance = 2.0 * resolution + 1e-9
    if commanded != 0.0 and abs(value - previous) < 0.5 * resolution and abs(commanded) > tolerance:
        e[a, BELIEVED] = expected
        return expected, ev.ENCODER_FROZEN, commanded, 0.0, True
    if abs(value - expected) <= tolerance:
        state.jumped[a] = 0
        e[a, BELIEVED] = value
        return value, 0, 0.0, 0.0, False
    state.jumped[a] += 1
    if state.jumped[a] >= cfg.encoder_confirm:
        state.jumped[a] = 0
        e[a, BELIEVED] = value
        return value, ev.ENCODER_BELIEVED, value, float(cfg.encoder_confirm), False
    e[a, BELIEVED] = expected
    if state.jumped[a] == 1:
        return expected, ev.ENCODER_GLITCH, value, expected, False
    return expected, 0, 0.0, 0.0, False


# -- the wind guard -------------------------------------------------------------------------------

LEAST_WIND, MOST_WIND = READABLE


@kernel
def _unreadable(wind):
    """wind.unreadable."""
    return wind < LEAST_WIND or wind > MOST_WIND


@kernel
def _gusty(cfg, wind):
    if math.isnan(wind):
        return cfg.stow_when_missing
    return not wind <= cfg.wind_stow


@kernel
def wind_watch(state, t, wind, daylight):
    """WindGuard.watch: (event code or 0, value)."""
    s, k = state.s, state.k
    if math.isnan(wind) or _unreadable(wind):
        return 0, 0.0
    if k[WIND_STUCK]:
        if abs(wind - s[FLAT_VALUE]) <= STUCK_SPREAD:
            return 0, 0.0
        k[WIND_STUCK] = 0
        s[FLAT_VALUE] = wind if daylight else math.nan
        s[FLAT_SINCE] = t if daylight else math.nan
        return ev.ANEMOMETER_MOVING, wind
    if not daylight:
        s[FLAT_VALUE] = math.nan
        return 0, 0.0
    if math.isnan(s[FLAT_VALUE]) or abs(wind - s[FLAT_VALUE]) > STUCK_SPREAD:
        s[FLAT_VALUE] = wind
        s[FLAT_SINCE] = t
        return 0, 0.0
    if t - s[FLAT_SINCE] >= 60.0 * STUCK_HOURS:
        k[WIND_STUCK] = 1
        return ev.ANEMOMETER_STUCK, s[FLAT_VALUE]
    return 0, 0.0


@kernel
def wind_heard(state, wind):
    """WindGuard.heard: the reading, NaN outside `READABLE` or while the anemometer is stuck at it."""
    if _unreadable(wind) or state.k[WIND_STUCK] and not math.isnan(wind) \
            and abs(wind - state.s[FLAT_VALUE]) <= STUCK_SPREAD:
        return math.nan
    return wind


@kernel
def wind_update(cfg, state, t, wind):
    """WindGuard.update: whether the (heard) reading is a gust."""
    s = state.s
    if _gusty(cfg, wind):
        s[CALM_SINCE] = math.inf
        return True
    if wind <= cfg.wind_release or math.isnan(wind):
        if math.isinf(s[CALM_SINCE]):
            s[CALM_SINCE] = t
    else:
        s[CALM_SINCE] = math.inf
    return False


@kernel
def wind_released(cfg, state, t):
    """WindGuard.released."""
    return not math.isinf(state.s[CALM_SINCE]) and t - state.s[CALM_SINCE] >= cfg.wind_hold


# -- the sky watch --------------------------------------------------------------------------------

# A queue's places are its counts masked by its capacity, a power of two (`bridge._window_capacity`):
# a mask where a remainder would divide, several times a scan.

@kernel
def _push(state, q, t, value):
    mask = state.window_t.shape[1] - 1
    tail = state.window_ends[q, TAIL]
    state.window_t[q, tail & mask] = t
    state.window_v[q, tail & mask] = value
    state.window_ends[q, TAIL] = tail + 1


@kernel
def _back(state, q):
    return state.window_v[q, (state.window_ends[q, TAIL] - 1) & (state.window_t.shape[1] - 1)]


@kernel
def _front(state, q):
    head = state.window_ends[q, HEAD] & (state.window_t.shape[1] - 1)
    return state.window_t[q, head], state.window_v[q, head]


@kernel
def _empty(state, q):
    return state.window_ends[q, HEAD] == state.window_ends[q, TAIL]


@kernel
def most_in_window(minutes, width):
    """The most scans a trailing window of `width` minutes, ``(t − width, t]``, holds over the run:
    the size `trailing_range` and `trailing_mean` need for their queues."""
    most, start = 0, 0
    for i in range(minutes.shape[0]):
        while start <= i and minutes[start] <= minutes[i] - width:
            start += 1
        most = max(most, i - start + 1)
    return most


@kernel
def trailing_range(state, highs, lows, window, t, value):
    """TrailingRange.add over the queues `highs` and `lows`."""
    if not math.isnan(value):
        while not _empty(state, highs) and _back(state, highs) <= value:
            state.window_ends[highs, TAIL] -= 1
        _push(state, highs, t, value)
        while not _empty(state, lows) and _back(state, lows) >= value:
            state.window_ends[lows, TAIL] -= 1
        _push(state, lows, t, value)
    start = t - window
    while not _empty(state, highs) and _front(state, highs)[0] <= start:
        state.window_ends[highs, HEAD] += 1
    while not _empty(state, lows) and _front(state, lows)[0] <= start:
        state.window_ends[lows, HEAD] += 1
    if _empty(state, highs):
        return math.nan
    return _front(state, highs)[1] - _front(state, lows)[1]


@kernel
def trailing_mean(state, window, t, value):
    """TrailingMean.add."""
    s = state.s
    if not math.isnan(value):
        _push(state, MEAN, t, value)
        s[MEAN_TOTAL] += value
    start = t - window
    while not _empty(state, MEAN) and _front(state, MEAN)[0] <= start:
        s[MEAN_TOTAL] -= _front(state, MEAN)[1]
        state.window_ends[MEAN, HEAD] += 1
    if _empty(state, MEAN):
        s[MEAN_TOTAL] = 0.0
        return math.nan
    return s[MEAN_TOTAL] / (state.window_ends[MEAN, TAIL] - state.window_ends[MEAN, HEAD])


@kernel
def _normalised(cfg, value, which):
    lo, hi = cfg.ranges[2 * which], cfg.ranges[2 * which + 1]
    return min(max(10.0 * (value - lo) / (hi - lo), 0.0), 10.0) / cfg.table_step


@kernel
def table_score(cfg, intensity, variation):
    """ClassifierTable.score."""
    if math.isnan(intensity) or math.isnan(variation):
        return math.nan
    u, v = _normalised(cfg, intensity, 0), _normalised(cfg, variation, 1)
    i, j = min(int(u), cfg.table_last - 1), min(int(v), cfg.table_last - 1)
    fu, fv = u - i, v - j
    table = cfg.table
    return ((1.0 - fu) * ((1.0 - fv) * table[i, j] + fv * table[i, j + 1])
            + fu * ((1.0 - fv) * table[i + 1, j] + fv * table[i + 1, j + 1]))


@kernel
def table_code(cfg, score):
    """ClassifierTable.code."""
    if math.isnan(score):
        return UNKNOWN
    for b in range(cfg.edges.shape[0]):
        if score < cfg.edges[b]:
            return cfg.codes[b]
    return cfg.codes[cfg.codes.shape[0] - 1]


@kernel
def _sky_inputs(cfg, state, t, intensity, expected, altitude):
    absolute = trailing_mean(state, cfg.smoothing, t, intensity) if cfg.smoothing > 0 else intensity
    absolute_variation = trailing_range(state, ABSOLUTE_HIGHS, ABSOLUTE_LOWS, cfg.window, t, absolute)
    if not cfg.sky_relative:
        return absolute, absolute_variation
    low = not (altitude >= cfg.min_altitude) or not expected > 0
    relative = math.nan if low else min((absolute - cfg.dark) / expected, 1.0)
    relative_variation = trailing_range(state, RELATIVE_HIGHS, RELATIVE_LOWS, cfg.window, t, relative)
    if low:
        if cfg.low_sun_absolute:
            return absolute, absolute_variation
        return math.nan, math.nan
    lo, hi, vlo, vhi = cfg.ranges[0], cfg.ranges[1], cfg.ranges[2], cfg.ranges[3]
    floor = cfg.relative_floor
    share = min(max((relative - floor) / (1.0 - floor), 0.0), 1.0)
    return lo + (hi - lo) * share, vlo + (vhi - vlo) * relative_variation / cfg.full_variation


@kernel
def sky_update(cfg, state, t, intensity, expected, altitude):
    """SkyWatch.update: (sky code, score, variation input)."""
    level, variation = _sky_inputs(cfg, state, t, intensity, expected, altitude)
    score = table_score(cfg, level, variation)
    return table_code(cfg, score), score, variation


# -- the sensor gate and its Kalman filter --------------------------------------------------------

@kernel
def kalman_reset(state, a, angle, rate):
    kf = state.kf
    kf[a, X0], kf[a, X1] = angle, rate
    kf[a, P00], kf[a, P01], kf[a, P11] = 1.0, 0.0, 0.1


@kernel
def kalman_predict(cfg, state, a, dt):
    kf, q = state.kf, cfg.q
    kf[a, X0] += dt * kf[a, X1]
    p00, p01, p11 = kf[a, P00], kf[a, P01], kf[a, P11]
    kf[a, P00] = p00 + 2.0 * dt * p01 + dt * dt * p11 + q * dt**3 / 3.0
    kf[a, P01] = p01 + dt * p11 + q * dt * dt / 2.0
    kf[a, P11] = p11 + q * dt


@kernel
def kalman_update(cfg, state, a, z, scale):
    kf = state.kf
    y, s = z - kf[a, X0], kf[a, P00] + cfg.r[a] * scale
    k0, k1 = kf[a, P00] / s, kf[a, P01] / s
    kf[a, X0] += k0 * y
    kf[a, X1] += k1 * y
    p00, p01, p11 = kf[a, P00], kf[a, P01], kf[a, P11]
    kf[a, P00] = (1.0 - k0) * p00
    kf[a, P01] = (1.0 - k0) * p01
    kf[a, P11] = p11 - k1 * p01


@kernel
def _spread(values, a):
    """max - min of row `a`."""
    high = low = values[a, 0]
    for value in values[a, 1:]:
        high, low = max(high, value), min(low, value)
    return high - low


#: sensing.axis_offset itself, compiled: the same steps, so the same bits.
axis_offset = kernel(reference_axis_offset)
#: sensing.reading_scale itself, compiled.
reading_scale = kernel(reference_reading_scale)


@kernel
def gate_judge(cfg, state, a, measured, valid, coarse, expected):
    """SensorGate.judge (its two deques as rings of `stuck_scans`)."""
    if math.isnan(measured) or math.isnan(expected):
        state.stuck_fill[a] = 0
    else:
        scans = cfg.stuck_scans
        slot = state.stuck_fill[a] % scans
        state.stuck_angles[a, slot] = measured
        state.stuck_expected[a, slot] = expected
        state.stuck_fill[a] += 1
        if state.stuck_fill[a] >= scans:
            if _spread(state.stuck_angles, a) < cfg.stuck_spread and \
                    _spread(state.stuck_expected, a) > 10.0 * cfg.stuck_spread:
                return STUCK
    if not valid:
        return LOW_LIGHT if math.isnan(coarse) else OUT_OF_VIEW
    if math.isnan(measured) or abs(measured) > 90.0:
        return INVALID
    return OK


@kernel
def gate_take(cfg, state, a, z, dt, miss, bound, rate, scale):
    """SensorGate.take."""
    if abs(miss) > bound:
        return IMPLAUSIBLE
    gate = state.gate
    if not gate[a, READY]:
        kalman_reset(state, a, z, rate)
        gate[a, READY] = 1
        return OK
    kalman_predict(cfg, state, a, dt)
    y, s = z - state.kf[a, X0], state.kf[a, P00] + cfg.r[a] * scale
    if s > bound * bound and not math.isnan(miss):
        kalman_reset(state, a, z, rate)
        gate[a, REJECTED] = 0
        return OK
    if y * y > cfg.gate2 * s:
        gate[a, REJECTED] += 1
        if gate[a, REJECTED] < cfg.reacquire:
            return OUTLIER
        kalman_reset(state, a, z, rate)
    else:
        kalman_update(cfg, state, a, z, scale)
    gate[a, REJECTED] = 0
    return OK


@kernel
def gate_coast(cfg, state, a, dt):
    """SensorGate.coast."""
    if state.gate[a, READY]:
        kalman_predict(cfg, state, a, dt)


# -- calibration: the offset, the mount fit, the disagreement watch -------------------------------

@kernel
def calibrator_learn(cfg, state, a, dt, residual, model_step, bound):
    """Calibrator.learn."""
    c = state.calibration
    if not abs(model_step) <= cfg.max_rate * dt or math.isnan(residual):
        return
    c[a, LEARNED] += dt
    alpha = max(1.0 - math.exp(-dt / cfg.tau), dt / c[a, LEARNED] if c[a, LEARNED] < cfg.tau else 0.0)
    c[a, OFFSET] += alpha * (residual - c[a, OFFSET])
    c[a, OFFSET] = max(-bound, min(bound, c[a, OFFSET]))


@kernel
def _start_day(state):
    """Calibrator.start_day on every axis."""
    state.calibration[:, OFFSET] = 0.0


@kernel
def _forget_scale(p, m, factor, prior):
    """MountEstimator.forget's scale of parameter `m`: sqrt(min(1, prior / (p[m, m] / factor))),
    NaN through as numpy's minimum passes it."""
    ratio = prior / (p[m, m] / factor)
    return math.sqrt(ratio if not ratio >= 1.0 else 1.0)


@kernel
def fit_forget(p, information, evidence, memory, prior, dt):
    """MountEstimator.forget (in place on `p`, `information` and `evidence`): each element the
    reference's p / factor times its outer product of scales, the off-diagonal ones first, while
    the diagonal the scales come from is still the old one; no array is made."""
    factor = math.exp(-dt / memory)
    n = p.shape[0]
    for i in range(n):
        for j in range(n):
            if i != j:
                p[i, j] = p[i, j] / factor * (_forget_scale(p, i, factor, prior) * _forget_scale(p, j, factor, prior))
    for i in range(n):
        scale = _forget_scale(p, i, factor, prior)
        p[i, i] = p[i, i] / factor * (scale * scale)
        for j in range(n):
            information[i, j] = information[i, j] * factor
        evidence[i] = evidence[i] * factor


@kernel(allocates=True)
def fit_condition(information):
    """MountEstimator._check's condition number of the information matrix."""
    singular = np.linalg.svd(information.copy())[1]
    return singular[0] / max(singular[-1], 1e-300)


#: mountfit.spd_inverse itself, compiled: the same Cholesky steps in the same order, so the same bits.
spd_inverse = kernel(reference_spd_inverse, allocates=True)


@kernel(allocates=True)
def fit_solve(theta, p, information, evidence, prior):
    """MountEstimator.solve, into `theta` and `p`: θ = (Λ + I/σ₀²)⁻¹ b, P = (Λ + I/σ₀²)⁻¹."""
    n = theta.shape[0]
    p[:, :] = spd_inverse(information + np.eye(n) / prior)
    for i in range(n):
        total = 0.0
        for j in range(n):
            total += p[i, j] * evidence[j]
        theta[i] = total


@kernel(allocates=True)
def fit_check(theta, p, information, evidence, prior, frozen):
    """MountEstimator._check: the condition number and whether the pedestal stays frozen (at a
    release `fit_solve`)."""
    condition = fit_condition(information)
    now = condition > MAX_CONDITION
    if frozen and not now:
        fit_solve(theta, p, information, evidence, prior)
    return condition, now


@kernel(allocates=True)
def fit_update(theta, p, information, evidence, r, clip, frozen, derivatives, weight, residual):
    """MountEstimator.update of the row `derivatives` · `weight` (Joseph form; frozen pedestal
    terms as consider parameters), in place on `theta`, `p`, `information` and `evidence`: each
    number the reference's, summed in its order, with the Joseph form's A = I − g·rowᵀ taken
    element by element (`_joseph`) and two arrays made where the reference made eleven."""
    n = derivatives.shape[0]
    for i in range(n):
        for j in range(n):
            information[i, j] = information[i, j] + derivatives[i] * weight * (derivatives[j] * weight) / r
        evidence[i] = evidence[i] + derivatives[i] * weight * residual / r
    gain = np.empty(n)
    for m in range(n):
        gain[m] = _row_dot(derivatives, weight, p[m])  # P·row, before it is scaled to the gain
    s = r + _row_dot(derivatives, weight, gain)
    for m in range(n):
        gain[m] = 0.0 if frozen and m < 2 else gain[m] / s
    bound = clip * math.sqrt(s)
    innovation = residual - _row_dot(derivatives, weight, theta)
    error = max(-bound, min(bound, innovation))
    for m in range(n):
        theta[m] = theta[m] + gain[m] * error
    _joseph(p, gain, derivatives, weight, r)


@kernel
def _row_dot(derivatives, weight, y):
    """ordered_dot(row, y) of the row `derivatives` · `weight`."""
    total = derivatives[0] * weight * y[0]
    for k in range(1, y.shape[0]):
        total = total + derivatives[k] * weight * y[k]
    return total


@kernel
def _joseph_a(gain, derivatives, weight, i, k):
    """Element (i, k) of the Joseph form's A = I − g·rowᵀ, as np.eye − np.outer gives it."""
    return (1.0 if i == k else 0.0) - gain[i] * (derivatives[k] * weight)


@kernel(allocates=True)
def _joseph(p, gain, derivatives, weight, r):
    """P ← A P Aᵀ + r g gᵀ in place, each product summed in turn as `mountfit.ordered_matmul`."""
    n = p.shape[0]
    ap = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            total = _joseph_a(gain, derivatives, weight, i, 0) * p[0, j]
            for k in range(1, n):
                total = total + _joseph_a(gain, derivatives, weight, i, k) * p[k, j]
            ap[i, j] = total
    for i in range(n):
        for j in range(n):
            total = ap[i, 0] * _joseph_a(gain, derivatives, weight, j, 0)
            for k in range(1, n):
                total = total + ap[i, k] * _joseph_a(gain, derivatives, weight, j, k)
            p[i, j] = total + r * (gain[i] * gain[j])


@kernel
def fit_excess_light(state, ratio):
    """MountEstimator.excess_light: the light ratio above the clear sky's level (less the
    tolerance), then the level (`s[LIGHT_LEVEL]`) updated."""
    if not math.isfinite(ratio):
        return 0.0
    s = state.s
    if math.isnan(s[LIGHT_LEVEL]):
        s[LIGHT_LEVEL] = ratio
    excess = max(0.0, ratio - s[LIGHT_LEVEL] - LIGHT_TOLERANCE)
    s[LIGHT_LEVEL] += (ratio - s[LIGHT_LEVEL]) / LEVEL_READINGS
    return excess


@kernel
def pull_spread(gain, excess, altitude):
    """mountfit.pull_spread: 1σ of a reading's cloud pull, degrees."""
    rise = math.sin(math.radians(altitude)) if altitude == altitude else 0.0
    return gain * excess / max(rise, HORIZON)


@kernel
def disagreement_add(state, normalised, residual, limit):
    """DisagreementMonitor.add."""
    s, k = state.s, state.k
    s[CUSUM_HIGH] = max(0.0, s[CUSUM_HIGH] + normalised - ALLOWANCE)
    s[CUSUM_LOW] = max(0.0, s[CUSUM_LOW] - normalised - ALLOWANCE)
    if s[CUSUM_HIGH] == 0.0 and s[CUSUM_LOW] == 0.0:
        k[CUSUM_RUN], s[CUSUM_SUM] = 0, 0.0
        return False
    k[CUSUM_RUN] += 1
    s[CUSUM_SUM] += residual
    if (s[CUSUM_HIGH] <= THRESHOLD and s[CUSUM_LOW] <= THRESHOLD) or k[CUSUM_RUN] < MIN_RUN:
        return False
    if abs(s[CUSUM_SUM] / k[CUSUM_RUN]) >= limit:
        return True
    _disagreement_reset(state)
    return False


@kernel
def _disagreement_reset(state):
    state.s[CUSUM_HIGH] = state.s[CUSUM_LOW] = 0.0
    state.k[CUSUM_RUN], state.s[CUSUM_SUM] = 0, 0.0


@kernel(allocates=True)
def _checkpoint(state):
    """Controller.memory, kept as the checkpoint."""
    state.checkpoint_offsets[:] = state.calibration[:, OFFSET]
    state.checkpoint_theta[:] = state.theta
    state.checkpoint_p[:, :] = state.p
    state.checkpoint_information[:, :] = state.information
    state.checkpoint_evidence[:] = state.evidence
    state.k[CHECKPOINT_FROZEN] = state.k[FROZEN]
    state.k[CHECKPOINT_UPDATES] = state.k[UPDATES]
    state.k[HAS_CHECKPOINT] = 1


@kernel(allocates=True)
def _recall(cfg, state):
    """Controller._recall of the checkpoint (Calibrator.carry: past the running-mean phase)."""
    state.calibration[:, OFFSET] = state.checkpoint_offsets
    state.calibration[:, LEARNED] = cfg.tau
    state.theta[:] = state.checkpoint_theta
    state.p[:, :] = state.checkpoint_p
    state.information[:, :] = state.checkpoint_information
    state.evidence[:] = state.checkpoint_evidence
    state.k[FROZEN] = state.k[CHECKPOINT_FROZEN]
    state.k[UPDATES] = state.k[CHECKPOINT_UPDATES]


@kernel
def _against_checkpoint(row, theta, p, r, w):
    """Controller._against_checkpoint: the fit's correction at `row` and the spread in pointing
    terms (sqrt(r + w²·row·(p·row)))."""
    spread = row[0] * ordered_dot(p[0], row)
    for m in range(1, row.shape[0]):
        spread = spread + row[m] * ordered_dot(p[m], row)
    return ordered_dot(row, theta), math.sqrt(r + w * w * spread)


@kernel(inline=True)
def _disagrees(cfg, state, log, i, miss, spread):
    if state.k[UPDATES] < SETTLE_UPDATES:
        return False
    if state.s[CUSUM_HIGH] == 0.0 and state.s[CUSUM_LOW] == 0.0:
        _checkpoint(state)
    if not disagreement_add(state, miss / spread, miss, cfg.disagreement):
        return False
    count = state.k[CUSUM_RUN]
    mean = state.s[CUSUM_SUM] / count if count else 0.0
    _disagreement_reset(state)
    if cfg.follow_sensor:  # on_disagreement = "sensor": the mount moved, the fit follows the sensor
        _checkpoint(state)
        _alarm(i, ev.DISAGREEMENT_FOLLOWED, mean, float(count), state, log)
        return False
    if state.k[HAS_CHECKPOINT]:
        _recall(cfg, state)
    state.s[DISTRUSTED_UNTIL] = state.s[PREVIOUS_T] + cfg.distrust
    _alarm(i, ev.DISAGREEMENT, mean, float(count), state, log)
    return True


@kernel
def _reading_variance(cfg, intensity):
    """Controller._reading_variance: the datasheet noise grown as the light in view falls (as
    stated where the responsivity is not known, 0 here)."""
    if cfg.responsivity <= 0.0:
        return cfg.fit_r
    light = (intensity - cfg.dark) / cfg.responsivity
    if not light >= cfg.sun_threshold:  # NaN too
        light = cfg.sun_threshold
    ratio = REFERENCE_LIGHT / light
    return cfg.fit_r * ratio * ratio


@kernel(inline=True)
def _learn(cfg, plan, state, log, i, a, dt, z, m0, m1, bound, intensity):
    t = state.s[PREVIOUS_T]
    if cfg.has_fit and t - state.fitted_at[a] >= FIT_EVERY:
        state.fitted_at[a] = t
        fit_forget(state.p, state.information, state.evidence, cfg.fit_memory, cfg.prior, t - state.s[FIT_SINCE])
        state.s[FIT_SINCE] = t
        has = state.k[HAS_CHECKPOINT]
        w = plan.weight[i, a]
        r = _reading_variance(cfg, intensity)
        fitted, spread = _against_checkpoint(plan.jacobian[i, a], state.checkpoint_theta if has else state.theta,
                                             state.checkpoint_p if has else state.p, r, w)
        miss = _turn(cfg, a, z - m0 - fitted) * w
        expected = plan.clear_light[i]
        ratio = (intensity - cfg.dark) / expected if expected > 0 else math.nan
        pull = w * pull_spread(cfg.pull_gain, fit_excess_light(state, ratio), plan.altitude[i])
        fit_update(state.theta, state.p, state.information, state.evidence, r + pull * pull, cfg.clip,
                   state.k[FROZEN], plan.jacobian[i, a], w, _turn(cfg, a, z - m0) * w)
        state.k[UPDATES] += 1
        if state.k[UPDATES] % cfg.check_every == 0:
            state.s[CONDITION], state.k[FROZEN] = fit_check(state.theta, state.p, state.information, state.evidence,
                                                            cfg.prior, state.k[FROZEN])
        if _disagrees(cfg, state, log, i, miss, spread):
            return
        rate = _turn(cfg, a, m0 - m1) / dt if dt > 0 else math.nan
        if math.isfinite(rate):
            clock_add(state, t, a, plan.jacobian[i, a], rate, _turn(cfg, a, z - m0), w)
    mount = _correction(cfg, plan, state, i, a) - state.calibration[a, OFFSET]
    residual = _turn(cfg, a, state.kf[a, X0] - m0 - mount)
    calibrator_learn(cfg, state, a, dt, residual, _turn(cfg, a, m0 - m1), bound)


# -- the clock watch ------------------------------------------------------------------------------

@kernel
def clock_add(state, t, a, row, rate, residual, weight):
    """ClockWatch.add: rows [0, k[CLOCK_ROWS]) are counted (and summed, `clock_count`), the
    current spell's follow them."""
    s, k = state.s, state.k
    if not t - s[SPELL_LAST] <= SPELL_GAP:  # a new spell
        k[CLOCK_PENDING] = 0
        s[SPELL_START] = t
    s[SPELL_LAST] = t
    n = k[CLOCK_ROWS] + k[CLOCK_PENDING]
    if n >= state.clock_t.shape[0]:  # pragma: no cover - sized for one reading per axis per FIT_EVERY
        return
    per_second = -rate / 60.0
    m = row.shape[0]
    state.clock_t[n] = t
    state.clock_axis[n] = a
    for j in range(m):
        state.clock_x[n, j] = row[j] * weight
    state.clock_x[n, m] = per_second * weight
    state.clock_y[n] = residual * weight
    k[CLOCK_PENDING] += 1
    if t - s[SPELL_START] >= SPELL:
        for counted in range(k[CLOCK_ROWS], k[CLOCK_ROWS] + k[CLOCK_PENDING]):
            clock_count(state.clock_t, state.clock_axis, state.clock_x, state.clock_y, state.clock_moments,
                        state.clock_sums, state.clock_last, counted)
        k[CLOCK_ROWS] += k[CLOCK_PENDING]
        k[CLOCK_PENDING] = 0


@kernel
def _clock_column(times, rows, row, j):
    """Column `j` of reading `row` in the clock fit: the mount's and the clock's columns as
    added, then the drift's (the clock's column times the days since the first reading)."""
    columns = rows.shape[1]
    if j < columns:
        return rows[row, j]
    return rows[row, columns - 1] * (times[row] - times[0]) / 1440.0


@kernel
def clock_count(times, axis, rows, values, moments, sums, last, row):
    """Add counted reading `row` to the running sums the clock fit is solved from
    (`clock_solve`): its own moments and, with the reading before it on its axis (`last`) when
    that is within `SPELL_GAP`, the pair's (the residuals' serial correlation). Each reading is
    summed once, so a year's evenings cost what its readings do, not their square."""
    n = moments.shape[1]
    y = values[row]
    previous = last[axis[row]]
    last[axis[row]] = row
    linked = previous >= 0 and times[row] - times[previous] <= SPELL_GAP
    yp = values[previous] if linked else 0.0
    for j in range(n):
        xj = _clock_column(times, rows, row, j)
        sums[XY, j] += xj * y
        for m in range(n):
            moments[XX, j, m] += xj * _clock_column(times, rows, row, m)
        if linked:
            pj = _clock_column(times, rows, previous, j)
            sums[PY_P, j] += pj * yp
            sums[CY_C, j] += xj * y
            sums[PY_C, j] += pj * y
            sums[CY_P, j] += xj * yp
            for m in range(n):
                moments[PP, j, m] += pj * _clock_column(times, rows, previous, m)
                moments[CC, j, m] += xj * _clock_column(times, rows, row, m)
                moments[PC, j, m] += pj * _clock_column(times, rows, row, m)
    sums[YY, n] += y * y
    if linked:
        sums[YP_YP, n] += yp * yp
        sums[YC_YC, n] += y * y
        sums[YP_YC, n] += yp * y
        sums[LINKED, n] += 1.0


@kernel
def clock_recount(times, axis, rows, values, moments, sums, last, count):
    """The running sums of the first `count` readings, summed afresh (a run carried on from an
    earlier one's readings, `hybridtrack.streaming`)."""
    moments[:, :, :] = 0.0
    sums[:, :] = 0.0
    last[:] = -1
    for row in range(count):
        clock_count(times, axis, rows, values, moments, sums, last, row)


@kernel
def _quadratic(moments, which, beta, k):
    """βᵀ M β over the first `k` parameters of moment matrix `which`."""
    total = 0.0
    for j in range(k):
        for m in range(k):
            total += beta[j] * moments[which, j, m] * beta[m]
    return total


@kernel
def _linear(sums, which, beta, k):
    """β · v over the first `k` parameters of sum vector `which`."""
    total = 0.0
    for j in range(k):
        total += beta[j] * sums[which, j]
    return total


@kernel(allocates=True)
def clock_solve(moments, sums, count, span, prior, r):
    """ClockWatch.solve from the running sums of its `count` readings (`clock_count`) spanning
    `span` days: (estimate, 1σ), each of the mount's parameters, the clock's error and its drift
    (held at zero, 1σ infinite, under DRIFT_DAYS). The residuals' squares are the sums expanded
    about the estimate, Σ(y − xβ)² = Σy² − 2β·Σxy + βᵀ(Σxxᵀ)β, so no evening goes over the
    readings. The 1σ is the scaled readings' information with the priors' as they are (the
    reference's words)."""
    n = prior.shape[0]
    k = n if span >= DRIFT_DAYS else n - 1
    projected = np.zeros(k)
    for j in range(k):
        projected[j] = sums[XY, j] / r
    estimate = np.linalg.inv(_information(moments, prior, r, k)) @ projected
    squares = max(sums[YY, n] - 2.0 * _linear(sums, XY, estimate, k) + _quadratic(moments, XX, estimate, k), 0.0)
    unit_variance = max(1.0, squares / r / max(count - k, 1))
    covariance = np.linalg.inv(_information(moments, prior, r * unit_variance * _correlation_factor(moments, sums,
                                                                                                   estimate, k), k))
    estimates, std = np.zeros(n), np.full(n, np.inf)
    for j in range(k):
        estimates[j] = estimate[j]
        std[j] = math.sqrt(covariance[j, j])
    return estimates, std


@kernel(allocates=True)
def _information(moments, prior, r, k):
    """The clock fit's information over its first `k` parameters: the readings' moments over the
    noise variance `r`, and the priors'."""
    information = np.zeros((k, k))
    for j in range(k):
        for m in range(k):
            information[j, m] = moments[XX, j, m] / r
        information[j, j] += prior[j]
    return information


@kernel
def _correlation_factor(moments, sums, beta, k):
    """clockwatch._correlation_factor from the linked pairs' sums: the lag-one products of the
    residuals, e = y − xβ, expanded about the estimate."""
    n = moments.shape[1]
    if sums[LINKED, n] < 2.0:
        return 1.0
    aa = sums[YP_YP, n] - 2.0 * _linear(sums, PY_P, beta, k) + _quadratic(moments, PP, beta, k)
    bb = sums[YC_YC, n] - 2.0 * _linear(sums, CY_C, beta, k) + _quadratic(moments, CC, beta, k)
    ab = sums[YP_YC, n] - _linear(sums, PY_C, beta, k) - _linear(sums, CY_P, beta, k) \
        + _quadratic(moments, PC, beta, k)
    rho = min(max(ab / max(math.sqrt(max(aa, 0.0) * max(bb, 0.0)), 1e-300), 0.0), 0.95)
    return (1.0 + rho) / (1.0 - rho)


@kernel(allocates=True)
def clock_verdict(cfg, state, log, i):
    """ClockWatch.verdict: each alarm raised once, as an event."""
    k = state.k
    count = k[CLOCK_ROWS]
    n = cfg.clock_prior.shape[0]
    if count < n:
        return
    span = (state.clock_t[count - 1] - state.clock_t[0]) / 1440.0
    estimate, std = clock_solve(state.clock_moments, state.clock_sums, count, span, cfg.clock_prior, cfg.clock_r)
    clock, drift = estimate[n - 2], estimate[n - 1]
    clock_std, drift_std = std[n - 2], std[n - 1]
    seen = cfg.clock_constant_seen  # a heliostat's: not a single axis's (`ClockWatch`)
    if seen and not k[CLOCK_RAISED] and abs(clock) >= max(ALARM_SIGMAS * clock_std, CLOCK_TOLERANCE):
        k[CLOCK_RAISED] = 1
        _alarm3(i, ev.CLOCK_OFF, clock, clock_std, float(count), state, log)
    if not k[DRIFT_RAISED] and span >= DRIFT_DAYS and abs(drift) >= max(ALARM_SIGMAS * drift_std, DRIFT_TOLERANCE):
        k[DRIFT_RAISED] = 1
        _alarm3(i, ev.CLOCK_DRIFTING, drift, drift_std, span, state, log)


# -- one scan -------------------------------------------------------------------------------------

@kernel
def _plausibility_bound(cfg, plan, i, a, axes):
    if axes == 2 and a == 0:
        return cfg.plausibility / max(math.cos(math.radians(plan.model[i, 1])), 0.05)
    return cfg.plausibility


@kernel(inline=True)
def _offer(cfg, plan, state, log, i, a, dt, z, trusted, axes, intensity, scale):
    m0 = plan.model[i, a]
    m1 = plan.model[i - 1, a] if i else math.nan
    bound = _plausibility_bound(cfg, plan, i, a, axes)
    has_model = cfg.uses_model and not math.isnan(m0)
    miss = _turn(cfg, a, z - m0 - _correction(cfg, plan, state, i, a)) if has_model else math.nan
    if has_model and dt > 0 and not math.isnan(m1):
        rate = _turn(cfg, a, m0 - m1) / dt
    else:  # no computed sun: the filter's own rate, once it has one
        rate = state.kf[a, X1] if state.gate[a, READY] else 0.0
    verdict = gate_take(cfg, state, a, z, dt, miss, bound, rate, scale)
    if verdict == IMPLAUSIBLE and not abs(miss) <= abs(state.s[HELD_MISS]):  # the first, or further off
        state.s[HELD_MISS] = miss
    if verdict == OK and trusted and has_model:
        _learn(cfg, plan, state, log, i, a, dt, z, m0, m1, bound, intensity)
    return verdict


@kernel
def _expected_sun(cfg, plan, state, i, a, t):
    if cfg.uses_model:
        return plan.model[i, a] + _correction(cfg, plan, state, i, a)
    return state.kf[a, X1] * t if state.gate[a, READY] else math.nan


@kernel
def _trusts_sensor(cfg, sky, true_sky):
    if cfg.trusts_always:
        return True
    if cfg.oracle:
        return true_sky == SUNNY
    return sky == SUNNY


@kernel(inline=True)
def _sense(cfg, plan, state, out, log, i, t, dt, obs, obs_axes, reading, awake, sky, valid):
    axes = valid.shape[0]
    valid[:] = False
    mode = state.k[MODE]
    if not (cfg.uses_sensor and awake and mode != STOW_WIND and mode != FAULT):
        return NOT_READ
    status = OK
    trusted = cfg.calibrates and _trusts_sensor(cfg, sky, obs[4])
    state.s[HELD_MISS] = math.nan
    predicted = 0  # bit a: axis a's gate judged an outlier, so it has predicted across this scan
    for a in range(axes):
        offset = obs_axes[a, 1]
        verdict = gate_judge(cfg, state, a, offset, obs[2] != 0.0, obs_axes[a, 2],
                             _turn(cfg, a, _expected_sun(cfg, plan, state, i, a, t) - reading[a]))
        if verdict == OK and obs[0] < state.s[DISTRUSTED_UNTIL]:
            verdict = IMPLAUSIBLE
        if verdict == OK:
            offset, measures = axis_offset(obs_axes[:, 1], a, reading)
            if not measures and cfg.uses_model and not math.isnan(plan.model[i, a]):
                verdict = INVALID  # no measure of the azimuth near the zenith: the calibrated model steers
            else:
                verdict = _offer(cfg, plan, state, log, i, a, dt, reading[a] + offset, trusted and measures, axes,
                                 obs[3], reading_scale(obs_axes[:, 1], a, reading))
        valid[a] = verdict == OK
        if verdict == OUTLIER:
            predicted |= 1 << a
        if valid[a]:
            out.sun[i, a] = state.kf[a, X0]
        if verdict != OK and status == OK:
            status = verdict
    for a in range(axes):
        if not (valid[a] or predicted >> a & 1):
            gate_coast(cfg, state, a, dt)
    _held_off(state, log, i, t, valid.all())
    if valid.all():
        state.s[INVALID_SINCE] = math.nan
        if cfg.sensor_only and not state.k[FOUND_TODAY]:
            for a in range(axes):
                state.park[a] = state.kf[a, X0]
            state.k[FOUND_TODAY] = 1
    elif math.isnan(state.s[INVALID_SINCE]):
        state.s[INVALID_SINCE] = t
    return status


@kernel
def _held_off(state, log, i, t, plausible):
    """Controller._held_off."""
    if plausible:
        state.s[HELD_OFF_SINCE] = math.nan
        state.k[HELD_OFF_RAISED] = 0
        return
    if math.isnan(state.s[HELD_MISS]):
        return
    if math.isnan(state.s[HELD_OFF_SINCE]):
        state.s[HELD_OFF_SINCE] = t
    if not state.k[HELD_OFF_RAISED] and t - state.s[HELD_OFF_SINCE] >= HELD_OFF_MINUTES:
        state.k[HELD_OFF_RAISED] = 1
        _alarm(i, ev.HELD_OFF, state.s[HELD_MISS], t - state.s[HELD_OFF_SINCE], state, log)


@kernel
def _choose_mode(cfg, state, log, i, t, status, valid, sky, true_sky):
    mode = state.k[MODE]
    if mode != ASTRONOMICAL and mode != SENSOR and mode != SEARCH:
        return
    sensor_ok = cfg.uses_sensor and valid.all()
    faulty = status == STUCK or status == IMPLAUSIBLE or status == INVALID
    lost_for = t - state.s[INVALID_SINCE]
    if cfg.sensor_only:  # no sun model: a sensor faulty for `sensor_loss` hands over to the cells
        if mode == SEARCH and sensor_ok:
            _switch(i, SENSOR, ev.SUN_BACK, 0.0, t, state, log)
        elif mode == SENSOR and (status == STUCK or status == IMPLAUSIBLE) and lost_for >= cfg.loss:
            _switch(i, SEARCH, ev.SENSOR_LOST, float(status), t, state, log)
        elif mode == SENSOR and status == OUT_OF_VIEW:
            _switch(i, SEARCH, ev.OUT_OF_FINE_VIEW, 0.0, t, state, log)
        return
    want = cfg.uses_sensor and _trusts_sensor(cfg, sky, true_sky)
    since = t - state.s[MODE_SINCE]
    if mode == SENSOR and not sensor_ok and (faulty or lost_for >= cfg.loss):
        _switch(i, ASTRONOMICAL, ev.SENSOR_LOST, float(status), t, state, log)
    elif mode == SENSOR and not want and since >= cfg.dwell:
        _switch(i, ASTRONOMICAL, ev.TRUE_SKY_NOT_SUNNY if cfg.oracle else ev.SKY_NOT_SUNNY, float(sky), t, state, log)
    elif mode == ASTRONOMICAL and want and sensor_ok and since >= cfg.dwell:
        _switch(i, SENSOR, ev.SENSOR_TRUSTED if cfg.trusts_always else ev.SKY_SUNNY, 0.0, t, state, log)


@kernel
def _daylight(cfg, state, t, intensity):
    if intensity >= cfg.dusk_current:
        state.s[DARK_SINCE] = math.nan
        return True
    if math.isnan(state.s[DARK_SINCE]):
        state.s[DARK_SINCE] = t
    return t - state.s[DARK_SINCE] < DUSK_MINUTES


@kernel
def _read_encoders(cfg, state, log, i, t, obs_axes, reading):
    reckoned = state.k[MODE] == FAULT or state.k[BLIND_STOW] != 0
    for a in range(reading.shape[0]):
        value, code, number, other, frozen = encoder_read(cfg, state, a, obs_axes[a, 0], reckoned)
        if frozen and state.k[MODE] != FAULT:
            _switch(i, FAULT, code, number, t, state, log)
            log.value[state.k[EVENTS] - 1, 2] = a  # the axis, for its name
        elif code:
            _alarm3(i, code, number, other, float(a), state, log)
        reading[a] = value


@kernel
def _night_in_gap(cfg, state, log, i, t, minutes):
    """Controller._night_in_gap: the night slept in the gap before scan `i`."""
    mode = state.k[MODE]
    if mode != STOW_WIND and mode != FAULT and mode != STOW_NIGHT:
        _switch(i, STOW_NIGHT, ev.NIGHT_GAP, minutes, t, state, log)
        state.k[FOUND_TODAY] = 0
    if state.k[WAS_AWAKE] and cfg.has_fit:
        clock_verdict(cfg, state, log, i)
    state.gate[:, READY] = 0
    state.k[WAS_AWAKE] = 0


@kernel
def _day_and_wind(cfg, state, log, i, t, awake, gusty, wind, read):
    mode = state.k[MODE]
    resume = SENSOR if cfg.sensor_only else ASTRONOMICAL
    if gusty and mode != STOW_WIND:
        if _unreadable(read):
            code, wind = ev.WIND_UNREADABLE, read
        else:
            code = ev.WIND_MISSING if math.isnan(wind) else ev.WIND_HIGH
        if mode == FAULT:
            for a in range(state.blind_stow.shape[0]):
                state.blind_stow[a] = cfg.stow[a] - state.encoder[a, BELIEVED]
            state.k[BLIND_STOW] = 1
            code += ev.BLIND
        _switch(i, STOW_WIND, code, wind, t, state, log)
    elif mode == STOW_WIND and not gusty and wind_released(cfg, state, t):
        if state.k[BLIND_STOW]:
            state.k[BLIND_STOW] = 0
            _switch(i, FAULT, ev.WIND_RELEASED_FROZEN, 0.0, t, state, log)
        else:
            _switch(i, resume, ev.WIND_RELEASED, 0.0, t, state, log)
    mode = state.k[MODE]
    if mode == FAULT:
        if awake and not state.k[WAS_AWAKE]:
            _switch(i, resume, ev.NEW_DAY_PROBE, 0.0, t, state, log)
    elif mode != STOW_WIND:
        if not awake and mode != STOW_NIGHT:
            _switch(i, STOW_NIGHT, ev.NIGHT, 0.0, t, state, log)
            state.k[FOUND_TODAY] = 0
        elif awake and mode == STOW_NIGHT:
            _switch(i, resume, ev.WAKE, 0.0, t, state, log)


@kernel
def _watch_sky(cfg, plan, state, out, i, t, intensity):
    out.intensity[i] = intensity
    if not cfg.classifying:
        return UNKNOWN
    code, score, variation = sky_update(cfg, state, t, intensity, plan.clear_light[i], plan.altitude[i])
    out.sky[i] = code
    out.score[i] = score
    out.variation[i] = variation
    return code


@kernel
def _strayed(cfg, plan, state, i, a, angle):
    """Controller._strayed."""
    m = plan.model[i, a]
    if not cfg.uses_model or math.isnan(m):
        return False
    bound = _plausibility_bound(cfg, plan, i, a, state.kf.shape[0])
    return abs(_turn(cfg, a, angle - m - _correction(cfg, plan, state, i, a))) > bound


@kernel
def _target(cfg, plan, state, i, a, t, dt, reading, valid, rough):
    mode = state.k[MODE]
    deadband = cfg.deadband[a]
    if mode == STOW_WIND:
        return cfg.stow[a]
    if mode == STOW_NIGHT:
        return _night_target(cfg, state, a)
    if mode == SENSOR:
        coasting = not valid and t - state.s[INVALID_SINCE] <= cfg.coast_for
        if not (state.gate[a, READY] and (valid or not cfg.sensor_only or coasting)):
            return reading
        if valid or not _strayed(cfg, plan, state, i, a, state.kf[a, X0]):
            return state.kf[a, X0] + (_lead(state.kf[a, X1], dt, deadband) if cfg.lead else 0.0)
    if mode == SEARCH:
        return reading if math.isnan(rough) else reading + rough
    m = plan.model[i, a]
    if math.isnan(m):
        return cfg.stow[a]
    target = m + _correction(cfg, plan, state, i, a)
    previous = plan.model[i - 1, a] if i else math.nan
    if cfg.lead and not math.isnan(previous) and dt > 0:
        target += _lead(_turn(cfg, a, m - previous) / dt, dt, deadband)
    if cfg.circular[a]:
        target = reading + _turn(cfg, a, target - reading)
        if not cfg.low[a] <= target <= cfg.high[a]:
            target += 360.0 if target < cfg.low[a] else -360.0
    return target


@kernel
def _command(cfg, plan, state, awake_plan, i, t, dt, reading, valid, obs_axes, targets, moves):
    mode = state.k[MODE]
    stowing = mode == STOW_NIGHT or mode == STOW_WIND
    state.k[RESTING] = mode == STOW_NIGHT and not awake_plan
    for a in range(reading.shape[0]):
        state.encoder[a, COMMANDED] = 0.0
        if mode == FAULT:
            targets[a] = reading[a]
            moves[a] = 0.0
            continue
        if state.k[BLIND_STOW]:
            left = state.blind_stow[a]
            limit = cfg.stow_speed[a] * dt
            step = max(-limit, min(limit, left))
            state.blind_stow[a] = left - step
            state.encoder[a, COMMANDED] = step
            state.travel[a] += abs(step)
            state.moves[a] += 1 if step else 0
            targets[a] = cfg.stow[a]
            moves[a] = step
            continue
        low, high = cfg.low[a], cfg.high[a]
        rough = axis_offset(obs_axes[:, 2], a, reading)[0]
        target = min(max(_target(cfg, plan, state, i, a, t, dt, reading[a], valid[a], rough), low), high)
        error = target - reading[a]
        held = mode == STOW_WIND and abs(reading[a] - cfg.stow[a]) <= cfg.deadband[a]
        threshold = cfg.resolution[a] if stowing or mode == SEARCH else cfg.deadband[a]
        step = 0.0
        if not held and abs(error) > threshold:
            speed = cfg.stow_speed[a] if stowing else cfg.speed[a]
            step = max(-speed * dt, min(speed * dt, error))
            state.encoder[a, COMMANDED] = step
            state.moves[a] += 1
            state.travel[a] += abs(step)
            state.k[RESTING] = 0
        targets[a] = target
        moves[a] = step


@kernel(inline=True)
def controller_step(cfg, plan, state, out, log, i, obs, obs_axes, moves, reading, targets, valid):
    """Controller.step: take scan `i`'s readings (`obs`: t, wind, valid, intensity, true sky;
    `obs_axes`: encoder, offset, coarse per axis); write the move of each axis into `moves`
    (`reading`, `targets` and `valid` are scratch)."""
    axes = moves.shape[0]
    s, k = state.s, state.k
    t = obs[0]
    dt = t - s[PREVIOUS_T] if not math.isnan(s[PREVIOUS_T]) else 1.0
    s[PREVIOUS_T] = t
    awake = plan.awake[i] and (not cfg.sensor_only or _daylight(cfg, state, t, obs[3]))
    if plan.alarm[i]:
        _alarm(i, ev.PLAN_ALARM, 0.0, 0.0, state, log)
    if plan.clock_steps[i]:
        _alarm(i, ev.CLOCK_STEPPED, plan.clock_steps[i], 0.0, state, log)
    _read_encoders(cfg, state, log, i, t, obs_axes, reading)
    code, value = wind_watch(state, t, obs[1], awake)
    if code:
        _alarm(i, code, value, 0.0, state, log)
    wind = wind_heard(state, obs[1])
    gusty = wind_update(cfg, state, t, wind)
    if k[RESTING] and not awake and not gusty:
        k[WAS_AWAKE] = 0
        out.sky[i] = UNKNOWN
        for a in range(axes):
            targets[a] = _night_target(cfg, state, a)
        _record(cfg, plan, state, out, i, NOT_READ, targets, reading)
        moves[:] = 0.0
        return
    if plan.slept[i]:
        _night_in_gap(cfg, state, log, i, t, dt)
    _day_and_wind(cfg, state, log, i, t, awake, gusty, wind, obs[1])
    if k[WAS_AWAKE] and not awake and cfg.has_fit:  # the day's end: judge the clock
        clock_verdict(cfg, state, log, i)
    if awake and not k[WAS_AWAKE]:  # a new day: the residual offsets were the evening sky's
        _start_day(state)
    k[WAS_AWAKE] = awake
    sky = _watch_sky(cfg, plan, state, out, i, t, obs[3])
    status = _sense(cfg, plan, state, out, log, i, t, dt, obs, obs_axes, reading, awake, sky, valid)
    _choose_mode(cfg, state, log, i, t, status, valid, sky, obs[4])
    _command(cfg, plan, state, plan.awake[i], i, t, dt, reading, valid, obs_axes, targets, moves)
    _record(cfg, plan, state, out, i, status, targets, reading)
    if k[MODE] == STOW_NIGHT:
        state.gate[:, READY] = 0


@kernel
def sleeps_until(plan, i):
    """Controller.sleeps_until."""
    j = i
    while j < plan.awake.shape[0] and not plan.awake[j]:
        j += 1
    return j


@kernel
def controller_rest(cfg, plan, state, out, i, j, last_t):
    """Controller.rest: scans `i` to `j` - 1 asleep at stow, recorded in bulk."""
    state.s[PREVIOUS_T] = last_t
    for scan in range(i, j):
        out.mode[scan] = STOW_NIGHT
        out.status[scan] = NOT_READ
        out.sky[scan] = UNKNOWN
        for a in range(state.encoder.shape[0]):
            out.target[scan, a] = _night_target(cfg, state, a)
            out.reading[scan, a] = state.encoder[a, BELIEVED]
            out.calibration[scan, a] = _correction(cfg, plan, state, scan, a)
            out.sun[scan, a] = math.nan
        for m in range(out.fit_value.shape[1]):
            out.fit_value[scan, m] = state.theta[m]
            out.fit_std[scan, m] = math.sqrt(max(state.p[m, m], 0.0))

