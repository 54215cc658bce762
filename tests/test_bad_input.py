"""The bad input matrix (docs/robustness.md): every mistake, through the API and the CLI alike.

Each row makes the bad input, calls the Python API (which must raise HybridtrackError) and
the command line (which must print one line naming the problem and exit with status 2),
and checks both say the same thing.
"""

import dataclasses
import math
import os

import pandas as pd
import pytest

from hybridtrack import HybridtrackError, simulate, sites
from hybridtrack.cli import main
from hybridtrack.collectors import Collector
from hybridtrack.control import ControllerConfig
from hybridtrack.drive import Drive
from hybridtrack.fuzzy import FuzzyConfig
from hybridtrack.io import read_weather
from hybridtrack.outputs import replacing
from hybridtrack.sensor import SensorModel
from hybridtrack.simulation import SimulationConfig, run_step
from hybridtrack.sky import synthetic
from hybridtrack.skyinputs import SkyInputConfig
from hybridtrack.sun import solar_position
from hybridtrack.times import local_range
from hybridtrack.world import Imperfections

GOOD_ROWS = "2021-06-21 12:00,900,800,100,3\n2021-06-21 12:01,901,801,101,3\n2021-06-21 12:02,902,802,102,3\n"
HEADER = "time,ghi,dni,dhi,wind_speed\n"


def weather_file(content):
    def make(tmp):
        path = tmp / "weather.csv"
        if content is not None:
            path.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
        return path
    return make


def config_file(text, name="config.toml"):
    def make(tmp):
        path = tmp / name
        path.write_text(text)
        return path
    return make


SIMULATE = ["simulate", "--site", "lanzhou", "--date", "2021-06-21"]
CLASSIFY = ["classify", "--intensity", "1", "--variation", "1"]


def planted_link(name):
    """An output folder ``out`` holding a link `name` to a file outside it (or, for None, a link
    ``out`` to another folder)."""
    def make(tmp):
        victim = tmp / "victim"
        victim.mkdir()
        out = tmp / "out"
        if name is None:
            out.symlink_to(victim, target_is_directory=True)
        else:
            out.mkdir()
            (out / name).symlink_to(victim / name)
        return out
    return make


def existing_files(*names):
    def make(tmp):
        out = tmp / "out"
        out.mkdir()
        for name in names:
            (out / name).write_text("the user's own\n")
        return out
    return make


def refusing(write):
    """Call `write` under the command line's policy: existing files are not replaced."""
    with replacing(False):
        write()


