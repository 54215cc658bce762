"""Output files are refused before a recorded file is read, not after its report.

An ``--out`` there already (without ``--force``) had been refused only once the file was read
and its whole validation report printed, after minutes for a year of 1-second data; and
validate-sky's ``--json`` and ``--out`` naming one file wrote the CSV over the JSON (found by a
helper replaying messy files).
"""

from __future__ import annotations

import pandas as pd
import pvlib
import pytest

from hybridtrack.cli import main


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """Two clear days at Lanzhou (pvlib's Ineichen clear sky), 10-minute stamps with their offset."""
    times = pd.date_range("2021-06-21", periods=288, freq="10min", tz="Asia/Shanghai")
    clear = pvlib.location.Location(36.06, 103.84, "Asia/Shanghai", 1517).get_clearsky(times)
    frame = clear[["ghi", "dni", "dhi"]].round(1)
    frame.index = times.strftime("%Y-%m-%dT%H:%M:%S+08:00")
    path = tmp_path_factory.mktemp("record") / "day.csv"
    frame.to_csv(path, index_label="time")
    return path


def test_check_refuses_an_existing_out_before_reading(record, tmp_path, capsys):
    out = tmp_path / "clean.csv"
    out.write_text("an earlier run's\n")
    assert main(["check", str(record), "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and str(out) in captured.err and captured.err.count("\n") == 1
    assert out.read_text() == "an earlier run's\n"


@pytest.mark.parametrize("flag", ["--json", "--out", "--plot"])
def test_validate_sky_refuses_an_existing_output_before_scoring(record, tmp_path, capsys, flag):
    out = tmp_path / "scores.png"
    out.write_bytes(b"an earlier run's")
    assert main(["validate-sky", str(record), "--site", "lanzhou", flag, str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and str(out) in captured.err and captured.err.count("\n") == 1
    assert out.read_bytes() == b"an earlier run's"


def test_validate_sky_refuses_two_outputs_of_one_name(record, tmp_path, capsys):
    out = tmp_path / "scores.json"
    assert main(["validate-sky", str(record), "--site", "lanzhou", "--json", str(out), "--out", str(out),
                 "--force"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "--json and --out both name" in captured.err and not out.exists()
