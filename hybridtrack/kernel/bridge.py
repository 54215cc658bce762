"""From the Python objects to the kernels' arrays and back.

`pack_world` and `pack_controller` read a freshly built `World` and `Controller` (so every
initial value, a warm start's memory included, comes from the reference's own constructors);
`run_compiled` steps them through `run_scans` and writes back what the rest of `simulate` reads:
the world's angles, the controller's outputs, events, mount fit and calibration offsets.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from ..control.controller import CLASSIFYING, FIT_EVERY, Controller, ControllerOutputs
from ..control.modes import MODES
from ..world import World
from . import controller as kc
from .events import wording
from .loop import EVENTS_PER_SCAN, run_scans
from .world import WorldArrays, WorldState

__all__ = ["run_compiled"]

log = logging.getLogger("hybridtrack.control")

#: Scans per call of the kernel: progress is reported between calls.
CHUNK = 65536


def pack_world(world: World) -> tuple[WorldArrays, WorldState]:
    """The world's frame-wide arrays and its moving state."""
    n, axes = world.n, world.axes
    beam, aureole, patch, patch_offset, diffuse = world.scene
    faults = world.faults
    sensor = world.sensor

    def per_axis(name, default):
        values = faults.get(name)
        return np.full((axes, n), default) if values is None else np.ascontiguousarray(np.asarray(values, float).T)

    def per_scan(name, default, dtype=float):
        values = faults.get(name)
        return np.full(n, default, dtype) if values is None else np.asarray(values, dtype)

    recorded = world.recorded_current
    pointing = world.recorded_pointing
    arrays = WorldArrays(
        world.truth_axes, beam, aureole, patch, patch_offset, diffuse, world.noise, world.current_noise,
        world.coarse_noise, recorded if recorded is not None else np.zeros(n), recorded is not None,
        world.wind, world.minutes, np.asarray(world.true_sky if world.true_sky is not None else np.full(n, -1), float),
        per_axis("sensor", math.nan), per_scan("sensor_drift", 0.0), per_scan("sensor_dropout", False, bool),
        per_axis("encoder", 0.0), per_scan("encoder_frozen", False, bool),
        float(sensor.bias), float(sensor.field_of_view), float(sensor.direct_threshold), float(sensor.noise),
        float(sensor.coarse_field_of_view), float(sensor.coarse_accuracy), float(sensor.dark_current),
        float(sensor.responsivity), float(sensor.diffuse_share), float(sensor.current_noise),
        float(world.imperfections.encoder_offset), np.array([d.resolution for d in world.drives]),
        np.array([d.limits[0] for d in world.drives]), np.array([d.limits[1] for d in world.drives]),
        np.array(world.circular, bool), pointing if pointing is not None else np.zeros((axes, 0)), pointing is not None)
    arrays = WorldArrays(*(_read_only(v) if isinstance(v, np.ndarray) else v for v in arrays))
    state = WorldState(np.array(world.actual, float), np.array(world.last_encoder, float), world.angles)
    return arrays, state


def _read_only(values, dtype=None) -> np.ndarray:
    """`values` as a C-contiguous array marked read-only, as the kernel takes every array it only
    reads. numba compiles (and caches) the kernel once for each layout and each read-only flag of
    its arrays: a frame's column can be a strided view, and is read-only under pandas' copy on
    write while an array computed here is not, so a run with a recorded photocurrent, or a sensor
    strategy on a heliostat, had compiled the kernel again (one to three minutes each)."""
    array = np.ascontiguousarray(values, dtype).view()
    array.flags.writeable = False
    return array


