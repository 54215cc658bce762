"""Progress bars on standard error that clear themselves when done.

A tqdm bar made with ``leave=False`` redraws itself with carriage returns and, when it closes,
blanks its line with one more. On a terminal the bar is then gone and the next line starts
clean. In a file (``2> run.log``, a CI log) every redraw stays on one physical line, and
whatever came next was appended to that line. An error (``hybridtrack: error: ...``) then
did not start a line of its own, so ``grep '^hybridtrack: error'`` missed it. `bar` ends that line
where standard error is not a terminal.
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
        if shown and not _is_terminal(self.fp):
            self.fp.write("\n")  # tqdm's wrapper of the stream ignores a closed or full one
            self.fp.flush()


def _is_terminal(stream) -> bool:
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
