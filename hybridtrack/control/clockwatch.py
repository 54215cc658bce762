"""Does the controller's clock keep the sun's time? Its error and drift, from what the sensor shows.

A clock that is `tau` seconds ahead puts the computed sun where the true sun will be `tau`
later, so a trusted sensor reading differs from the computed target by the target's rate times
`tau`, on top of what the mount's errors make. Each reading the mount fit takes (the sun's
angle on each axis, `mountfit`) is also one equation of a batch least-squares fit of

    sensed - computed = J · mount - rate · (tau + drift · days)

with the mount's derivatives `J` (`mountfit.jacobian`), the computed target's rate (degrees a
second), the clock's error `tau` (seconds) and its drift (seconds a day, `days` since the first
reading). A time error's effect scales with the sun's rate, which changes through the day, so it
is told from a constant offset; whether it is told from the mount as well depends on the
collector, and the fit's own covariance says how well (each parameter's marginal 1σ, the mount
included: a parameter the data cannot separate keeps its prior's 1σ and is never alarmed):

* a single-axis collector's sensor cannot show a constant clock error at all. A clock error is a
  turn of the sky about the polar axis, and to first order that is a turn of the mount: an
  encoder zero of -ω·tau·cos(latitude) and an axis azimuth error of -ω·tau·sin(latitude) for a
  north-south axis (ω = 15°/h; Stine & Geyer 2001, ch. 4). The mount fit absorbs it, and the
  error it leaves in pointing is nil while the fit holds. A *drift* is seen: the turn grows day
  by day while the mount stays put;
* a heliostat's mirror bisects the sun and a fixed aim point, so a turned sky is not a turned
  pedestal, and a constant error shows as well. Its mount's derivatives include the sensor's
  collimation error (its mounting bias across the mirror's face, sec(e) of azimuth: `mountfit`),
  which a clock error must be told from: without that term a 0.06° bias had been read as a clock
  160-210 s fast over three sunny days at Delingha. With it one day's 1σ is about a fifth wider
  (80 s against 66 s at Delingha in June), and a 5-minute error takes a second day to alarm.

At the end of each day (the controller's night stow) the fit is solved. An error is alarmed once
it is at least `ALARM_SIGMAS` of its 1σ and at least `CLOCK_TOLERANCE`, on a heliostat only
(`constant_seen`): a single axis's estimate of it rests on the second-order geometry alone (the
refraction of a low sun, which does not turn with the sky and which the controller's sun model
leaves out), so what it reads is the model's own error, not the clock's. On healthy clocks, one
sunny trough day in late October read +529 to +1,420 s at Madrid (40.4° N) and -738 to +1,399 s
at Cape Town, 1σ 300-360 s, two alarms in eight days (helper-44); its estimate is still reported.
A drift once the
readings span `DRIFT_DAYS` and it is at least `ALARM_SIGMAS` of its 1σ and `DRIFT_TOLERANCE`.
Each alarm is raised once (latched, as a PLC's alarm is until someone acknowledges it).
A site longitude error is a clock error of 240 s a degree, and is seen as one.

References
----------
Stine, W. B. & Geyer, M. (2001). *Power From The Sun*, ch. 3-4 (the sun's hour angle turns
15° an hour about the polar axis). powerfromthesun.net.

Stone, K. W. (1986). *Automatic heliostat track alignment method*. US Patent 4,564,275.

Bretherton, C. S., Widmann, M., Dymnikov, V. P., Wallace, J. M. & Bladé, I. (1999). The effective
number of spatial degrees of freedom of a time-varying field. *Journal of Climate* 12(7),
1990-2009. doi:10.1175/1520-0442(1999)012<1990:TENOSD>2.0.CO;2
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

__all__ = ["ClockWatch", "ALARM_SIGMAS", "CLOCK_TOLERANCE", "DRIFT_TOLERANCE", "DRIFT_DAYS"]

#: Standard deviations an estimate must be from zero to be alarmed (a 4σ gate, as the sensor's).
ALARM_SIGMAS = 4.0
#: Seconds: a smaller clock error is tolerated. At the sun's fastest rate on a trough's axis
#: (15°/h at noon) 30 s is 0.125°, half the sensor-model disagreement limit (0.25°).
CLOCK_TOLERANCE = 30.0
#: Seconds a day: a smaller drift is tolerated; three times the S7-1200's ±2 s a day (±60 s a month).
DRIFT_TOLERANCE = 6.0
#: Days the readings must span before a drift is judged.
DRIFT_DAYS = 1.5
#: Minutes a clear spell must last before its readings count: a sun between passing clouds is
#: pulled by the bright cloud edge beside it (docs/world.md, the sensor under cloud), and an hour
#: of unbroken trusted readings is a sky the sensor sees clearly.
SPELL = 60.0
#: Minutes between trusted readings that break a spell (two of the mount fit's five-minute readings).
SPELL_GAP = 10.0
#: The priors' 1σ, which keep the batch fit invertible where the sun cannot tell the parameters
#: apart: the mount fit's own (2°), a clock set by hand (600 s), and as much a day.
PRIOR = {"mount": 2.0, "clock": 600.0, "drift": 600.0}


class ClockWatch:
    """A batch least-squares fit of the mount, the clock's error and its drift, from trusted readings.

    Parameters
    ----------
    parameters : int
        Mount parameters (columns of the jacobian).
    noise : float
        Degrees, 1σ of one sun-angle reading (the controller's datasheet value).
    constant_seen : bool
        Whether a constant clock error shows in the readings apart from the mount, and so is
        alarmed (a heliostat's; not a single axis's).
    """

    def __init__(self, parameters: int, noise: float, *, constant_seen: bool = True):
        self.n = parameters + 2
        prior = np.array([PRIOR["mount"]] * parameters + [PRIOR["clock"], PRIOR["drift"]], float)
        self.prior_information = np.diag(1.0 / prior**2)
        self.rows: list = []  # per reading counted: timer, axis, weighted derivatives, weighted residual
        self.pending: list = []  # the current spell's readings, until it has lasted `SPELL`
        self.spell_start = self.spell_last = math.nan
        self.r = noise * noise
        self.raised: set[str] = set()
        self.constant_seen = constant_seen

    @property
    def readings(self) -> int:
        """Readings counted (from clear spells)."""
        return len(self.rows)

    @property
    def span(self) -> float:
        """Days from the first reading counted to the last."""
        return (self.rows[-1][0] - self.rows[0][0]) / 1440.0 if self.rows else 0.0

    def add(self, t: float, axis: int, row, rate: float, residual: float, weight: float) -> None:
        """One trusted reading at timer `t` (minutes) on `axis`: the mount's derivatives `row`, the
        computed target's `rate` (degrees a minute), sensed less computed angle `residual`
        (degrees), and the axis's `weight` in pointing terms. It counts once its clear spell has
        lasted `SPELL`."""
        if not t - self.spell_last <= SPELL_GAP:  # a new spell
            self.pending, self.spell_start = [], t
        self.spell_last = t
        per_second = -rate / 60.0  # a clock ahead computes the sun where it will be: sensed - computed = -rate·tau
        self.pending.append((t, axis, np.append(np.asarray(row, float), per_second) * weight, residual * weight))
        if t - self.spell_start >= SPELL:
            self.rows.extend(self.pending)
            self.pending = []

    def solve(self) -> tuple[np.ndarray, np.ndarray]:
        """The estimate and each parameter's 1σ (the mount's, then the clock's error in seconds at
        the first reading and its drift in seconds a day). Until the readings span `DRIFT_DAYS` the
        drift is held at zero (within a day it would only blur the error).

        The 1σ is the datasheet noise's, scaled by the fit's own residual scatter where that is
        larger (the variance of unit weight) and by the residuals' serial correlation: readings
        five minutes apart through one filter, under one sky, are not independent, and an AR(1)
        series of lag-one correlation ρ carries (1 - ρ)/(1 + ρ) of its readings' information
        (Bretherton et al. 1999). Both scale the readings' information, not the priors': a
        parameter the readings cannot tell keeps its prior's 1σ (a trough's constant clock error,
        600 s), where scaling the whole covariance had reported it at 1,884 s after a year.
        """
        t = np.array([r[0] for r in self.rows])
        axis = np.array([r[1] for r in self.rows])
        x = np.array([r[2] for r in self.rows])
        x = np.column_stack([x, x[:, -1] * (t - t[0]) / 1440.0])
        y = np.array([r[3] for r in self.rows])
        k = self.n if self.span >= DRIFT_DAYS else self.n - 1
        x = x[:, :k]
        covariance = np.linalg.inv(x.T @ x / self.r + self.prior_information[:k, :k])
        estimate = covariance @ (x.T @ y) / self.r
        error = y - x @ estimate
        unit_variance = max(1.0, float(error @ error) / self.r / max(len(y) - k, 1))
        scale = unit_variance * _correlation_factor(t, axis, error)
        std = np.sqrt(np.diag(np.linalg.inv(x.T @ x / (self.r * scale) + self.prior_information[:k, :k])))
        if k < self.n:
            estimate, std = np.append(estimate, 0.0), np.append(std, math.inf)
        return estimate, std

    def verdict(self) -> list[str]:
        """The alarms not yet raised that the readings so far call for (usually none)."""
        if self.readings < self.n:
            return []
        estimate, std = self.solve()
        alarms = []
        clock, drift = estimate[-2:]
        clock_std, drift_std = std[-2:]
        span = self.span
        if self.constant_seen and "clock" not in self.raised \
                and abs(clock) >= max(ALARM_SIGMAS * clock_std, CLOCK_TOLERANCE):
            self.raised.add("clock")
            alarms.append(f"controller clock off by {clock:+.0f} s (±{clock_std:.0f} s) against the sun the sensor "
                          f"shows, over {self.readings} readings")
        if ("drift" not in self.raised and span >= DRIFT_DAYS
                and abs(drift) >= max(ALARM_SIGMAS * drift_std, DRIFT_TOLERANCE)):
            self.raised.add("drift")
            alarms.append(f"controller clock drifting {drift:+.1f} s a day (±{drift_std:.1f}) against the sun the "
                          f"sensor shows, over {span:.1f} days")
        return alarms

    def save(self, start) -> dict:
        """What a next run's watch needs to go on (`restore`), as arrays: the readings (``t``,
        ``axis``, ``x``, ``y``; the first ``counted`` counted, the rest the current spell's), the
        spell, the alarms raised, and `start`, the instant this run's timer counts from (its first
        scan); `rebase` moves the timers onto the next run's."""
        rows = self.rows + self.pending
        return {"start": start, "counted": len(self.rows), "t": np.array([r[0] for r in rows], float),
                "axis": np.array([r[1] for r in rows], np.int64),
                "x": np.array([r[2] for r in rows], float).reshape(len(rows), self.n - 1),
                "y": np.array([r[3] for r in rows], float), "spell_start": self.spell_start,
                "spell_last": self.spell_last, "raised": sorted(self.raised)}

    def restore(self, saved: dict) -> None:
        """Go on from `save` (timers already on this run's, `rebase`): the readings of earlier runs
        count toward the clock's error and drift, and an alarm raised stays raised."""
        rows = [(t, a, x, y) for t, a, x, y in zip(saved["t"].tolist(), saved["axis"].tolist(), saved["x"].copy(),
                                                    saved["y"].tolist())]
        self.rows, self.pending = rows[:saved["counted"]], rows[saved["counted"]:]
        self.spell_start, self.spell_last = float(saved["spell_start"]), float(saved["spell_last"])
        self.raised = set(saved["raised"])

    @staticmethod
    def rebase(saved: dict, start) -> dict:
        """`saved` (`save`) with its timers counted from `start` instead, a later run's first scan."""
        shift = (start - saved["start"]) / pd.Timedelta(minutes=1)
        return {**saved, "start": start, "t": saved["t"] - shift, "spell_start": saved["spell_start"] - shift,
                "spell_last": saved["spell_last"] - shift}

    def state(self) -> dict:
        """The clock's error at the first reading counted (s) and its drift (s a day, once the
        readings span `DRIFT_DAYS`), each with its 1σ, the readings counted and the days they span."""
        if self.readings < self.n:
            return {"readings": self.readings}
        estimate, std = self.solve()
        drift = {"drift_s_per_day": round(float(estimate[-1]), 2), "drift_std_s_per_day": round(float(std[-1]), 2)} \
            if self.span >= DRIFT_DAYS else {}
        return {"error_s": round(float(estimate[-2]), 1), "error_std_s": round(float(std[-2]), 1), **drift,
                "readings": self.readings, "days": round(float(self.span), 3)}


def _correlation_factor(t: np.ndarray, axis: np.ndarray, error: np.ndarray) -> float:
    """(1 + ρ)/(1 - ρ), at least 1, for the lag-one correlation ρ of the residuals of successive
    readings on one axis within one spell."""
    order = np.lexsort((t, axis))
    t, axis, error = t[order], axis[order], error[order]
    linked = (np.diff(t) <= SPELL_GAP) & (axis[1:] == axis[:-1])
    if linked.sum() < 2:
        return 1.0
    a, b = error[:-1][linked], error[1:][linked]
    rho = float(np.clip(np.dot(a, b) / max(math.sqrt(np.dot(a, a) * np.dot(b, b)), 1e-300), 0.0, 0.95))
    return (1.0 + rho) / (1.0 - rho)
