"""Columns a reading passes over are named in the report, not dropped unseen."""

from __future__ import annotations

from hybridtrack.cli import main
from hybridtrack.io import read_weather, validation_report

ROWS = ["time,ghi,dni,dhi,battery_v,RECORD"] + [
    f"2021-06-21 12:{m:02d}:00+08:00,900.0,800.0,150.0,12.{m % 10},{m}" for m in range(0, 60, 10)]


def _file(tmp_path):
    path = tmp_path / "logger.csv"
    path.write_text("\n".join(ROWS) + "\n")
    return path


def test_columns_no_quantity_is_read_from_are_listed(tmp_path):
    frame = read_weather(_file(tmp_path), site="lanzhou")
    assert frame.attrs["validation"]["not_read"] == ["'battery_v'", "'RECORD'"]
    assert "  not read: 'battery_v', 'RECORD'" in validation_report(frame).splitlines()


def test_a_mapping_that_takes_another_column_says_the_files_own_is_unread(tmp_path):
    # --map ghi=dni reads GHI from the 'dni' column (800 W/m²): the file's own 'ghi' (900) is
    # left, and the report says so with what it looks like
    frame = read_weather(_file(tmp_path), site="lanzhou", columns={"ghi": "dni"})
    assert frame["ghi"].iloc[0] == 800.0
    assert frame.attrs["validation"]["not_read"][0] == "'ghi' (looks like ghi)"


def test_the_command_line_report_names_them(tmp_path, capsys):
    assert main(["check", str(_file(tmp_path)), "--site", "lanzhou", "--map", "ghi=dni"]) == 0
    assert "  not read: 'ghi' (looks like ghi), 'battery_v', 'RECORD'" in capsys.readouterr().out


def test_a_file_whose_every_column_is_read_has_no_such_line(tmp_path):
    path = tmp_path / "clean.csv"
    path.write_text("\n".join(row.rsplit(",", 2)[0] for row in ROWS) + "\n")
    frame = read_weather(path, site="lanzhou")
    assert "not_read" not in frame.attrs["validation"]
    assert "not read" not in validation_report(frame)
