"""numba where it imports: `kernel` compiles a function with ``njit(cache=True)``, or leaves it
plain Python where numba is missing (`available` then says so, warning once).

The compiled controller is only ever run when `available` is true; without numba the package
runs the readable reference controller, as the fuzzy engine (`hybridtrack.fuzzy.compiled`) falls
back to numpy.
"""

from __future__ import annotations

import warnings

__all__ = ["available", "kernel"]

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; the fallback is tested by hiding it
    numba = None

_WARNED: list = []


def kernel(function):
    """Compile `function` with numba (cached on disk), or return it unchanged without numba."""
    if numba is None:  # pragma: no cover
        return function
    return numba.njit(cache=True, error_model="numpy")(function)


def available() -> bool:
    """Whether the compiled kernel can run here; warns once when numba is missing."""
    if numba is None and not _WARNED:
        _WARNED.append(True)
        warnings.warn("numba is not installed: simulations run the reference controller loop "
                      "(slower, same results)", RuntimeWarning, stacklevel=3)
    return numba is not None
