"""Progress bars on standard error that clear themselves when done.

A tqdm bar made with ``leave=False`` redraws itself with carriage returns and, when it closes,
blanks its line with one more. On a terminal the bar is then gone and the next line starts
clean. In a file (``2> run.log``, a CI log) every redraw stays on one physical line, and
whatever came next was appended to that line. An error (``hybridtrack: error: ...``) then
did not start a line of its own, so ``grep '^hybridtrack: error'`` missed it. `bar` ends that line
where standard error is not a terminal, nor a Jupyter kernel's stream, whose front end redraws a
line in place as a terminal does (there the ended line had shown as an empty one under the cell).
"""

from __future__ import annotations

import sys

from tqdm import tqdm

__all__ = ["bar"]


class _ClearingBar(tqdm):
    """A ``leave=False`` bar that ends its line when it closes on a stream that is not a terminal."""

    def close(self) -> None:
        shown = not self.disable  # tqdm disables a bar as it closes it: a second close writes nothing
        super().close()
        if shown and not _redraws_in_place(self.fp):
            self.fp.write("\n")  # tqdm's wrapper of the stream ignores a closed or full one
            self.fp.flush()


def _redraws_in_place(stream) -> bool:
    """Whether `stream` (tqdm's wrapper of it, or itself) shows a carriage return as a redraw: a
    terminal, or a Jupyter kernel's output stream."""
    wrapped = getattr(stream, "_wrapped", stream)
    if type(wrapped).__module__.split(".")[0] == "ipykernel":
        return True
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):  # no isatty, or a closed stream
        return False


def bar(total: int | None, *, unit: str, desc: str | None = None, unit_scale: bool = False, disable: bool = False,
        mininterval: float = 0.1) -> tqdm:
    """A tqdm bar on standard error over `total` `unit`\\ s that clears itself when done and leaves
    a file's line ended (see the module's notes)."""
    return _ClearingBar(total=total, unit=unit, desc=desc, unit_scale=unit_scale, disable=disable, leave=False,
                        file=sys.stderr, mininterval=mininterval)
