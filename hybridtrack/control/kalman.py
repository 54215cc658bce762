"""The controller's Kalman filter on (angle, rate): filterpy's, and an equal one in plain floats.

The state is the sun's angle in encoder coordinates and its rate (degrees per minute), under a
white-noise acceleration model (Bar-Shalom, Li & Kirubarajan 2001, *Estimation with
Applications to Tracking and Navigation*, §6.2, doi:10.1002/0471221279). The measurement is
the sensor's pointing offset added to the encoder reading; its variance R comes from the
controller's own config (the sensor's datasheet accuracy plus the encoder's quantisation),
never from the simulated world.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FastKalman", "FilterpyKalman", "make_filter"]


class FastKalman:
    """Constant-rate Kalman filter on (angle, rate) in plain floats; matches `FilterpyKalman`."""

    def __init__(self, q: float, r: float):
        self.q, self.r = q, r
        self.x0 = self.x1 = 0.0
        self.p00, self.p01, self.p11 = 1.0, 0.0, 0.1

    def reset(self, angle: float, rate: float) -> None:
        """Start again at `angle` (degrees) moving at `rate` (degrees per minute)."""
        self.x0, self.x1 = angle, rate
        self.p00, self.p01, self.p11 = 1.0, 0.0, 0.1

    def predict(self, dt: float) -> None:
        """Advance the state `dt` minutes (white-noise acceleration model)."""
        q = self.q
        self.x0 += dt * self.x1
        p00, p01, p11 = self.p00, self.p01, self.p11
        self.p00 = p00 + 2.0 * dt * p01 + dt * dt * p11 + q * dt**3 / 3.0
        self.p01 = p01 + dt * p11 + q * dt * dt / 2.0
        self.p11 = p11 + q * dt

    def innovation(self, z: float, scale: float = 1.0) -> tuple[float, float]:
        """The residual of a measurement `z` and its variance (R times `scale`)."""
        return z - self.x0, self.p00 + self.r * scale

    def update(self, z: float, scale: float = 1.0) -> None:
        """Take in a measurement of the angle, degrees, of variance R times `scale`."""
        y, s = z - self.x0, self.p00 + self.r * scale
        k0, k1 = self.p00 / s, self.p01 / s
        self.x0 += k0 * y
        self.x1 += k1 * y
        p00, p01, p11 = self.p00, self.p01, self.p11
        self.p00 = (1.0 - k0) * p00
        self.p01 = (1.0 - k0) * p01
        self.p11 = p11 - k1 * p01

    @property
    def angle(self) -> float:
        """Filtered angle, degrees."""
        return self.x0

    @property
    def rate(self) -> float:
        """Filtered rate, degrees per minute."""
        return self.x1


class FilterpyKalman:
    """The same filter through filterpy's ``KalmanFilter`` (the reference)."""

    def __init__(self, q: float, r: float):
        from filterpy.kalman import KalmanFilter

        self.q = q
        self.kf = KalmanFilter(dim_x=2, dim_z=1)
        self.kf.H = np.array([[1.0, 0.0]])
        self.kf.R = np.array([[r]])
        self.reset(0.0, 0.0)

    def reset(self, angle: float, rate: float) -> None:
        """Start again at `angle` (degrees) moving at `rate` (degrees per minute)."""
        self.kf.x = np.array([[angle], [rate]])
        self.kf.P = np.array([[1.0, 0.0], [0.0, 0.1]])

    def predict(self, dt: float) -> None:
        """Advance the state `dt` minutes (white-noise acceleration model)."""
        q = self.q
        self.kf.F = np.array([[1.0, dt], [0.0, 1.0]])
        self.kf.Q = q * np.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])
        self.kf.predict()

    def innovation(self, z: float, scale: float = 1.0) -> tuple[float, float]:
        """The residual of a measurement `z` and its variance (R times `scale`)."""
        return z - float(self.kf.x[0, 0]), float(self.kf.P[0, 0] + self.kf.R[0, 0] * scale)

    def update(self, z: float, scale: float = 1.0) -> None:
        """Take in a measurement of the angle, degrees, of variance R times `scale` (filterpy's
        ``R`` for this one update)."""
        self.kf.update(np.array([[z]]), R=self.kf.R * scale)

    @property
    def angle(self) -> float:
        """Filtered angle, degrees."""
        return float(self.kf.x[0, 0])

    @property
    def rate(self) -> float:
        """Filtered rate, degrees per minute."""
        return float(self.kf.x[1, 0])


def make_filter(engine: str, q: float, r: float):
    """A filter by engine name: ``fast`` (plain floats) or ``filterpy`` (the reference)."""
    return FilterpyKalman(q, r) if engine == "filterpy" else FastKalman(q, r)
