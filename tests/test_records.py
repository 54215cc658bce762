"""Recorded weather files: messy CSVs, pvlib formats, DST, derivations, resampling, clear errors."""

import os
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.io import read_weather, validation_report
from hybridtrack.io.resample import resample

ROOT = Path(__file__).resolve().parents[1]
PVLIB_DATA = Path(os.path.dirname(pvlib.__file__)) / "data"


def write(tmp_path, name, text, encoding="utf-8"):
    path = tmp_path / name
    path.write_bytes(text.encode(encoding) if isinstance(text, str) else text)
    return path


def test_semicolons_decimal_commas_header_block_and_units(tmp_path):
    path = write(tmp_path, "logger.csv", "Station: Lanzhou roof\nLogger: CR1000\n\n"
                 "Timestamp;Global [kW/m2];Direct Normal;Diffuse;Wind speed [km/h]\n"
                 "2021-06-21 12:00;0,9005;850,0;110,2;36,0\n2021-06-21 12:01;0,9010;851,5;111,0;18,0\n")
    frame = read_weather(path, tz="Asia/Shanghai")
    assert list(frame.columns) == ["ghi", "dni", "dhi", "wind_speed"]
    assert frame["ghi"].iloc[0] == pytest.approx(900.5) and frame["wind_speed"].iloc[0] == pytest.approx(10.0)
    report = frame.attrs["validation"]
    assert report["skipped"]["notes before the header"] == [1, 2]
    assert report["separator"] == "semicolon" and report["decimal"] == ","
    assert frame.index[0] == pd.Timestamp("2021-06-21 12:00", tz="Asia/Shanghai")


def test_iso_stamps_with_offsets_keep_them_or_convert(tmp_path):
    path = write(tmp_path, "iso.csv", "time,ghi,dni,dhi\n2021-06-21T12:00:00+08:00,900,800,100\n"
                 "2021-06-21T12:01:00+08:00,901,801,100\n")
    kept = read_weather(path)
    assert kept.index[0].utcoffset() == pd.Timedelta(hours=8)
    converted = read_weather(path, tz="UTC")
    assert converted.index[0] == pd.Timestamp("2021-06-21 04:00", tz="UTC")


def test_naive_stamps_need_a_time_zone(tmp_path):
    path = write(tmp_path, "naive.csv", "time,ghi,dni,dhi\n2021-06-21 12:00,900,800,100\n2021-06-21 12:01,9,8,1\n")
    with pytest.raises(HybridtrackError, match="naive time stamps.*give the time zone"):
        read_weather(path)
    assert str(read_weather(path, tz="Asia/Shanghai").index.tz) == "Asia/Shanghai"


def test_dst_fall_back_and_spring_forward(tmp_path):
    fall = pd.date_range("2021-11-07 00:00", "2021-11-07 03:00", freq="30min", tz="America/New_York")
    path = write(tmp_path, "fall.csv", pd.DataFrame({"time": fall.tz_localize(None).strftime("%Y-%m-%d %H:%M"),
                                                     "ghi": 0, "dni": 0, "dhi": 0}).to_csv(index=False))
    frame = read_weather(path, tz="America/New_York")
    assert frame.index.equals(fall) and frame.attrs["validation"]["dst_repeated"]["count"] == 4
    spring = pd.date_range("2021-03-14 00:00", "2021-03-14 04:00", freq="30min")
    path = write(tmp_path, "spring.csv", pd.DataFrame({"time": spring.strftime("%Y-%m-%d %H:%M"),
                                                       "ghi": 0, "dni": 0, "dhi": 0}).to_csv(index=False))
    frame = read_weather(path, tz="America/New_York")
    dropped = frame.attrs["validation"]["dst_dropped"]
    assert dropped["count"] == 2 and dropped["lines"] == [6, 7] and len(frame) == 7
    assert ("dropped (DST: stamps that do not exist, or repeated ones their order could not place): count 2, "
            "lines 6, 7") in validation_report(frame)


