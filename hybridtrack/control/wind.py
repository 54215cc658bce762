"""The wind guard: stow above the threshold at once; release only after a calm spell."""

from __future__ import annotations

import math

__all__ = ["WindGuard"]


class WindGuard:
    """Judges each anemometer reading.

    A reading that is not a number is missing wind data, never calm: with ``missing="stow"``
    (a live controller's default) it counts as a gust; with ``missing="track"`` (replaying a
    file that has no wind at all) it counts as no gust, and the run says the wind was missing.
    """

    __slots__ = ("stow_above", "release_at", "hold", "calm_since", "stow_when_missing")

    def __init__(self, stow_above: float, release_at: float, hold_minutes: float, missing: str = "stow"):
        self.stow_above = stow_above
        self.release_at = release_at
        self.hold = hold_minutes
        self.calm_since = -math.inf
        self.stow_when_missing = missing == "stow"

    def gusty(self, wind: float) -> bool:
        """Whether this reading demands a stow."""
        if math.isnan(wind):
            return self.stow_when_missing
        return not wind <= self.stow_above

    def update(self, t: float, wind: float) -> bool:
        """Take a reading at scan time `t` (minutes); return whether it is a gust."""
        if self.gusty(wind):
            self.calm_since = math.inf
            return True
        if wind <= self.release_at or math.isnan(wind):
            if math.isinf(self.calm_since):
                self.calm_since = t
        else:
            self.calm_since = math.inf
        return False

    def released(self, t: float) -> bool:
        """Whether the wind has stayed at or below the release speed for the hold time."""
        return not math.isinf(self.calm_since) and t - self.calm_since >= self.hold
