"""Each way a recorded file or its flags can be refused: one line from the API and the CLI alike.

Every row makes the file, calls `read_weather` (which must raise HybridtrackError with one
line) and `hybridtrack check` (exit status 2, one ``hybridtrack: error:`` line, no traceback),
and both must name the problem and, for a file's content, its line and column.
"""

from __future__ import annotations

import gzip
import io
import zipfile

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.io import read_weather

ROWS = "".join(f"2021-06-05 {h:02d}:00,{g},{d},{f},2.0\n" for h, g, d, f in
               ((6, 40, 300, 20), (9, 600, 800, 90), (12, 950, 900, 100), (15, 700, 820, 95), (18, 200, 500, 60)))
PLAIN = "time,ghi,dni,dhi,wind_speed\n" + ROWS


def zipped(members: dict) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, text in members.items():
            archive.writestr(name, text)
    return buffer.getvalue()


# (id, file content, read_weather keywords, CLI flags, message parts)
REFUSALS = [
    ("dates mixing day-first and month-first", "time,ghi\n13/06/2021 10:00,500\n06/14/2021 10:00,500\n",
     {"tz": "UTC"}, ["--tz", "UTC"], ["line 3, column 'time'", "the column mixes both"]),
    ("the clock before a date nothing orders", "time,ghi\n10:00 05/06/2021,500\n11:00 05/06/2021,600\n",
     {"tz": "UTC"}, ["--tz", "UTC"], ["line 2, column 'time': '10:00 05/06/2021' could be day-first or month-first",
                                      "--dayfirst or --monthfirst"]),
    ("decimal commas beside decimal points, tab-separated", "time\tghi\n2021-06-05 10:00\t812.5\n"
     "2021-06-05 11:00\t700,5\n", {"tz": "UTC"}, ["--tz", "UTC"],
     ["line 3, column 'ghi': '700,5' is not a number (nor are 1 of its 2 values)"]),
    ("a date after its clock beside an ISO stamp", "time,ghi\n2021-06-05 10:00,500\n11:00 05/06/2021,600\n",
     {"tz": "UTC"}, ["--tz", "UTC"], ["line 2, column 'time'", "is not written like the column's other dates"]),
    ("dates written two ways", "time,ghi\n05/06/2021 10:00,500\n2021-06-05 11:00,500\n", {"tz": "UTC"},
     ["--tz", "UTC"], ["line 3, column 'time'", "is not written like the column's other dates"]),
    ("an empty stamp", "time,ghi\n2021-06-05 10:00,500\n,500\n", {"tz": "UTC"}, ["--tz", "UTC"],
     ["line 3, column 'time'", "empty time stamp"]),
    ("stamps with and without offsets", "time,ghi\n2021-06-05T10:00+08:00,500\n2021-06-05T11:00,500\n", {}, [],
     ["line 3, column 'time'", "has no UTC offset, but other stamps"]),
    ("a row longer than the header", "time,ghi\n2021-06-05 10:00,500\n2021-06-05 11:00,500,7\n", {"tz": "UTC"},
     ["--tz", "UTC"], ["line 3: 3 fields", "names 2"]),
    ("a TOA5 file cut short", '"TOA5","x","CR1000"\n"TIMESTAMP","GHI_Avg"\n"TS","W/m^2"\n', {"tz": "UTC"},
     ["--tz", "UTC"], ["a TOA5 file needs its four header lines and data"]),
    ("an unknown unit in a units row", '"TOA5","x"\n"TIMESTAMP","GHI_Avg"\n"TS","furlongs"\n"","Avg"\n'
     '"2021-06-05 10:00",500\n"2021-06-05 11:00",600\n', {"tz": "UTC"}, ["--tz", "UTC"],
     ["column 'GHI_Avg'", "unknown unit 'furlongs' for ghi"]),
    ("a zip of two files", zipped({"a.csv": PLAIN, "b.csv": PLAIN}), {"tz": "UTC"}, ["--tz", "UTC"],
     ["a zip archive must hold exactly one file; it holds a.csv, b.csv"]),
    ("an Excel workbook (a zip of XML parts)", zipped({"[Content_Types].xml": "<Types/>", "_rels/.rels": "<r/>",
                                                       "xl/workbook.xml": "<workbook/>",
                                                       "xl/worksheets/sheet1.xml": "<worksheet/>"}),
     {"tz": "UTC"}, ["--tz", "UTC"], ["an Excel workbook: save it as CSV (File > Save As > CSV)"]),
    ("a damaged gzip file", gzip.compress(PLAIN.encode())[:30], {"tz": "UTC"}, ["--tz", "UTC"],
     ["a damaged gzip file"]),
    ("light at midnight", PLAIN + "".join(
        f"2021-06-05 {h:02d}:30,300,600,50,2.0\n" for h in (0, 1, 2, 3, 23)), {"site": "lanzhou"},
     ["--site", "lanzhou"], ["line 7, column 'dni'", "of 10 lit rows have dni while the sun is down", "--lenient"]),
    ("a unit for an unknown quantity", PLAIN, {"tz": "UTC", "units": {"pressure": "hPa"}},
     ["--tz", "UTC", "--units", "pressure=hPa"], ["unknown column name 'pressure' in --units"]),
    ("an unknown unit given", PLAIN, {"tz": "UTC", "units": {"wind_speed": "furlongs/fortnight"}},
     ["--tz", "UTC", "--units", "wind_speed=furlongs/fortnight"], ["--units: unknown unit 'furlongs/fortnight'"]),
    ("--map on a pvlib format", PLAIN, {"tz": "UTC", "format": "epw", "columns": {"ghi": "x"}},
     ["--tz", "UTC", "--format", "epw", "--map", "ghi=x"], ["--map and --units apply to tables"]),
    ("a resample step of nan", PLAIN, {"tz": "UTC", "freq": "nan"}, ["--tz", "UTC", "--freq", "nan"],
     ["step 'nan' is not a duration"]),
    ("a resample step of 1 ns over a day", PLAIN, {"tz": "UTC", "freq": "1ns"}, ["--tz", "UTC", "--freq", "1ns"],
     ["resampling 12h of data to 1ns: 43,200,000,000,001 steps of 1ns would need about", "use a step of 1s"]),
    ("most stamps repeat (a date without its clock)", "date,ghi\n2021-06-05,10\n2021-06-05,500\n2021-06-05,700\n",
     {"tz": "UTC"}, ["--tz", "UTC"], ["line 3: 2 of 3 stamps repeat an earlier one", "clock column"]),
    ("negative wind beyond an offset (strict)", PLAIN.replace(",2.0\n", ",-0.2\n", 1), {"tz": "UTC", "strict": True},
     ["--tz", "UTC", "--strict"], ["line 2, column 'wind_speed': a negative wind reading (strict)"]),
    ("a DNI column without a number (strict)", PLAIN.replace(",300,", ",,").replace(",800,", ",,").replace(
        ",900,", ",,").replace(",820,", ",,").replace(",500,", ",,"), {"site": "lanzhou", "strict": True},
     ["--site", "lanzhou", "--strict"], ["column 'dni': an irradiance column without a readable value (strict)"]),
]


