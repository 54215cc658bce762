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
from .params import angle_pair, number, whole

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


#: Degrees any axis limit may lie within: a heliostat's azimuth with a cable wrap of one turn
#: either way of south runs -180° to 540°; one more half turn either way is still a mechanism.
LIMIT_RANGE = (-360.0, 720.0)
#: Degrees the limits may span at most: two full turns (the cable wrap above).
MAX_TRAVEL = 720.0
#: Degrees per minute a drive may turn at most: a full turn a minute, six times the fastest
#: stow move of the collectors modelled here (60°/min).
MAX_SPEED = 360.0
#: Degrees per minute the sun's hour angle turns (the earth's rotation, 360° in 24 h): a drive
#: slower than this falls behind the sun on every axis and never catches up.
SUN_RATE = 0.25


def _speed(value, name: str) -> float:
    """A drive speed in degrees per minute, refused when slower than the sun (`SUN_RATE`): at
    1e-300 °/min a collector had run a whole day 46° off its target without a word."""
    return number(value, f"drive: {name} (degrees per minute; the sun turns {SUN_RATE:g}, a slower axis never "
                         "keeps up)", SUN_RATE, MAX_SPEED)


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
        object.__setattr__(self, "limits", angle_pair(self.limits, "drive: limits (degrees)", *LIMIT_RANGE))
        if self.limits[1] - self.limits[0] > MAX_TRAVEL:
            raise HybridtrackError(f"drive: limits {list(self.limits)} span more than {MAX_TRAVEL:g}° (two turns)")
        # kept as Python's numbers: numpy's are taken, and TOML cannot write them
        object.__setattr__(self, "deadband", number(self.deadband, "drive: deadband (degrees)", 0, 10))
        for name in ("speed", "stow_speed"):
            object.__setattr__(self, name, _speed(getattr(self, name), name))
        object.__setattr__(self, "stow", number(self.stow, "drive: stow (degrees)", *self.limits))
        object.__setattr__(self, "encoder_bits", whole(self.encoder_bits, "drive: encoder_bits", 8, 24))

    @property
    def resolution(self) -> float:
        """Degrees per encoder count."""
        return 360.0 / 2**self.encoder_bits
