"""Inputs an adversary feeds the command line and the file readers, each found to break once: a
wrong file or flag is one line naming it and where, status 2, never a traceback (nor a hang)."""

from __future__ import annotations

import pytest

from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.io import read_weather

HEADER = "time,ghi,dni,dhi,wind_speed\n"
ROWS = "".join(f"2021-06-05 {h:02d}:00,{g},{d},{f},2.0\n" for h, g, d, f in
               ((6, 40, 300, 20), (9, 600, 800, 90), (12, 950, 900, 100), (15, 700, 820, 95), (18, 200, 500, 60)))


def refused(path, kwargs, flags, capsys) -> str:
    """The API's message for `path`, after checking that ``hybridtrack check`` prints the same
    one line with status 2."""
    with pytest.raises(HybridtrackError) as error:
        read_weather(path, **kwargs)
    message = str(error.value)
    assert "\n" not in message
    assert main(["check", str(path), *flags]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {message}\n"
    return message


def test_a_stamp_of_millions_of_characters_is_refused_at_once_and_quoted_cut(tmp_path, capsys):
    # a corrupted logger line of 5 million digits in the time column: the date parser had taken
    # minutes over it (a hang), and the message then quoted all 5 million characters
    path = tmp_path / "record.csv"
    path.write_text(HEADER + ROWS + "9" * 5_000_000 + ",1,1,1,1\n" + ROWS.replace("-05 ", "-06 "))
    message = refused(path, {"tz": "UTC"}, ["--tz", "UTC"], capsys)
    assert message == (f"{path}: line 7, column 'time': '99999999999999999999'... (5,000,000 characters) is not a "
                       "time stamp (longer than 80 characters)")