# (id, make the input, API call, CLI args, message both must contain)
MATRIX = [
    ("file missing", weather_file(None), lambda p: read_weather(p, tz="UTC"),
     lambda p: ["check", str(p), "--tz", "UTC"], "no such file"),
    ("file empty", weather_file(""), lambda p: read_weather(p, tz="UTC"),
     lambda p: ["check", str(p), "--tz", "UTC"], "the file is empty"),
    ("file binary", weather_file(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR"), lambda p: read_weather(p, tz="UTC"),
     lambda p: ["check", str(p), "--tz", "UTC"], "looks binary"),
    ("Latin-1 text in a number", weather_file((HEADER + "2021-06-21 12:00,9\xe900,1,1,1\n").encode("latin-1")),
     lambda p: read_weather(p, tz="UTC"), lambda p: ["check", str(p), "--tz", "UTC"],
     "line 2, column 'ghi': '9\xe900' is not a number"),
    ("no time column", weather_file("ghi,dni\n1,2\n3,4\n"), lambda p: read_weather(p, tz="UTC"),
     lambda p: ["check", str(p), "--tz", "UTC"], "no time column found"),
    ("unknown column in mapping", weather_file(HEADER + GOOD_ROWS),
     lambda p: read_weather(p, tz="UTC", columns={"dni": "Beam"}),
     lambda p: ["check", str(p), "--tz", "UTC", "--map", "dni=Beam"], "no column 'Beam' (mapped to dni)"),
    ("unsorted (strict)", weather_file(HEADER + "2021-06-21 12:01,1,1,1,1\n2021-06-21 12:00,1,1,1,1\n"),
     lambda p: read_weather(p, tz="UTC", strict=True), lambda p: ["check", str(p), "--tz", "UTC", "--strict"],
     "line 3: time stamps out of order (strict)"),
    ("duplicated (strict)", weather_file(HEADER + GOOD_ROWS + "2021-06-21 12:02,1,1,1,1\n"),
     lambda p: read_weather(p, tz="UTC", strict=True), lambda p: ["check", str(p), "--tz", "UTC", "--strict"],
     "line 5: a repeated time stamp (strict)"),
    ("text in a numeric column", weather_file(HEADER + "2021-06-21 12:00,bright,1,1,1\n2021-06-21 12:01,sunny,1,1,1\n"),
     lambda p: read_weather(p, tz="UTC"), lambda p: ["check", str(p), "--tz", "UTC"],
     "line 2, column 'ghi': 'bright' is not a number"),
    ("negative wind (strict)", weather_file(HEADER + GOOD_ROWS + "2021-06-21 12:03,900,800,100,-4\n"),
     lambda p: read_weather(p, tz="UTC", strict=True), lambda p: ["check", str(p), "--tz", "UTC", "--strict"],
     "line 5, column 'wind_speed': a physically impossible value (strict)"),
    ("GHI 5000 W/m2 throughout", weather_file(HEADER + "2021-06-21 12:00,5000,800,100,3\n2021-06-21 12:01,5100,8,1,3\n"),
     lambda p: read_weather(p, tz="UTC"), lambda p: ["check", str(p), "--tz", "UTC"],
     "line 2, column 'ghi': 100% of values are outside -50..1500 (W/m²); wrong unit?"),
    ("GHI in kJ/m2 from the second hour",
     weather_file(HEADER + "2021-06-21 11:00,0,0,0,3\n2021-06-21 12:00,3000,8,1,3\n2021-06-21 13:00,3100,8,1,3\n"),
     lambda p: read_weather(p, tz="UTC"), lambda p: ["check", str(p), "--tz", "UTC"],
     "line 3, column 'ghi': 67% of values are outside -50..1500 (W/m²); wrong unit? kJ/m² or J/m² sums?"),
    ("naive stamps without a time zone", weather_file(HEADER + GOOD_ROWS), lambda p: read_weather(p),
     lambda p: ["check", str(p)], "naive time stamps"),
    ("unknown time zone", weather_file(HEADER + GOOD_ROWS), lambda p: read_weather(p, tz="Moon/Tranquility"),
     lambda p: ["check", str(p), "--tz", "Moon/Tranquility"], "unknown time zone 'Moon/Tranquility'"),
    ("fuzzy config: unknown key", config_file("colour = 'blue'\n"), lambda p: FuzzyConfig.from_toml(p),
     lambda p: ["classify", "--intensity", "1", "--variation", "1", "--config", str(p)], "unknown key 'colour'"),
    ("fuzzy config: wrong type", config_file("[resolution]\ninput = 'fine'\n"), lambda p: FuzzyConfig.from_toml(p),
     lambda p: ["classify", "--intensity", "1", "--variation", "1", "--config", str(p)],
     "resolution.input: must be a whole number"),
    ("fuzzy config: inverted membership", config_file(
        "[output]\nterms.overcast = {shape='trimf', params=[10, 5, 0]}\nterms.cloudy = {shape='trimf', "
        "params=[10, 15, 20]}\nterms.sunny = {shape='trimf', params=[20, 25, 30]}\n"),
     lambda p: FuzzyConfig.from_toml(p), lambda p: ["surface", "--config", str(p), "--out", str(p) + ".png"],
     "output.weather.terms.overcast: trimf parameters must be in order"),
    ("fuzzy config: rule with unknown term", config_file(
        "[[rules]]\nintensity = 'dazzling'\nvariation = 'small'\nweather = 'sunny'\n"),
     lambda p: FuzzyConfig.from_toml(p), lambda p: ["classify", "--intensity", "1", "--variation", "1", "--config", str(p)],
     "rules[1]: unknown term 'dazzling' for intensity"),
    ("run config: unknown key", config_file("[drive]\ndeadbnd = 0.2\n"), lambda p: SimulationConfig.from_toml(p),
     lambda p: ["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--config", str(p)],
     "drive.deadbnd: unknown key"),
    ("run config: wrong type", config_file("[imperfections]\nclock_error = 'late'\n"),
     lambda p: SimulationConfig.from_toml(p),
     lambda p: ["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--config", str(p)],
     "imperfections.clock_error: must be a number"),
    ("latitude beyond 90", lambda tmp: None, lambda p: sites.custom(95.0, 10.0, "UTC"),
     lambda p: ["sun", "--lat", "95", "--lon", "10", "--tz", "UTC", "--date", "2021-06-21"],
     "95.0 is outside [-90, 90]"),  # the API names latitude, the command line --lat
    ("site with unknown time zone", lambda tmp: None, lambda p: sites.custom(30.0, 10.0, "Nowhere/Land"),
     lambda p: ["simulate", "--lat", "30", "--lon", "10", "--tz", "Nowhere/Land", "--date", "2021-06-21"],
     "unknown time zone 'Nowhere/Land'"),
    ("unknown site", lambda tmp: None, lambda p: sites.get("atlantis"),
     lambda p: ["simulate", "--site", "atlantis", "--date", "2021-06-21"], "unknown site 'atlantis'"),
    ("date that does not exist", lambda tmp: None, lambda p: local_range("2021-02-29", "UTC"),
     lambda p: ["simulate", "--site", "nanjing", "--date", "2021-02-29"], "date '2021-02-29' does not exist"),
    ("month that does not exist", lambda tmp: None, lambda p: local_range("2021-13-01", "UTC"),
     lambda p: ["sky", "--site", "nanjing", "--date", "2021-13-01"], "date '2021-13-01' does not exist"),
    # dates past pandas' nanosecond timestamps (1677-09-21 to 2262-04-11) had raised OutOfBoundsDatetime
    ("a date after the last a run covers", lambda tmp: None, lambda p: synthetic("lanzhou", "2262-04-12"),
     lambda p: ["field", "trough", "--site", "lanzhou", "--date", "2262-04-12", "--count", "1"],
     "date '2262-04-12' is outside the dates a run can cover, 1678-01-01 to 2261-12-31"),
    ("a date before the first a run covers", lambda tmp: None, lambda p: local_range("0001-01-01", "UTC"),
     lambda p: SIMULATE[:-2] + ["--date", "0001-01-01"], "date '0001-01-01' is outside the dates a run can cover"),
    ("a heliostat aimed below its mirror", lambda tmp: None, lambda p: Collector("heliostat", aim=(0.0, 20.0, -50.0)),
     lambda p: SIMULATE + ["--collector", "heliostat", "--aim", "0", "20", "-50"],
     "collector: aim (m): the aim point must be above the mirror, at least 0.1 m, got -50 m up"),
    ("a heliostat aimed at its mirror", lambda tmp: None, lambda p: Collector("heliostat", aim=(0.0, 0.0, 0.05)),
     lambda p: SIMULATE + ["--collector", "heliostat", "--aim", "0", "0", "0.05"],
     "collector: aim (m): the aim point must be above the mirror, at least 0.1 m, got 0.05 m up"),
    ("a date object outside the span", lambda tmp: None,
     lambda p: local_range(__import__("datetime").date(2262, 1, 1), "UTC"), None,
     "date 2262-01-01 is outside the dates a run can cover"),
    ("a frame of stamps in seconds in 2500", lambda tmp: None,
     lambda p: simulate(pd.DataFrame({"dni": [0.0, 0.0]}, index=pd.date_range("2500-01-01", periods=2, freq="min",
                                                                             unit="s", tz="UTC")), "lanzhou"),
     None, "the weather frame (2500-01-01 00:00:00+00:00 to 2500-01-01 00:01:00+00:00) is outside the dates"),
    ("a commissioning before the first date", lambda tmp: None,
     lambda p: simulate(synthetic("lanzhou", "1680-01-01", weather="sunny"), "lanzhou",
                        strategy="astronomical-commissioned",
                        config=SimulationConfig(imperfections=Imperfections(commissioned_days_ago=3000.0))),
     None, "its clear day 3000 days before (1671-10-15, for warm start or commissioning"),
    # a dict for a config: simulate refused it, a field and a stream leaked AttributeError ({}: silently the default)
    ("a dict for a field's config", lambda tmp: None,
     lambda p: __import__("hybridtrack").simulate_field(synthetic("lanzhou", "2021-06-21"), "lanzhou",
                                                        __import__("hybridtrack.fields").fields.TroughLoop(count=1),
                                                        config={"drive": {}}),
     None, "config must be a SimulationConfig (SimulationConfig.from_dict for a dict), got dict"),
    ("an empty dict for a stream's config", lambda tmp: tmp,
     lambda p: __import__("hybridtrack.streaming").streaming.stream(
         __import__("hybridtrack.streaming").streaming.synthetic_days("lanzhou", "2021-06-21", freq="1min"), p / "s",
         config={}),
     None, "config must be a SimulationConfig (SimulationConfig.from_dict for a dict), got dict"),
    ("naive times to the sun model", lambda tmp: None,
     lambda p: solar_position(__import__("pandas").date_range("2021-06-21", periods=2, freq="h"), "nanjing"),
     None, "naive"),
    # parameters at the door (issue 11, item 4)
    ("axis azimuth NaN", lambda tmp: None, lambda p: Collector("trough-ns", float("nan")),
     lambda p: SIMULATE + ["--axis-azimuth", "nan"],
     "collector: axis_azimuth (degrees from north) must be a finite number within [-360, 360], got nan"),
    ("negative seed", lambda tmp: None, lambda p: synthetic("lanzhou", "2021-06-21", seed=-1),
     lambda p: SIMULATE + ["--seed=-1"], "seed must be a whole number within [0, 9,223,372,036,854,775,807], got -1"),
    ("negative seed in a run config", config_file("seed = -1\n"), lambda p: SimulationConfig.from_toml(p),
     lambda p: SIMULATE + ["--config", str(p)], "config.toml: seed must be a whole number within [0, "),
    # 86,400 s x 1e9 steps a second; x 2,000 bytes a step = 1.728e17 bytes
    ("a step of 1 ns", lambda tmp: None, lambda p: synthetic("lanzhou", "2021-06-21", freq="1ns"),
     lambda p: SIMULATE + ["--freq", "1ns"],
     "2021-06-21 to 2021-06-21: 86,400,000,000,000 steps of 1ns would need about 172,800,000.0 GB of memory"),
    # 365 x 86,400 = 31,536,000 steps x 2,000 bytes = 63.1 GB, over the 16 GiB cap on any machine
    ("a year at 1 s", lambda tmp: None, lambda p: synthetic("lanzhou", "2021-01-01", "2021-12-31", freq="1s"),
     lambda p: ["simulate", "--site", "lanzhou", "--date", "2021-01-01", "--days", "365", "--freq", "1s"],
     "2021-01-01 to 2021-12-31: 31,536,000 steps of 1s would need about 63.1 GB of memory"),
    ("a sun table at 1 ns", lambda tmp: None, lambda p: local_range("2021-06-21", "UTC", freq="1ns"),
     lambda p: ["sun", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "1ns"], "steps of 1ns would need about"),
    # a day at 2-day steps is its midnight alone: it had been refused as a frame, naming no step
    ("a step longer than the period", lambda tmp: None, lambda p: synthetic("lanzhou", "2021-06-21", freq="2d"),
     None, "step '2d' leaves 1 time step in the period: a weather frame needs"),
    # the command line refuses a step no run takes before it makes a frame (it had said "resample the frame")
    ("a step longer than a run's", lambda tmp: None, lambda p: run_step("2d"),
     lambda p: SIMULATE + ["--freq", "2d"], "step '2d' is longer than a run's longest, 1 h"),
    ("an empty step", lambda tmp: None, lambda p: synthetic("lanzhou", "2021-06-21", freq=""),
     lambda p: SIMULATE + ["--freq", ""], "step '' is not a duration"),
    ("reversed working hours", config_file("[controller]\nworking_hours = ['20:00', '05:00']\n"),
     lambda p: SimulationConfig.from_toml(p), lambda p: SIMULATE + ["--config", str(p)],
     "controller: working_hours ['20:00', '05:00'] must end after they start on the same day"),
    ("drive limits of 1e308", config_file("[drive]\nlimits = [0.0, 1e308]\n"), lambda p: SimulationConfig.from_toml(p),
     lambda p: SIMULATE + ["--config", str(p)], "config.toml: drive: limits (degrees) = 1e+308 is outside [-360, 720]"),
    ("heliostat limits beyond two turns", config_file("[heliostat_drive]\nlimits = [-360.0, 720.0]\n"),
     lambda p: SimulationConfig.from_toml(p), lambda p: SIMULATE + ["--config", str(p)],
     "heliostat_drive: drive: limits [-360.0, 720.0] span more than 720° (two turns)"),
    ("process noise of 1e308", config_file("[controller]\nprocess_noise = 1e308\n"),
     lambda p: SimulationConfig.from_toml(p), lambda p: SIMULATE + ["--config", str(p)],
     "controller: process_noise = 1e+308 is outside (0, 10]"),
    ("a duration of nan", config_file("[controller]\ndwell = 'nan'\n"), lambda p: SimulationConfig.from_toml(p),
     lambda p: SIMULATE + ["--config", str(p)], "controller: dwell 'nan' is not a positive duration such as '20min'"),
    ("one stuck scan", config_file("[controller]\nstuck_scans = 1\n"), lambda p: SimulationConfig.from_toml(p),
     lambda p: SIMULATE + ["--config", str(p)], "controller: stuck_scans must be a whole number within [3, 10,000]"),
    ("fuzzy config: infinite raw_range", config_file(
        "[inputs.intensity]\nraw_range = [30, inf]\nterms.weak = {shape='gaussmf', params=[0, 1]}\n"
        "[inputs.variation]\nraw_range = [0, 180]\nterms.small = {shape='gaussmf', params=[0, 1]}\n"),
     lambda p: FuzzyConfig.from_toml(p), lambda p: CLASSIFY + ["--config", str(p)],
     "inputs.intensity: raw_range must be two finite numbers [low, high] with low < high, got [30.0, inf]"),
    # it had mapped every reading a sensor gives onto the universe's floor: each day overcast
    ("fuzzy config: a raw_range past any reading", config_file(
        "[inputs.intensity]\nraw_range = [30, 1e308]\nterms.weak = {shape='gaussmf', params=[0, 1]}\n"
        "[inputs.variation]\nraw_range = [0, 180]\nterms.small = {shape='gaussmf', params=[0, 1]}\n"),
     lambda p: FuzzyConfig.from_toml(p), lambda p: CLASSIFY + ["--config", str(p)],
     "inputs.intensity: raw_range [30.0, 1e+308]: 1e+308 is no reading; over 100,000 mA, which no sun sensor gives"),
    ("fuzzy config: a raw_range below zero", config_file(
        "[inputs.intensity]\nraw_range = [30, 300]\nterms.weak = {shape='gaussmf', params=[0, 1]}\n"
        "[inputs.variation]\nraw_range = [-20, 180]\nterms.small = {shape='gaussmf', params=[0, 1]}\n"),
     lambda p: FuzzyConfig.from_toml(p), lambda p: CLASSIFY + ["--config", str(p)],
     "inputs.variation: raw_range [-20.0, 180.0]: -20 is no reading; a variation is a range, max - min, never "
     "below zero"),
    ("fuzzy config: NaN membership parameter", config_file(
        "[output]\nterms.overcast = {shape='trimf', params=[0, nan, 10]}\n"),
     lambda p: FuzzyConfig.from_toml(p), lambda p: CLASSIFY + ["--config", str(p)],
     "output.weather.terms.overcast: parameters must be finite numbers"),
    ("an infinite tuning margin", config_file("intensity,variation,weather\n100,20,sunny\n50,100,cloudy\n",
                                              "labels.csv"),
     lambda p: __import__("hybridtrack.fuzzy.tuning").fuzzy.tuning.tune(None, p, margin=math.inf),
     lambda p: ["tune", str(p), "--out", str(p) + ".toml", "--margin", "inf"],
     "margin (score units) must be a finite number within [0, 30], got inf"),
    ("an unknown ablation policy", lambda tmp: None,
     lambda p: __import__("hybridtrack.ablation").ablation.AblationPlan(policies=("bogus",)),
     lambda p: ["ablate", "--policies", "bogus"], "'bogus'"),
    # outputs kept (issue 11, item 5)
    ("an output through a symlink", planted_link("run.toml"),
     lambda p: SimulationConfig().to_toml(p / "run.toml"), lambda p: ["init", str(p)],
     "run.toml is a symbolic link; results are never written through one"),
    ("an output folder that is a symlink", planted_link(None),
     lambda p: SimulationConfig().to_toml(p / "run.toml"), lambda p: ["init", str(p)],
     "out is a symbolic link; results are never written through one"),
    ("an existing output without --force", existing_files("run.toml"),
     lambda p: refusing(lambda: SimulationConfig().to_toml(p / "run.toml")), lambda p: ["init", str(p)],
     "run.toml; give --force to replace it"),
    ("a full disk", lambda tmp: None, lambda p: SimulationConfig().to_toml("/dev/full"),
     lambda p: ["sun", "--site", "lanzhou", "--date", "2021-06-21", "--csv", "/dev/full", "--force"],
     "/dev/full: cannot write (No space left on device)"),
    ("an image kind matplotlib cannot draw", lambda tmp: None,
     lambda p: __import__("hybridtrack.report").report.save_figure(__import__("matplotlib.figure").figure.Figure(),
                                                                    "x.xyz"),
     lambda p: ["surface", "--out", "x.xyz"], "x.xyz: cannot draw a .xyz image"),
]


@pytest.mark.parametrize("make, api, cli, message", [row[1:] for row in MATRIX], ids=[row[0] for row in MATRIX])
def test_bad_input_is_one_clear_line_from_api_and_cli(tmp_path, capsys, make, api, cli, message):
    path = make(tmp_path)
    with pytest.raises(HybridtrackError) as error:
        api(path)
    assert message in str(error.value) and "\n" not in str(error.value)
    if cli is None:
        return
    assert main(cli(path)) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and message in captured.err
    assert captured.err.startswith("hybridtrack: error: ") and "Traceback" not in captured.err


@pytest.mark.parametrize("argv", [["field", "trough", "--date", "2021-06-21", "--count", "1", "--out", ""], SIMULATE + ["--out", " "],
                                  ["sun", "--site", "lanzhou", "--date", "2021-06-21", "--csv", ""],
                                  ["demo", "--out", ""]])
def test_an_empty_output_path_is_refused_not_read_as_no_output(capsys, argv):
    """``--out "$DIR"`` with DIR unset had run the whole command and written nothing, silently."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is empty: give a file or folder to write" in err


@pytest.mark.parametrize("argv", [["ablate", "--policies", "bogus"], ["simulate", "--date", "2021-06-21", "--freq"],
                                  ["sun", "--variation"], [], ["classify", "--intensity", "--variation", "1"],
                                  ["simulate", "--date", "2021-06-21", "--bogus"]])
def test_a_command_line_argparse_refuses_is_one_line_too(capsys, argv):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("hybridtrack: error: ") and "--help)" in err
    assert not err.startswith("hybridtrack: error: hybridtrack: ")  # the prefix once, a command named after it


@pytest.mark.parametrize("argv, flag", [
    (["field", "fresnel", "--site", "lanzhou", "--date", "2021-06-21", "--rows=1_0,2"], "--rows"),
    (["field", "trough", "--site", "lanzhou", "--date", "2021-06-21", "--count", "1_2"], "--count"),
    (["classify", "--intensity", "2_00", "--variation", "5"], "--intensity"),
    (["simulate", "--date", "2021-06-21", "--seed", "1_000"], "--seed")])
def test_a_number_with_underscores_is_refused_not_read_as_another(capsys, argv, flag):
    """Python's int() and float() read "1_0" as 10: a typo on a command line ran a field of row 10."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and flag in err and "_" in err


@pytest.mark.parametrize("argv, flag", [
    (["field", "trough", "--site", "lanzhou", "--date", "2021-06-21", "--count", "\uff11\uff12"], "--count"),
    (["classify", "--intensity", "\u0662\u0660\u0660", "--variation", "5"], "--intensity"),
    (["simulate", "--date", "2021-06-21", "--seed", "\u0967"], "--seed")])
def test_a_number_in_other_digits_is_refused(capsys, argv, flag):
    """int() and float() read full-width "１２", Arabic-Indic "٢٠٠" and Devanagari "१" as 12, 200
    and 1: a stray input method changed a run without a word."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and flag in err and "ASCII" in err


@pytest.mark.parametrize("text", ["\uff12\uff10\uff12\uff11-06-21", "2021-\u0660\u0666-21"])
def test_a_date_in_other_digits_is_refused(text):
    from hybridtrack.times import parse_date

    with pytest.raises(HybridtrackError, match="YYYY-MM-DD"):
        parse_date(text)


def test_ctrl_c_is_one_line_and_the_shells_status(monkeypatch, capsys, tmp_path):
    import hybridtrack.cli.runs as runs
    import hybridtrack.streaming as streaming

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(runs, "synthetic_frame", interrupted)
    assert main(["simulate", "--site", "lanzhou", "--date", "2021-06-21"]) == 130
    err = capsys.readouterr().err.strip()
    assert err == "hybridtrack: interrupted; files already written are left as they are"  # no streamed run's files
    monkeypatch.setattr(streaming, "stream", interrupted)
    assert main(["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--stream", "--out", str(tmp_path)]) == 130
    assert capsys.readouterr().err.strip().endswith("(the finished days in log.partial.parquet and events.partial.csv)")


def test_ctrl_c_while_the_command_loads_is_one_line_and_after_it_is_done_is_ignored(monkeypatch, capsys):
    """A Ctrl-C in the first half second (pandas loading) printed an import's traceback; one while
    Dask shut down at exit printed a weak reference's, after every file was written."""
    import signal
    import sys
    import types

    from hybridtrack import launch

    class Loading(types.ModuleType):
        def __getattr__(self, name):
            raise KeyboardInterrupt

    monkeypatch.setitem(sys.modules, "hybridtrack.cli", Loading("hybridtrack.cli"))
    assert launch.main() == 130
    err = capsys.readouterr().err.strip()
    assert err == "hybridtrack: interrupted while starting; nothing was done"
    monkeypatch.undo()
    previous = signal.getsignal(signal.SIGINT)
    monkeypatch.setattr(sys, "argv", ["hybridtrack", "classify", "--intensity", "200", "--variation", "50"])
    try:
        assert launch.main() == 0 and signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, previous)


