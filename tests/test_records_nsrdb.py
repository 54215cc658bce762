"""NSRDB (PSM3) and SAM CSV files: the site and the stamps' zone from their first two lines, the
stamp from year, month, day, hour and minute columns (tests/records/nsrdb-psm3-*.csv read to their
truth in test_records_corpus.py; here the variants users download or damage)."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pandas as pd
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.io import read_weather

sys.path.insert(0, str(Path(__file__).resolve().parent / "records"))
from make_records import _PSM3_HEADER, _PSM3_NAMES, _PSM3_VALUES  # noqa: E402

HEADER = "Year,Month,Day,Hour,Minute,GHI,DNI,DHI,Wind Speed,Temperature"


def _rows(days, noon=(500, 700, 100)) -> list[str]:
    """Hourly rows of whole days, `noon` light (GHI, DNI, DHI) from 10:00 to 14:00, dark otherwise."""
    return [f"{y},{m},{d},{h},0," + ",".join(map(str, noon if 10 <= h <= 14 else (0, 0, 0))) + ",2.0,15.0"
            for y, m, d in days for h in range(24)]


def _psm3(tmp_path, days, zone="-7", values=None, header=HEADER) -> Path:
    path = tmp_path / "psm3.csv"
    values = values or _PSM3_VALUES.format(zone=zone)
    path.write_text("\n".join([_PSM3_NAMES, values, header] + _rows(days)) + "\n")
    return path


def _refused(path, capsys, message, **kwargs):
    with pytest.raises(HybridtrackError) as refused:
        read_weather(path, **kwargs)
    assert str(refused.value) == message
    assert main(["check", str(path)]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {message}\n"


def test_a_typical_year_is_read_in_one_year(tmp_path):
    """A PSM3 TMY file's months come from different years (January 2005, February 2012, March
    2009): read as written, they were a decade with gaps; they are read in 2019, and said so."""
    frame = read_weather(_psm3(tmp_path, [(2005, 1, 5), (2012, 2, 5), (2009, 3, 5)]))
    zone = "Etc/GMT+7"
    assert frame.index[0] == pd.Timestamp("2019-01-05 00:00", tz=zone) and len(frame) == 72
    assert frame.loc[pd.Timestamp("2019-02-05 12:00", tz=zone), "ghi"] == 500.0
    assert frame.index[-1] == pd.Timestamp("2019-03-05 23:00", tz=zone)
    assert frame.attrs["validation"]["time"] == ("naive stamps in UTC-07:00, as the file's Time Zone (line 2) says; "
                                                 "one year (2019) for a typical-year file (its years change between "
                                                 "months)")


def test_29_february_in_a_typical_year_is_refused_naming_its_line(tmp_path, capsys):
    path = _psm3(tmp_path, [(2005, 1, 5), (2012, 2, 29)])
    _refused(path, capsys, f"{path}: line 28: 29 February in a typical-year file, which is read in 2019, a year "
                           "without one; remove that day")


def test_real_years_keep_their_years_across_new_year(tmp_path):
    frame = read_weather(_psm3(tmp_path, [(2020, 12, 31), (2021, 1, 1)]))
    assert frame.index[0] == pd.Timestamp("2020-12-31 00:00", tz="Etc/GMT+7") and len(frame) == 48
    assert "typical" not in frame.attrs["validation"]["time"]


@pytest.mark.parametrize("name, cell, what", [("Latitude", "abc", "latitude (-90 to 90)"),
                                               ("Longitude", "255.2", "longitude (-180 to 180)"),
                                               ("Time Zone", "UTC", "UTC offset in hours (-14 to 14)")])
def test_a_site_line_that_is_no_number_is_refused_naming_its_line_and_column(tmp_path, capsys, name, cell, what):
    names = _PSM3_NAMES.split(",")
    values = _PSM3_VALUES.format(zone=-7).split(",")
    values[names.index(name)] = cell
    path = _psm3(tmp_path, [(2021, 6, 5)], values=",".join(values))
    _refused(path, capsys, f"{path}: line 2, column {name!r}: {cell!r} is not a {what}")


def test_a_missing_time_zone_asks_for_one(tmp_path, capsys):
    """No zone on line 2 ('-'): the stamps' zone is not guessed, and --tz gives it."""
    path = _psm3(tmp_path, [(2021, 6, 5)], zone="-")
    with pytest.raises(HybridtrackError, match=re.escape(f"{path}: line 4, column 'Year + Month + Day + Hour + "
                                                         "Minute': naive time stamps")):
        read_weather(path)
    frame = read_weather(path, tz="Etc/GMT+7")
    assert frame.index[12] == pd.Timestamp("2021-06-05 12:00", tz="Etc/GMT+7") and frame.attrs["site"] == "NSRDB 149190"


