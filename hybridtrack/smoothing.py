"""A first-order recursive filter, compiled where numba is installed: scipy's ``lfilter`` of one
pole without importing ``scipy.signal``.

The sky's smoothed noise (an AR(1) series, `hybridtrack.sky.smooth_noise`) and the side of the
sun a cloud's bright edge is on (`hybridtrack.sensor`) are each one pole, ``y[n] = z + g·x[n]``
with the state ``z = k·y[n]`` carried to the next sample. ``scipy.signal.lfilter`` computes
them, but importing ``scipy.signal`` takes 0.5–0.7 s of every process after pvlib (1.4 s
alone): a command-line run's, a benchmark's, each sweep worker's. The loop here is
``lfilter``'s own recursion (its direct form II transposed: the output the state plus the gain
times the input, then the state the pole times the output), so it gives the same bits; a test
holds the two equal bit for bit. Without numba it is ``lfilter`` itself.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from .errors import HybridtrackError

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; the lfilter path is tested by asking for it
    numba = None

__all__ = ["one_pole"]


def _recursion(values, gain, pole, state, out):
    for n in range(values.shape[0]):
        out[n] = state + gain * values[n]
        state = 0.0 * values[n] - (-pole) * out[n]  # lfilter's b = [gain, 0]: 0·inf and -0.0 as it has them


if numba is not None:
    _recursion = numba.njit(cache=True, nogil=True, error_model="numpy")(_recursion)


def one_pole(values: np.ndarray, gain: float, pole: float, state: float = 0.0, *, engine: str = "auto") -> np.ndarray:
    """The first-order recursive filter ``y[n] = z + gain·x[n]``, then ``z = pole·y[n]``, from
    the state `state`: ``scipy.signal.lfilter([gain], [1, -pole], values, zi=[state])[0]``.

    Parameters
    ----------
    values : array_like, shape (N,)
        The input samples.
    gain, pole : float
        The numerator's one coefficient and the pole (``pole = exp(-step / time constant)`` for
        an AR(1) series or an exponential smoothing).
    state : float
        The filter's state before the first sample (``zi``).
    engine : {"auto", "lfilter"}
        ``lfilter`` scipy's own; ``auto`` the compiled recursion where numba is installed, the
        same bits.

    Returns
    -------
    ndarray, shape (N,)

    References
    ----------
    Oppenheim, A. V. & Schafer, R. W. (2010). *Discrete-Time Signal Processing*, 3rd ed.,
    Pearson, section 6.5 (the transposed direct form II, which lfilter implements).
    """
    if engine not in ("auto", "lfilter"):
        raise HybridtrackError(f"one_pole: unknown engine {engine!r}; choose auto, lfilter")
    given = np.asarray(values)
    if given.dtype.kind not in "fiub" or given.ndim != 1:
        raise HybridtrackError(f"one_pole: values must be one series of numbers, shape (N,); got "
                               f"{given.dtype} of shape {given.shape}")
    for name, number in (("gain", gain), ("pole", pole), ("state", state)):
        if isinstance(number, (bool, np.bool_)) or not isinstance(number, numbers.Real) or not math.isfinite(number):
            raise HybridtrackError(f"one_pole: {name} must be a finite number, got {number!r:.60}")
    values = np.ascontiguousarray(given, dtype=float)
    if engine == "lfilter" or numba is None:
        from scipy.signal import lfilter

        return lfilter([gain], [1.0, -pole], values, zi=[state])[0]
    out = np.empty(len(values))
    _recursion(values, float(gain), float(pole), float(state), out)
    return out