def test_without_strict_the_same_problems_are_repaired_and_reported(tmp_path):
    path = tmp_path / "messy.csv"
    path.write_text(HEADER + "2021-06-21 12:01,1,1,1,1\n2021-06-21 12:00,1,1,1,-4\n2021-06-21 12:00,1,1,1,1\n"
                    "2021-06-21 12:02,oops,1,1,1\n2021-06-21 12:03,5,1,1,1\n2021-06-21 12:04,5,1,1,1\n")
    frame = read_weather(path, tz="UTC")
    report = frame.attrs["validation"]
    assert {"unsorted", "duplicates", "impossible", "unreadable"} <= set(report)
    assert report["unreadable"]["ghi"]["lines"] == [5] and len(frame) == 5


# -- every numeric field of every config class: NaN, inf, -1 and 1e308 ---------------------------

from hybridtrack.fields import FresnelField, HeliostatField, ImperfectionSpread, TroughLoop  # noqa: E402

CONFIG_CLASSES = (ControllerConfig, Imperfections, SensorModel, Drive, SkyInputConfig, SimulationConfig, Collector,
                  ImperfectionSpread, FresnelField, TroughLoop, HeliostatField)
BAD_NUMBERS = (math.nan, math.inf, -1, 1e308)
#: Fields where -1 is a real value: signed angles, offsets, errors and distances. Every other
#: numeric field, including any added later, must refuse it.
SIGNED = {("ControllerConfig", "min_altitude"), ("SkyInputConfig", "min_altitude"), ("SensorModel", "bias"),
          ("Drive", "limits"), ("Collector", "axis_azimuth"), ("Collector", "row_distance"), ("Collector", "aim"),
          ("FresnelField", "row_distances"), ("FresnelField", "axis_azimuth"), ("TroughLoop", "axis_azimuth"),
          ("HeliostatField", "aim")} | {("Imperfections", name) for name in (
              "axis_azimuth_error", "axis_tilt_error", "encoder_offset", "clock_error", "clock_drift",
              "latitude_error", "longitude_error", "sensor_bias", "axis_roll_error")}


