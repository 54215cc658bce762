"""The recorded-file corpus (tests/records): each file reads to exactly its truth, or is refused in one line.

The truths are plain ISO-UTC tables read here with pandas alone; the corpus files are the same
weather in the shapes loggers and stations write (tests/records/README.md). A file that is read
must give the truth's stamps and values, with only the changes its quirks call for, through the
API and through ``hybridtrack check --out``; a file that is refused must be refused with one
line naming the problem, the row and the column, by the API (HybridtrackError) and the CLI
(exit status 2, no traceback). pvlib's own readers and models are the reference for the
station formats and the gap filling.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib
import pytest

from hybridtrack import HybridtrackError, sites
from hybridtrack.cli import main
from hybridtrack.io import read_weather

RECORDS = Path(__file__).resolve().parent / "records"
sys.path.insert(0, str(RECORDS))
from make_records import truth  # noqa: E402

SHANGHAI = "Asia/Shanghai"
GOLDEN = sites.custom(39.742, -105.18, "Etc/GMT+7", 1829.0, name="golden")
EUGENE = sites.custom(44.0467, -123.0743, "Etc/GMT+8", 150.0, name="eugene")
ALL = ["ghi", "dni", "dhi", "wind_speed", "temp_air"]
PVLIB_DATA = Path(os.path.dirname(pvlib.__file__)) / "data"


def read(truth_name, columns=ALL, **expect):
    return {"truth": truth_name, "columns": columns, **expect}


def refused(*parts):
    return {"refused": parts}


#: An NSRDB PSM3 file: every third row of the truth (half-hourly), irradiance written in whole
#: W/m² and wind in tenths, its site (Golden, at NSRDB's grid point) from its site lines.
PSM3 = {"every": 3, "decimals": {"ghi": 0, "dni": 0, "dhi": 0, "wind_speed": 1},
        "site": ("NSRDB 149190", 39.74, -105.18, 1829.0, "Etc/GMT+7")}

# (id, file, read_weather keywords, what must come out)
CASES = [
    ("pandas index, offsets", "pandas-index.csv", {}, read("lanzhou-day")),
    ("pandas index, --map time=", "pandas-index.csv", {"columns": {"time": ""}}, read("lanzhou-day")),
    ("pandas index, --map time='Unnamed: 0'", "pandas-index.csv", {"columns": {"time": "Unnamed: 0"}},
     read("lanzhou-day")),
    ("pandas index, naive, site's zone", "pandas-index-naive.csv", {"site": "lanzhou"}, read("lanzhou-day")),
    ("naive stamps, no zone, no site", "naive-no-zone.csv", {},
     refused("line 2, column ''", "naive time stamps", "give the time zone")),
    ("Campbell TOA5", "toa5-cr1000.dat", {"tz": SHANGHAI}, read("lanzhou-day")),
    ("TOA5 with a card's NUL padding", "toa5-nul-padded.dat", {"tz": SHANGHAI},
     read("lanzhou-day", report={"padding": (None, 512)}, padding_line=102)),
    ("TOA5, WS_ms_S_WVT, zero offsets", "toa5-wvt-offsets.dat", {"site": "lanzhou"},
     read("lanzhou-day", zero={"wind_speed": [0, 1, 2, 3]}, report={"calm_clipped": ("wind_speed", 4)})),
    ("dd.mm.yyyy, semicolons, decimal commas", "dotted-dates.csv", {"tz": SHANGHAI}, read("lanzhou-day")),
    ("ISO T stamps, semicolons, decimal commas", "iso-t-semicolons.csv", {"tz": SHANGHAI},
     read("lanzhou-day", decimal=",")),
    ("French Date;Heure, Windows-1252, CRLF", "french-date-heure.csv", {"site": "lanzhou"},
     read("lanzhou-days", order="day-first (line 194 is no date month-first)", decimal=",")),
    ("tabs and decimal commas", "tab-decimal-commas.txt", {"tz": SHANGHAI},
     read("lanzhou-day", ["ghi", "dni", "dhi", "temp_air"], wind="missing", decimal=",")),
    ("quoted decimal commas, comma-separated", "quoted-decimal-commas.csv", {"tz": SHANGHAI},
     read("lanzhou-day", decimal=",")),
    ("dd/mm/yyyy over ten days", "ddmmyyyy-days.csv", {"site": "lanzhou"},
     read("lanzhou-days", ["ghi", "dni", "dhi"], wind="missing")),
    ("mm/dd/yyyy over ten days", "mmddyyyy-days.csv", {"site": "lanzhou"},
     read("lanzhou-days", ["ghi", "dni", "dhi"], wind="missing")),
    ("05/06/2021 alone is ambiguous", "ambiguous-dates.csv", {"site": "lanzhou"},
     refused("line 2, column 'Date/Time'", "could be day-first or month-first", "--dayfirst")),
    ("05/06/2021 with --dayfirst", "ambiguous-dates.csv", {"site": "lanzhou", "dayfirst": True},
     read("lanzhou-day", ["ghi", "dni", "dhi"], wind="missing")),
    ("yy-mm-dd over ten days", "yymmdd-days.csv", {"site": "lanzhou"},
     read("lanzhou-days", ["ghi", "dni", "dhi"], wind="missing",
          order="year-first (line 2 is no date month-first; read day-first, line 26 moves a month or more)")),
    ("yy-mm-dd on one day is ambiguous", "yymmdd-one-day.csv", {"site": "lanzhou"},
     refused("line 2, column 'Date/Time': '21-06-05 05:00' could be day-first or year-first (2005-06-21 or "
             "2021-06-05)", "write the years with four digits")),
    ("yymmdd over ten days", "yymmdd-six-digits.csv", {"site": "lanzhou"},
     read("lanzhou-days", ["ghi", "dni", "dhi"], wind="missing", order="year-first (line 2 is no date month-first")),
    ("the clock before dd/mm/yyyy", "clock-first-days.csv", {"site": "lanzhou"},
     read("lanzhou-days", ["ghi", "dni", "dhi"], wind="missing", order="day-first (line 194 is no date month-first)")),
    ("HH:MM only", "clock-only.csv", {"site": "lanzhou"}, refused("line 2, column 'Time'", "has no date")),
    ("date and time columns", "date-and-time-columns.csv", {"tz": SHANGHAI},
     read("lanzhou-day", ["ghi", "dni", "dhi", "wind_speed"])),
    ("epoch seconds", "epoch-seconds.csv", {}, read("lanzhou-day", ["ghi", "dni", "dhi", "wind_speed"])),
    ("UTC logger declared local", "utc-declared-local.csv", {"site": "lanzhou"},
     refused("line 8, column 'DNI'", "while the sun is down", "shifted by +8h", "stamps in UTC+00:00")),
    ("UTC logger, --tz UTC at the site", "utc-declared-local.csv", {"site": "lanzhou", "tz": "UTC"},
     read("lanzhou-day", ["ghi", "dni", "dhi", "wind_speed"])),
    ("UTC logger declared local, --lenient", "utc-declared-local.csv", {"site": "lanzhou", "lenient": True},
     read("lanzhou-day", ["ghi", "dni", "dhi", "wind_speed"], shift="-8h", warning=True)),
    ("kW/m² unlabelled, at a site", "kilowatts-unlabelled.csv", {"site": "lanzhou"},
     refused("line 50, column 'GHI'", "look like kW/m² read as W/m²", "--units ghi=kW/m2")),
    ("kW/m² unlabelled, no site", "kilowatts-unlabelled.csv", {},
     refused("line 50, column 'GHI'", "at most 1.1413 over 16 hours", "kW/m²")),
    ("kW/m² unlabelled, --units", "kilowatts-unlabelled.csv",
     {"units": {"ghi": "kW/m2", "dni": "kW/m2", "dhi": "kW/m2"}}, read("lanzhou-day", ["ghi", "dni", "dhi"])),
    ("kW/m² labelled", "kilowatts-labelled.csv", {}, read("lanzhou-day", ["ghi", "dni", "dhi", "wind_speed"])),
    ("inf and 1e400", "non-finite.csv", {}, read("lanzhou-day", ["ghi", "dni", "dhi", "wind_speed"],
                                                  nan={"dni": [49, 50]}, report={"impossible": ("dni", 2)})),
    ("W/m^2, W m-2, km/h, K", "caret-units.csv", {}, read("lanzhou-day", atol=2e-3)),
    ("(vent/cor) is a note", "header-notes.csv", {},
     read("lanzhou-day", ["ghi", "dni", "dhi"], notes="vent/cor", wind="missing")),
    ("semicolons, decimal commas, 0;0 rows", "semicolon-zero-rows.csv", {"site": "lanzhou"},
     read("lanzhou-day", ["ghi", "dni"], wind="missing")),
    ("plain logger CSV", "plain.csv", {"tz": SHANGHAI}, read("lanzhou-day")),
    ("gzip", "logger.csv.gz", {"tz": SHANGHAI}, read("lanzhou-day")),
    ("zip", "logger.zip", {"tz": SHANGHAI}, read("lanzhou-day")),
    ("Excel Unicode text (UTF-16, tabs)", "excel-unicode.txt", {"tz": SHANGHAI},
     read("lanzhou-day", ["ghi", "dni", "dhi", "temp_air"], wind="missing")),
    ("Latin-1 with degree signs", "latin1.csv", {"site": "lanzhou"},
     read("lanzhou-day", ["ghi", "dni", "temp_air"], wind="missing")),
    ("UTF-8 with BOM", "utf8-bom.csv", {"tz": SHANGHAI}, read("lanzhou-day")),
    ("# comments anywhere", "comments-anywhere.csv", {"tz": SHANGHAI}, read("lanzhou-day", comments=3)),
    ("repeated, unsorted, negative, NAN", "messy.csv", {"tz": SHANGHAI},
     read("lanzhou-day", nan={"dni": [60]}, report={"duplicates": (None, 1), "unsorted": (None, 1),
                                                     "negative_clipped": ("ghi", 1), "nan": ("dni", 1)})),
    ("GHI alone, Erbs", "ghi-only.csv", {"site": "lanzhou"}, read("lanzhou-day", ["ghi"], erbs=True, wind="missing")),
    ("EPW without --format", "lanzhou.epw", {}, {"pvlib": "epw"}),
    ("NREL MIDC", "midc-bms.csv", {"site": GOLDEN}, read("golden-day")),
    ("NREL MIDC at the wrong site", "midc-bms.csv", {"site": "lanzhou"},
     refused("line 9, column 'Direct Normal [W/m^2]'", "while the sun is down", "shifted by +620min",
             "beyond any time zone: is the file from another site? Give")),
    ("NSRDB PSM3 in local standard time", "nsrdb-psm3-local.csv", {}, read("golden-day", **PSM3)),
    ("NSRDB PSM3 in UTC", "nsrdb-psm3-utc.csv", {}, read("golden-day", **PSM3)),
    ("NSRDB PSM3 at the wrong site", "nsrdb-psm3-local.csv", {"site": "lanzhou"},
     refused("line 1: the file's header places it at NSRDB 149190 (39.740°, -105.180°)", "give the right site")),
    ("NOAA SURFRAD", "surfrad-bon.dat", {}, {"pvlib": "surfrad"}),
    ("University of Oregon SRML", "srml-eugene.tsv", {"site": EUGENE}, {"pvlib": "srml"}),
    ("BSRN station-to-archive", "bsrn-bon.dat", {}, {"pvlib": "bsrn"}),
    ("--units with an unknown name", "plain.csv", {"tz": SHANGHAI, "units": {"wind": "km/h"}},
     refused("unknown column name 'wind' in --units")),
    ("one column mapped twice", "plain.csv", {"tz": SHANGHAI, "columns": {"ghi": "GHI", "dni": "GHI"}},
     refused("column 'GHI' is mapped to both ghi and dni")),
    ("resampled to 7 minutes", "plain.csv", {"tz": SHANGHAI, "freq": "7min"}, {"interp": "lanzhou-day"}),
]


def cli_flags(kwargs: dict) -> list[str]:
    """The command-line flags that say what `kwargs` say to `read_weather`."""
    flags = []
    site = kwargs.get("site")
    if isinstance(site, str):
        flags += ["--site", site]
    elif site is not None:
        flags += ["--lat", str(site.latitude), "--lon", str(site.longitude)]
    if "tz" in kwargs:
        flags += ["--tz", kwargs["tz"]]
    for name, column in kwargs.get("columns", {}).items():
        flags += ["--map", f"{name}={column}"]
    for name, unit in kwargs.get("units", {}).items():
        flags += ["--units", f"{name}={unit}"]
    if kwargs.get("dayfirst") is not None:
        flags.append("--dayfirst" if kwargs["dayfirst"] else "--monthfirst")
    if kwargs.get("lenient"):
        flags.append("--lenient")
    if "freq" in kwargs:
        flags += ["--freq", kwargs["freq"]]
    return flags


def _expected(expect: dict) -> pd.DataFrame:
    frame = truth(expect["truth"])[expect["columns"]].iloc[::expect.get("every", 1)].copy()
    for name, digits in expect.get("decimals", {}).items():  # as the file writes them
        frame[name] = [float(f"{value:.{digits}f}") for value in frame[name]]
    for name, rows in expect.get("nan", {}).items():
        frame.iloc[rows, frame.columns.get_loc(name)] = np.nan
    for name, rows in expect.get("zero", {}).items():
        frame.iloc[rows, frame.columns.get_loc(name)] = 0.0
    if "shift" in expect:
        frame.index = frame.index + pd.Timedelta(expect["shift"])
    return frame


def _erbs_reference(ghi: pd.Series) -> pd.DataFrame:
    """pvlib's Erbs with pvlib's own SPA true zenith, as its docs ask."""
    site = sites.get("lanzhou")
    zenith = pvlib.solarposition.spa_python(ghi.index, site.latitude, site.longitude, altitude=site.altitude,
                                            pressure=pvlib.atmosphere.alt2pres(site.altitude),
                                            temperature=12.0)["zenith"]
    return pvlib.irradiance.erbs(ghi, zenith, ghi.index)


def check_read(frame: pd.DataFrame, expect: dict) -> None:
    expected = _expected(expect)
    assert frame.index.tz is not None
    pd.testing.assert_index_equal(frame.index.tz_convert("UTC"), expected.index.tz_convert("UTC"), check_names=False)
    for name in expected.columns:
        np.testing.assert_allclose(frame[name].to_numpy(float), expected[name].to_numpy(float), rtol=1e-9,
                                   atol=expect.get("atol", 1e-9), err_msg=name)
    report = frame.attrs["validation"]
    for key, (column, count) in expect.get("report", {}).items():
        entry = report[key] if column is None else report[key][column]
        assert (entry["count"] if isinstance(entry, dict) else entry) == count, key
    assert frame.attrs["wind_data"] == expect.get("wind", "measured")
    if frame.attrs["wind_data"] == "missing":
        assert frame["wind_speed"].isna().all() and "wind_missing" in report
    if expect.get("warning"):
        assert report["sun_check"].startswith("WARNING") and "UTC+00:00" in report["sun_check"]
    if "notes" in expect:
        assert expect["notes"] in str(report["header_notes"])
    if "padding_line" in expect:
        assert report["padding"]["lines"] == [expect["padding_line"]]
    if "site" in expect:
        name, latitude, longitude, altitude, tz = expect["site"]
        assert frame.attrs["site"] == name and report["site"] == (
            f"{name} ({latitude:.3f}°, {longitude:.3f}°, {altitude:g} m, {tz}), from the file's header")
        assert report["sun_check"].startswith(f"light follows the sun at {name}")
    if "decimal" in expect:
        assert report["decimal"] == expect["decimal"]
    if "order" in expect:
        assert report["date_order"].startswith(expect["order"]), report["date_order"]
    if "comments" in expect:
        assert len(report["skipped"]["comments"]) == expect["comments"]
    if expect.get("erbs"):
        reference = _erbs_reference(frame["ghi"])
        np.testing.assert_allclose(frame["dni"], reference["dni"], rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(frame["dhi"], reference["dhi"].clip(lower=0.0), rtol=1e-6, atol=1e-6)


def check_pvlib(frame: pd.DataFrame, path: Path, fmt: str) -> None:
    reader = {"epw": pvlib.iotools.read_epw,  # two days running forward in one year: real-year data, in its own year (2021)
              "surfrad": pvlib.iotools.read_surfrad, "srml": pvlib.iotools.read_srml,
              "bsrn": pvlib.iotools.read_bsrn}[fmt]
    data = reader(str(path))
    data = data[0] if isinstance(data, tuple) else data.rename(columns=lambda c: c.removesuffix("_0"))
    pd.testing.assert_index_equal(frame.index.tz_convert("UTC"), data.index.tz_convert("UTC"), check_names=False)
    for name in ALL:
        if name in data:
            np.testing.assert_allclose(frame[name], data[name].astype(float), rtol=1e-12, err_msg=name)
        else:  # BSRN's basic record holds no wind: missing, never calm
            assert frame[name].isna().all() and frame.attrs["wind_data"] == "missing"
    assert frame.attrs["validation"]["format"] == fmt
    assert frame.attrs["validation"]["sun_check"].startswith("light follows the sun")


def check_interpolated(frame: pd.DataFrame, name: str) -> None:
    """Linear interpolation onto 7-minute steps counted from local midnight, NaN outside the data."""
    source = truth(name)
    start = source.index[0].tz_convert(SHANGHAI).normalize()
    assert ((frame.index - start) % pd.Timedelta("7min") == pd.Timedelta(0)).all()
    assert frame.index[0] <= source.index[0] < frame.index[0] + pd.Timedelta("7min")
    assert frame.index[-1] <= source.index[-1] < frame.index[-1] + pd.Timedelta("7min")
    x = (frame.index.tz_convert("UTC") - source.index[0]) / pd.Timedelta(minutes=1)
    xp = (source.index - source.index[0]) / pd.Timedelta(minutes=1)
    for column in ALL:
        expected = np.interp(x, xp, source[column], left=np.nan, right=np.nan)
        np.testing.assert_allclose(frame[column], expected, rtol=1e-9, atol=1e-9, err_msg=column)


@pytest.mark.parametrize("name, kwargs, expect", [case[1:] for case in CASES], ids=[case[0] for case in CASES])
def test_each_record_reads_to_its_truth_or_is_refused_in_one_line(tmp_path, capsys, name, kwargs, expect):
    path = RECORDS / name
    out = tmp_path / "checked.csv"
    command = ["check", str(path), *cli_flags(kwargs), "--out", str(out)]
    if "refused" in expect:
        with pytest.raises(HybridtrackError) as error:
            read_weather(path, **kwargs)
        message = str(error.value)
        assert "\n" not in message and all(part in message for part in expect["refused"]), message
        assert main(command) == 2
        err = capsys.readouterr().err
        assert err.startswith("hybridtrack: error: ") and err.count("\n") == 1 and "Traceback" not in err
        assert message in err
        return
    frame = read_weather(path, **kwargs)
    if "pvlib" in expect:
        check_pvlib(frame, path, expect["pvlib"])
    elif "interp" in expect:
        check_interpolated(frame, expect["interp"])
    else:
        check_read(frame, expect)
    assert main(command) == 0
    printed = capsys.readouterr().out
    assert "verdict:" in printed and f"wrote {len(frame)} rows" in printed
    written = pd.read_csv(out, index_col="time")
    np.testing.assert_array_equal(pd.to_datetime(written.index, utc=True), frame.index.tz_convert("UTC"))
    for column in frame.columns:
        np.testing.assert_allclose(written[column], frame[column], rtol=1e-5, atol=1e-9, err_msg=column)


def test_the_corpus_has_thirty_files_each_described():
    files = sorted(p.name for p in RECORDS.iterdir() if p.name not in ("README.md", "make_records.py")
                   and not p.name.startswith("truth-") and p.name != "__pycache__")
    readme = (RECORDS / "README.md").read_text()
    assert len(files) >= 30
    assert [f for f in files if f"`{f}`" not in readme] == []
    assert {case[1] for case in CASES} == set(files)


def test_the_corpus_files_are_what_the_script_writes():
    import make_records

    for name, make in make_records.FILES.items():
        content = make()
        content = content if isinstance(content, bytes) else content.encode("utf-8")
        assert (RECORDS / name).read_bytes() == content, name


@pytest.mark.parametrize("name, coordinates", [("703165TY.csv", ("55.317", "-160.517")),
                                               ("12839.tm2", ("25.8", "-80.267"))])
def test_the_weather_files_pvlib_ships_read_with_no_flags_but_the_site(capsys, name, coordinates):
    path = PVLIB_DATA / name
    frame = read_weather(path)
    reference = (pvlib.iotools.read_tmy3(str(path), coerce_year=2019) if name.endswith(".csv")
                 else pvlib.iotools.read_tmy2(str(path)))[0]
    assert len(frame) == len(reference) == 8760 and frame.attrs["wind_data"] == "measured"
    scale = 0.1 if name.endswith(".tm2") else 1.0  # TMY2 keeps tenths of °C and m/s
    names = {"ghi": "GHI", "dni": "DNI", "dhi": "DHI", "temp_air": "DryBulb", "wind_speed": "Wspd"}
    for column in ALL:
        source = reference[column] if column in reference else reference[names[column]] * (
            scale if column in ("temp_air", "wind_speed") else 1.0)
        np.testing.assert_allclose(frame[column], source.astype(float), rtol=1e-12, err_msg=column)
    assert frame.attrs["validation"]["sun_check"].startswith("light follows the sun")
    assert main(["check", str(path), "--lat", coordinates[0], "--lon", coordinates[1]]) == 0
    assert "verdict: clean" in capsys.readouterr().out
