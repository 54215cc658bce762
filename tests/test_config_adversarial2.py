"""Configs and their commands against a user's slips: refused in one line, status 2, nothing written."""

import os

import pytest

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