def _numeric_fields():
    """(class, field name, default) of every field whose default is a number or a tuple of numbers."""
    for cls in CONFIG_CLASSES:
        default = cls()
        for field in dataclasses.fields(cls):
            value = getattr(default, field.name)
            plain = isinstance(value, (int, float)) and not isinstance(value, bool)
            numbers = isinstance(value, tuple) and value and all(isinstance(v, (int, float)) for v in value)
            if plain or numbers or (cls is Collector and field.name == "axis_azimuth"):
                yield cls, field.name, value


def _with_bad(value, bad):
    """`bad` in place of a number, or in each place of a tuple in turn."""
    if isinstance(value, tuple):
        return [tuple(bad if j == i else v for j, v in enumerate(value)) for i in range(len(value))]
    return [bad]


NUMERIC_FIELDS = list(_numeric_fields())


def test_the_sweep_covers_every_config_class():
    assert {cls for cls, _, _ in NUMERIC_FIELDS} == set(CONFIG_CLASSES) and len(NUMERIC_FIELDS) >= 60


@pytest.mark.parametrize("bad", BAD_NUMBERS, ids=["nan", "inf", "minus-one", "1e308"])
@pytest.mark.parametrize("cls, name, value", NUMERIC_FIELDS, ids=[f"{c.__name__}.{n}" for c, n, _ in NUMERIC_FIELDS])
def test_every_numeric_field_refuses_nan_inf_negative_and_absurd(cls, name, value, bad):
    for given in _with_bad(value, bad):
        try:
            cls(**{name: given})
        except HybridtrackError as error:
            said = str(error)
            assert (name in said or name.replace("_", " ") in said or "heliostat 1" in said) and "\n" not in said
        else:  # a real value (a limit's low end of -1°, say) may be accepted only where the field is signed
            assert bad == -1 and (cls.__name__, name) in SIGNED, f"{cls.__name__}({name}={given!r}) was accepted"