def _settings(controller: Controller) -> kc.ControllerSettings:
    config, drives, sky, gate, fit = controller.config, controller.drives, controller.sky, controller.gates[0], \
        controller.fit
    clock = controller.clock
    table, inputs = sky.table, sky.inputs
    calibrator = controller.calibrators[0]
    return kc.ControllerSettings(
        config.uses_sensor, config.uses_model, config.calibrates, config.sensor_only, config.strategy in CLASSIFYING,
        config.strategy in ("hybrid-always", "sensor"), config.strategy == "hybrid-oracle", bool(config.lead),
        controller.dwell, controller.loss, controller.coast_for, float(config.dusk_current),
        float(config.sensor_plausibility), float(config.disagreement), config.on_disagreement == "sensor",
        float(config.minutes("distrust")),
        float(controller.wind.stow_above), float(controller.wind.release_at), float(controller.wind.hold),
        controller.wind.stow_when_missing, int(config.encoder_confirm),
        float(gate.filter.q), np.array([g.filter.r for g in controller.gates], float), int(gate.angles.maxlen),
        float(gate.stuck_spread), float(gate.gate2), int(gate.reacquire), float(calibrator.tau),
        float(calibrator.max_rate),
        fit is not None, float(fit.r) if fit else 1.0, float(fit.prior) if fit else 1.0,
        float(fit.memory) if fit else 1.0, float(fit.clip) if fit else 1.0, int(fit.check_every) if fit else 1,
        float(config.pull_gain), float(controller.responsivity or 0.0), float(controller.sun_threshold),
        float(clock.r) if clock else 1.0,
        np.array(np.diag(clock.prior_information) if clock else [], float), bool(clock and clock.constant_seen),
        inputs.mode == "relative", float(sky.mean.window) if sky.mean is not None else 0.0, float(sky.window_minutes),
        float(inputs.min_altitude), inputs.low_sun == "absolute", float(inputs.relative_floor),
        float(inputs.full_variation), float(sky.dark),
        np.array(table.scores, float), float(table.step), int(table.last),
        np.array([v for pair in table.ranges for v in pair], float), np.array(table.edges, float),
        np.array(table.codes, np.int64),
        *(np.array([getattr(d, name) for d in drives], float) for name in ("deadband", "speed", "stow_speed")),
        np.array([d.limits[0] for d in drives], float), np.array([d.limits[1] for d in drives], float),
        np.array([d.stow for d in drives], float), np.array([d.resolution for d in drives], float),
        np.array(controller.circular, bool))


def _plan(controller: Controller) -> kc.ControllerPlanArrays:
    plan, axes = controller.plan, controller.axes
    n = len(plan.awake)
    alarm = np.zeros(n, bool)
    alarm[list(controller.plan_alarms)] = True
    jacobian = plan.jacobian if plan.jacobian is not None else np.zeros((n, axes, 0))
    weight = plan.weight if plan.weight is not None else np.zeros((n, axes))

    def scans(values):
        return np.full(n, np.nan) if values is None else values

    return kc.ControllerPlanArrays(
        _read_only(plan.model, float), _read_only(plan.awake, bool), _read_only(plan.slept, bool),
        _read_only(plan.clock_steps, float),
        _read_only(alarm), _read_only(scans(plan.clear_light), float), _read_only(scans(plan.apparent_altitude), float),
        _read_only(jacobian, float), _read_only(weight, float))


def _window_capacity(minutes: np.ndarray, windows: list[float]) -> int:
    """The most scans any trailing window can hold, with room for the one being added, rounded up
    to a power of two (the queues mask their counts by it)."""
    need = max(kc.most_in_window(minutes, float(width)) for width in windows) + 2
    return 1 << (need - 1).bit_length()


def _clock_capacity(controller: Controller, minutes: np.ndarray) -> int:
    """The most readings the clock watch can take: one per axis every `FIT_EVERY` minutes."""
    if controller.clock is None or len(minutes) == 0:
        return 0
    carried = len(controller.clock.rows) + len(controller.clock.pending)  # from an earlier run (`carry`)
    return carried + controller.axes * (int((minutes[-1] - minutes[0]) / FIT_EVERY) + 2)


