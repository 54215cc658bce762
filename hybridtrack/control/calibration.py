"""Continuous calibration: the offset between the filtered sun and the computed one, per axis.

Whenever the filter takes a valid reading while the model's target moves slowly, the offset
moves toward (filtered − model): a running mean over the first `tau` of readings, then
exponential forgetting with time constant `tau`. It is bounded by the plausibility limit.

It is not carried into a new day (`start_day`). What it holds is what the fitted mount leaves at
the hour it was learned (the controller's sun model's error for that hour, the fit's own misfit
there), which is why the disagreement check leaves it out; the evening's offset was learned with the
sun on the other side of the sky from the morning's, and the mount fit carries over what the
night does not change (`docs/world.md`, issue 10's acceptance: an overcast morning, tracked on
the computed sun, ran on the evening's +0.08°).
"""

from __future__ import annotations

import math

__all__ = ["Calibrator"]


class Calibrator:
    """One axis's calibration offset, degrees in encoder coordinates."""

    __slots__ = ("offset", "learned", "tau", "max_rate")

    def __init__(self, tau_minutes: float, max_rate: float):
        self.offset = 0.0
        self.learned = 0.0
        self.tau = tau_minutes
        self.max_rate = max_rate

    def start_day(self) -> None:
        """A new day: the offset starts again from zero (how fast it learns is left as it was)."""
        self.offset = 0.0

    def carry(self, offset: float) -> None:
        """Start from an offset learned earlier, past the running-mean phase."""
        self.offset = float(offset)
        self.learned = self.tau

    def learn(self, dt: float, residual: float, model_step: float, bound: float) -> None:
        """Move toward `residual` (filtered sun less the model), unless the target turns fast."""
        if not abs(model_step) <= self.max_rate * dt or math.isnan(residual):
            return
        self.learned += dt
        alpha = max(1.0 - math.exp(-dt / self.tau), dt / self.learned if self.learned < self.tau else 0.0)
        self.offset += alpha * (residual - self.offset)
        self.offset = max(-bound, min(bound, self.offset))