def test_missing_dni_by_closure_or_decomposition(tmp_path):
    times = pd.date_range("2013-06-21 08:00", periods=5, freq="1h", tz="Asia/Shanghai")
    ghi, dhi = np.array([400.0, 600, 800, 900, 850]), np.array([100.0, 120, 130, 140, 135])
    path = write(tmp_path, "gd.csv", pd.DataFrame({"time": times.strftime("%Y-%m-%dT%H:%M:%S%z"), "ghi": ghi,
                                                   "dhi": dhi}).to_csv(index=False))
    with pytest.raises(HybridtrackError, match="dni missing; deriving it needs the sun's position"):
        read_weather(path)
    closure = read_weather(path, site="nanjing")
    from hybridtrack.sun import solar_position

    # pvlib documents the true (not refraction-corrected) zenith for closure, erbs and dirint
    zenith = solar_position(closure.index, "nanjing")["zenith"]
    cos_z = np.cos(np.radians(zenith))
    np.testing.assert_allclose(closure["dni"] * cos_z + closure["dhi"], ghi, rtol=1e-9)
    assert closure.attrs["dni_source"].startswith("closure")
    path = write(tmp_path, "g.csv", pd.DataFrame({"time": times.strftime("%Y-%m-%dT%H:%M:%S%z"), "ghi": ghi})
                 .to_csv(index=False))
    erbs = read_weather(path, site="nanjing")
    assert erbs.attrs["dni_source"].startswith("erbs") and (erbs["dni"] > 0).all() and (erbs["dhi"] > 0).all()
    expected = pvlib.irradiance.erbs(pd.Series(ghi, index=times), zenith.to_numpy(), times)
    np.testing.assert_allclose(erbs["dni"], expected["dni"], rtol=1e-12)
    dirint = read_weather(path, site="nanjing", decomposition="dirint")
    assert dirint.attrs["dni_source"].startswith("dirint")
    np.testing.assert_allclose(dirint["dni"], pvlib.irradiance.dirint(pd.Series(ghi, index=times), zenith.to_numpy(),
                                                                      times).fillna(0.0), rtol=1e-12)


def test_five_minute_data_is_interpolated_to_the_control_step(tmp_path):
    times = pd.date_range("2021-06-21 12:00", periods=4, freq="5min", tz="Asia/Shanghai")
    path = write(tmp_path, "5min.csv", pd.DataFrame({"time": times.strftime("%Y-%m-%dT%H:%M:%S%z"),
                                                     "ghi": [900, 950, 900, 850], "dni": [800, 850, 800, 750],
                                                     "dhi": 100}).to_csv(index=False))
    frame = read_weather(path, freq="1min")
    assert len(frame) == 16 and frame["ghi"].iloc[1] == pytest.approx(910.0)
    assert frame.attrs["resampling"].startswith("linear in time from 5min to 1min")
    ten = read_weather(path, freq="10min")
    assert ten["ghi"].iloc[0] == pytest.approx(925.0) and ten.attrs["resampling"] == "mean over each 10min step"


def test_upsampling_invents_no_value_beside_a_nan_reading(tmp_path):
    """interpolate(limit=...) filled the first steps of every NaN stretch: an hourly file with GHI
    NaN from 12:00 to 17:00 got 12:01 = 889.3 W/m², a line from 11:00 to 18:00, though the report
    said gaps were left empty."""
    times = pd.date_range("2021-06-21 10:00", "2021-06-21 18:00", freq="1h", tz="Asia/Shanghai")
    ghi = [800.0, 900.0, *[np.nan] * 6, 420.0]  # 12:00-17:00 missing
    path = write(tmp_path, "h.csv", pd.DataFrame({"time": times.strftime("%Y-%m-%dT%H:%M:%S%z"), "ghi": ghi,
                                                  "dni": 700.0, "dhi": 100.0}).to_csv(index=False))
    frame = read_weather(path, freq="1min")
    assert frame.loc["2021-06-21 10:30", "ghi"] == pytest.approx(850.0)  # (800 + 900) / 2
    assert frame.loc["2021-06-21 11:00", "ghi"] == 900.0 and frame.loc["2021-06-21 18:00", "ghi"] == 420.0
    assert frame.loc["2021-06-21 11:01":"2021-06-21 17:59", "ghi"].isna().all()
    assert frame.loc["2021-06-21 12:30", "dni"] == 700.0  # a column with its readings is interpolated