def test_a_day_that_does_not_exist_to_draw_is_refused(tmp_path, capsys):
    assert main(["validate-sky", "data/nanjing-2013-cloudy.csv", "--site", "nanjing", "--day", "2021-13-01",
                 "--plot", str(tmp_path / "day.png")]) == 2
    assert capsys.readouterr().err == "hybridtrack: error: date '2021-13-01' does not exist or is not YYYY-MM-DD\n"


def _small_day():
    from hybridtrack.sky import synthetic

    return synthetic("lanzhou", "2021-06-21", freq="10min")


@pytest.mark.parametrize("frame, message", [
    (lambda f: f.set_axis(pd.MultiIndex.from_tuples([(c, "x") for c in f.columns]), axis=1),
     "columns must be plain names"),  # AttributeError: 'DataFrame' object has no attribute 'dtype'
    (lambda f: f.assign(photocurrent="x"), "column 'photocurrent' must hold numbers"),  # ValueError
    (lambda f: f.assign(dni=f["dni"] * 1e200), r"W/m² is not light \(over 14,080"),  # LinAlgError in the fit
    (lambda f: f.assign(dni=f["dni"] * 1000), r"is not light \(over 14,080: a unit mixed up\?\)"),  # ran silently
    (lambda f: f.assign(dni=f["dni"].astype(complex)), "must hold numbers, got dtype complex128"),  # imaginary dropped
    (lambda f: f.assign(photocurrent=math.inf), "inf mA is not light"),
    (lambda f: f.assign(ghi=f["ghi"].astype(str)), "column 'ghi' must hold numbers"),  # TypeError in the kW check
    (lambda f: f.assign(ghi=f["ghi"].astype(object).where(f["ghi"] < 500, "abc")), "column 'ghi' must hold numbers"),
    (lambda f: f.assign(ghi=f["ghi"].astype(object).where(f.index.hour != 11, "abc")),  # named the dtype, not the row
     "column 'ghi' must hold numbers, got dtype object; the first that is none, at 2021-06-21 11:00:00\\+08:00: 'abc'"),
    (lambda f: f.assign(temp_air=f["temp_air"].astype(str).where(f.index.hour != 12, "warm")),
     "column 'temp_air' must hold numbers, got dtype (str|object); the first that is none, at 2021-06-21 12:00:00"),
    (lambda f: f.assign(ghi=math.inf), "column 'ghi' at .*: inf W/m² is not light"),  # blamed dni as kW/m²
    (lambda f: f.assign(ghi=-math.inf), r"column 'ghi' at .*: -inf W/m² is no reading \(infinite\)"),  # "over 14,080"
])
def test_a_weather_frame_of_no_light_or_no_names_is_refused_in_one_line(frame, message):
    with pytest.raises(HybridtrackError, match=message):
        simulate(frame(_small_day()), "lanzhou")


