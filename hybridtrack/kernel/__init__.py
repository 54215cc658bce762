"""The compiled controller kernel (numba): the same controller and world step as the readable
reference (`hybridtrack.control`, `hybridtrack.world`), run over the scans in compiled code.

`SimulationConfig.engine` chooses: ``auto`` (the default) runs the kernel where it supports the
run, numba imports and the kernel is quicker than the reference loop: compiled in this process
already, or the run long enough to pay for loading it from the disk cache (`LOAD_PAYS_AT` scans)
or for compiling it (`COMPILE_PAYS_AT`); ``compiled`` insists on it, ``reference`` runs the
Python loop. The two give the same results, so ``auto`` only chooses
the faster way.
See ``docs/kernel.md`` for what it covers, how parity with the reference is tested, and its speed.
"""

from __future__ import annotations

import dataclasses

from ..errors import HybridtrackError
from .jit import available

__all__ = ["ENGINES", "COMPILE_PAYS_AT", "LOAD_PAYS_AT", "COMPILING", "available", "cached", "compiled", "compiles_first",
           "unsupported", "uses_kernel", "decided", "run_compiled"]

#: The choices of `SimulationConfig.engine`.
ENGINES = ("auto", "compiled", "reference")
#: Scans from which ``auto`` compiles the kernel when it is not compiled yet: compiling into an
#: empty cache took 76 s on a 2-core machine (115 s with the other core busy) and the compiled
#: loop saves about 20 µs a scan against the reference loop, so it pays from about 4 million
#: scans (docs/kernel.md, measured).
COMPILE_PAYS_AT = 4_000_000
#: Scans from which ``auto`` loads the kernel from its disk cache: loading took 0.9-1.5 s, so it
#: pays from 45,000-75,000 scans by the loop's saving alone (fewer end to end): 50,000, 35 days
#: at 1 minute.
LOAD_PAYS_AT = 50_000


def unsupported(config) -> str | None:
    """Why the kernel cannot run `config` (a `SimulationConfig`), or None when it can."""
    if config.controller.kalman != "fast":
        return f"the kernel runs the 'fast' Kalman filter, not {config.controller.kalman!r}"
    return None


def compiled() -> bool:
    """Whether the kernel's scan loop is compiled in this process already."""
    if not available():
        return False
    from .loop import run_scans

    return bool(run_scans.signatures)


def cached() -> bool:
    """Whether numba's disk cache holds the kernel's scan loop for these sources (its first call
    in a process then loads it in about a second instead of compiling)."""
    if not available():
        return False
    from .loop import run_scans  # importing empties a cache stamped for other sources (`jit`)

    try:
        return bool(run_scans._cache._cache_file._load_index())  # {} when absent or stale
    except Exception:  # pragma: no cover - numba's cache internals moved: compile only when it pays
        return False


#: What a run with a progress bar says before it compiles the kernel: its bar stands still meanwhile.
COMPILING = ("compiling the controller kernel before the first step (numba; once per install or upgrade, "
             "about 2 minutes on 2 cores, then kept in its cache)")


def compiles_first(config, scans: int = 0) -> bool:
    """Whether a run of `config` over `scans` scans compiles the kernel before its first scan: it
    takes the kernel (`uses_kernel`), which is neither compiled in this process nor in numba's
    disk cache (76-115 s on a 2-core machine, ``docs/kernel.md``), while its bar shows nothing done."""
    return uses_kernel(config, scans) and not compiled() and not cached()


def uses_kernel(config, scans: int = 0) -> bool:
    """Whether a run of `config` over `scans` scans goes through the kernel; ``compiled`` refuses
    what it cannot run; ``auto`` takes it where it is compiled already or the run pays for
    loading it (`LOAD_PAYS_AT`, from the disk cache) or compiling it (`COMPILE_PAYS_AT`)."""
    if config.engine == "reference":
        return False
    why = unsupported(config)
    if config.engine == "compiled":
        if why:
            raise HybridtrackError(f"engine 'compiled': {why}; use engine 'auto' or 'reference'")
        if not available():
            raise HybridtrackError("engine 'compiled' needs numba, which is not installed (pip install numba)")
        return True
    if why is not None or not available():
        return False
    return compiled() or scans >= COMPILE_PAYS_AT or (scans >= LOAD_PAYS_AT and cached())


def decided(config, scans: int):
    """`config` with ``engine = "auto"`` decided for `scans` scans in all.

    For a caller that runs many runs (a field's collectors, a stream's days, a sweep's runs):
    whether the kernel pays is a question of all of them, not of each run's own scans, which had
    run every collector of a field-year on the reference loop where the kernel was not cached
    (a 20-row Fresnel year: 34 s a row against 0.6 s, after one compile of two to three minutes).

    Parameters
    ----------
    config : SimulationConfig
    scans : int
        The scans of every run the caller will make.

    Returns
    -------
    SimulationConfig
        With ``engine = "compiled"`` where ``auto`` takes the kernel for `scans` (`uses_kernel`);
        `config` itself otherwise (``reference``, ``compiled``, or ``auto`` that does not pay).

    References
    ----------
    ``docs/kernel.md``, "Choosing it": where the measured costs behind `LOAD_PAYS_AT` and
    `COMPILE_PAYS_AT` are given.
    """
    if config.engine == "auto" and uses_kernel(config, scans):
        return dataclasses.replace(config, engine="compiled")
    return config


def run_compiled(world, controller, progress, bulk_nights, stop=None, fit_columns=True):
    """Run the scans through the kernel (`hybridtrack.kernel.bridge.run_compiled`)."""
    from .bridge import run_compiled as run

    return run(world, controller, progress, bulk_nights, stop, fit_columns)
