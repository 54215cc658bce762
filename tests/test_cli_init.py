"""hybridtrack init writes three files that load as written."""

import pytest

from hybridtrack.cli import main
from hybridtrack.fuzzy import FuzzyConfig
from hybridtrack.io import read_toml
from hybridtrack.simulation import SimulationConfig
from hybridtrack.testing import load_cases


def test_init_writes_a_run_config_a_fuzzy_config_and_a_rule_table_that_load(tmp_path, capsys):
    assert main(["init", str(tmp_path / "start")]) == 0
    folder = tmp_path / "start"
    run = (folder / "run.toml").read_text()
    assert run.count("\n# ") > 20  # commented, key by key
    assert SimulationConfig.from_toml(folder / "run.toml") == SimulationConfig()
    assert FuzzyConfig.from_toml(folder / "fuzzy.toml") == FuzzyConfig.default()
    cases = load_cases(folder / "test_site.rules.csv")
    assert [c.weather for c in cases] == ["sunny", "cloudy", "cloudy", "overcast"]
    for case in cases:
        assert case.config_path == str((folder / "fuzzy.toml").resolve())
        case.check()
    assert read_toml(folder / "run.toml")["controller"]["wind_stow"] == 17.2
    # the keys a run does not read say so where a user would edit them
    assert "# Not read by a run (leave it as it is); a run reads imperfections.sensor_bias" in run
    assert run.count("# Not read by a run") == 5


def test_init_refuses_to_overwrite_without_force(tmp_path, capsys):
    assert main(["init", str(tmp_path)]) == 0
    assert main(["init", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert f"would replace 3 existing files: {tmp_path / 'run.toml'}, " in err and "give --force" in err
    assert main(["init", str(tmp_path), "--force"]) == 0
    assert f"replaced (--force): {tmp_path / 'run.toml'}, " in capsys.readouterr().out


def test_init_into_a_file_is_an_error(tmp_path, capsys):
    target = tmp_path / "file"
    target.write_text("x")
    assert main(["init", str(target)]) == 2
    assert "is a file, not a folder" in capsys.readouterr().err


@pytest.mark.parametrize("command", [["init", "--help"], ["rules", "--help"]])
def test_new_commands_have_help(command, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(command)
    assert exit_.value.code == 0 and "usage: hybridtrack" in capsys.readouterr().out
