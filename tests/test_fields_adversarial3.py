"""Adversarial pass 3 over fields: each test holds a defect found and fixed."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.distance import pdist

from hybridtrack.fields import HeliostatField


@pytest.mark.parametrize("first_radius, spacing, first_ring", [
    (11.46, 12.0, 5),  # 2 r sin(π/5) = 13.47 m; six would stand 2 r sin(π/6) = 11.46 m apart
    (6 / (2 * np.pi), 1.0, 5),  # 0.955 m at the least spacing: six had been refused as overlapping
    (20.0, 12.0, 10),  # 2 r sin(π/10) = 12.36 m; eleven would stand 11.27 m apart
    (6.0, 12.0, 2),  # a ring exactly one spacing across holds two, face to face
    (5.0, 12.0, 1),  # too small for two
])
def test_rings_keep_mirrors_the_spacing_apart_in_a_straight_line(first_radius, spacing, first_ring):
    """Counted along the arc, a ring of 11.46 m had put mirrors of a 12 m spacing 11.46 m apart."""
    field = HeliostatField.rings(40, first_radius=first_radius, spacing=spacing)
    radii = np.hypot(*field.positions[:, :2].T)
    assert np.sum(np.isclose(radii, first_radius)) == first_ring
    assert pdist(field.positions).min() >= spacing - 1e-9


def test_rings_put_no_rounding_dust_in_positions():
    """A mirror due south had stood 7e-16 m east of the tower's line (the sine of a half turn)."""
    field = HeliostatField.rings(2, first_radius=6.0, spacing=12.0)
    np.testing.assert_array_equal(field.positions, [[0.0, 6.0, 0.0], [0.0, -6.0, 0.0]])


def test_a_partial_last_ring_stands_evenly_round_the_tower():
    """The default dozen had filled the first ring's 31 places from north clockwise: an arc east
    of the tower. A ring with fewer mirrors than places spreads them evenly round it."""
    field = HeliostatField.rings(12, first_radius=60.0, spacing=12.0)
    bearings = np.sort(np.degrees(np.arctan2(*field.positions[:, :2].T)) % 360.0)
    np.testing.assert_allclose(bearings, np.arange(12) * 30.0, atol=1e-9)
    full_then_partial = HeliostatField.rings(31 + 5, first_radius=60.0, spacing=12.0)  # 2 r sin(π/31) = 12.13 m
    outer = full_then_partial.positions[31:, :2]
    np.testing.assert_allclose(np.hypot(*outer.T), 72.0)
    np.testing.assert_allclose(np.sort(np.degrees(np.arctan2(*outer.T)) % 360.0), 36.0 + 72.0 * np.arange(5))
