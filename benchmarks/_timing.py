"""Shared helpers for the benchmark scripts: medians of repeated runs, a process's peak memory,
a plain table."""

from __future__ import annotations

import resource
import statistics
import time
from collections.abc import Callable, Sequence


def median_seconds(function: Callable[[], object], repeats: int = 5) -> float:
    """Median wall time of `repeats` calls (after one warm-up call)."""
    function()
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


def peak_rss_bytes() -> int:
    """This process's peak resident memory in bytes: Linux's ``VmHWM``, or ``ru_maxrss`` where
    there is no ``/proc``. A child started by ``subprocess`` inherits its parent's ``ru_maxrss``
    through the exec (a child of a 2 GiB parent reports 2 GiB before it allocates anything), so
    ``ru_maxrss`` would measure the parent; ``VmHWM`` belongs to the child's own address space."""
    try:
        with open("/proc/self/status") as status:
            return next(int(line.split()[1]) * 1024 for line in status if line.startswith("VmHWM:"))
    except (OSError, StopIteration):
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KiB on Linux


def print_table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> None:
    """Print rows under a header as an aligned plain-text table."""
    cells = [[str(c) for c in header]] + [[str(c) for c in row] for row in rows]
    widths = [max(len(row[i]) for row in cells) for i in range(len(header))]
    for n, row in enumerate(cells):
        print("  ".join(cell.rjust(w) if i else cell.ljust(w) for i, (cell, w) in enumerate(zip(row, widths))))
        if n == 0:
            print("  ".join("-" * w for w in widths))
