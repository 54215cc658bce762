"""``check --out x.csv`` writes a frame that reads back as it was (found by a helper replaying
messy files: stamps were written to the whole second, so half-second data read back with half
its rows dropped as repeated stamps)."""

from __future__ import annotations

import pandas as pd
import pytest

from hybridtrack.cli import main
from hybridtrack.io import read_weather


@pytest.mark.parametrize("step, first", [("500ms", "2021-06-21T12:00:00.000000+00:00"),
                                         ("1s", "2021-06-21T12:00:00+00:00")])
def test_the_written_csv_reads_back_to_the_same_stamps(tmp_path, step, first):
    stamps = pd.date_range("2021-06-21 12:00", periods=40, freq=step, tz="UTC")
    record = tmp_path / "fast.csv"
    record.write_text("time,ghi,dni,dhi\n" + "\n".join(f"{t.isoformat()},{800 + i},700,100"
                                                      for i, t in enumerate(stamps)) + "\n")
    out = tmp_path / "clean.csv"
    assert main(["check", str(record), "--out", str(out)]) == 0
    assert out.read_text().splitlines()[1].startswith(first + ",800,")
    again = read_weather(out)
    assert again.index.equals(stamps) and list(again["ghi"]) == [800.0 + i for i in range(40)]
