"""How big a run may be: its step count and memory, estimated before any array is made.

A span cut into steps becomes arrays of one value per step in every stage of a run (the weather
frame, the sun, the controller's log). The figure used for all of them is the peak memory one
step of ``simulate`` takes, measured with `tracemalloc` as the slope between a 2-day and an
8-day run at a 30 s step: about 1,350 bytes per step for a trough, about 1,800 for a heliostat
(two axes). `BYTES_PER_STEP` rounds the larger up.

A run may use half the memory the operating system reports available, and never more than
`MAX_BUDGET` (16 GiB), so the same request is refused the same way on every machine with at
least 32 GiB free. A request beyond that is refused with one line naming a coarser step or a
shorter span that fits, and, for a run of a day or more whose single day fits, the streamed run
(`hybridtrack.streaming`), which holds one day at a time and is checked a day at a time.
"""

from __future__ import annotations

import os

import pandas as pd

from .errors import HybridtrackError

__all__ = ["BYTES_PER_STEP", "MAX_BUDGET", "available_memory", "memory_budget", "check_steps", "readable_size"]

#: Peak bytes one step of a run takes (measured; see the module's notes).
BYTES_PER_STEP = 2_000
#: The share of the available memory a run may use.
BUDGET_SHARE = 0.5
#: The most a run may use on any machine, bytes.
MAX_BUDGET = 16 * 2**30
#: Steps offered as coarser alternatives, shortest first.
_STEPS = ("1s", "2s", "5s", "10s", "15s", "30s", "1min", "2min", "5min", "10min", "15min", "30min", "1h")


def available_memory() -> int:
    """Bytes of memory the operating system reports available (``MemAvailable`` on Linux)."""
    try:
        with open("/proc/meminfo") as info:
            for line in info:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - neither Linux nor POSIX
        return MAX_BUDGET


def memory_budget() -> int:
    """Bytes a run may use: `BUDGET_SHARE` of `available_memory`, at most `MAX_BUDGET`."""
    return int(min(BUDGET_SHARE * available_memory(), MAX_BUDGET))


def readable_size(size: float) -> str:
    """Bytes as a person reads them: GB from 100 MB, MB from 1 MB, kB below."""
    if size >= 1e8:
        return f"{size / 1e9:,.1f} GB"
    return f"{size / 1e6:,.0f} MB" if size >= 1e6 else f"{size / 1e3:,.0f} kB"


def check_steps(first, last, step, *, bytes_per_step: int = BYTES_PER_STEP, what: str = "the run") -> int:
    """The number of steps from `first` to `last` at `step`, refused if they would not fit in memory.

    Parameters
    ----------
    first, last : pandas.Timestamp
        The first and last instant of the span.
    step : pandas.Timedelta or str
    bytes_per_step : int
        Peak bytes a step takes; more than `BYTES_PER_STEP` where more is kept per step (a
        field's log of every collector).
    what : str
        What is being sized, for the message.

    Returns
    -------
    int
        The step count.

    Raises
    ------
    HybridtrackError
        When the steps would need more than `memory_budget`: the message names the smallest
        step of `_STEPS` and the longest span at this step that fit.
    """
    step = pd.Timedelta(step)
    steps = int((pd.Timestamp(last) - pd.Timestamp(first)) // step) + 1
    per_step = int(bytes_per_step)
    budget = memory_budget()
    if steps * per_step <= budget:
        return steps
    from .io.checks import span as duration

    span = pd.Timestamp(last) - pd.Timestamp(first)
    fitting = [s for s in _STEPS if (span // pd.Timedelta(s) + 1) * per_step <= budget and pd.Timedelta(s) > step]
    coarser = f"a step of {fitting[0]}" if fitting else "a coarser step"
    longest = (budget // per_step - 1) * step
    if longest >= pd.Timedelta(days=1):
        at_most = f"at most {longest / pd.Timedelta(days=1):,.1f} days"
    else:
        at_most = f"at most {duration(longest.floor('s'))}" if longest >= pd.Timedelta(seconds=1) else "under a second"
    streamed = ""
    day_fits = (pd.Timedelta(days=1) // step + 1) * per_step <= budget
    if per_step == BYTES_PER_STEP and span >= pd.Timedelta(days=1) and day_fits:
        streamed = ("; or stream it to disk a day at a time, in bounded memory (hybridtrack simulate --stream, "
                    "hybridtrack.streaming.stream)")
    raise HybridtrackError(f"{what}: {steps:,} steps of {duration(step)} would need about "
                           f"{readable_size(steps * per_step)} of memory, over the {readable_size(budget)} a run may use; "
                           f"use {coarser} or a span of {at_most} at this step{streamed}")