def test_a_field_refuses_a_ghi_of_no_numbers_by_name():
    from hybridtrack import simulate_field
    from hybridtrack.fields import TroughLoop

    day = _small_day()
    with pytest.raises(HybridtrackError, match="column 'ghi' must hold numbers"):
        simulate_field(day.assign(ghi=day["ghi"].astype(str)), "lanzhou", TroughLoop(count=2))


@pytest.mark.parametrize("options, message", [
    (dict(classifier="x"), "classifier must be a FuzzyWeatherClassifier or None"),  # AttributeError deep inside
    (dict(warm_start="no"), "warm_start must be True, False or an earlier run's Result.memory"),  # read as True
    (dict(bulk_nights="no"), "bulk_nights must be True or False"),
    (dict(warm_start={"theta": "abc"}), "warm_start: theta must be numbers"),  # ValueError
    (dict(warm_start={"clock": 5}), "warm_start: clock must be the clock watch's readings"),  # TypeError
    (dict(warm_start={"x": 1}), "warm_start: unknown key 'x'"),  # ignored
])
def test_simulates_options_of_another_kind_are_refused_by_name(options, message):
    with pytest.raises(HybridtrackError, match=message):
        simulate(_small_day(), "lanzhou", **options)


def test_an_earlier_runs_memory_is_still_taken_whole():
    day = _small_day()
    following = day.set_axis(day.index + pd.Timedelta(days=1))  # a memory carries forward in time
    for strategy in ("hybrid", "astronomical-commissioned"):
        memory = simulate(day, "lanzhou", strategy=strategy).memory
        assert simulate(following, "lanzhou", strategy=strategy, warm_start=memory).summary["steps"] == len(day)


