"""The actuator and its position feedback, as run in the field (``docs/physics.md`` §5).

Intermittent drive: the target is recomputed every control period, and the drive moves
only when the target and the encoder reading differ by more than the deadband (0.4°). It
then moves at its speed, fast, and stops. Position comes from a 12-bit absolute Gray-code
encoder: 360°/4096 = 0.088° a count. Commands are clamped to the mechanical limits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import HybridtrackError

__all__ = ["Drive", "gray_encode", "gray_decode", "encoder_reading"]


def gray_encode(count):
    """Binary count -> Gray code."""
    count = np.asarray(count, dtype=np.int64)
    return count ^ (count >> 1)


def gray_decode(code):
    """Gray code -> binary count."""
    code = np.asarray(code, dtype=np.int64)
    count = code.copy()
    shift = code >> 1
    while np.any(shift):
        count ^= shift
        shift >>= 1
    return count


def encoder_reading(angle: float, resolution: float) -> float:
    """What an absolute encoder of `resolution` degrees a count reads at `angle` (degrees)."""
    return round(angle / resolution) * resolution


@dataclass(frozen=True)
class Drive:
    """Parameters of one axis's drive and encoder.

    Parameters
    ----------
    deadband : float
        Degrees: move only when |target - reading| exceeds this.
    speed : float
        Tracking speed, degrees per minute.
    stow_speed : float
        Speed driving to or from stow, degrees per minute.
    limits : tuple of float
        Mechanical range of the axis, degrees; commands are clamped into it.
    stow : float
        The stow angle, degrees (90: the aperture faces the zenith).
    encoder_bits : int
        Absolute encoder resolution, 360°/2**bits a count.
    """

    deadband: float = 0.4
    speed: float = 30.0
    stow_speed: float = 60.0
    limits: tuple[float, float] = (0.0, 180.0)
    stow: float = 90.0
    encoder_bits: int = 12

    def __post_init__(self) -> None:
        object.__setattr__(self, "limits", tuple(float(v) for v in self.limits))
        if not 0 <= self.deadband <= 10:
            raise HybridtrackError(f"drive: deadband {self.deadband!r}° is outside 0-10°")
        if not (self.speed > 0 and self.stow_speed > 0):
            raise HybridtrackError("drive: speeds must be positive")
        if len(self.limits) != 2 or not self.limits[0] < self.limits[1]:
            raise HybridtrackError(f"drive: limits must be [low, high] with low < high, got {list(self.limits)}")
        if not self.limits[0] <= self.stow <= self.limits[1]:
            raise HybridtrackError(f"drive: stow {self.stow}° is outside the limits {list(self.limits)}")
        if not 8 <= self.encoder_bits <= 24:
            raise HybridtrackError(f"drive: encoder_bits {self.encoder_bits!r} is outside 8-24")

    @property
    def resolution(self) -> float:
        """Degrees per encoder count."""
        return 360.0 / 2**self.encoder_bits
