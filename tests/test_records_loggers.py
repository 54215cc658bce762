"""Logger files as engineers have them: stamps and units the reader had misread or crashed on.

Each file is one June day at Lanzhou, 10-minute steps, written by `_day` in the way a logger or
export tool writes it (found by a helper replaying messy files).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.io import read_weather
from hybridtrack.sky import synthetic


@pytest.fixture(scope="module")
def day():
    return synthetic("lanzhou", "2021-06-21", weather="sunny", freq="10min", seed=2)[["ghi", "dni", "dhi"]].round(1)


def _write(path, stamps, day, *, header="time,ghi,dni,dhi", tail=""):
    rows = [f"{stamp},{g},{n},{d}" for stamp, (g, n, d) in zip(stamps, day.to_numpy())]
    path.write_text(header + "\n" + "\n".join(rows) + "\n" + tail)
    return path


def test_hour_only_utc_offsets_are_read_as_offsets(tmp_path, day):
    """'2021-06-21 00:00:00+08' (PostgreSQL's timestamptz) raised pandas' TypeError: a traceback."""
    stamps = day.index.strftime("%Y-%m-%d %H:%M:%S") + "+08"
    frame = read_weather(_write(tmp_path / "pg.csv", stamps, day), site="lanzhou")
    assert frame.index[0] == pd.Timestamp("2021-06-21 00:00", tz="Asia/Shanghai") and len(frame) == len(day)
    assert frame.attrs["validation"]["time"].startswith("stamps with UTC offset +08")


def test_a_last_line_cut_short_is_dropped_and_reported_not_read_as_another_day(tmp_path, day):
    """'2021-06-2' (power lost mid-line) had been read as 2 June: the replay started 19 days early."""
    path = _write(tmp_path / "cut.csv", day.index.strftime("%Y-%m-%d %H:%M"), day, tail="2021-06-2")
    frame = read_weather(path, site="lanzhou")
    assert frame.index[0] == day.index[0] and len(frame) == len(day)
    assert frame.attrs["validation"]["truncated"]["lines"] == [len(day) + 2]
    with pytest.raises(HybridtrackError, match="a last line cut short \\(strict\\)"):
        read_weather(path, site="lanzhou", strict=True)


def test_ten_digit_hourly_stamps_are_dates_not_epoch_seconds(tmp_path, day):
    """'2021062112' had been read as epoch seconds: 24 one-second rows in 2034."""
    hourly = day.iloc[::6]
    frame = read_weather(_write(tmp_path / "h.csv", hourly.index.strftime("%Y%m%d%H"), hourly), site="lanzhou")
    assert frame.index[12] == pd.Timestamp("2021-06-21 12:00", tz="Asia/Shanghai") and len(frame) == 24


def test_day_first_dates_followed_by_a_comma_are_decided_for_the_whole_column(tmp_path):
    """'10/06/2021, 00:00:00' (toLocaleString('en-GB')) was parsed one stamp at a time: 10-12 June
    became 6 October, November and December, and 13-15 June stayed right."""
    days = synthetic("lanzhou", "2021-06-10", "2021-06-15", weather="sunny", freq="1h", seed=2)
    stamps = '"' + days.index.strftime("%d/%m/%Y, %H:%M:%S") + '"'
    frame = read_weather(_write(tmp_path / "gb.csv", stamps, days[["ghi", "dni", "dhi"]].round(1)), tz="Asia/Shanghai")
    assert frame.index[0] == days.index[0] and frame.index[-1] == days.index[-1] and frame.index.is_monotonic_increasing


@pytest.mark.parametrize("header, unit", [("time,GHI (Wh/m2),dni,dhi", "Wh/m2"),
                                          ("time,ghi,dni,dhi,Wind Speed (km/s)", "km/s")])
def test_a_unit_in_a_header_the_reader_does_not_convert_is_refused_not_kept_as_a_note(tmp_path, day, header, unit):
    """'GHI (Wh/m2)' had been read as W/m² and 'Wind (km h-1)' as m/s, the unit reported as a note
    and the file called clean."""
    extra = ",3.0" if header.count(",") == 4 else ""
    rows = [f"{t},{g},{n},{d}{extra}" for t, (g, n, d) in zip(day.index.strftime("%Y-%m-%d %H:%M"), day.to_numpy())]
    (tmp_path / "u.csv").write_text(header + "\n" + "\n".join(rows) + "\n")
    with pytest.raises(HybridtrackError, match=f"the unit '{unit}' is not one hybridtrack converts"):
        read_weather(tmp_path / "u.csv", site="lanzhou")


def test_wind_in_si_and_imperial_spellings_is_converted(tmp_path, day):
    for header, factor in (("Wind Speed (km h-1)", 1 / 3.6), ("Wind Speed (mi/h)", 0.44704)):
        rows = [f"{t},{g},{n},{d},10.0" for t, (g, n, d) in zip(day.index.strftime("%Y-%m-%d %H:%M"), day.to_numpy())]
        (tmp_path / "w.csv").write_text(f"time,ghi,dni,dhi,{header}\n" + "\n".join(rows) + "\n")
        assert read_weather(tmp_path / "w.csv", site="lanzhou")["wind_speed"].iloc[0] == pytest.approx(10 * factor)


def test_dni_in_kilowatts_beside_ghi_and_dhi_in_watts_is_refused(tmp_path, day, capsys):
    """It was called clean, and the replay ran a clear day as overcast (sensor mode 0 %)."""
    kilowatts = day.assign(dni=(day["dni"] / 1000).round(4))
    path = _write(tmp_path / "kw.csv", day.index.strftime("%Y-%m-%d %H:%M"), kilowatts)
    assert main(["check", str(path), "--site", "lanzhou"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the values look like kW/m² read as W/m²" in err and "--units dni=kW/m2" in err
    assert np.isfinite(read_weather(path, site="lanzhou", units={"dni": "kW/m2"})["dni"]).any()


def test_a_spreadsheets_empty_padding_columns_are_skipped_and_said(tmp_path, day, capsys):
    """Excel pads rows to the sheet's used range ('time;ghi;dni;dhi;;'): the two unnamed columns had
    been refused as one name given twice."""
    rows = [f"{t};{g};{n};{d};;" for t, (g, n, d) in zip(day.index.strftime("%Y-%m-%d %H:%M"), day.to_numpy())]
    path = tmp_path / "excel.csv"
    path.write_text("time;ghi;dni;dhi;;\n" + "\n".join(rows) + "\n")
    frame = read_weather(path, site="lanzhou")
    assert len(frame) == len(day) and frame.attrs["validation"]["empty_columns"] == 2
    assert main(["check", str(path), "--site", "lanzhou"]) == 0
    assert "skipped 2 empty column(s) without a name" in capsys.readouterr().out


@pytest.mark.parametrize("marker", [-9999, -999, 7999])
def test_a_loggers_missing_value_marker_is_missing_data_counted_not_a_wrong_unit(tmp_path, day, marker):
    """A temperature sensor unplugged (-9999 in every row) had refused the whole file as a wrong
    unit, with a hint (--units temp_air=K) that would have made it worse."""
    rows = [f"{t},{g},{n},{d},{marker}" for t, (g, n, d) in zip(day.index.strftime("%Y-%m-%d %H:%M"), day.to_numpy())]
    path = tmp_path / "marked.csv"
    path.write_text("time,ghi,dni,dhi,temp_air\n" + "\n".join(rows) + "\n")
    frame = read_weather(path, site="lanzhou")
    assert frame["temp_air"].isna().all() and frame["dni"].notna().all()
    assert frame.attrs["validation"]["missing_markers"]["temp_air"]["count"] == len(day)
    with pytest.raises(HybridtrackError, match="a logger's missing-value marker \\(strict\\)"):
        read_weather(path, site="lanzhou", strict=True)


@pytest.mark.parametrize("header", ["time_utc", "UTC", "Time (UTC)"])
def test_a_time_column_named_utc_is_read_as_utc(tmp_path, day, header):
    """Its stamps had been read as the site's local time (and refused by the sun check, 8 h off)."""
    utc = day.index.tz_convert("UTC")
    path = _write(tmp_path / "utc.csv", utc.strftime("%Y-%m-%d %H:%M"), day, header=f"{header},ghi,dni,dhi")
    frame = read_weather(path, site="lanzhou")
    assert frame.index[0] == day.index[0] and "as the time or clock column's name says" in frame.attrs["validation"]["time"]


def test_a_units_row_in_brackets_is_read(tmp_path, day):
    """'[W/m2]' under the header had been refused as an unknown unit; a header's brackets were read."""
    path = _write(tmp_path / "units.csv", day.index.strftime("%Y-%m-%d %H:%M"), day.assign(dni=day["dni"] / 1000),
                  header="Timestamp,GHI,DNI,DHI\n[yyyy-mm-dd hh:mm],[W/m2],[kW/m2],[W/m2]")
    frame = read_weather(path, site="lanzhou")
    np.testing.assert_allclose(frame["dni"].to_numpy(), day["dni"].to_numpy(), atol=0.06)


def test_a_header_repeated_mid_file_is_skipped_and_listed(tmp_path, day):
    """A logger restarted, or daily files joined with cat: the repeated header had been refused as
    a time stamp ('time' is not a time stamp)."""
    stamps = day.index.strftime("%Y-%m-%d %H:%M")
    rows = [f"{t},{g},{n},{d}" for t, (g, n, d) in zip(stamps, day.to_numpy())]
    rows.insert(80, "time,ghi,dni,dhi")
    (tmp_path / "joined.csv").write_text("time,ghi,dni,dhi\n" + "\n".join(rows) + "\n")
    frame = read_weather(tmp_path / "joined.csv", site="lanzhou")
    assert len(frame) == len(day) and frame.attrs["validation"]["skipped"]["repeated header lines"] == [82]


def test_thousands_grouped_by_dots_beside_a_decimal_comma_are_read(tmp_path, day):
    """'1.073,3' (German Excel) had been unreadable text: every value of 1000 W/m² or more, a clear
    noon, set to NaN."""
    def german(value):
        whole, fraction = f"{value:.1f}".split(".")
        return (f"{int(whole):,}".replace(",", ".")) + "," + fraction

    rows = [f"{t};{german(g)};{german(n)};{german(d)}" for t, (g, n, d) in
            zip(day.index.strftime("%d.%m.%Y %H:%M"), day.to_numpy())]
    (tmp_path / "de.csv").write_text("Datum;GHI;DNI;DHI\n" + "\n".join(rows) + "\n")
    frame = read_weather(tmp_path / "de.csv", site="lanzhou")
    np.testing.assert_allclose(frame["ghi"].to_numpy(), day["ghi"].to_numpy(), atol=0.051)
    assert day["ghi"].max() >= 1000 and "unreadable" not in frame.attrs["validation"]


def test_thousands_grouped_by_dots_in_a_whole_numbered_file_are_read(tmp_path, day):
    """'1.063' beside '998' (German Excel, whole W/m², no decimal comma anywhere) had been read as
    1.063 W/m²: a clear noon read as night, without a word."""
    def german(value):
        return f"{int(round(value)):,}".replace(",", ".")

    rows = [f"{t};{german(g)};{german(n)};{german(d)}" for t, (g, n, d) in
            zip(day.index.strftime("%d.%m.%Y %H:%M"), day.to_numpy())]
    (tmp_path / "de.csv").write_text("Datum;GHI;DNI;DHI\n" + "\n".join(rows) + "\n")
    frame = read_weather(tmp_path / "de.csv", site="lanzhou")
    np.testing.assert_allclose(frame["ghi"].to_numpy(), day["ghi"].to_numpy(), atol=0.5)
    grouped = int((day[["ghi", "dni", "dhi"]].round() >= 1000).to_numpy().sum())
    assert grouped > 0 and sum(frame.attrs["validation"]["thousands_values"].values()) == grouped
    assert "'.' in" in frame.attrs["validation"]["thousands"]


@pytest.mark.parametrize("cells", [
    ["850.000", "998.000", "1.003"],  # three decimals everywhere: decimals, not groups
    ["850", "998", "1.5", "1.063"],  # a decimal beside the whole values
    ["0.850", "1", "1.063"],  # kW/m²: nothing whole is bright
])
def test_dots_that_may_be_decimals_stay_decimals(cells):
    from hybridtrack.io.weather import _thousands_by_dots

    values = np.array(cells, float)
    report = {}
    np.testing.assert_array_equal(_thousands_by_dots(cells, values, "dni", report), values)
    assert report == {}


def test_a_stamp_of_24_00_ends_its_day(tmp_path, day):
    """'21.06.2021 24:00', as many European hourly files close a day, had been refused as no time stamp."""
    hourly = day.iloc[6::6]  # 01:00 to 23:00
    stamps = list(hourly.index.strftime("%d.%m.%Y %H:%M")) + ["21.06.2021 24:00"]
    rows = [f"{t};{g};{n};{d}" for t, (g, n, d) in zip(stamps, np.vstack([hourly.to_numpy(), [[0.0, 0.0, 0.0]]]))]
    (tmp_path / "h24.csv").write_text("Datum;GHI;DNI;DHI\n" + "\n".join(rows) + "\n")
    frame = read_weather(tmp_path / "h24.csv", tz="Asia/Shanghai")
    assert frame.index[-1] == pd.Timestamp("2021-06-22 00:00", tz="Asia/Shanghai") and len(frame) == 24


@pytest.mark.parametrize("suffix, shown", [(" UTC+8", "'UTC+8' read as UTC+08:00"), (" GMT+8", "'GMT+8' read as UTC+08:00"),
                                           (" UTC+08:00", "'UTC+08:00' read as UTC+08:00"),
                                           (" +0800 (CST)", "'+0800 (CST)': the zone's name ignored")])
def test_offsets_written_after_utc_or_with_a_zone_name_are_read_with_the_iso_sign(tmp_path, capsys, day, suffix,
                                                                                  shown):
    """'... UTC+8' raised pandas' TypeError (a traceback), and pandas reads it as UTC-08:00 (POSIX)."""
    path = _write(tmp_path / "utc8.csv", day.index.strftime("%Y-%m-%d %H:%M:%S") + suffix, day)
    frame = read_weather(path, site="lanzhou")
    assert frame.index[0] == pd.Timestamp("2021-06-20 16:00", tz="UTC") and len(frame) == len(day)
    assert main(["check", str(path), "--site", "lanzhou"]) == 0
    assert shown in capsys.readouterr().out


def test_a_zone_the_reader_does_not_know_is_refused_naming_the_line(tmp_path, capsys, day):
    """'CST+8' is a POSIX zone string (UTC-08:00 to pandas, +08:00 to the logger): refused, not guessed."""
    path = _write(tmp_path / "posix.csv", day.index.strftime("%Y-%m-%d %H:%M:%S") + " CST+8", day)
    assert main(["check", str(path), "--site", "lanzhou"]) == 2
    err = capsys.readouterr().err
    assert "line 2, column 'time'" in err and "ends in a time zone hybridtrack does not read" in err
    assert len(err.strip().splitlines()) == 1


def test_a_field_over_the_csv_modules_limit_is_read_and_a_long_cell_is_not_a_number(tmp_path, day):
    """A 140,000-digit cell and a 200,000-character note line stopped the reader with csv's
    'field larger than field limit' traceback; the cell had then read as infinity."""
    stamps = day.index.strftime("%Y-%m-%d %H:%M")
    path = _write(tmp_path / "long.csv", stamps, day)
    lines = path.read_text().splitlines()
    lines[3] = lines[3].split(",")[0] + "," + "1" * 140_000 + ",0,0"
    path.write_text("Station notes: " + "y" * 200_000 + "\n" + "\n".join(lines) + "\n")
    frame = read_weather(path, site="lanzhou")
    assert len(frame) == len(day) and np.isnan(frame["ghi"].iloc[2]) and frame["ghi"].iloc[3] == day["ghi"].iloc[3]
    unreadable = frame.attrs["validation"]["unreadable"]["ghi"]
    assert unreadable["count"] == 1 and unreadable["lines"] == [5]
    assert unreadable["first"] == "'11111111111111111111'... (140,000 characters)"


def test_a_long_comment_column_in_readings_is_classified(tmp_path, capsys):
    """'hybridtrack classify FILE' with a 200,000-character quoted note stopped with a traceback."""
    (tmp_path / "r.csv").write_text('intensity,variation,note\n200,84,"' + "z" * 200_000 + '"\n250,20,ok\n')
    assert main(["classify", str(tmp_path / "r.csv")]) == 0
    assert "unknown 0" in capsys.readouterr().out


def test_a_quote_never_closed_is_refused_naming_its_line(tmp_path, day):
    """The csv module reads every line after an open quote into one field: rows and lines part."""
    path = _write(tmp_path / "q.csv", day.index.strftime("%Y-%m-%d %H:%M"), day)
    lines = path.read_text().splitlines()
    lines[4] = lines[4].replace(",", ',"', 1)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(HybridtrackError, match='line 5: a quote \\(\\"\\) opens a field and is never closed'):
        read_weather(path, site="lanzhou")


def test_a_statistics_column_is_never_the_quantity(tmp_path, day):
    """'WS_ms_Std' and 'GHI_Std' listed before their '_Avg' had been read as the wind and the GHI:
    a storm of 12-27 m/s replayed without one wind stow."""
    rows = [f"{t},{g / 50},{g},{n},{d},1.5,{20 + i % 7},{30 + i % 7}"
            for i, (t, (g, n, d)) in enumerate(zip(day.index.strftime("%Y-%m-%d %H:%M"), day.to_numpy()))]
    path = tmp_path / "stats.csv"
    path.write_text("TIMESTAMP,GHI_Std,GHI_Avg,DNI_Avg,DHI_Avg,WS_ms_Std,WS_ms_Avg,WS_ms_Max\n" + "\n".join(rows) + "\n")
    frame = read_weather(path, site="lanzhou")
    assert frame.attrs["validation"]["columns"]["ghi"] == "GHI_Avg"
    assert frame.attrs["validation"]["columns"]["wind_speed"] == "WS_ms_Avg"
    np.testing.assert_array_equal(frame["ghi"], day["ghi"])
    assert frame["wind_speed"].iloc[8] == 21.0  # 20 + 8 % 7, the mean, not the deviation (1.5)


def test_two_columns_that_match_one_quantity_are_refused(tmp_path, capsys, day):
    """The first of 'GHI' and 'Global' had been taken without a word."""
    path = _write(tmp_path / "two.csv", day.index.strftime("%Y-%m-%d %H:%M"), day, header="time,GHI,Global,dhi")
    assert main(["check", str(path), "--site", "lanzhou"]) == 2
    err = capsys.readouterr().err
    assert "columns 'GHI' and 'Global' both look like ghi; say which holds it with --map ghi=COLUMN" in err
    assert main(["check", str(path), "--site", "lanzhou", "--map", "ghi=GHI", "--map", "dni=Global"]) == 0


@pytest.mark.parametrize("header, written, name, expected", [
    ("Wind Speed (kts)", 10.0, "wind_speed", 10 * 1852 / 3600), ("Wind Speed (knot)", 10.0, "wind_speed", 10 * 1852 / 3600),
    ("Wind Speed (km/h, 10-min mean)", 36.0, "wind_speed", 10.0), ("Temperature (Fahrenheit)", 50.0, "temp_air", 10.0),
    ("Sun sensor offset (arcmin)", 30.0, "pointing", 0.5)])
def test_units_in_brackets_the_reader_had_kept_as_notes_are_converted(tmp_path, day, header, written, name, expected):
    """'(kts)', '(knot)', '(Fahrenheit)', '(arcmin)' and a bracket with a comma had been notes, the
    values read in the frame's unit: a 6-13.6 m/s wind read as 12-26 m/s stowed all day."""
    rows = [f"{t},{g},{n},{d},{written}" for t, (g, n, d) in zip(day.index.strftime("%Y-%m-%d %H:%M"), day.to_numpy())]
    (tmp_path / "u.csv").write_text(f'time,ghi,dni,dhi,"{header}"\n' + "\n".join(rows) + "\n")
    frame = read_weather(tmp_path / "u.csv", site="lanzhou")
    assert frame[name].iloc[0] == pytest.approx(expected, rel=1e-12)
    assert name in frame.attrs["validation"]["units_converted"]


def test_a_unit_before_a_comma_that_the_reader_does_not_convert_is_refused(tmp_path, day):
    rows = [f"{t},{g},{n},{d},3" for t, (g, n, d) in zip(day.index.strftime("%Y-%m-%d %H:%M"), day.to_numpy())]
    (tmp_path / "u.csv").write_text('time,ghi,dni,dhi,"Wind (ft/s, mean)"\n' + "\n".join(rows) + "\n")
    with pytest.raises(HybridtrackError, match="the unit 'ft/s' is not one hybridtrack converts for wind_speed"):
        read_weather(tmp_path / "u.csv", site="lanzhou")


def test_thousands_grouped_by_commas_beside_a_decimal_point_are_read(tmp_path, day):
    """'"1,060.2"' (US Excel) had been unreadable text: every value of 1000 W/m² or more set to NaN."""
    rows = [f'{t},"{g:,.1f}","{n:,.1f}","{d:,.1f}"' for t, (g, n, d) in
            zip(day.index.strftime("%Y-%m-%d %H:%M"), day.to_numpy())]
    (tmp_path / "us.csv").write_text("time,GHI,DNI,DHI\n" + "\n".join(rows) + "\n")
    frame = read_weather(tmp_path / "us.csv", site="lanzhou")
    np.testing.assert_array_equal(frame["ghi"].to_numpy(), day["ghi"].to_numpy())
    grouped = int((day[["ghi", "dni", "dhi"]] >= 1000).to_numpy().sum())
    report = frame.attrs["validation"]
    assert grouped > 0 and sum(report["thousands_values"].values()) == grouped and "unreadable" not in report
    assert report["thousands"].startswith(f"',' in {grouped} values")


def test_a_decimal_comma_in_a_dot_decimal_column_is_not_taken_for_thousands(tmp_path, day):
    """Beside '0,5' (a decimal comma), '1,060' may be 1.06: both stay unreadable text, counted."""
    path = _write(tmp_path / "mixed.csv", day.index.strftime("%Y-%m-%d %H:%M"), day)
    lines = path.read_text().splitlines()
    lines[60], lines[61] = (line.split(",", 1)[0] + f',"{cell}",0,0' for line, cell in zip(lines[60:62], ("0,5", "1,060")))
    path.write_text("\n".join(lines) + "\n")
    report = read_weather(path, site="lanzhou").attrs["validation"]
    assert report["unreadable"]["ghi"]["lines"] == [61, 62] and "thousands" not in report


def test_a_time_column_wins_over_a_written_out_index(tmp_path, day):
    """A reset_index() export ('index,time,ghi,...') had its counter 0, 1, 2 taken for the time:
    'line 2, column 'index': '0' is not a time stamp'."""
    frame = day.rename_axis("time").reset_index().reset_index()
    frame.to_csv(tmp_path / "idx.csv", index=False)
    read = read_weather(tmp_path / "idx.csv", site="lanzhou")
    assert read.index[0] == day.index[0] and len(read) == len(day)


@pytest.fixture(scope="module")
def two_days():
    """15 and 16 June 2021 at Lanzhou, hourly: every number of a yy-mm-dd stamp is 31 or less."""
    days = synthetic("lanzhou", "2021-06-15", "2021-06-16", weather="sunny", freq="1h", seed=2)
    return days[["ghi", "dni", "dhi"]].round(1)


def test_year_first_two_digit_dates_are_told_by_their_days_running(tmp_path, two_days):
    """'21-06-15 12:00' (yy-mm-dd) had been read as 21 June 2015, day-first, and the report said
    so as if the column had told it: read day-first, the dates jump a year at midnight."""
    path = _write(tmp_path / "ymd.csv", two_days.index.strftime("%y-%m-%d %H:%M"), two_days)
    frame = read_weather(path, tz="Asia/Shanghai")
    assert frame.index[0] == pd.Timestamp("2021-06-15 00:00", tz="Asia/Shanghai")
    assert frame.index[-1] == pd.Timestamp("2021-06-16 23:00", tz="Asia/Shanghai") and len(frame) == 48
    assert frame.attrs["validation"]["date_order"] == "year-first (line 2 is no date month-first; read day-first, " \
                                                      "line 26 moves a month or more)"


def test_day_first_two_digit_dates_are_still_day_first(tmp_path, two_days):
    """'15-06-21' could be yy-mm-dd too (2015-06-21): read so, the dates would jump a year a day."""
    path = _write(tmp_path / "dmy.csv", two_days.index.strftime("%d-%m-%y %H:%M"), two_days)
    frame = read_weather(path, tz="Asia/Shanghai")
    assert frame.index[0] == pd.Timestamp("2021-06-15 00:00", tz="Asia/Shanghai") and len(frame) == 48
    assert frame.attrs["validation"]["date_order"].startswith("day-first")


def test_two_digit_dates_no_row_of_which_tells_the_order_are_refused(tmp_path, capsys, day):
    """A day of '21-06-21 HH:MM' is 21 June 2021 either way, but '21-06-15' on one day is 2021-06-15
    or 2015-06-21 and nothing in the file tells: refused with both readings, not guessed."""
    path = _write(tmp_path / "one.csv", day.index.strftime("21-06-15 %H:%M"), day)
    with pytest.raises(HybridtrackError) as refused:
        read_weather(path, tz="Asia/Shanghai")
    message = str(refused.value)
    assert message.startswith(f"{path}: line 2, column 'time': '21-06-15 00:00' could be day-first or year-first "
                              "(2015-06-21 or 2021-06-15), and no date in the column tells")
    assert main(["check", str(path), "--tz", "Asia/Shanghai"]) == 2
    err = capsys.readouterr().err
    assert err == f"hybridtrack: error: {message}\n"
    assert read_weather(path, tz="Asia/Shanghai", dayfirst=True).index[0] == pd.Timestamp("2015-06-21 00:00",
                                                                                          tz="Asia/Shanghai")


def test_two_digit_dates_that_read_the_same_every_way_are_read(tmp_path, day):
    """'21-06-21' is 21 June 2021 read day-first or year-first: nothing to decide, nothing refused."""
    frame = read_weather(_write(tmp_path / "same.csv", day.index.strftime("%d-%m-%y %H:%M"), day), tz="Asia/Shanghai")
    assert frame.index[0] == pd.Timestamp("2021-06-21 00:00", tz="Asia/Shanghai") and len(frame) == len(day)


@pytest.mark.parametrize("written", ["%d/%m/%y %H:%M", "%d/%m/%Y %H:%M"])
def test_a_gap_of_weeks_in_the_record_does_not_hide_its_date_order(tmp_path, written):
    """A logger off for seven weeks: read day-first the dates move a month once, at the gap; read
    year- or month-first they do at every midnight. Such files were refused as if no date told."""
    hours = pd.date_range("2021-05-01", "2021-05-10 23:00", freq="1h").append(
        pd.date_range("2021-07-01", "2021-07-10 23:00", freq="1h"))
    days = pd.DataFrame({"ghi": 0.0, "dni": 0.0, "dhi": 0.0}, index=hours)
    frame = read_weather(_write(tmp_path / "gap.csv", hours.strftime(written), days), tz="Asia/Shanghai")
    assert frame.index[0] == pd.Timestamp("2021-05-01 00:00", tz="Asia/Shanghai")
    assert frame.index[-1] == pd.Timestamp("2021-07-10 23:00", tz="Asia/Shanghai") and len(frame) == 480
    assert frame.attrs["validation"]["date_order"].startswith("day-first (")
    assert "read day-first, only 1 line moves a month or more: a gap" in frame.attrs["validation"]["date_order"]


def test_monthfirst_reads_a_one_day_two_digit_year_file_month_first(tmp_path, capsys, day):
    """'06/12/21' on one day is 12 June 2021 month-first or 21 December 2006 year-first; given
    --monthfirst it had still been refused as either, and the only way out offered was to edit the file."""
    path = _write(tmp_path / "us.csv", day.index.strftime("06/12/21 %H:%M"), day)
    frame = read_weather(path, tz="Asia/Shanghai", dayfirst=False)
    assert frame.index[0] == pd.Timestamp("2021-06-12 00:00", tz="Asia/Shanghai") and len(frame) == len(day)
    assert main(["check", str(path), "--tz", "Asia/Shanghai", "--monthfirst"]) == 0


def test_nul_padding_after_a_short_or_utf16_file_is_dropped_and_counted(tmp_path, day):
    """A card's unwritten tail within a file's first 4096 bytes had made it 'binary'; in UTF-16
    the last character's NUL half belongs to the text, the seven bytes after it do not."""
    rows = day.iloc[70:76]  # 11:40 to 12:30
    text = _write(tmp_path / "t.csv", rows.index.strftime("%Y-%m-%dT%H:%M:%S+08:00"), rows).read_text()
    for name, raw, count in (("short.csv", text.encode() + b"\x00" * 100, 100),
                             ("wide.csv", text.encode("utf-16") + b"\x00" * 7, 7)):
        (tmp_path / name).write_bytes(raw)
        frame = read_weather(tmp_path / name)
        assert (frame.index == rows.index).all() and np.array_equal(frame[["ghi", "dni", "dhi"]], rows)
        assert frame.attrs["validation"]["padding"] == {"count": count, "lines": [8]}


def test_nul_bytes_inside_the_text_are_refused_naming_the_line(tmp_path, capsys, day):
    path = _write(tmp_path / "cut.csv", day.index.strftime("%Y-%m-%dT%H:%M:%S+08:00"), day)
    lines = path.read_bytes().split(b"\n")
    path.write_bytes(b"\n".join(lines[:119] + [b"\x00" * 10 + lines[119]] + lines[120:]))
    message = f"{path}: line 120: NUL bytes inside the text (a damaged file?)"
    with pytest.raises(HybridtrackError, match=re.escape(message)):
        read_weather(path)
    assert main(["check", str(path)]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {message}\n"