@pytest.mark.parametrize("argv, option", [
    (["sun", "--site", "lanzhou", "--date", "2021-06-21", "--site=nanjing"], "--site"),
    (["simulate", "--site", "lanzhou", "--start", "2021-06-21", "--seed", "1", "--seed", "2"], "--seed"),
    (["ablate", "--sites", "lanzhou", "--sites", "nanjing"], "--sites"),
])
def test_an_option_that_takes_one_value_is_refused_when_given_twice(capsys, argv, option):
    # argparse keeps the last: the run had gone to Nanjing, or run seed 2, without a word
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and f"{option} is given twice" in err and "give it once" in err


def test_options_that_add_up_may_be_repeated(tmp_path):
    path = tmp_path / "w.csv"
    day = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=1)
    day[["ghi", "dni", "dhi"]].rename(columns={"ghi": "G", "dni": "B"}).to_csv(path, index_label="time")
    assert main(["check", str(path), "--site", "lanzhou", "--map", "ghi=G", "--map", "dni=B"]) == 0


def _refuse_above_ten(values: dict) -> None:
    """A check for `blamed`: a, b and c default to 1; a or c above 10 is refused, and so is a + b above 10."""
    a, b, c = (values.get(name, 1) for name in "abc")
    if a > 10 or c > 10:
        raise HybridtrackError("a or c is above 10")
    if a + b > 10:
        raise HybridtrackError("a + b is above 10")


@pytest.mark.parametrize("given, named", [
    ({"a": 11, "b": 1, "c": 1}, ["a"]),  # alone
    ({"a": 11, "b": 1, "c": 11}, ["a", "c"]),  # each alone, the same refusal
    ({"a": 6, "b": 6, "c": 1}, ["a", "b"]),  # only together: each named, not c
    ({"a": 1, "b": 1, "c": 11}, ["c"]),
])
def test_a_refusal_is_blamed_on_the_values_it_came_from(given, named):
    from hybridtrack.errors import blamed

    with pytest.raises(HybridtrackError) as refused:
        _refuse_above_ten(given)
    assert blamed(_refuse_above_ten, given, str(refused.value)) == named


def test_a_refusal_without_any_of_the_values_is_blamed_on_none():
    from hybridtrack.errors import blamed

    def refused_always(values):
        raise HybridtrackError("the file is bad")

    assert blamed(refused_always, {"a": 1, "b": 2}, "the file is bad") == []


@pytest.mark.parametrize("argv", [
    ["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--config", ""],  # had run the defaults, seed 0
    ["compare", "--site", "lanzhou", "--date", "2021-06-21", "--config", " "],
    ["classify", "--intensity", "200", "--variation", "50", "--config", ""],
    ["field", "heliostat", "--site", "lanzhou", "--date", "2021-06-21", "--positions", ""],
])
def test_an_empty_path_to_read_is_refused_by_its_flag(argv, capsys):
    """``--config "$CONFIG"`` with the variable unset is no file: refused, not read as no option."""
    assert main(argv) == 2
    flag = argv[argv.index("") - 1] if "" in argv else "--config"
    assert capsys.readouterr().err == f"hybridtrack: error: {flag} is empty: give a file to read, or leave {flag} out " \
                                      "(an unset shell variable?)\n"


def test_a_sensor_too_dull_to_see_the_sun_is_refused_and_the_dullest_taken_runs():
    """A responsivity of 1e-300 mA per W/m² had been taken, and broke the mount fit's SVD mid-run
    (a traceback from astronomical-commissioned and hybrid-oracle); the least taken runs."""
    from hybridtrack.sensor import MIN_RESPONSIVITY, SensorModel
    from hybridtrack.sky import synthetic

    with pytest.raises(HybridtrackError, match=r"^sensor: responsivity = 1e-300 is outside \[0.001, 10\]$"):
        SensorModel(responsivity=1e-300)
    frame = synthetic("lanzhou", "2021-06-21", weather="mixed", seed=1, freq="5min")
    config = SimulationConfig(sensor=SensorModel(responsivity=MIN_RESPONSIVITY))
    for strategy in ("astronomical-commissioned", "hybrid-oracle"):
        assert simulate(frame, "lanzhou", strategy=strategy, config=config).summary["tracking_error_deg"]["rms"] < 1.0


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero here")
def test_a_config_that_never_ends_is_refused_at_its_limit(capsys):
    """``--config /dev/zero`` had been read until the memory ran out (a MemoryError traceback)."""
    assert main(["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--config", "/dev/zero"]) == 2
    # refused at its first piece as binary (before, once 16 MiB had been read, as too large)
    assert capsys.readouterr().err == ("hybridtrack: error: /dev/zero: looks binary, not a text config file (a device "
                                       "or a stream of binary data?)\n")


