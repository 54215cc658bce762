"""The field command: a run end to end, and every mistake as one line with status 2."""

import json

import numpy as np
import pytest

from hybridtrack.cli import main


def test_field_runs_a_fresnel_field_and_writes_its_files(tmp_path, capsys):
    out = tmp_path / "field"
    assert main(["field", "fresnel", "--site", "lanzhou", "--date", "2021-06-21", "--weather", "sunny",
                 "--rows=-4,0,4", "--metric", "energy_capture", "--threads", "2", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "FresnelField of 3 (fresnel)" in printed and "energy capture (field)" in printed and "row 3" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["collectors"] == 3 and summary["site"] == "lanzhou"
    assert (out / "field_map.png").stat().st_size > 0 and (out / "log.nc").exists()


def test_field_reads_heliostat_positions_and_aims(tmp_path, capsys):
    path = tmp_path / "mirrors.csv"
    path.write_text("East, North, Up, aim_east, aim_north, aim_up\n0,-80,0,0,0,100\n40,-70,1,2,0,98\n")
    assert main(["field", "heliostat", "--site", "nanjing", "--date", "2021-03-20", "--positions", str(path)]) == 0
    assert "HeliostatField of 2 (heliostat)" in capsys.readouterr().out


def test_a_positions_files_columns_it_does_not_read_are_named(tmp_path, capsys):
    """An 'elevation' column meant as up had been dropped without a word: the mirrors stood at 0 m."""
    from hybridtrack.cli.field import read_positions

    path = tmp_path / "mirrors.csv"
    path.write_text("id,east,north,elevation\n1,0,-100,3\n")
    positions, _ = read_positions(str(path))
    assert positions.tolist() == [[0.0, -100.0]]
    assert capsys.readouterr().err == f"{path}: not read: id, elevation (mirrors are read from east, north, up and " \
                                      "aim_east, aim_north, aim_up)\n"


def test_a_positions_files_note_goes_to_stderr_leaving_stdout_the_results(tmp_path, capsys):
    """The "not read" note had been printed on standard output, above the field's summary."""
    path = tmp_path / "mirrors.csv"
    path.write_text("name,east,north\nm1,0,-80\n")
    assert main(["field", "heliostat", "--site", "nanjing", "--date", "2021-03-20", "--freq", "30min",
                 "--positions", str(path)]) == 0
    printed = capsys.readouterr()
    assert "not read" not in printed.out and printed.out.startswith("nanjing, 2021-03-20")
    assert printed.err.splitlines()[0] == f"{path}: not read: name (mirrors are read from east, north, up and " \
                                          "aim_east, aim_north, aim_up)"


def test_positions_files_in_a_spreadsheets_shapes_read_the_same(tmp_path):
    from hybridtrack.cli.field import read_positions

    want = np.array([[0.0, -80.0], [40.0, -70.5]])
    for name, text in (("comma", "east,north\n0,-80\n40,-70.5\n"), ("semicolon", "east;north\n0;-80\n40;-70.5\n"),
                       ("tab", "east\tnorth\n0\t-80\n40\t-70.5\n"), ("bar", "east|north\n0|-80\n40|-70.5\n"),
                       ("comments and trailing separators", "# site survey\neast,north,\n0,-80,\n40,-70.5,\n")):
        path = tmp_path / f"{name}.csv"
        path.write_text(text)
        positions, aims = read_positions(str(path))
        np.testing.assert_array_equal(positions, want, err_msg=name)
        assert aims is None


@pytest.mark.parametrize("content, extra, message", [
    ("east,north\n0,-100\n50,abc\n", [], "row 3, column 'north': 'abc' is not a number"),
    ("east,north\n0,-100\n50,\n", [], "row 3, column 'north': empty"),
    ("east,north\n0,-100\n50,nan\n", [], "row 3, column 'north': empty or NaN"),  # it said 'empty' of a NaN
    ("east,north\n0,-100\n50,1e400\n", [], "row 3, column 'north': inf is not a finite number"),
    ("east,north\nTrue,0\n", [], "row 2, column 'east': 'True' is not a number"),  # pandas read it as 1 m east
    ("east,north\n0,-100\n6000,0\n", [], "mirrors.csv: heliostat 2: its position or aim point lies beyond"),
    # 1e200 m: the overlap check had squared it first (scipy's overflow ValueError, a traceback; helper-37)
    ("east,north\n1e200,60\n-10,60\n", [], "mirrors.csv: heliostat 1: its position or aim point lies beyond"),
    ("# mirrors\neast,north\n0,-100\n50,abc\n", [], "row 4, column 'north': 'abc' is not a number"),
    # a row longer than its header had been read with its first field as the index: every mirror moved
    ("east,north\n0,-100,5\n30,-90,5\n", [], "line 2: 3 fields, but the header on line 1 names 2"),
    # a column named twice had been read as two (a traceback) or one silently dropped (east.1)
    ("east,north,EAST\n60,0,1\n0,60,2\n", [], "line 1: column 'east' appears more than once in the header"),
    ("# mirrors\neast,north,east\n60,0,1\n0,60,2\n", [], "line 2: column 'east' appears more than once"),
    # as pandas reads the header: a comment after a name, a quoted name after a space (found by helper-2)
    ("east,north,east #comment\n60,0,1\n0,60,2\n", [], "line 1: column 'east' appears more than once"),
    ('east,north, "east"\n60,0,1\n0,60,2\n', [], "line 1: column 'east' appears more than once"),
    ("east,north,#up\n60,0,1\n0,60,2\n", [], "line 2: 3 fields, but the header on line 1 names 2"),  # 'up' was dropped
    ("x,y\n0,1\n", [], "no column 'east'"),
    # the file's aim points were used and --aim ignored without a word
    ("east,north,aim_east,aim_north,aim_up\n60,0,0,0,100\n", ["--aim", "0", "0", "50"],
     "--aim gives every mirror one aim point; "),
    ("east,north,aim_up\n0,-100,4\n", [], "aim points need all of"),
    ("east,north\n0,-100\n", ["--metric", "shine"], "--metric: no collector metric 'shine'"),
    ("east,north\n0,-100\n", ["--spread", "encoder_offset=-1"], "encoder_offset must be a finite number >= 0"),
    ("east,north\n0,-100\n", ["--spread", "colour=1"], "--spread: unknown imperfection 'colour'"),
    ("east,north\n0,-100\n", ["--spread", "encoder_offset=1_0"], "--spread encoder_offset: '1_0' is not a number"),
    ("east,north\n0,-100\n", ["--spread", "encoder_offset=1", "--no-spread"], "not both"),
])
def test_bad_field_input_is_one_line_and_status_2(tmp_path, capsys, content, extra, message):
    path = tmp_path / "mirrors.csv"
    path.write_text(content)
    status = main(["field", "heliostat", "--site", "nanjing", "--date", "2021-03-20", "--positions", str(path), *extra])
    error = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(error) == 1 and error[0].startswith("hybridtrack: error:") and message in error[0]


@pytest.mark.parametrize("flags, message", [
    (["fresnel", "--rows", "1,x"], "--rows takes numbers"),
    (["fresnel", "--rows="], "--rows takes numbers separated by commas, got ''"),  # not the default 20 rows
    (["fresnel", "--receiver-height", "0"], "receiver height must be finite and positive"),
    (["trough", "--count", "0"], "count must be a whole number"),
    (["heliostat", "--positions", "/no/such/file.csv"], "no such file"),
    (["trough", "--count", "2", "--threads", "0"], "--threads must be a whole number within [1,"),
    (["trough", "--count", "2", "--workers", "0"], "--workers must be a whole number within [1,"),  # named no flag
    (["trough", "--count", "2", "--threads", "2", "--workers", "1"], "give one or the other"),
    (["trough", "--count", "2", "--workers", "1", "--scheduler", "tcp://127.0.0.1:1"], "--scheduler or --workers, not both"),
    (["fresnel", "--rows=1,,2"], "--rows takes numbers separated by commas, got '1,,2'"),  # not two rows
    (["trough", "--metric", "moves"], "--metric colours the field map, which only --out writes"),  # had been unused
    # a flag that describes another kind of field had been ignored
    (["fresnel", "--positions", "/no/such/file.csv"], "--positions describes a heliostat field, not a fresnel one"),
    (["fresnel", "--count", "99"], "--count describes a trough or heliostat field, not a fresnel one"),
    (["fresnel", "--aim", "1", "2", "3"], "--aim describes a heliostat field, not a fresnel one"),
    (["trough", "--rows=0,1"], "--rows describes a fresnel field, not a trough one"),
    (["trough", "--receiver-height", "5"], "--receiver-height describes a fresnel field, not a trough one"),
    (["heliostat", "--axis-azimuth", "3"], "--axis-azimuth describes a fresnel or trough field, not a heliostat"),
    (["heliostat", "--collector-length", "3"], "--collector-length describes a trough field"),
    (["heliostat", "--count", "3", "--positions", "m.csv"], "give one or the other"),
    # had been refused as a frame to resample, a frame the user never gave
    (["trough", "--count", "2", "--freq", "2h"], "--freq: step '2h' is longer than a run's longest, 1 h"),
])
def test_bad_field_flags(capsys, flags, message):
    assert main(["field", *flags, "--site", "lanzhou", "--date", "2021-06-21"]) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("flags, message", [
    (["fresnel", "--rows", "nan"], "--rows: row distances must be finite, got [nan]"),
    (["fresnel", "--rows=-1,2,-1"], "--rows: rows 1 and 3 are both at -1 m from the receiver line: two collectors "
                                    "cannot share a place"),
    (["fresnel", "--rows=1,2", "--receiver-height", "-1"], "--receiver-height: receiver height must be finite and "
                                                           "positive, got [-1.0]"),
    (["fresnel", "--row-length", "0"], "--row-length: row length must be finite and positive, got [0.0]"),
    (["fresnel", "--axis-azimuth", "nan"], "--axis-azimuth: axis azimuth must be finite, got [nan]"),
    (["trough", "--count", "0"], "--count: trough loop: count must be a whole number from 1 to 100000, got 0"),
    (["trough", "--collector-length", "1e-300", "--count", "2"],  # both at one place
     "--collector-length: trough loop: collector length must be at least 1 m (the collectors stand one length apart: "
     "shorter, they would overlap), got 1e-300"),
    (["trough", "--collector-length", "-5", "--count", "3"], "--collector-length: collector length must be finite and "
                                                             "positive, got [-5.0]"),
    # 33 of the default 150 m (4950 m) and 12 of 160 m are within 5000 m; 33 of 160 m are not: both named
    (["trough", "--count", "33", "--collector-length", "160", "--axis-azimuth", "10"],
     "--count, --collector-length: trough loop: 33 collectors of 160 m reach 5120 m along the axis, beyond 5000 m"),
    (["heliostat", "--count", "0"], "--count: heliostat count must be a whole number from 1 to 100000, got 0"),
    (["heliostat", "--count", "3", "--aim", "0", "0", "-5"], "--aim: heliostat 1: its aim point is not above the "
                                                             "mirror (-5 m up from it, at least 0.1 m): a heliostat reflects the sun "
                                                             "up to its receiver"),
    (["fresnel", "--spread", "encoder_offset=-1"], "--spread encoder_offset: imperfection spread: encoder_offset "
                                                   "must be a finite number >= 0, got -1.0"),
    (["fresnel", "--freq", "soon"], "--freq: step 'soon' is not a duration such as '1min' or '10s'"),
    (["fresnel", "--weather", "sunny,cloudy"], "--weather: 2 weathers given for 1 days; give one per day"),
])
def test_a_field_flags_refusal_names_the_flag(capsys, flags, message):
    """--rows nan said "row distances must be finite, got [nan]", naming no flag."""
    assert main(["field", *flags, "--site", "lanzhou", "--date", "2021-06-21"]) == 2
    printed = capsys.readouterr()
    assert printed.err == f"hybridtrack: error: {message}\n" and printed.out == ""


def test_a_positions_files_refusal_names_the_file_and_aim_only_when_it_came_from_aim(tmp_path, capsys):
    path = tmp_path / "mirrors.csv"
    path.write_text("east,north\n0,-80\n0,-80\n")
    base = ["field", "heliostat", "--site", "nanjing", "--date", "2021-03-20", "--positions", str(path)]
    assert main([*base, "--aim", "0", "0", "100"]) == 2  # the file's two mirrors in one place, not --aim's fault
    assert capsys.readouterr().err == f"hybridtrack: error: {path}: heliostats 1 and 2 are both at 0, -80, 0 m " \
                                      "(east, north, up): two collectors cannot share a place\n"
    path.write_text("east,north\n0,-80\n")
    assert main([*base, "--aim", "0", "0", "-100"]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {path}: --aim: heliostat 1: its aim point is not above " \
                                      "the mirror (-100 m up from it, at least 0.1 m): a heliostat reflects the sun up to its " \
                                      "receiver\n"


def test_the_apis_field_messages_name_no_flag():
    from hybridtrack import HybridtrackError
    from hybridtrack.fields import FresnelField

    with pytest.raises(HybridtrackError) as refused:
        FresnelField(row_distances=[float("nan")])
    assert str(refused.value) == "row distances must be finite, got [nan]"


def test_a_config_files_strategy_runs_unless_the_flag_gives_another(tmp_path, capsys):
    """--strategy's default (hybrid) had replaced the config file's: a sensor-only field was
    reported, and scored, as hybrid."""
    config = tmp_path / "run.toml"
    config.write_text('[controller]\nstrategy = "astronomical"\n')
    base = ["field", "trough", "--count", "2", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10min",
            "--config", str(config)]
    for flags, strategy in (([], "astronomical"), (["--strategy", "sensor"], "sensor")):
        assert main(base + flags) == 0
        out = capsys.readouterr().out
        assert out.splitlines()[0].endswith(f"(trough-ns), {strategy}")
    assert main(["compare", *base[4:], "--strategy", "sensor"]) == 2  # it had been ignored: compare runs them all
    assert "compare runs every strategy: --strategy is not taken" in capsys.readouterr().err


def test_field_help(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["field", "--help"])
    assert stop.value.code == 0 and "--positions" in capsys.readouterr().out
