"""Does the sensor still agree with the calibrated model? A two-sided CUSUM on the fit's
normalised innovations, with a checkpoint of the calibration to roll back to.

A healthy sensor's residuals against the calibrated model are zero-mean with the spread the
fit predicts. A sensor that drifts, or takes on a bias, or a mount that shifts, leaves a run of
residuals of one sign: Page's CUSUM accumulates them, less an allowance `ALLOWANCE` per reading,
and flags a disagreement above `THRESHOLD` (Page 1954; Montgomery 2009, §9.1). The model the
residuals are judged against leaves out small time-of-day terms (the clock's drift, the site's
coordinates, the linearisation), so a flagged run is an alarm only if its mean residual is also
at least the controller's `disagreement` limit; a smaller one is model misfit, and the sums
start again. While both sums are at zero the calibration is checkpointed; on an alarm the
calibration goes back to the last checkpoint, so what the disagreeing readings taught it is
undone.

References
----------
Page, E. S. (1954). Continuous inspection schemes. *Biometrika* 41(1/2), 100-115.
doi:10.1093/biomet/41.1-2.100

Montgomery, D. C. (2009). *Introduction to Statistical Quality Control*, 6th ed. Wiley.
"""

from __future__ import annotations

__all__ = ["DisagreementMonitor", "ALLOWANCE", "THRESHOLD"]

#: Half the shift (in standard deviations) the CUSUM is tuned to see at once.
ALLOWANCE = 0.5
#: Readings in a flagged run before it can be an alarm (half an hour of fit readings): a few large
#: residuals are a passing cloud's pull, not a fault.
MIN_RUN = 6
#: The sum that raises the alarm; with k = 0.5 a healthy sensor takes on the order of a thousand
#: fit readings (five-minute apart) to reach it by chance.
THRESHOLD = 8.0


class DisagreementMonitor:
    """Two-sided CUSUM of normalised innovations; remembers the mean residual of the current run."""

    __slots__ = ("high", "low", "run", "run_sum")

    def __init__(self):
        self.high = self.low = 0.0
        self.run = 0
        self.run_sum = 0.0

    @property
    def calm(self) -> bool:
        """Both sums at zero: a moment to checkpoint the calibration."""
        return self.high == 0.0 and self.low == 0.0

    def add(self, normalised: float, residual: float, limit: float) -> bool:
        """Take one innovation (in its standard deviations) and its size (degrees); True on an alarm:
        a run the CUSUM flags whose mean residual is at least `limit` degrees."""
        self.high = max(0.0, self.high + normalised - ALLOWANCE)
        self.low = max(0.0, self.low - normalised - ALLOWANCE)
        if self.calm:
            self.run, self.run_sum = 0, 0.0
            return False
        self.run += 1
        self.run_sum += residual
        if (self.high <= THRESHOLD and self.low <= THRESHOLD) or self.run < MIN_RUN:
            return False
        if abs(self.mean_residual()) >= limit:
            return True
        self.reset()  # flagged but small: model misfit, not a fault
        return False

    def mean_residual(self) -> float:
        """The mean residual (degrees) over the run of readings that led to the alarm."""
        return self.run_sum / self.run if self.run else 0.0

    def reset(self) -> None:
        """Start afresh."""
        self.high = self.low = 0.0
        self.run, self.run_sum = 0, 0.0
