"""numba where it imports: `kernel` compiles a function with ``njit(cache=True)``, or leaves it
plain Python where numba is missing (`available` then says so, warning once).

numba's disk cache is keyed on each function's own file, not on the functions it calls or the
constants it imports: a cached loop would keep an old controller after the controller's file
changed. So the cache is stamped with a hash of every source the kernels are built from, and
emptied when that changes.

The compiled controller is only ever run when `available` is true; without numba the package
runs the readable reference controller, as the fuzzy engine (`hybridtrack.fuzzy.compiled`) falls
back to numpy.
"""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path

__all__ = ["available", "kernel"]

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; the fallback is tested by hiding it
    numba = None

_WARNED: list = []
_STAMPED: list = []
_HERE = Path(__file__).parent
#: The sources compiled into the kernels (their constants included).
SOURCES = (*sorted(_HERE.glob("*.py")), *sorted((_HERE.parent / "control").glob("*.py")), _HERE.parent / "world.py")


def _sources_hash() -> str:
    digest = hashlib.sha256()
    for path in SOURCES:
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _empty_stale_cache(folder: Path = _HERE / "__pycache__") -> None:
    """Remove the cached kernels when any source they were built from has changed (numba's
    default cache folder; one set by NUMBA_CACHE_DIR is left alone)."""
    stamp = folder / "kernel-sources.sha256"
    current = _sources_hash()
    try:
        if stamp.is_file() and stamp.read_text() == current:
            return
        folder.mkdir(exist_ok=True)
        for cached in [*folder.glob("*.nbi"), *folder.glob("*.nbc")]:
            cached.unlink(missing_ok=True)
        stamp.write_text(current)
    except OSError:  # a read-only install: numba caches elsewhere or not at all
        pass


def kernel(function=None, *, allocates: bool = False, entry: bool = False, inline: bool = False):
    """Compile `function` with numba (cached on disk), or return it unchanged without numba.

    The kernels pass tuples of many arrays from piece to piece. With numba's reference counting
    every call would count a reference to each of those arrays, in and out, and cost more than
    the piece itself; so the pieces are compiled without it (``_nrt=False``: they must not make
    arrays). The few that make arrays (``allocates=True``: the mount fit's matrix algebra) are
    given only the arrays they need, and the loop (``entry=True``) makes the scratch arrays
    the pieces write into.

    A call between compiled pieces passes every array of every tuple as separate arguments (a
    tuple of 20 arrays is about 140 machine words), on the stack once registers run out; LLVM
    does not inline a large piece, so a scan paid for thousands of stores and loads. The large
    pieces every scan goes through (``inline=True``) are inlined into their caller by numba
    before LLVM sees them (``inline="always"``): the loop then holds one copy of each tuple
    (`docs/kernel.md`, "One function a scan"). The same bits: inlining changes no arithmetic.
    """
    if function is None:
        return lambda f: kernel(f, allocates=allocates, entry=entry, inline=inline)
    if numba is None:  # pragma: no cover
        return function
    if not _STAMPED:
        _STAMPED.append(True)
        _empty_stale_cache()
    return numba.njit(cache=True, error_model="numpy", _nrt=allocates or entry, nogil=entry,
                      inline="always" if inline else "never")(function)


#: The one warning a process gets where numba is missing, whichever compiled part asks first: one
#: missing compiler, one warning (the controller's loop and the fuzzy engine had given one each).
MISSING = ("numba is not installed: simulations run the reference controller loop and the fuzzy engine "
           "numpy (slower, same results)")


def warn_missing(stacklevel: int = 3) -> None:
    """Warn, once a process, that numba is missing (`MISSING`)."""
    if not _WARNED:
        _WARNED.append(True)
        warnings.warn(MISSING, RuntimeWarning, stacklevel=stacklevel + 1)


def available() -> bool:
    """Whether the compiled kernel can run here; warns once when numba is missing (`warn_missing`)."""
    if numba is None:
        warn_missing()
    return numba is not None