def test_upsampling_counts_every_value_left_empty_by_column():
    """The count was of steps empty in every column: GHI missing all afternoon beside measured DNI
    and DHI read 'empty 0', though the docs count every step a NaN reading leaves empty."""
    times = pd.date_range("2021-06-21 10:00", "2021-06-21 18:00", freq="1h", tz="Asia/Shanghai")
    dni = [700.0] * 9
    dni[5] = np.nan  # 15:00
    frame = pd.DataFrame({"ghi": [800.0, 900.0, *[np.nan] * 6, 420.0], "dni": dni, "dhi": 100.0}, index=times)
    report = {}
    resample(frame, "1min", report, {})
    # ghi: 11:01 to 17:59 (7 h less a minute); dni: 14:01 to 15:59 (2 h less a minute)
    assert report["resampled"]["empty"] == 419 + 119
    assert report["resampled"]["empty_by_column"] == {"ghi": 419, "dni": 119}


def test_the_report_says_the_values_left_empty_by_column(tmp_path):
    times = pd.date_range("2021-06-21 10:00", "2021-06-21 18:00", freq="1h", tz="Asia/Shanghai")
    ghi = [800.0, 900.0, *[np.nan] * 6, 420.0]
    path = write(tmp_path, "h.csv", pd.DataFrame({"time": times.strftime("%Y-%m-%dT%H:%M:%S%z"), "ghi": ghi,
                                                  "dni": 700.0, "dhi": 100.0}).to_csv(index=False))
    assert "empty 419: ghi 419)" in validation_report(read_weather(path, freq="1min"))


def test_checks_sort_deduplicate_clip_flag_and_count(tmp_path):
    path = write(tmp_path, "messy.csv", "time,ghi,dni,dhi,wind_speed\n"
                 "2021-06-21 12:00,-3,0,0,2\n2021-06-21 12:02,900,800,100,3\n2021-06-21 12:01,905,5000,100,-4\n"
                 "2021-06-21 12:02,900,800,100,3\n2021-06-21 12:03,,800,100,3\n2021-06-21 12:10,900,800,100,3\n")
    frame = read_weather(path, tz="Asia/Shanghai")
    report = frame.attrs["validation"]
    assert report["unsorted"]["count"] == 1 and report["duplicates"]["count"] == 1
    assert report["negative_clipped"]["ghi"]["lines"] == [2] and frame["ghi"].iloc[0] == 0.0
    assert report["impossible"]["dni"]["lines"] == [4] and report["impossible"]["wind_speed"]["count"] == 1
    assert report["nan"]["ghi"] == 1 and report["gaps"]["count"] == 1 and report["gaps"]["longest"] == "7min"
    assert np.isnan(frame.loc["2021-06-21 12:01", "dni"])


def test_pvlib_formats_go_through_pvlib(tmp_path):
    tmy = read_weather(PVLIB_DATA / "723170TYA.CSV", format="tmy3")
    assert len(tmy) == 8760 and set(tmy.columns) >= {"ghi", "dni", "dhi", "temp_air", "wind_speed"}
    assert tmy.index.tz is not None and tmy.attrs["validation"]["format"] == "tmy3"
    epw = write(tmp_path, "tiny.epw", EPW)
    frame = read_weather(epw, format="epw")
    assert len(frame) == 3 and frame["dni"].iloc[1] == 612.0 and frame["temp_air"].iloc[1] == pytest.approx(21.5)
    with pytest.raises(HybridtrackError, match="pvlib could not read it as EPW"):
        read_weather(write(tmp_path, "bad.epw", "not an epw\n"), format="epw")


EPW_HEADER = ("LOCATION,Nanjing,JS,CHN,SYN,582380,31.93,118.90,8.0,7.1\nDESIGN CONDITIONS,0\n"
              "TYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\n"
              "COMMENTS 1,test\nCOMMENTS 2,test\n"
              "DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n")


def _epw_row(hour, ghi, dni, dhi, temp, date=(2013, 6, 21)):
    fields = [*date, hour, 0, "?", temp, 15.0, 60, 101000, 0, 0, 350, ghi, dni, dhi, 0, 0, 0, 0, 180, 3.0, 5, 5,
              20.0, 77777, 9, 999999999, 0, 0.1, 0, 88, 0.2, 0, 1]
    return ",".join(map(str, fields))


EPW = EPW_HEADER + "\n".join(_epw_row(h, g, d, f, t) for h, g, d, f, t in
                             ((11, 700, 600, 120, 21.0), (12, 720, 612, 125, 21.5), (13, 690, 590, 118, 21.9))) + "\n"


