"""The compiled one-pole filter (`hybridtrack.smoothing.one_pole`) against scipy's lfilter, its
reference, bit for bit, as the sky's AR(1) noise and the cloud edge's side use it."""

import numpy as np
import pytest
from scipy.signal import lfilter

from hybridtrack.errors import HybridtrackError
from hybridtrack.smoothing import one_pole


def _same_bits(got, expected):
    assert got.shape == expected.shape
    assert np.array_equal(got.view(np.int64), expected.view(np.int64))


@pytest.mark.parametrize("seed", range(4))
def test_the_skys_ar1_noise_is_lfilters_bit_for_bit(seed):
    shocks = np.random.default_rng(seed).normal(0.0, 0.3, 200_000)
    for minutes in (2.0, 20.0, 30.0):
        phi = np.exp(-1.0 / minutes)
        expected = lfilter([1.0], [1.0, -phi], shocks)
        _same_bits(one_pole(shocks, 1.0, phi), expected)
        _same_bits(one_pole(shocks, 1.0, phi, engine="lfilter"), expected)


@pytest.mark.parametrize("seed", range(4))
def test_the_cloud_edges_side_is_lfilters_bit_for_bit(seed):
    """A run of ±1 steps smoothed from its first value (`hybridtrack.sensor`'s cloud edges)."""
    rng = np.random.default_rng(seed)
    sign = np.where(np.cumsum(rng.random(50_000) < 0.01) % 2 == 0, 1.0, -1.0)
    keep = np.exp(-1.0 / 2.0)
    expected = lfilter([1.0 - keep], [1.0, -keep], sign, zi=[keep * sign[0]])[0]
    _same_bits(one_pole(sign, 1.0 - keep, keep, keep * sign[0]), expected)


@pytest.mark.parametrize("values, pole, state", [([1.0, np.inf, 2.0], 0.5, 0.0), ([1.0, -np.inf, 2.0], 0.5, 0.0),
                                                 ([0.0, 0.0], 0.5, -0.0),
                                                 ([-0.0, 0.0, -0.0], -0.5, 0.0), ([np.nan, 1.0], 0.9, 1.0)])
@pytest.mark.parametrize("gain", [1.0, -1.0, 0.0])
def test_infinities_nans_and_signed_zeros_are_lfilters(values, pole, state, gain):
    """Its state update is lfilter's own, 0·x − (−pole)·y (lfilter pads b to [gain, 0]): 0·inf is
    NaN there and a −0.0 turns +0.0, which pole·y alone had not done."""
    values = np.array(values)
    _same_bits(one_pole(values, gain, pole, state), lfilter([gain], [1.0, -pole], values, zi=[state])[0])


def test_by_hand_and_refusals():
    """y[0] = z + g·x[0]; then z = k·y: a unit step through g = 0.5, k = 0.5 from rest."""
    np.testing.assert_array_equal(one_pole(np.ones(3), 0.5, 0.5), [0.5, 0.75, 0.875])
    assert one_pole(np.zeros(0), 1.0, 0.5).shape == (0,)
    with pytest.raises(HybridtrackError, match="unknown engine"):
        one_pole(np.ones(3), 1.0, 0.5, engine="scipy")
    with pytest.raises(HybridtrackError, match=r"one series of numbers, shape \(N,\); got float64 of shape \(2, 3\)"):
        one_pole(np.ones((2, 3)), 1.0, 0.5)
    for bad in (None, "x", [1.0, "a"]):
        with pytest.raises(HybridtrackError, match="one series of numbers"):
            one_pole(bad, 1.0, 0.5)
    for name, bad in (("gain", "x"), ("pole", None), ("state", [0.0]), ("gain", True), ("pole", np.nan),
                      ("state", np.inf)):
        with pytest.raises(HybridtrackError, match=f"one_pole: {name} must be a finite number"):
            one_pole(np.ones(3), **{"gain": 1.0, "pole": 0.5, name: bad})
