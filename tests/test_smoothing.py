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


def test_by_hand_and_refusals():
    """y[0] = z + g·x[0]; then z = k·y: a unit step through g = 0.5, k = 0.5 from rest."""
    np.testing.assert_array_equal(one_pole(np.ones(3), 0.5, 0.5), [0.5, 0.75, 0.875])
    assert one_pole(np.zeros(0), 1.0, 0.5).shape == (0,)
    with pytest.raises(HybridtrackError, match="unknown engine"):
        one_pole(np.ones(3), 1.0, 0.5, engine="scipy")
    with pytest.raises(HybridtrackError, match=r"one series, shape \(N,\); got shape \(2, 3\)"):
        one_pole(np.ones((2, 3)), 1.0, 0.5)
