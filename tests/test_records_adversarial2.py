"""Logger exports a field engineer has, read to hand-checked values or refused in one line.

Found by a helper replaying messy files; each test names what had happened.
"""

from __future__ import annotations

import numpy as np
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.io import read_weather, validation_report

#: Four 10-minute rows at noon, UTC stamps; DNI of the last is 645.3 W/m².
ROWS = ["2021-06-21T04:00:00Z,812.4,640.1,150.2",
        "2021-06-21T04:10:00Z,815.0,642.7,150.9",
        "2021-06-21T04:20:00Z,817.1,644.0,151.5"]


def _write(path, lines):
    path.write_text("time,ghi,dni,dhi\n" + "\n".join(lines))
    return path


def test_a_last_line_cut_short_in_its_fields_is_dropped_not_read(tmp_path):
    """'...,818.9,64' (DNI 645.3 cut by a power loss) had been read as a DNI of 64 W/m², the
    missing DHI as NaN, with no word but a NaN count."""
    path = _write(tmp_path / "cut.csv", ROWS + ["2021-06-21T04:30:00Z,818.9,64"])
    frame = read_weather(path)
    assert len(frame) == 3 and list(frame["dni"]) == [640.1, 642.7, 644.0]
    report = frame.attrs["validation"]
    assert report["truncated"]["lines"] == [5] and report["rows_read"] == 4
    assert "dropped (a last line cut short)" in validation_report(frame)
    with pytest.raises(HybridtrackError, match="line 5: a last line cut short \\(strict\\)"):
        read_weather(path, strict=True)


def test_a_short_row_inside_the_file_keeps_its_values(tmp_path):
    """Only the last line is taken for one cut short: a short row inside the file is read, its
    missing fields NaN and counted."""
    path = _write(tmp_path / "short.csv", [ROWS[0], "2021-06-21T04:10:00Z,815.0,642.7", ROWS[2]])
    frame = read_weather(path)
    assert len(frame) == 3 and frame["dni"].iloc[1] == 642.7 and np.isnan(frame["dhi"].iloc[1])
    assert "truncated" not in frame.attrs["validation"] and frame.attrs["validation"]["nan"] == {"dhi": 1}
