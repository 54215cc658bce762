"""Whether to believe the encoder: glitches ignored until confirmed, a frozen encoder caught."""

from __future__ import annotations

import math

__all__ = ["EncoderMonitor", "AXIS_NAMES"]

#: What an encoder's events call it, by the collector's number of axes: a heliostat's two encoders
#: had given the same text, and a field engineer could not tell which had frozen.
AXIS_NAMES = {1: ("",), 2: ("azimuth ", "elevation ")}


class EncoderMonitor:
    """One axis's encoder, judged against where the last commanded move should have left it.

    A reading that jumps away from the expected position is a glitch: ignored for that scan,
    believed only once it has persisted for `confirm` scans. A reading that does not change
    although the drive was commanded to move is a frozen encoder: the drive moved, its encoder
    did not count, so the axis is where the move should have left it, and from then on (while
    the controller does not believe the encoder) where the moves commanded since have taken it.
    A timed stow move is measured from there: taken from the frozen reading, it had left a trough
    frozen on its first move of the morning (30° off stow) where it stood through a gale.
    """

    __slots__ = ("resolution", "confirm", "believed", "last", "jumped", "commanded", "name")

    def __init__(self, resolution: float, confirm: int, name: str = ""):
        self.name = name  # "", or the axis and a space (`AXIS_NAMES`)
        self.resolution = resolution
        self.confirm = confirm
        self.believed = math.nan
        self.last = math.nan
        self.jumped = 0
        self.commanded = 0.0

    def read(self, value: float, reckoned: bool) -> tuple[float, str | None, bool]:
        """The position to use, an alarm text or None, and whether the encoder looks frozen;
        `reckoned`: the encoder is not believed (judged frozen), the position is dead reckoned."""
        previous, self.last = self.last, value
        if math.isnan(self.believed):
            self.believed = value
            return value, None, False
        expected = self.believed + self.commanded
        if reckoned:
            self.believed = expected
            return expected, None, False
        tolerance = 2.0 * self.resolution + 1e-9
        if self.commanded and abs(value - previous) < 0.5 * self.resolution and abs(self.commanded) > tolerance:
            self.believed = expected
            return expected, f"{self.name}encoder frozen: commanded {self.commanded:+.2f}°, reading unchanged; drive halted", True
        if abs(value - expected) <= tolerance:
            self.jumped = 0
            self.believed = value
            return value, None, False
        self.jumped += 1
        if self.jumped >= self.confirm:
            self.jumped = 0
            self.believed = value
            return value, f"{self.name}encoder reading {value:.3f}° held for {self.confirm} scans; believed", False
        self.believed = expected
        note = f"{self.name}encoder glitch: read {value:.3f}°, expected {expected:.3f}°; ignored" if self.jumped == 1 else None
        return expected, note, False
