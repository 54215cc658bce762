"""The README's "For people" section runs as written, so it cannot drift."""

import re
import shlex
import shutil
from pathlib import Path

import pytest

from hybridtrack.cli import main

ROOT = Path(__file__).resolve().parents[1]


def section_blocks(language: str) -> list[str]:
    text = (ROOT / "README.md").read_text()
    section = re.search(r"## For people.*?(?=\n## )", text, re.S).group(0)
    return re.findall(rf"```{language}\n(.*?)```", section, re.S)


def commands() -> list[list[str]]:
    lines = [line.split("#")[0].strip() for block in section_blocks("bash") for line in block.splitlines()]
    return [shlex.split(line)[1:] for line in lines if line.startswith("hybridtrack ")]


def test_the_python_block_runs_on_a_run_of_that_day():
    import hybridtrack
    from hybridtrack.sky import synthetic

    frame = synthetic("nanjing", "2013-12-22", weather="mixed", seed=3, freq="5min")  # the README's run, coarser
    namespace = {"result": hybridtrack.simulate(frame, "nanjing", collector="trough-ns")}
    (block,) = section_blocks("python")
    for line in block.splitlines():
        code = line.split("#")[0].strip()
        if code:
            exec(code, namespace)  # each line is an expression a reader would type


@pytest.mark.parametrize("argv", [pytest.param(a, marks=pytest.mark.slow) if a[0] == "tune" else a
                                  for a in commands()], ids=lambda a: a[0])
def test_each_command_runs(argv, tmp_path, monkeypatch, capsys):
    shutil.copytree(ROOT / "examples" / "tuning", tmp_path / "examples" / "tuning")
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 0
    assert "wrote" in capsys.readouterr().out