def test_the_site_lines_cut_off_leave_a_table_of_year_month_day_hour_columns(tmp_path):
    """Without its first two lines, a PSM3 file is a table whose stamp is in five columns."""
    path = tmp_path / "cut.csv"
    path.write_text("\n".join([HEADER] + _rows([(2021, 6, 5)])) + "\n")
    frame = read_weather(path, tz="Etc/GMT+7")
    assert frame.index[10] == pd.Timestamp("2021-06-05 10:00", tz="Etc/GMT+7") and frame["dni"].iloc[10] == 700.0
    assert "site" not in frame.attrs


def test_a_half_hour_zone_and_a_sam_csv_without_minutes(tmp_path):
    """SAM's CSV: 'Year,Month,Day,Hour,GHI,DNI,DHI,Tdry,Wspd', no minute; a zone of 5.5 h (India)."""
    path = tmp_path / "sam.csv"
    rows = [row.split(",", 5)[:4] + row.split(",")[5:] for row in _rows([(2021, 3, 20)])]
    path.write_text("Source,Location ID,City,State,Country,Latitude,Longitude,Time Zone,Elevation\n"
                    "NSRDB,1234,Delhi,-,India,28.61,77.21,5.5,216\nYear,Month,Day,Hour,GHI,DNI,DHI,Wspd,Tdry\n"
                    + "\n".join(",".join(row) for row in rows) + "\n")
    frame = read_weather(path)
    assert frame.index[12] == pd.Timestamp("2021-03-20 06:30", tz="UTC") and frame["ghi"].iloc[12] == 500.0
    assert frame["temp_air"].iloc[0] == 15.0 and frame.attrs["site"] == "Delhi"
    assert frame.attrs["validation"]["time"] == "naive stamps in UTC+05:30, as the file's Time Zone (line 2) says"


def test_a_file_without_its_site_values_line_is_refused_naming_it(tmp_path, capsys):
    """The second line cut out: the table's header under line 1's names had been read as the site's
    values, and the first data row as the header ('column '0' appears more than once')."""
    path = tmp_path / "psm3.csv"
    path.write_text("\n".join([_PSM3_NAMES, _PSM3_HEADER] + _rows([(2021, 6, 5)])) + "\n")
    _refused(path, capsys, f"{path}: line 2: no number under line 1's names (Latitude, Longitude, ...): an NSRDB or "
                           "SAM CSV file's second line holds the site's values")


def test_a_table_whose_header_starts_with_source_and_latitude_is_a_table(tmp_path):
    """A mobile logger's 'Source,Latitude,Longitude,Timestamp,...' header names no site lines:
    its first row is data, not the site's values."""
    path = tmp_path / "rover.csv"
    path.write_text("Source,Latitude,Longitude,Timestamp,GHI,DNI,DHI\n"
                    + "".join(f"rover,36.10,103.73,2021-06-05T{h}:00:00+08:00,500,700,100\n" for h in (11, 12, 13)))
    frame = read_weather(path)
    assert len(frame) == 3 and frame.index[0] == pd.Timestamp("2021-06-05 11:00", tz="Asia/Shanghai")
    assert frame.attrs["validation"]["table"] == "table"
