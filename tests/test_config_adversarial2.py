"""Configs and their commands against a user's slips: refused in one line, status 2, nothing written."""

import os

import pytest

from hybridtrack import HybridtrackError
from hybridtrack.simulation import SimulationConfig
from hybridtrack.cli import main


@pytest.mark.parametrize("folder", ["", "  "])
def test_init_into_an_empty_folder_name_is_refused_and_writes_nothing(folder, tmp_path, capsys, monkeypatch):
    # init "$DIR" with DIR unset had written run.toml, fuzzy.toml and the rule table into the current folder
    monkeypatch.chdir(tmp_path)
    assert main(["init", folder]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "DIR is empty" in err
    assert os.listdir(tmp_path) == []


def test_init_without_a_folder_still_writes_here(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["init"]) == 0
    assert sorted(os.listdir(tmp_path)) == ["fuzzy.toml", "run.toml", "test_site.rules.csv"]


def _options(name, parser):
    """Every option of `parser` and its sub-commands' parsers, with the command it belongs to."""
    import argparse

    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child, sub in action.choices.items():
                yield from _options(f"{name} {child}", sub)
        else:
            yield name, action


def test_every_option_with_a_default_says_it_in_its_help():
    # tune --margin, classify --engine and --intensity-col had defaults their help did not name
    import argparse

    from hybridtrack.cli import build_parser

    silent = [f"{command} {'/'.join(action.option_strings) or action.dest}"
              for command, action in _options("hybridtrack", build_parser())
              if action.default not in (None, False, argparse.SUPPRESS) and "default" not in (action.help or "")]
    assert silent == []


def test_init_suggests_a_command_that_pastes_whole_into_a_shell(tmp_path, capsys):
    # a folder with a blank had been printed bare: pasted, --config took only its first word
    import shlex

    folder = tmp_path / "my runs"
    assert main(["init", str(folder)]) == 0
    suggested = capsys.readouterr().out.splitlines()[-1].removeprefix("try: ")
    assert shlex.split(suggested)[-2:] == ["--config", str(folder / "run.toml")]


@pytest.mark.parametrize("text", ["", "\n  \n", "\ufeff"])
def test_an_empty_config_file_is_refused_not_run_as_the_defaults(text, tmp_path, capsys):
    """A 0-byte run.toml (a write cut short, `> run.toml` by mistake) had run the defaults unsaid."""
    path = tmp_path / "run.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(HybridtrackError, match=r"run.toml: the config file is empty; leave it out for the defaults"):
        SimulationConfig.from_toml(path)
    assert main(["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--config", str(path),
                 "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the config file is empty" in err
    assert not (tmp_path / "out").exists()


def test_a_config_of_comments_alone_is_read_as_the_defaults(tmp_path):
    path = tmp_path / "run.toml"
    path.write_text("# every setting at its default\n")
    assert SimulationConfig.from_toml(path) == SimulationConfig()


@pytest.mark.parametrize("value", ["5", 5, 5.0, " 5 "])
def test_a_duration_without_a_unit_is_refused_not_read_as_nanoseconds(value):
    """pandas reads a bare number as nanoseconds: a TOML `dwell = "5"` had been a dwell of 5 ns
    (and `dwell = 5` too), a mode switch allowed at every scan, without a word."""
    from hybridtrack.control import ControllerConfig

    with pytest.raises(HybridtrackError, match=r"controller: dwell .*5.* has no unit; write it with one, such as '5(\.0)?min'"):
        ControllerConfig(dwell=value)


@pytest.mark.parametrize("name, value", [("wind_hold", "400D"), ("distrust", "25h"), ("calibration_tau", "2D")])
def test_a_controller_timing_longer_than_a_day_is_refused(name, value):
    """Every controller timing works within its day (offsets and windows start afresh each
    morning); `wind_hold = "400D"` (for 400min) had held the stow for 400 days."""
    from hybridtrack.control import ControllerConfig

    with pytest.raises(HybridtrackError, match=f"controller: {name} '{value}' is longer than a day"):
        ControllerConfig(**{name: value})
    assert ControllerConfig(**{name: "24h"}).minutes(name) == 1440.0


def test_numpys_scalars_are_taken_as_pythons_numbers():
    """np.int64 had been refused as "no whole number" where np.float64 was taken, and where
    simulate_field and sweeps take it (helper-37); np.bool_ stays no number."""
    import numpy as np

    from hybridtrack.fuzzy import FuzzyConfig
    from hybridtrack.simulation import SimulationConfig

    config = SimulationConfig.from_dict({"seed": np.int64(3), "drive": {"deadband": np.float32(0.25)}})
    assert config.seed == 3 and type(config.seed) is int and config.drive.deadband == 0.25
    with pytest.raises(HybridtrackError, match="seed: must be int, got True"):
        SimulationConfig.from_dict({"seed": np.bool_(True)})
    data = FuzzyConfig().to_dict()
    data["resolution"] = {"input": np.int64(1001), "output": np.int32(3001)}
    assert FuzzyConfig.from_dict(data) == FuzzyConfig()
    data["resolution"]["input"] = np.bool_(True)
    with pytest.raises(HybridtrackError, match="resolution.input: must be a whole number"):
        FuzzyConfig.from_dict(data)
