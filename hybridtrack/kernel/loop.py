"""The scan loop compiled: `hybridtrack.simulation._run` over the world and controller kernels.

`run_scans` steps scans ``start`` to ``stop`` as the reference loop does (a night asleep at stow
in one go where nothing can happen), and returns early when the event log is nearly full, so
that the caller can grow it and report progress between calls.
"""

from __future__ import annotations

import numpy as np

from .controller import (CLOCK_ROWS, EVENTS, RESTING, WIND_STUCK, clock_recount, controller_rest, controller_step,
                         sleeps_until)
from .jit import kernel
from .world import world_move, world_observe, world_rest

__all__ = ["run_scans", "EVENTS_PER_SCAN"]

#: More events than one scan can raise (alarms, switches and notes of both axes).
EVENTS_PER_SCAN = 32


@kernel(entry=True)
def run_scans(start, stop, bulk_nights, wind_ok, world, world_state, cfg, plan, state, out, log, obs, obs_axes,
              moves):
    """Step world and controller from scan `start` until `stop` (or a nearly full event log);
    return the next scan. A run's first call first sums the clock watch's readings carried from
    an earlier run (`clock_recount`)."""
    if start == 0:
        clock_recount(state.clock_t, state.clock_axis, state.clock_x, state.clock_y, state.clock_moments,
                      state.clock_sums, state.clock_last, state.k[CLOCK_ROWS])
    axes = moves.shape[0]
    offsets, reported = np.empty(axes), np.empty(axes)  # the world's scratch
    reading, targets, valid = np.empty(axes), np.empty(axes), np.zeros(axes, np.bool_)  # the controller's
    return _scans(start, stop, bulk_nights, wind_ok, world, world_state, cfg, plan, state, out, log, obs, obs_axes,
                  moves, offsets, reported, reading, targets, valid)


@kernel
def _scans(start, stop, bulk_nights, wind_ok, world, world_state, cfg, plan, state, out, log, obs, obs_axes, moves,
           offsets, reported, reading, targets, valid):
    """`run_scans`' loop, compiled without reference counting (`jit.kernel`): called from a loop
    that counts references, each piece would count one for every array of the tuples it is handed,
    in and out, at every scan (`docs/kernel.md`, "The loop without reference counting")."""
    capacity = log.scan.shape[0]
    i = start
    while i < stop:
        if state.k[EVENTS] + EVENTS_PER_SCAN > capacity:
            return i
        if bulk_nights and state.k[RESTING] and not state.k[WIND_STUCK] and not plan.awake[i]:
            j = sleeps_until(plan, i)
            if j > i + 1 and wind_ok[j] == wind_ok[i]:
                controller_rest(cfg, plan, state, out, i, j, world.minutes[j - 1])
                world_rest(world_state, i, j)
                i = j
                continue
        world_observe(world, world_state, i, obs, obs_axes, offsets, reported)
        controller_step(cfg, plan, state, out, log, i, obs, obs_axes, moves, reading, targets, valid)
        world_move(world, world_state, i, moves)
        i += 1
    return i