def _state(controller: Controller, minutes: np.ndarray) -> kc.ControllerState:
    c, axes = controller, controller.axes
    s = np.zeros(kc.FLOAT_SLOTS)
    s[[kc.MODE_SINCE, kc.INVALID_SINCE, kc.PREVIOUS_T, kc.DARK_SINCE, kc.DISTRUSTED_UNTIL, kc.FIT_SINCE]] = \
        [c.mode_since, c.invalid_since, c.previous_t, c.dark_since, c.distrusted_until, c.fit_since]
    s[[kc.CALM_SINCE, kc.FLAT_VALUE, kc.FLAT_SINCE]] = [c.wind.calm_since, c.wind.flat_value, c.wind.flat_since]
    s[kc.CONDITION] = c.fit.condition if c.fit else math.inf
    s[kc.LIGHT_LEVEL] = c.fit.level if c.fit else math.nan
    s[[kc.HELD_OFF_SINCE, kc.HELD_MISS]] = [c.held_off_since, c.held_miss]
    clock = c.clock
    s[[kc.SPELL_START, kc.SPELL_LAST]] = [clock.spell_start, clock.spell_last] if clock else [math.nan, math.nan]
    k = np.zeros(kc.INT_SLOTS, np.int64)
    k[[kc.MODE, kc.RESTING, kc.WAS_AWAKE, kc.FOUND_TODAY, kc.WIND_STUCK]] = \
        [c.mode, c.resting, c.was_awake, c.found_today, c.wind.stuck]
    k[kc.BLIND_STOW] = c.blind_stow is not None
    k[kc.HELD_OFF_RAISED] = c.held_off_raised
    k[[kc.MOUNT_AT_SCAN, kc.MOUNT_AT_UPDATES]] = -1
    fit = c.fit
    p = fit.n if fit else 0
    if fit:
        k[[kc.UPDATES, kc.FROZEN]] = [fit.updates, fit.axis_frozen]
    windows = [c.sky.window_minutes] + ([c.sky.mean.window] if c.sky.mean is not None else [])
    capacity = _window_capacity(minutes, windows)
    readings = _clock_capacity(c, minutes)
    columns = c.clock.n - 1 if c.clock else 0
    parameters = columns + 1 if c.clock else 0  # with the drift's column
    clock_arrays = (np.zeros(readings), np.zeros(readings, np.int64), np.zeros((readings, columns)),
                    np.zeros(readings), np.zeros((4, parameters, parameters)), np.zeros((5, parameters + 1)),
                    np.full(axes, -1, np.int64))
    if c.clock is not None and (c.clock.rows or c.clock.pending or c.clock.raised):  # carried from an earlier run
        for m, (t, a, x, y) in enumerate(c.clock.rows + c.clock.pending):
            clock_arrays[0][m], clock_arrays[1][m], clock_arrays[2][m], clock_arrays[3][m] = t, a, x, y
        k[[kc.CLOCK_ROWS, kc.CLOCK_PENDING]] = [len(c.clock.rows), len(c.clock.pending)]
        k[[kc.CLOCK_RAISED, kc.DRIFT_RAISED]] = ["clock" in c.clock.raised, "drift" in c.clock.raised]
    return kc.ControllerState(
        s, k, np.array([[m.believed, m.last, m.commanded] for m in c.encoders], float),
        np.array([m.jumped for m in c.encoders], np.int64),
        np.array([[g.filter.x0, g.filter.x1, g.filter.p00, g.filter.p01, g.filter.p11] for g in c.gates], float),
        np.array([[g.ready, g.rejected] for g in c.gates], np.int64),
        np.zeros((axes, c.gates[0].angles.maxlen)), np.zeros((axes, c.gates[0].angles.maxlen)),
        np.zeros(axes, np.int64), np.array([[cal.offset, cal.learned] for cal in c.calibrators], float),
        np.array(c.fitted_at, float), np.zeros(axes), np.array(c.park, float), np.array(c.moves, np.int64),
        np.array(c.travel, float), np.zeros(axes),
        np.array(fit.theta if fit else [], float), np.array(fit.p if fit else np.zeros((0, 0)), float),
        np.array(fit.information if fit else np.zeros((0, 0)), float),
        np.zeros(axes), np.zeros(p), np.zeros((p, p)), np.zeros((p, p)),
        np.array(fit.evidence if fit else [], float), np.zeros(p),
        np.zeros((5, capacity)), np.zeros((5, capacity)), np.zeros((5, 2), np.int64), *clock_arrays)


def _record(n: int, axes: int, parameters: int) -> kc.ControllerRecord:
    return kc.ControllerRecord(
        np.zeros(n, np.int8), np.zeros(n, np.int8), np.zeros(n, np.int8), np.full(n, np.nan), np.full(n, np.nan),
        np.full(n, np.nan), *(np.full((n, axes), np.nan) for _ in range(4)),
        np.full((n, parameters), np.nan), np.full((n, parameters), np.nan))


def _events(capacity: int) -> kc.EventLog:
    return kc.EventLog(np.zeros(capacity, np.int64), np.zeros(capacity, np.int64), np.zeros(capacity, np.int64),
                       np.zeros(capacity, np.int64), np.zeros((capacity, 3)))


def _grown(events: kc.EventLog) -> kc.EventLog:
    bigger = _events(2 * len(events.scan))
    for old, new in zip(events, bigger):
        new[:len(old)] = old
    return bigger


