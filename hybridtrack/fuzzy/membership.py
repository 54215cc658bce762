"""Membership functions: the eleven types MATLAB's Fuzzy Logic Toolbox and scikit-fuzzy share.

Parameters follow scikit-fuzzy's argument order, which is this project's order everywhere
except in ``.fis`` files (`to_matlab` and `from_matlab` convert):

============  ==========================  ==========================
type          here (scikit-fuzzy)         MATLAB ``.fis``
============  ==========================  ==========================
trimf         a, b, c                     a, b, c
trapmf        a, b, c, d                  a, b, c, d
gaussmf       mean, sigma                 sigma, mean
gauss2mf      mean1, sigma1, mean2, sig2  sigma1, mean1, sigma2, mean2
gbellmf       a (width), b (slope), c     a, b, c
sigmf         centre, slope               slope, centre
dsigmf        c1, a1, c2, a2              a1, c1, a2, c2
psigmf        c1, a1, c2, a2              a1, c1, a2, c2
pimf          a, b, c, d                  a, b, c, d
smf, zmf      a, b                        a, b
============  ==========================  ==========================

The formulas are scikit-fuzzy's (``skfuzzy.membership``), which are MATLAB's, with one
exception: ``dsigmf`` is the absolute difference of its two sigmoids, as MATLAB defines it,
so that it never goes negative; where the first sigmoid dominates (the usual use) the two
agree.

References
----------
MathWorks (2024). Fuzzy Logic Toolbox: membership functions (trimf, trapmf, gaussmf,
gauss2mf, gbellmf, sigmf, dsigmf, psigmf, pimf, smf, zmf). https://www.mathworks.com/help/fuzzy/
Warner, J. et al. (2019). scikit-fuzzy 0.4.2. Zenodo. https://doi.org/10.5281/zenodo.3541386
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import HybridtrackError

__all__ = ["SHAPES", "membership", "check_params", "centre", "to_matlab", "from_matlab"]

#: Membership types and their parameter counts.
SHAPES = {"trimf": 3, "trapmf": 4, "gaussmf": 2, "gauss2mf": 4, "gbellmf": 3, "sigmf": 2, "dsigmf": 4,
          "psigmf": 4, "pimf": 4, "smf": 2, "zmf": 2}

# MATLAB's order as a permutation of ours: matlab[i] = ours[_MATLAB_ORDER[shape][i]]
_MATLAB_ORDER = {"gaussmf": (1, 0), "gauss2mf": (1, 0, 3, 2), "sigmf": (1, 0), "dsigmf": (1, 0, 3, 2),
                 "psigmf": (1, 0, 3, 2)}


def to_matlab(shape: str, params) -> list[float]:
    """Parameters in MATLAB's ``.fis`` order."""
    order = _MATLAB_ORDER.get(shape)
    return [float(params[i]) for i in order] if order else [float(p) for p in params]


def from_matlab(shape: str, values) -> tuple[float, ...]:
    """Parameters in this project's order from MATLAB's (the permutations are their own inverses)."""
    order = _MATLAB_ORDER.get(shape)
    if order and len(values) == len(order):
        return tuple(float(values[i]) for i in order)
    return tuple(float(v) for v in values)


def _sigmoid(x, centre_, slope):
    return 1.0 / (1.0 + np.exp(-slope * (x - centre_)))


def _s_curve(x, a, b):
    """MATLAB's/scikit-fuzzy's smf: 0 below a, 1 above b, two parabolas between."""
    mid = 0.5 * (a + b)
    rise = 2.0 * ((x - a) / (b - a)) ** 2
    top = 1.0 - 2.0 * ((x - b) / (b - a)) ** 2
    return np.where(x <= a, 0.0, np.where(x <= mid, rise, np.where(x <= b, top, 1.0)))


def _gaussian(x, mean, sigma):
    """``exp(-(x - mean)² / 2σ²)``, written so that no σ a term takes over- or underflows it: σ²
    of 1e200 had raised OverflowError, of 1e-200 divided by zero (NaN at the mean)."""
    return np.exp(-0.5 * ((x - mean) / sigma) ** 2)


def membership(shape: str, params, x) -> np.ndarray:
    """The membership of the points `x` in a term of type `shape` with `params`.

    Parameters
    ----------
    shape : str
        One of `SHAPES`.
    params : sequence of float
        The shape's parameters, in scikit-fuzzy's order (`check_params` holds them valid).
    x : array_like
        Points of the universe.

    Returns
    -------
    numpy.ndarray
        Memberships in [0, 1]; a steep or far term's values past float's range are read as
        their limits (0 or 1), without a warning.
    """
    with np.errstate(over="ignore", under="ignore"):  # an exponent or a slope past float's range: 0 or 1
        return _membership(shape, [float(v) for v in params], np.asarray(x, float))


