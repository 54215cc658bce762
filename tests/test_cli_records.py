import pandas as pd
import pytest

from hybridtrack.cli import main


def test_check_prints_the_validation_summary(tmp_path, capsys):
    path = tmp_path / "log.csv"
    path.write_text("Site;Lanzhou\n\nStamp;Direct Normal;Global;Diffuse\n2021-06-21 12:00;800,0;900,0;100,0\n"
                    "2021-06-21 12:01;801,0;901,0;-4,0\n2021-06-21 12:01;801,0;901,0;100,0\n")
    assert main(["check", str(path), "--tz", "Asia/Shanghai", "--map", "time=Stamp", "--map", "dni=Direct Normal"]) == 0
    out = capsys.readouterr().out
    assert "3 rows read, 2 rows out, step 1min" in out
    assert "semicolon-separated, decimal ','" in out and "dni <- 'Direct Normal'" in out
    assert "dropped (repeated stamps, the first kept): count 1, lines 6" in out
    assert "clipped to 0 (negative irradiance): dhi count 1, lines 5, lowest -4.0" in out


def test_check_a_shipped_record(capsys):
    assert main(["check", "data/lanzhou-2021-overcast.csv"]) == 0
    assert "3604 rows read" in capsys.readouterr().out


@pytest.mark.parametrize("args, message", [
    (["check", "missing.csv"], "missing.csv: no such file"),
    (["check", "data/lanzhou-2021-sunny.csv", "--map", "dni"], "--map takes NAME=VALUE, got 'dni'"),
    (["check", "data/lanzhou-2021-sunny.csv", "--map", "beam=ghi"], "unknown column name 'beam'"),
    (["check", "data/lanzhou-2021-sunny.csv", "--tz", "Nowhere/Land"], "unknown time zone 'Nowhere/Land'"),
    (["sky", "--site", "lanzhou", "--date", "2021-06-31"], "date '2021-06-31' does not exist"),
    (["sky", "--site", "lanzhou", "--date", "2021-06-21", "--weather", "foggy"], "unknown weather 'foggy'"),
    (["sky", "--site", "lanzhou", "--date", "2021-06-21", "--days", "0"], "--days must be between 1 and 3660"),
])
def test_record_commands_bad_input(capsys, args, message):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def test_sky_prints_the_day_and_writes_csv_and_plot(tmp_path, capsys):
    out, png = tmp_path / "sky.csv", tmp_path / "sky.png"
    assert main(["sky", "--site", "nanjing", "--date", "2013-12-22", "--weather", "sunny,overcast", "--days", "2",
                 "--out", str(out), "--plot", str(png)]) == 0
    printed = capsys.readouterr().out
    rows = {line.split()[0]: line.split()[1] for line in printed.splitlines() if line.startswith("2013-12-2")}
    assert rows == {"2013-12-22": "sunny", "2013-12-23": "overcast"} and "fuzzy_cloudy" in printed
    frame = pd.read_csv(out, index_col="time")
    assert {"ghi", "dni", "dhi", "wind_speed", "temp_air", "sky", "intensity_ma", "variation_ma"} <= set(frame.columns)
    assert len(frame) == 2 * 1440 and png.stat().st_size > 30_000


def test_the_report_gives_the_dates_and_every_change_with_where(capsys):
    """A messy file at a 5-minute step: each kind of change is listed with its count and file lines."""
    assert main(["check", "tests/records/messy.csv", "--site", "lanzhou", "--freq", "5min", "--map", "dhi=DHI"]) == 0
    out = capsys.readouterr().out
    assert "98 rows read, 193 rows out, step 10min read, 5min out\n" in out
    assert "dates: 2021-06-05 05:00:00+08:00 to 2021-06-05 21:00:00+08:00" in out
    assert "renamed: 'DHI' -> dhi, 'GHI' -> ghi, 'DNI' -> dni" in out
    assert "sorted (stamps out of order): count 1, lines 33" in out
    assert "dropped (repeated stamps, the first kept): count 1, lines 82" in out
    assert "clipped to 0 (negative irradiance): ghi count 1, lines 3, lowest -2.5" in out
    # DNI is NaN at 15:00 (line 62): 14:55, 15:00 and 15:05 are left empty (the count had been of rows empty in
    # every column: 0)
    assert "resampled: linear in time from 10min to 5min" in out
    assert "(rows 193, interpolated 96, empty 3: dni 3)" in out
    assert "NaN kept: dni 1" in out


def test_ghi_alone_lists_the_filled_components(capsys):
    assert main(["check", "tests/records/ghi-only.csv", "--site", "lanzhou"]) == 0
    out = capsys.readouterr().out
    assert "filled: dni count 97, how erbs decomposition of GHI (pvlib.irradiance.erbs, true zenith)" in out
    assert "wind: MISSING: no wind column in the file" in out


def test_a_utc_logger_replays_at_a_built_in_site_with_tz_utc(tmp_path, capsys):
    """The file's zone is not the site's: refused without --tz (the sun check), right with it."""
    import json

    record = "tests/records/utc-declared-local.csv"
    assert main(["replay", record, "--site", "lanzhou"]) == 2
    assert "stamps in UTC+00:00" in capsys.readouterr().err
    out = tmp_path / "run"
    assert main(["replay", record, "--site", "lanzhou", "--tz", "UTC", "--perfect", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "naive stamps localised to UTC" in printed and "light follows the sun at lanzhou" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["energy_capture"] > 0.9
    by_coordinates = tmp_path / "run2"
    assert main(["replay", record, "--lat", "36.1055556", "--lon", "103.726389", "--altitude", "1520", "--tz", "UTC",
                 "--site-tz", "Asia/Shanghai", "--perfect", "--out", str(by_coordinates)]) == 0
    capsys.readouterr()
    again = json.loads((by_coordinates / "summary.json").read_text())
    # the same coordinates, zone and file are the same run, whatever the site is called (the energy
    # had been compared to within 1e-3 only, room for a different run to pass)
    assert again["site"] == "custom" and {**again, "site": "lanzhou"} == summary


def test_check_writes_parquet_for_a_parquet_name_and_a_streamed_replay_reads_it(tmp_path, capsys):
    """'--out x.parquet' had written CSV text under that name: a streamed replay then failed with
    'Parquet magic bytes not found'."""
    from hybridtrack.sky import synthetic

    day = synthetic("lanzhou", "2021-06-21", weather="mixed", seed=2)[["ghi", "dni", "dhi", "wind_speed"]]
    day.to_csv(tmp_path / "day.csv", index_label="time")  # a whole local day: a streamed run's least
    out = tmp_path / "clean.parquet"
    assert main(["check", str(tmp_path / "day.csv"), "--out", str(out)]) == 0
    frame = pd.read_parquet(out)
    assert frame.index.tz is not None and frame.index.name == "time" and len(frame) == 1440
    assert main(["replay", str(out), "--site", "lanzhou", "--stream", "--out", str(tmp_path / "run")]) == 0
    assert main(["check", str(out)]) == 2  # not a text table, said so
    assert "a Parquet file, not a text table: replay it with --stream" in capsys.readouterr().err


def test_check_refuses_an_output_name_it_cannot_write_before_reading(tmp_path, capsys):
    assert main(["check", "data/lanzhou-2021-sunny.csv", "--out", str(tmp_path / "clean.xlsx")]) == 2
    captured = capsys.readouterr()
    assert "--out writes CSV or Parquet; name the file .csv or .parquet" in captured.err
    assert "rows read" not in captured.out  # refused before the file was read
