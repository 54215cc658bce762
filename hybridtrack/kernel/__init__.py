"""The compiled controller kernel (numba): the same controller and world step as the readable
reference (`hybridtrack.control`, `hybridtrack.world`), run over the scans in compiled code.

`SimulationConfig.engine` chooses: ``auto`` (the default) runs the kernel wherever it supports
the run and numba imports, ``compiled`` insists on it, ``reference`` runs the Python loop.
See ``docs/kernel.md`` for what it covers, how parity with the reference is tested, and its speed.
"""

from __future__ import annotations

from ..errors import HybridtrackError
from .jit import available

__all__ = ["ENGINES", "available", "unsupported", "uses_kernel", "run_compiled"]

#: The choices of `SimulationConfig.engine`.
ENGINES = ("auto", "compiled", "reference")


def unsupported(config) -> str | None:
    """Why the kernel cannot run `config` (a `SimulationConfig`), or None when it can."""
    if config.controller.kalman != "fast":
        return f"the kernel runs the 'fast' Kalman filter, not {config.controller.kalman!r}"
    return None


def uses_kernel(config) -> bool:
    """Whether a run of `config` goes through the kernel; ``compiled`` refuses what it cannot run."""
    if config.engine == "reference":
        return False
    why = unsupported(config)
    if config.engine == "compiled":
        if why:
            raise HybridtrackError(f"engine 'compiled': {why}; use engine 'auto' or 'reference'")
        if not available():
            raise HybridtrackError("engine 'compiled' needs numba, which is not installed (pip install numba)")
        return True
    return why is None and available()


def run_compiled(world, controller, progress, bulk_nights):
    """Run the scans through the kernel (`hybridtrack.kernel.bridge.run_compiled`)."""
    from .bridge import run_compiled as run

    return run(world, controller, progress, bulk_nights)