def _membership(shape: str, p: list, x: np.ndarray) -> np.ndarray:
    if shape == "gaussmf":
        return _gaussian(x, p[0], p[1])
    if shape == "gauss2mf":
        left = _gaussian(x, p[0], p[1])
        right = _gaussian(x, p[2], p[3])
        return np.where(x <= p[0], left, np.where(x > p[2], right, 1.0))
    if shape == "gbellmf":
        return 1.0 / (1.0 + np.abs((x - p[2]) / p[0]) ** (2.0 * p[1]))
    if shape == "sigmf":
        return _sigmoid(x, p[0], p[1])
    if shape == "dsigmf":
        return np.abs(_sigmoid(x, p[0], p[1]) - _sigmoid(x, p[2], p[3]))
    if shape == "psigmf":
        return _sigmoid(x, p[0], p[1]) * _sigmoid(x, p[2], p[3])
    if shape == "smf":
        return _s_curve(x, p[0], p[1])
    if shape == "zmf":
        return 1.0 - _s_curve(x, p[0], p[1])
    if shape == "pimf":
        return _s_curve(x, p[0], p[1]) * (1.0 - _s_curve(x, p[2], p[3]))
    if shape not in ("trimf", "trapmf"):
        raise HybridtrackError(f"unknown membership type {shape!r}; choose from {', '.join(SHAPES)}")
    a, b, c, d = (p[0], p[1], p[1], p[2]) if shape == "trimf" else p
    with np.errstate(divide="ignore", invalid="ignore"):
        rise = np.where(b > a, (x - a) / (b - a), 1.0)
        fall = np.where(d > c, (d - x) / (d - c), 1.0)
    y = np.clip(np.minimum(rise, fall), 0.0, 1.0)
    y = np.where((x < a) | (x > d), 0.0, y)
    return np.where((x >= b) & (x <= c), 1.0, y)


def _ordered(p, where: str, shape: str) -> None:
    if any(a > b for a, b in zip(p, p[1:])):
        raise HybridtrackError(f"{where}: {shape} parameters must be in order, got {list(p)}")


def check_params(shape: str, params, where: str) -> None:
    """Raise `HybridtrackError` if `params` do not make a valid term of type `shape`."""
    if shape not in SHAPES:
        raise HybridtrackError(f"{where}: unknown membership type {shape!r}; choose from {', '.join(SHAPES)}")
    p = tuple(params)
    if len(p) != SHAPES[shape]:
        raise HybridtrackError(f"{where}: {shape} takes {SHAPES[shape]} parameters, got {len(p)}")
    if not all(math.isfinite(v) for v in p):
        raise HybridtrackError(f"{where}: parameters must be finite numbers, got {list(p)}")
    if shape == "gaussmf" and not p[1] > 0:
        raise HybridtrackError(f"{where}: gaussmf sigma must be positive, got {p[1]}")
    if shape == "gauss2mf":
        if not (p[1] > 0 and p[3] > 0):
            raise HybridtrackError(f"{where}: gauss2mf sigmas must be positive, got {p[1]} and {p[3]}")
        if p[0] > p[2]:
            raise HybridtrackError(f"{where}: gauss2mf means are inverted ({p[0]} > {p[2]})")
    if shape in ("trimf", "trapmf"):
        _ordered(p, where, shape)
        if p[0] == p[-1]:
            raise HybridtrackError(f"{where}: {shape} has zero width, got {list(p)}")
    if shape == "gbellmf" and not (p[0] != 0 and p[1] > 0):
        raise HybridtrackError(f"{where}: gbellmf needs a non-zero width and a positive slope, got {list(p)}")
    if shape in ("smf", "zmf", "pimf"):
        _ordered(p, where, shape)
        if p[0] == p[1] or (shape == "pimf" and p[2] == p[3]):
            raise HybridtrackError(f"{where}: {shape} has a zero-width ramp, got {list(p)}")


def centre(shape: str, params) -> float:
    """Where a term peaks, or the middle of its plateau; the 0.5 crossing of an open sigmoid."""
    p = tuple(params)
    if shape in ("gaussmf", "sigmf"):
        return p[0]
    if shape == "trimf":
        return p[1]
    if shape == "gbellmf":
        return p[2]
    if shape in ("gauss2mf", "dsigmf", "psigmf"):
        return 0.5 * (p[0] + p[2])
    if shape in ("smf", "zmf"):
        return 0.5 * (p[0] + p[1])
    return 0.5 * (p[1] + p[2])  # trapmf, pimf