def _worded(controller: Controller, events: kc.EventLog, count: int) -> list:
    worded, reason = [], wording(controller.config, controller.plan_alarms, controller.axes)
    # asked once, not at each of a row-year's 3,700 events (7 ms of calls to a disabled logger)
    alarms, switches = log.isEnabledFor(logging.INFO), log.isEnabledFor(logging.DEBUG)
    for i, before, after, code, (value, other, third) in zip(events.scan[:count].tolist(), events.before[:count].tolist(),
                                                     events.after[:count].tolist(), events.code[:count].tolist(),
                                                     events.value[:count].tolist()):
        text = reason(code, value, other, i, third)
        if before == after and alarms:
            log.info("scan %d: %s", i, text)
        elif before != after and switches:
            log.debug("scan %d: %s -> %s (%s)", i, MODES[before], MODES[after], text)
        worded.append((i, MODES[before], MODES[after], text))
    return worded


def _write_back(controller: Controller, state: kc.ControllerState) -> None:
    """What `Controller.memory`, `Controller.carry` and `Controller.fitted_mount` read after the run."""
    controller.wind.stuck, controller.wind.flat_value = bool(state.k[kc.WIND_STUCK]), float(state.s[kc.FLAT_VALUE])
    for calibrator, (offset, learned) in zip(controller.calibrators, state.calibration.tolist()):
        calibrator.offset, calibrator.learned = offset, learned
    fit = controller.fit
    if fit is not None:
        fit.theta, fit.p, fit.information = state.theta.copy(), state.p.copy(), state.information.copy()
        fit.evidence = state.evidence.copy()
        fit.updates, fit.axis_frozen = int(state.k[kc.UPDATES]), bool(state.k[kc.FROZEN])
        fit.condition = float(state.s[kc.CONDITION])
        fit.level = float(state.s[kc.LIGHT_LEVEL])
        controller.theta = fit.theta.copy()
    clock = controller.clock
    if clock is not None:
        counted, pending = int(state.k[kc.CLOCK_ROWS]), int(state.k[kc.CLOCK_PENDING])
        kept = counted + pending  # each row's x a view of one copy: a copy a row took 2 µs, 9,000 a Fresnel year
        rows = list(zip(state.clock_t[:kept].tolist(), state.clock_axis[:kept].tolist(),
                        list(state.clock_x[:kept].copy()), state.clock_y[:kept].tolist()))
        clock.rows, clock.pending = rows[:counted], rows[counted:]
        clock.spell_start, clock.spell_last = float(state.s[kc.SPELL_START]), float(state.s[kc.SPELL_LAST])
        clock.raised = {name for name, slot in (("clock", kc.CLOCK_RAISED), ("drift", kc.DRIFT_RAISED))
                        if state.k[slot]}


def run_compiled(world: World, controller: Controller, progress, bulk_nights: bool, stop=None,
                 fit_columns: bool = True) -> ControllerOutputs:
    """Run the scans through the compiled kernels; return the controller's outputs, with the
    world's angles and the controller's memory written back into `world` and `controller`.
    A `stop` event (`threading.Event`) that is set ends the run at its next chunk of scans, its
    outputs cut short: for a caller that is giving up (Ctrl-C while the loop runs on a thread).
    Without `fit_columns` the outputs hold no mount fit at each scan (``fit_value`` and
    ``fit_std`` have no columns): a run scored without its log (a field's collector that keeps
    none) need not fill two numbers a scan for each mount parameter: 25 MB over a Fresnel row's
    year, 42 MB over a heliostat's."""
    n, axes = world.n, world.axes
    arrays, world_state = pack_world(world)
    cfg, plan = _settings(controller), _plan(controller)
    state = _state(controller, arrays.minutes)
    out = _record(n, axes, len(state.theta) if fit_columns else 0)
    events = _events(1024 + EVENTS_PER_SCAN)
    wind_ok = np.concatenate([[0], np.cumsum(controller.wind.gusts(world.wind))])
    obs, obs_axes, moves = np.zeros(5), np.zeros((axes, 3)), np.zeros(axes)
    i = 0
    while i < n and not (stop is not None and stop.is_set()):
        end = min(i + CHUNK, n)
        done = run_scans(i, end, bulk_nights, wind_ok, arrays, world_state, cfg, plan, state, out, events,
                         obs, obs_axes, moves)
        if progress is not None and done > i:
            progress(done - i)
        if done < end:
            events = _grown(events)
        i = done
    controller.events = _worded(controller, events, int(state.k[kc.EVENTS]))
    controller.moves, controller.travel = state.moves.tolist(), state.travel.tolist()
    _write_back(controller, state)
    return ControllerOutputs(out.mode, out.status, out.sky, out.score, out.intensity, out.variation, out.target,
                             out.reading, out.calibration, out.sun, out.fit_value, out.fit_std,
                             np.array(controller.moves), np.array(controller.travel), controller.events)
