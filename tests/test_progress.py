"""Progress bars that clear themselves leave a file's line ended (`hybridtrack.progress`): the
remains of a bar in ``2> run.log`` had shared their line with the error printed after them."""

import io
import sys

from hybridtrack.progress import bar


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _written(stream, monkeypatch, **options) -> str:
    monkeypatch.setattr(sys, "stderr", stream)
    with bar(3, unit="run", **options) as shown:
        shown.update(3)
    print("hybridtrack: error: after the bar", file=sys.stderr)
    return stream.getvalue()


def test_a_bar_in_a_file_ends_its_line_before_what_follows(monkeypatch):
    written = _written(io.StringIO(), monkeypatch)
    assert "0/3" in written  # drawn, then blanked (its next redraw waits out mininterval)
    assert written.endswith("\nhybridtrack: error: after the bar\n")
    assert written.splitlines()[-1] == "hybridtrack: error: after the bar"


def test_a_bar_on_a_terminal_clears_itself_and_adds_no_line(monkeypatch):
    written = _written(_Terminal(), monkeypatch)
    assert written.endswith("\rhybridtrack: error: after the bar\n")  # the line blanked, nothing added


class _KernelStream(io.StringIO):
    """Stands for ipykernel's OutStream, which is no terminal, but whose front end redraws a line."""


_KernelStream.__module__ = "ipykernel.iostream"


def test_a_bar_in_a_notebook_clears_itself_and_adds_no_empty_line(monkeypatch):
    written = _written(_KernelStream(), monkeypatch)
    assert written.endswith("\rhybridtrack: error: after the bar\n")


def test_a_disabled_bar_writes_nothing(monkeypatch):
    assert _written(io.StringIO(), monkeypatch, disable=True) == "hybridtrack: error: after the bar\n"


def test_a_bar_closed_twice_ends_its_line_once(monkeypatch):
    stream = io.StringIO()
    monkeypatch.setattr(sys, "stderr", stream)
    shown = bar(2, unit="step")
    shown.close()
    shown.close()
    assert stream.getvalue().count("\n") == 1