def _epw_days(dates) -> str:
    """An EPW of whole days at Nanjing: 500/400/100 W/m² from 09:00 to 15:00, dark otherwise (hour h
    of a day is the hour that starts at h - 1)."""
    rows = [_epw_row(hour, *((500, 400, 100) if 10 <= hour <= 16 else (0, 0, 0)), 10.0, date=date)
            for date in dates for hour in range(1, 25)]
    return EPW_HEADER + "\n".join(rows) + "\n"


def test_a_leap_year_of_real_data_in_an_epw_keeps_its_29_february(tmp_path, capsys):
    """An AMY file of 2020 was refused with pvlib's cut message ('day is out of range for month.
    You might want to try:'): every EPW was coerced into 2019, which has no 29 February."""
    path = write(tmp_path, "amy2020.epw", _epw_days([(2020, 2, 28), (2020, 2, 29), (2020, 3, 1)]))
    frame = read_weather(path)
    assert frame.index[0] == pd.Timestamp("2020-02-28 00:00", tz="Etc/GMT-8") and len(frame) == 72
    assert frame.loc["2020-02-29 09:00", "ghi"] == 500.0 and frame.loc["2020-02-29 16:00", "ghi"] == 0.0
    assert "the file's own years" in frame.attrs["validation"]["time"]
    assert main(["check", str(path)]) == 0


@pytest.mark.parametrize("dates", [[(2020, 2, 28), (2020, 2, 29), (2020, 3, 1)], [(2020, 12, 31), (2021, 1, 1)]])
def test_an_epw_of_real_years_with_a_missing_hour_keeps_its_years(tmp_path, dates):
    """One hour missing from an AMY file (line 20 here) made its steps unsteady: it was taken for a
    typical year, so a 2020 with 29 February was refused, and 31 December 2020 was put after
    1 January in 2019, a year apart."""
    lines = _epw_days(dates).splitlines()
    path = write(tmp_path, "amy-gap.epw", "\n".join(lines[:19] + lines[20:]) + "\n")
    frame = read_weather(path)
    assert frame.index[0] == pd.Timestamp(*dates[0], tz="Etc/GMT-8") and len(frame) == 24 * len(dates) - 1
    assert frame.index[-1] == pd.Timestamp(*dates[-1], 23, tz="Etc/GMT-8")
    assert "the file's own years" in frame.attrs["validation"]["time"]