def test_a_file_is_read_whole_up_to_its_limit_and_refused_one_byte_past_it(tmp_path):
    from hybridtrack.io.files import read_bytes

    path = tmp_path / "f.bin"
    path.write_bytes(b"x" * 1000)
    assert read_bytes(path, limit=1000) == b"x" * 1000
    with pytest.raises(HybridtrackError, match=r"f\.bin: larger than 0 MiB, more than a file can be"):
        read_bytes(path, limit=999)


@pytest.mark.parametrize("flags, message", [
    (["--lat", "95", "--lon", "100", "--tz", "UTC"], "--lat 95.0 is outside [-90, 90] degrees"),
    (["--lat", "30", "--lon", "200", "--tz", "UTC"], "--lon 200.0 is outside [-180, 180] degrees"),
    (["--lat", "30", "--lon", "100", "--tz", "UTC", "--altitude", "-9000"], "--altitude -9000.0 m is outside"),
    (["--lat", "30", "--lon", "100", "--tz", "Mars/X"], "--tz: unknown time zone 'Mars/X'"),
])
def test_a_site_by_coordinates_is_refused_by_its_flag(flags, message, capsys):
    """It had said "site 'custom': latitude 95.0 is outside ...", naming a site the user never named."""
    assert main(["simulate", "--date", "2021-06-21", *flags]) == 2
    assert capsys.readouterr().err.startswith(f"hybridtrack: error: {message}")


def test_replays_step_is_refused_by_its_flag_before_the_file_is_read(capsys):
    assert main(["replay", "no-such-file.csv", "--site", "lanzhou", "--step", "0min"]) == 2
    assert capsys.readouterr().err == "hybridtrack: error: --step: step '0min' must be positive\n"


def test_a_check_step_no_run_takes_is_refused_by_its_flag(tmp_path, capsys):
    """`check --freq 1d` had averaged 300 minutes into one row and called it clean: a file no
    replay can run. The step is refused, by its flag, before the file is read, as replay's is."""
    assert main(["check", "no-such-file.csv", "--freq", "1d"]) == 2
    assert capsys.readouterr() == ("", "hybridtrack: error: --freq: step '1d' is longer than a run's longest, 1 h (a "
                                       "tracking controller is replayed at steps of an hour or finer)\n")


def test_a_replay_step_no_run_takes_is_refused_by_its_flag(tmp_path, capsys):
    """`--step 1W` had printed the report of a file averaged onto weeks, then the run's refusal
    naming the frame's median step; a step that leaves one row had said "the weather frame needs
    at least two steps" (helper-37). Both name --step."""
    assert main(["replay", "no-such-file.csv", "--site", "lanzhou", "--step", "1W"]) == 2
    assert capsys.readouterr() == ("", "hybridtrack: error: --step: step '1W' is longer than a run's longest, 1 h (a "
                                       "tracking controller is replayed at steps of an hour or finer)\n")
    two = tmp_path / "two.csv"
    two.write_text("time,ghi,dni,dhi,wind_speed\n2021-06-21T12:00:00+08:00,900,800,100,2\n"
                   "2021-06-21T12:20:00+08:00,900,800,100,2\n")
    assert main(["replay", str(two), "--site", "lanzhou", "--step", "1h"]) == 2
    assert capsys.readouterr().err == (f"hybridtrack: error: --step 1h: {two} makes 1 step at that step; a run needs at "
                                       "least two: give a shorter --step\n")


@pytest.mark.parametrize("command", [["replay", "--strategy", "hybrid-oracle"], ["compare"]])
def test_a_files_sky_label_the_oracle_cannot_read_is_refused_by_line_and_column(tmp_path, capsys, command):
    """The hybrid-oracle policy's refusal of a file's label that names no sky had named a time stamp
    of the frame ("the frame's 'sky' column at 2021-06-21 11:40:00+08:00"), after compare had run
    every other policy. It names the file's line and column, before any run."""
    frame = synthetic("lanzhou", "2021-06-21", "2021-06-21", weather="mixed", freq="10min", seed=1)
    frame = frame[["ghi", "dni", "dhi", "wind_speed", "sky"]].assign(sky=lambda f: f["sky"].astype(str))
    frame.loc[frame.index[70:72], "sky"] = "foggy"
    frame.to_csv(tmp_path / "w.csv", index_label="Time")
    lines = (tmp_path / "w.csv").read_text().splitlines()
    first = next(n for n, line in enumerate(lines, 1) if line.endswith(",foggy"))
    assert main([command[0], str(tmp_path / "w.csv"), "--site", "lanzhou", *command[1:],
                 "--out", str(tmp_path / "run")]) == 2
    assert capsys.readouterr().err == (f"hybridtrack: error: {tmp_path / 'w.csv'}: column 'sky': 'foggy' (line {first}) "
                                       "is no sky label (2 such); the hybrid-oracle policy reads 'sunny', 'cloudy', "
                                       "'overcast', 'unknown'\n")
    assert not (tmp_path / "run").exists()