@pytest.mark.parametrize("content, kwargs, flags, parts", [r[1:] for r in REFUSALS], ids=[r[0] for r in REFUSALS])
def test_each_refusal_is_one_line_from_the_api_and_the_cli(tmp_path, capsys, monkeypatch, content, kwargs, flags,
                                                          parts):
    # the memory a run may use follows what the machine has free, which other work moves between
    # the two calls (11.6 GB, then 11.7 GB): held still, so the two messages are the same
    monkeypatch.setattr("hybridtrack.budget.available_memory", lambda: 24 * 2**30)
    path = tmp_path / "record.csv"
    path.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    with pytest.raises(HybridtrackError) as error:
        read_weather(path, **kwargs)
    message = str(error.value)
    assert "\n" not in message and all(part in message for part in parts), message
    assert main(["check", str(path), *flags]) == 2
    err = capsys.readouterr().err
    flag = "--freq: " if message.startswith("step ") else ""  # a flag's value refused is named by its flag
    assert err == f"hybridtrack: error: {flag}{message}\n"


@pytest.mark.parametrize("args, message", [
    (["--map", "dni=Direct", "--map", "dni=Beam"], "--map names dni twice ('Direct' and 'Beam')"),
    (["--site", "lanzhou", "--site-tz", "UTC"], "give either --site or --lat/--lon/--altitude/--site-tz, not both"),
    (["--lat", "36.1"], "--lat, --lon go together; one of them is missing"),
    (["--site-tz", "UTC"], "--site-tz goes with --lat/--lon"),
    (["--map", "time"], "--map takes NAME=VALUE, got 'time'"),
    (["--units", "ghi="], "--units takes NAME=VALUE, got 'ghi='"),
])
def test_record_flags_refused_in_one_line(tmp_path, capsys, args, message):
    path = tmp_path / "record.csv"
    path.write_text(PLAIN)
    assert main(["check", str(path), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and "Traceback" not in err


def test_replay_needs_the_sites_clock_with_coordinates_and_compare_refuses_tz_for_synthetic_days(tmp_path, capsys):
    path = tmp_path / "record.csv"
    path.write_text(PLAIN)
    assert main(["replay", str(path), "--lat", "36.1", "--lon", "103.7"]) == 2
    assert "--lat and --lon need the site's clock: --tz ZONE (or --site-tz)" in capsys.readouterr().err
    assert main(["compare", "--site", "lanzhou", "--tz", "UTC", "--date", "2021-06-21"]) == 2
    assert "--tz is a recorded file's time zone" in capsys.readouterr().err


def test_a_file_without_wind_is_never_calm_and_check_and_replay_say_so(tmp_path, capsys):
    times = pd.date_range("2021-06-05 06:00", "2021-06-05 20:00", freq="10min")
    path = tmp_path / "no-wind.csv"
    pd.DataFrame({"time": times.strftime("%Y-%m-%d %H:%M"), "ghi": 500.0, "dni": 600.0, "dhi": 80.0}).to_csv(
        path, index=False)
    frame = read_weather(path, site="lanzhou")
    assert frame.attrs["wind_data"] == "missing" and frame["wind_speed"].isna().all()
    assert main(["check", str(path), "--site", "lanzhou"]) == 0
    assert "wind: MISSING: no wind column in the file" in capsys.readouterr().out
    assert main(["replay", str(path), "--site", "lanzhou", "--tz", "Asia/Shanghai", "--step", "10min"]) == 0
    assert "wind: MISSING" in capsys.readouterr().out


def test_a_dead_pyrheliometer_column_is_derived_from_ghi_and_dhi_and_counted(tmp_path, capsys):
    """A DNI column without one number is not a day without beam: it is dropped and derived by
    closure, DNI = (GHI - DHI) / cos(zenith), and both changes are in the report."""
    import numpy as np
    import pvlib

    path = tmp_path / "dead-dni.csv"
    path.write_text("time,ghi,dni,dhi,wind_speed\n" + "".join(
        f"2021-06-05 {h:02d}:00,{g},,{d},2.0\n" for h, g, d in ((9, 600, 90), (12, 950, 100), (15, 700, 95))))
    frame = read_weather(path, site="lanzhou", tz="Asia/Shanghai")
    report = frame.attrs["validation"]
    assert report["empty_dropped"] == {"dni": {"rows": 3}} and "nan" not in report
    assert frame.attrs["dni_source"] != "measured"
    zenith = pvlib.solarposition.get_solarposition(frame.index, 36.1055556, 103.726389, 1520.0)["zenith"].to_numpy()
    expected = (frame["ghi"] - frame["dhi"]).to_numpy() / np.cos(np.radians(zenith))
    np.testing.assert_allclose(frame["dni"].to_numpy(), expected, rtol=0.01)  # pvlib's closure, to its sun
    assert main(["check", str(path), "--site", "lanzhou", "--tz", "Asia/Shanghai"]) == 0
    out = capsys.readouterr().out
    assert "dropped (irradiance column without a readable value): dni rows 3" in out and "NaN kept" not in out


def test_site_flags_keep_their_meaning_for_commands_without_a_file(capsys):
    assert main(["sun", "--site", "lanzhou", "--tz", "UTC", "--date", "2021-06-21"]) == 2
    assert "give either --site or --lat/--lon/--altitude/--tz, not both" in capsys.readouterr().err
    assert main(["sun", "--lat", "36.1", "--lon", "103.7", "--tz", "Asia/Shanghai", "--date", "2021-06-21"]) == 0


@pytest.mark.parametrize("args, message", [
    (["--site", "lanzhou", "--altitude", "nan"], "give either --site or --lat/--lon/--altitude/--tz, not both"),
    (["--altitude", "1500"], "--altitude goes with --lat/--lon"),
])
def test_an_altitude_without_coordinates_is_refused_not_ignored(capsys, args, message):
    """A site's altitude given beside a named site (or none) was silently dropped."""
    assert main(["simulate", *args, "--date", "2021-06-21", "--out", "unused"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and "Traceback" not in err


def test_a_file_whose_header_places_it_far_from_the_site_is_refused_or_warned(capsys):
    # a Lanzhou EPW checked at Nanjing (1,400 km east) was 'clean': at hourly steps the sun check
    # cannot see the hour of longitude between them, but the file's header says where it was made
    epw = "tests/records/lanzhou.epw"
    assert main(["check", epw, "--site", "nanjing"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"hybridtrack: error: {epw}: line 1: the file's header places it at Lanzhou (36.106°, "
                          "103.726°), 1,")
    assert "from the site nanjing" in err and "--lenient to read it anyway" in err
    with pytest.raises(HybridtrackError, match="header places it at Lanzhou"):
        read_weather(epw, site="nanjing")
    assert main(["check", epw, "--site", "nanjing", "--lenient"]) == 0
    out = capsys.readouterr().out
    assert "  place: WARNING: the file's header places it at Lanzhou" in out and "verdict: usable, with 1 kind" in out
    assert main(["check", epw, "--site", "lanzhou"]) == 0  # its own site
    assert "verdict: clean" in capsys.readouterr().out


def _clear_day_file(path, dni_scale=1.0):
    """A 1-minute clear day at Lanzhou from pvlib's Ineichen sky, whose components add up."""
    import pvlib

    from hybridtrack import sites

    site = sites.get("lanzhou")
    index = pd.date_range("2021-06-05 05:00", "2021-06-05 21:00", freq="1min", tz=site.tz)
    location = pvlib.location.Location(site.latitude, site.longitude, altitude=site.altitude)
    clear = location.get_clearsky(index, model="ineichen")
    frame = pd.DataFrame({"ghi": clear["ghi"].round(1).to_numpy(), "dni": (dni_scale * clear["dni"]).round(1).to_numpy(),
                          "dhi": clear["dhi"].round(1).to_numpy(), "wind_speed": 2.0}, index=index.tz_localize(None))
    frame.rename_axis("time").to_csv(path)
    return path


def test_the_components_of_a_clear_day_add_up_and_a_dead_pyrheliometer_is_named(tmp_path, capsys):
    """GHI = DNI·cos z + DHI (BSRN's comparison test, ±8 %): pvlib's clear day passes; a
    pyrheliometer that reads 0 all day (a dead one, not an empty column) passed every check
    before and is now a warning naming the first row, and a refusal in strict reading."""
    good = _clear_day_file(tmp_path / "clear.csv")
    report = read_weather(good, site="lanzhou", tz="Asia/Shanghai").attrs["validation"]
    assert report["closure"].startswith("GHI = DNI·cos z + DHI within BSRN's tolerance on 100.0% of")
    dead = _clear_day_file(tmp_path / "dead.csv", dni_scale=0.0)
    report = read_weather(dead, site="lanzhou", tz="Asia/Shanghai").attrs["validation"]
    assert report["closure"].startswith("WARNING: line ") and "do not add up on 100% of" in report["closure"]
    assert "is the DNI column dead" in report["closure"]
    assert main(["check", str(dead), "--site", "lanzhou", "--tz", "Asia/Shanghai"]) == 0
    out = capsys.readouterr().out
    assert "closure: WARNING" in out and "verdict: usable, with" in out
    assert main(["check", str(dead), "--site", "lanzhou", "--tz", "Asia/Shanghai", "--strict"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"hybridtrack: error: {dead}: line ") and err.rstrip().endswith("(strict)")
    assert len(err.strip().splitlines()) == 1


def test_hourly_components_are_not_judged_for_closure():
    report = read_weather("tests/records/lanzhou.epw", site="lanzhou").attrs["validation"]
    assert report["closure"].startswith("not judged (steps of 1h")


@pytest.mark.parametrize("options, message", [
    (dict(columns=5), "--map must map quantities to text, e.g. {'ghi': 'Global'}; got int"),  # TypeError
    (dict(columns=["ghi"]), "--map must map quantities to text.*got list"),  # ValueError
    (dict(columns={"dni": 3}), "--map dni: give text.*got 3"),  # AttributeError
    (dict(units="kW/m2"), "--units must map quantities to text, e.g. {'ghi': 'kW/m2'}; got str"),  # "column 'k'"
    (dict(units={"ghi": 1000}), "--units ghi: give text"),
    (dict(units={"ghi": " "}), "--units ghi: the unit is empty; give one, e.g. {'ghi': 'kW/m2'}, or leave ghi out"),
    (dict(columns={pd.NA: "dni"}), "unknown column name <NA> in --map"),  # TypeError (helper-37)
    (dict(decomposition=pd.NA), "unknown decomposition <NA>; choose 'erbs' or 'dirint'"),  # TypeError
    (dict(decomposition=np.array(["erbs", "x"])), "unknown decomposition array"),  # ValueError
    (dict(strict="no"), "read_weather: strict must be True or False, got 'no'"),  # read as True
    (dict(lenient="no"), "read_weather: lenient must be True or False, got 'no'"),  # taken as it came
    (dict(dayfirst="no"), r"read_weather: dayfirst must be True or False \(or None\), got 'no'"),
])
def test_read_weathers_options_of_another_kind_are_refused_by_name(tmp_path, options, message):
    path = tmp_path / "plain.csv"
    path.write_text(PLAIN)
    with pytest.raises(HybridtrackError, match=message):
        read_weather(path, tz="UTC", **options)
    read_weather(path, tz="UTC", columns={"ghi": "ghi"}, units={"ghi": "W/m2"}, strict=False, dayfirst=None)


def _two_days(tmp_path, second_day_factor: float, dni_second_day: float | None = None):
    """Two clear days at Lanzhou, 30 min, in W/m²; the second day's light times a factor."""
    rows = []
    for day, factor in (("2021-06-21", 1.0), ("2021-06-22", second_day_factor)):
        for half in range(48):
            hour = half / 2
            light = max(0.0, 1000.0 * np.sin(np.pi * (hour - 6.5) / 14.0)) if 6.5 <= hour <= 20.5 else 0.0
            dni = 0.85 * light if dni_second_day is None or day == "2021-06-21" else dni_second_day * (light > 0)
            rows.append(f"{day} {int(hour):02d}:{30 * (half % 2):02d},{light * factor:.4f},{dni * factor:.4f},"
                        f"{0.12 * light * factor:.4f},2.0\n")
    path = tmp_path / "two_days.csv"
    path.write_text("time,ghi,dni,dhi,wind_speed\n" + "".join(rows))
    return path


def test_a_file_whose_second_day_is_in_kw_is_refused_at_that_days_line(tmp_path, capsys):
    """Judged over the whole file, a second day in kW/m² hid behind the first's W/m²: the file was
    called clean and its replay refused by the run without a file or line (helper-35)."""
    path = _two_days(tmp_path, 1e-3)
    with pytest.raises(HybridtrackError, match=r"two_days\.csv: line (6[6-9]|[7-9]\d), column 'ghi': ghi is at most "
                                               r"[\d.]+ while the clear sky reaches \d+ W/m².*if its unit changes within the file"):
        read_weather(path, site="lanzhou", tz="Asia/Shanghai")
    assert main(["check", str(path), "--site", "lanzhou", "--tz", "Asia/Shanghai"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_a_day_of_a_dead_pyrheliometer_in_a_longer_file_is_still_read(tmp_path):
    """The day-by-day judgement is of kW/m² only: a day of DNI at 0 beside a W/m² GHI and DHI (a
    pyrheliometer off for a day) is a sensor's outage the closure check counts, not a unit."""
    frame = read_weather(_two_days(tmp_path, 1.0, dni_second_day=0.0), site="lanzhou", tz="Asia/Shanghai")
    assert len(frame) == 96


def test_sky_labels_rewritten_or_blank_are_counted_and_labels_of_no_sky_found(tmp_path, capsys):
    """The reader writes a file's true-sky labels in lower case without spaces and reads a blank
    one as missing: each is counted in the report (it had said "changes: none"), and labels that
    name no sky are found, kept (helper-35)."""
    labels = ["Sunny", " cloudy ", "", "partly cloudy", "overcast"]
    path = tmp_path / "sky.csv"
    path.write_text("time,ghi,dni,dhi,wind_speed,sky\n" + "".join(
        f"{row.split(',', 1)[0]},{row.split(',', 1)[1].strip()},{label}\n"
        for row, label in zip(ROWS.splitlines(), labels)))
    frame = read_weather(path, tz="UTC")
    assert frame["sky"].tolist()[:2] == ["sunny", "cloudy"] and pd.isna(frame["sky"].iloc[2])
    report = frame.attrs["validation"]
    assert report["sky_rewritten"]["count"] == 2 and report["sky_rewritten"]["lines"] == [2, 3]
    assert report["sky_blank"] == {"count": 1, "lines": [4], "action": "read as missing"}
    assert report["sky_unknown"]["count"] == 1 and report["sky_unknown"]["first"] == "'partly cloudy' (line 5)"
    assert main(["check", str(path), "--tz", "UTC"]) == 0
    out = capsys.readouterr().out
    assert "rewritten (sky labels in lower case, without spaces): count 2, lines 2, 3" in out
    assert "sky labels that name no sky: count 1, first 'partly cloudy' (line 5)" in out


def test_a_second_sky_column_is_said_not_read(tmp_path):
    """Of two sky columns (``sky`` and ``Sky``) the first is read; the second had been passed over
    without a word, listed neither as read nor as not read."""
    path = tmp_path / "skies.csv"
    path.write_text("time,ghi,dni,dhi,wind_speed,sky,Sky\n" + "".join(
        f"{row.split(',', 1)[0]},{row.split(',', 1)[1].strip()},sunny,OVERCAST\n" for row in ROWS.splitlines()))
    frame = read_weather(path, tz="UTC")
    assert set(frame["sky"]) == {"sunny"}
    assert frame.attrs["validation"]["not_read"] == ["'Sky' (looks like sky; the first, 'sky', is read)"]


def _days_file(tmp_path, name: str, frame: pd.DataFrame, columns: list[str]) -> "Path":
    path = tmp_path / name
    frame[columns].to_csv(path, index_label="time")
    return path


def _lanzhou_days(days: int = 4) -> pd.DataFrame:
    from hybridtrack.sky import synthetic

    return synthetic("lanzhou", "2021-06-20", pd.Timestamp("2021-06-20") + pd.Timedelta(days=days - 1),
                     weather="sunny", freq="30min", seed=2)


def test_a_utc_loggers_day_in_kw_is_refused_at_its_line(tmp_path):
    """A logger on UTC at a site eight hours east changes its unit on its own day, whose W/m² hours
    had kept each of the site's days above the limit: judged on the logger's days too (helper-36)."""
    frame = _lanzhou_days().tz_convert("UTC")
    day = frame.index.normalize() == pd.Timestamp("2021-06-21", tz="UTC")
    frame.loc[day, ["ghi", "dni", "dhi"]] /= 1000.0
    path = _days_file(tmp_path, "utc.csv", frame.tz_localize(None), ["ghi", "dni", "dhi", "wind_speed"])
    with pytest.raises(HybridtrackError, match=r"utc\.csv: line \d+, column 'ghi': ghi is at most"):
        read_weather(path, site="lanzhou", tz="UTC")


def test_a_kw_dni_day_beside_ghi_is_refused_at_its_line(tmp_path):
    frame = _lanzhou_days()
    day = frame.index.normalize() == pd.Timestamp("2021-06-21", tz=frame.index.tz)
    frame.loc[day, "dni"] /= 1000.0
    path = _days_file(tmp_path, "dni.csv", frame, ["ghi", "dni", "dhi", "wind_speed"])
    with pytest.raises(HybridtrackError, match=r"dni\.csv: line \d+, column 'dni': dni is at most [\d.]+ while ghi - dhi"):
        read_weather(path, site="lanzhou")


def test_a_dni_only_file_with_an_overcast_day_of_noise_gets_its_own_reason(tmp_path):
    """DNI alone is not judged day by day (an overcast day has none): the file is refused for what
    it lacks, as before the day-by-day check (which had called it kW/m², helper-36)."""
    frame = _lanzhou_days()
    day = frame.index.normalize() == pd.Timestamp("2021-06-21", tz=frame.index.tz)
    frame.loc[day, "dni"] = np.where(frame.loc[day, "dni"] > 0, 1.2, 0.0)
    path = _days_file(tmp_path, "dni_only.csv", frame, ["dni", "wind_speed"])
    with pytest.raises(HybridtrackError, match="only dni given; need GHI, or two of GHI, DNI, DHI"):
        read_weather(path, site="lanzhou")


def test_strict_refuses_rewritten_sky_labels_and_labels_of_no_sky_are_an_issue(tmp_path, capsys):
    path = tmp_path / "sky.csv"
    path.write_text("time,ghi,dni,dhi,wind_speed,sky\n" + "".join(
        f"{row},{label}\n" for row, label in zip(ROWS.splitlines(), ["Sunny", "cloudy", "0", "sunny", "sunny"])))
    with pytest.raises(HybridtrackError, match="a sky label in capitals or with spaces"):
        read_weather(path, tz="UTC", strict=True)
    assert main(["check", str(path), "--tz", "UTC"]) == 0
    assert "verdict: usable, with 1 kind of issue noted above" in capsys.readouterr().out


def _jittering_logger(tmp_path) -> "Path":
    """A 1-minute logger whose clock stamps a second or two late now and then (median step 61 s)."""
    start = pd.Timestamp("2021-06-21 10:00", tz="Asia/Shanghai")
    late = [0, 1, 2, 0, 1, 0, 2, 1, 0, 1] * 6
    rows = [f"{(start + pd.Timedelta(minutes=k, seconds=late[k])).isoformat()},{600 + k},{700 + k},{100 + k},2.0"
            for k in range(60)]
    path = tmp_path / "jitter.csv"
    path.write_text("time,ghi,dni,dhi,wind_speed\n" + "\n".join(rows) + "\n")
    return path


def test_a_jittering_loggers_stamps_go_on_its_minute_not_on_their_median(tmp_path, capsys):
    """Stamps a second or two late had made a 61 s median step, and the file was averaged onto
    61-second steps (60 rows to 59, neighbouring minutes mixed; helper-37). They are put on the
    logger's minute, each minute's value interpolated between the readings either side of it."""
    frame = read_weather(_jittering_logger(tmp_path), site="lanzhou")
    assert len(frame) == 60 and (frame.index == pd.date_range("2021-06-21 10:00", periods=60, freq="1min",
                                                               tz="Asia/Shanghai")).all()
    assert frame["ghi"].iloc[0] == 600.0  # on the grid already
    # minute 2 (10:02): readings 602 at 10:02:02 and 601 at 10:01:01; 61 s apart, 59 s after the first
    assert frame["ghi"].iloc[2] == pytest.approx(601 + 59 / 61)
    resampled = frame.attrs["validation"]["resampled"]
    assert resampled["method"].startswith("irregular stamps (median step 61s, a logger's 1min step): linear in time")
    assert main(["check", str(_jittering_logger(tmp_path)), "--site", "lanzhou"]) == 0
    assert "60 rows read, 60 rows out, step 61s read, 1min out" in capsys.readouterr().out


def test_strict_refuses_stamps_it_would_put_on_a_grid(tmp_path):
    """`--strict` refuses the first thing the reader would repair; irregular stamps, resampled
    unasked, had passed it."""
    with pytest.raises(HybridtrackError, match=r"jitter.csv: line 3: a time stamp off the file's 1min steps "
                                               r"\(irregular stamps, which the reader would put on a grid\) \(strict\)"):
        read_weather(_jittering_logger(tmp_path), strict=True)  # no site: its made-up light is not judged
    read_weather(_jittering_logger(tmp_path), strict=True, freq="1min")  # asked for: taken