def test_29_february_in_a_typical_year_epw_is_refused_naming_the_line(tmp_path, capsys):
    """A typical year's months come from different years (here a 2012 February after a 2005
    January): it is read in 2019, which has no 29 February."""
    typical = read_weather(write(tmp_path, "tmy-ok.epw", _epw_days([(2005, 1, 31), (2012, 2, 28)])))
    assert typical.index[0] == pd.Timestamp("2019-01-31 00:00", tz="Etc/GMT-8")
    assert typical.index[-1] == pd.Timestamp("2019-02-28 23:00", tz="Etc/GMT-8")
    path = write(tmp_path, "tmy.epw", _epw_days([(2005, 1, 31), (2012, 2, 29)]))
    message = (f"{path}: line 33: 29 February in a typical-year file (its stamps do not run forward through "
               "real years), which is read in 2019, a year without one; remove that day")
    with pytest.raises(HybridtrackError) as refused:
        read_weather(path)
    assert str(refused.value) == message
    assert main(["check", str(path)]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {message}\n"


def test_the_shipped_records_read_back_with_their_labels():
    frame = read_weather(ROOT / "data" / "nanjing-2013-cloudy.csv")
    assert len(frame) == 4 * 901 and set(frame["sky"].unique()) == {"cloudy"}
    assert frame.attrs["validation"]["gaps"]["count"] == 3  # the nights between the four days


def test_the_shipped_records_regenerate_byte_for_byte():
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_typical_days", ROOT / "data" / "make_typical_days.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for site, weather in (("lanzhou", "sunny"), ("nanjing", "overcast")):
        assert module.make(site, weather) == (ROOT / "data" / module.file_name(site, weather)).read_text()


@pytest.mark.parametrize("content, kwargs, message", [
    (None, {}, "no such file"),
    ("", {}, "the file is empty"),
    (b"\x89PNG\r\n\x1a\n\x00\x00binary", {}, "looks binary"),
    ("time,ghi\n2021-06-21 12:00,9\u00e900\n".encode("latin-1"), {"tz": "UTC"},
     "line 2, column 'ghi': '9\u00e900' is not"),
    ("a,b\n1,2\n3,4\n", {}, "no time column found"),
    ("time,pressure\n2021-06-21 12:00,1000\n2021-06-21 12:01,1000\n", {"tz": "UTC"}, "no irradiance column"),
    ("time,ghi\n2021-06-21 12:00,900\n2021-06-21 12:01,lots\n", {"tz": "UTC"}, "line 3, column 'ghi': 'lots' is not"),
    ("time,ghi\nyesterday,900\nnoon,900\n", {"tz": "UTC"}, "line 2, column 'time': 'yesterday' is not a time"),
    ("time,ghi\n2021-06-21 12:00,900\n2021-06-21 12:01,900\n", {"tz": "UTC", "columns": {"dni": "Beam"}},
     "no column 'Beam' \\(mapped to dni\\); columns are time, ghi"),
    ("time,ghi\n2021-06-21 12:00,900\n2021-06-21 12:01,900\n", {"tz": "Mars/Base"}, "unknown time zone 'Mars/Base'"),
    ("time,ghi\n2021-06-21 12:00,9000\n2021-06-21 12:01,9100\n", {"tz": "UTC"},
     "100% of values are outside.*wrong unit"),
    ("time,ghi\n2021-06-21 12:00,900\n2021-06-21 12:01,900\n", {"tz": "UTC", "units": {"ghi": "furlongs"}},
     "unknown unit 'furlongs'"),
    ("time,ghi\n2021-06-21 12:00,900\n", {"tz": "UTC"}, "fewer than two distinct time stamps"),
    ("time,ghi\n2021-06-21 12:00,900\n2021-06-21 12:01,900\n", {"format": "xlsx"}, "unknown format 'xlsx'"),
])
def test_bad_files_give_one_clear_line(tmp_path, content, kwargs, message):
    path = tmp_path / "bad.csv" if content is None else write(tmp_path, "bad.csv", content)
    with pytest.raises(HybridtrackError, match=message) as error:
        read_weather(path, **kwargs)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("name", sorted(p.name for p in (ROOT / "data").glob("*-*.csv")))
def test_the_shipped_days_follow_their_sites_sun_and_pass_the_magnitude_check(name):
    frame = read_weather(ROOT / "data" / name, site=name.split("-")[0])
    assert frame.attrs["validation"]["sun_check"].startswith("light follows the sun")


def _shifted_record(tmp_path, seed, weather, shift):
    """A synthetic Lanzhou day at 1 min written with its stamps moved by `shift` (a wrong clock)."""
    from hybridtrack.sky import synthetic

    frame = synthetic("lanzhou", "2021-06-21", weather=weather, seed=seed)
    stamps = (frame.index + pd.Timedelta(shift)).tz_convert("Asia/Shanghai")
    path = tmp_path / f"{weather}-{seed}.csv"
    pd.DataFrame({"time": stamps.strftime("%Y-%m-%d %H:%M"), "ghi": frame["ghi"].round(1),
                  "dni": frame["dni"].round(1), "dhi": frame["dhi"].round(1)}).to_csv(path, index=False)
    return path


@pytest.mark.parametrize("seed, weather", [(1, "mixed"), (2, "mixed"), (3, "cloudy"), (4, "overcast"),
                                           (5, "sunny")])
def test_the_sun_check_passes_true_clocks_under_any_sky_and_half_an_hour_off(tmp_path, seed, weather):
    for shift in ("0min", "30min", "-30min"):
        frame = read_weather(_shifted_record(tmp_path, seed, weather, shift), site="lanzhou")
        assert frame.attrs["validation"]["sun_check"].startswith("light follows the sun"), (shift, weather)


@pytest.mark.parametrize("shift, fits", [("1h", "shifted by -1h, i.e. stamps in UTC+09:00"),
                                         ("-2h", "shifted by +2h, i.e. stamps in UTC+06:00")])
def test_the_sun_check_refuses_a_clock_an_hour_or_more_off_and_names_the_offset(tmp_path, shift, fits):
    path = _shifted_record(tmp_path, 1, "mixed", shift)
    with pytest.raises(HybridtrackError, match=fits.replace("+", r"\+")):
        read_weather(path, site="lanzhou")
    frame = read_weather(path, site="lanzhou", lenient=True)
    assert frame.attrs["validation"]["sun_check"].startswith("WARNING")
    assert "verdict: usable" in validation_report(frame)


def test_excels_separator_line_is_obeyed(tmp_path):
    path = write(tmp_path, "excel.csv", "sep=;\nZeit;GHI;DNI;DHI\n2021-06-21T12:00+08:00;900,5;800;100\n"
                 "2021-06-21T12:01+08:00;901;801;101\n")
    frame = read_weather(path)
    assert frame["ghi"].tolist() == [900.5, 901.0] and "sep=;" in frame.attrs["validation"]["table"]


def test_midc_through_pvlib_maps_its_names(tmp_path):
    from hybridtrack import sites

    path = ROOT / "tests" / "records" / "midc-bms.csv"
    golden = sites.custom(39.742, -105.18, "Etc/GMT+7", 1829.0)
    frame = read_weather(path, format="midc", site=golden)
    reference = pvlib.iotools.read_midc(str(path))
    np.testing.assert_array_equal(frame["dni"], reference["Direct Normal [W/m^2]"].astype(float))
    np.testing.assert_array_equal(frame["temp_air"], reference["Tower Dry Bulb Temp [deg C]"].astype(float))
    assert frame.attrs["validation"]["format"] == "midc"


def test_the_fast_number_path_matches_the_careful_one(tmp_path):
    """Clean columns are parsed in one numpy call; a column with a missing-value word goes cell by cell."""
    cells = ["1.5", "-0.25", "1e400", "inf", "nan", "  3 ", "+2", "1e-3", "850"]
    stamps = pd.date_range("2021-06-21 12:00", periods=len(cells), freq="1min").strftime("%Y-%m-%dT%H:%M+08:00")
    fast = write(tmp_path, "fast.csv", "time,ghi\n" + "".join(f"{t},{c}\n" for t, c in zip(stamps, cells)))
    careful = write(tmp_path, "careful.csv", "time,ghi\n" + "".join(f"{t},{c}\n" for t, c in zip(stamps, cells))
                    + "2021-06-21T12:09+08:00,N/A\n")
    reference = np.array([float(c) for c in cells])  # Python's own float() is the reference
    reference[~((reference >= -50) & (reference <= 1500))] = np.nan  # inf and 1e400 are impossible
    reference[reference < 0] = np.nan  # negative at noon, the sun well up: no night offset (test_records_sun_up.py)
    np.testing.assert_array_equal(read_weather(fast, site="lanzhou")["ghi"].to_numpy(), reference)
    np.testing.assert_array_equal(read_weather(careful, site="lanzhou")["ghi"].to_numpy()[:-1], reference)


def test_packed_station_files_go_through_pvlib_decoded(tmp_path):
    """An EPW gzipped, and EnergyPlus's zip of .epw, .stat and .ddy, read like the plain EPW."""
    import gzip
    import zipfile

    epw = (ROOT / "tests" / "records" / "lanzhou.epw").read_text()
    plain = read_weather(ROOT / "tests" / "records" / "lanzhou.epw")
    packed = write(tmp_path, "lanzhou.epw.gz", gzip.compress(epw.encode()))
    bundle = tmp_path / "CHN_GS_Lanzhou.zip"
    with zipfile.ZipFile(bundle, "w") as archive:
        archive.writestr("CHN_GS_Lanzhou.epw", epw)
        archive.writestr("CHN_GS_Lanzhou.stat", "statistics")
        archive.writestr("CHN_GS_Lanzhou.ddy", "design days")
    for path in (packed, bundle):
        frame = read_weather(path)
        pd.testing.assert_frame_equal(frame, plain, check_like=True)
        assert frame.attrs["validation"]["format"] == "epw"


def test_a_loggers_sensor_pointing_column_is_read_in_degrees(tmp_path):
    """'Sensor offset [mrad]' is the sun sensor's pointing signal: read as ``pointing`` in degrees
    (1 mrad = 0.0572958°), its gaps kept as NaN (no reading), and the conversion reported."""
    path = tmp_path / "logger.csv"
    path.write_text("Timestamp,GHI [W/m2],DNI [W/m2],DHI [W/m2],Sensor offset [mrad]\n"
                    "2021-06-21 12:00,1000,900,100,1.0\n2021-06-21 12:01,1000,900,100,\n"
                    "2021-06-21 12:02,1000,900,100,-2.5\n")
    frame = read_weather(path, tz="Asia/Shanghai")
    np.testing.assert_allclose(frame["pointing"].to_numpy(), [0.0572958, np.nan, -0.1432394], rtol=1e-6)
    assert frame.attrs["validation"]["units_converted"]["pointing"] == "mrad -> °"
