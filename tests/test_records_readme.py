"""Every README command that reads a file runs on a file the suite provides; the documented aliases are the code's.

The files the README names (``logger.csv``, ``station.epw`` ...) are made here from the records
corpus and the project's data, in a scratch folder the commands run in.
"""

from __future__ import annotations

import re
import shlex
import shutil
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hybridtrack.cli import main
from hybridtrack.io import ALIASES

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "tests" / "records"
INPUT = re.compile(r"\.(csv|epw|toml|fis|tm2|dat|gz|zip)$")
OUTPUT_FLAGS = ("--out", "--csv", "--plot")


def readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    commands = []
    for block in re.findall(r"```bash\n(.*?)```", text, re.S):
        for line in block.splitlines():
            line = line.split("  #")[0].strip()
            if line.startswith("hybridtrack "):
                commands.append(line)
    return commands


def input_files(command: str) -> list[str]:
    words = shlex.split(command)[1:]
    return [w for i, w in enumerate(words) if INPUT.search(w) and (i == 0 or words[i - 1] not in OUTPUT_FLAGS)]


READING = [c for c in readme_commands() if input_files(c)]
SLOW = ("hybridtrack tune",)  # a seeded optimisation: about 15 s


def _logger_csv(path: Path) -> None:
    """A plain logger file at Lanzhou, naive Beijing time, with the names the README maps."""
    sys.path.insert(0, str(RECORDS))
    from make_records import truth

    day = truth("lanzhou-day")
    pd.DataFrame({"Timestamp": day.index.tz_convert("Asia/Shanghai").strftime("%Y-%m-%d %H:%M"),
                  "Direct Normal": day["dni"].to_numpy(), "Global": day["ghi"].to_numpy(),
                  "Diffuse": day["dhi"].to_numpy(), "Wind speed": day["wind_speed"].to_numpy()}
                 ).to_csv(path, index=False)


def _fuzzy_files(folder: Path) -> None:
    rng = np.random.default_rng(1)
    intensity, variation = rng.uniform(30, 300, 40), rng.uniform(0, 180, 40)
    pd.DataFrame({"I_mA": intensity, "dI_mA": variation}).to_csv(folder / "log.csv", index=False)
    weather = np.where(intensity > 200, np.where(variation < 60, "sunny", "cloudy"), "overcast")
    pd.DataFrame({"intensity": intensity, "variation": variation, "weather": weather}).to_csv(folder / "labels.csv",
                                                                                            index=False)


@pytest.fixture
def readme_folder(tmp_path, monkeypatch):
    shutil.copytree(ROOT / "data", tmp_path / "data")
    shutil.copytree(ROOT / "examples" / "tuning", tmp_path / "examples" / "tuning")  # the tuning walk-through's labels
    _logger_csv(tmp_path / "logger.csv")
    shutil.copy(RECORDS / "utc-declared-local.csv", tmp_path / "utc-logger.csv")
    shutil.copy(RECORDS / "lanzhou.epw", tmp_path / "station.epw")
    _fuzzy_files(tmp_path)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_the_readme_names_commands_that_read_files():
    names = {name for command in READING for name in input_files(command)}
    assert {"logger.csv", "utc-logger.csv", "station.epw"} <= names
    assert any(c.startswith("hybridtrack replay logger.csv") for c in READING)


@pytest.mark.parametrize("command", [pytest.param(c, marks=pytest.mark.slow) if c.startswith(SLOW) else c
                                     for c in READING])
def test_each_readme_command_that_reads_a_file_runs(readme_folder, capsys, command):
    for name in input_files(command):
        assert (readme_folder / name).exists(), f"the suite provides no {name}"
    assert main(shlex.split(command)[1:]) == 0, capsys.readouterr().err
    printed = capsys.readouterr().out
    if command.startswith(("hybridtrack check", "hybridtrack replay")):
        assert "verdict:" in printed


def test_the_readme_python_reading_example_runs(readme_folder, capsys):
    text = (ROOT / "README.md").read_text()
    block = next(b for b in re.findall(r"```python\n(.*?)```", text, re.S) if "read_weather(" in b)
    exec(compile(block, "README.md", "exec"), {})
    assert "logger.csv: 97 rows read, 961 rows out" in capsys.readouterr().out


def test_the_alias_table_in_the_docs_is_the_codes():
    rows = {}
    text = (ROOT / "docs" / "records.md").read_text()
    section = text[text.index("### Column names"):text.index("## Time stamps")]
    for line in section.splitlines():
        match = re.match(r"\| (time|date|clock|ghi|dni|dhi|wind_speed|temp_air|photocurrent|pointing_2|pointing)\b[^|]*\| (.*) \|$", line)
        if match:
            rows[match.group(1)] = set(re.findall(r"`([^`]*)`", match.group(2)))
    assert set(rows) == set(ALIASES)
    for name, aliases in ALIASES.items():
        documented = rows[name] | ({""} if "unnamed first column" in str(rows[name]) or name == "time" else set())
        assert {a for a in aliases if a} <= {d.lower() for d in documented}, name
