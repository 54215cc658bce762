"""Every ``hybridtrack`` command and every Python block of the README runs, on files made here.

The README names files a reader would have (``logger.csv``, ``station.epw``, ``labels.csv``,
``log.csv``); `readme_files` makes small ones of each. Commands run in that folder in README order;
the long ones (a simulated year, tuning with cross-validation, four-strategy comparisons) are
marked slow. A README command that needs a file not made here fails: add the file, do not skip.
"""

import re
import shlex
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hybridtrack.cli import main

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
SLOW = ("--days 365", "tune ", "compare ")


def bash_commands() -> list[str]:
    """The README's commands, but those that read a file: tests/test_records_readme.py runs them
    on the files it makes for them."""
    from test_records_readme import input_files

    commands = []
    for block in re.findall(r"```bash\n(.*?)```", README, re.S):
        for line in block.splitlines():
            for part in line.split("#")[0].split("&&"):
                if part.strip().startswith("hybridtrack ") and not input_files(part.strip()):
                    commands.append(part.strip())
    return commands


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README, re.S)


def write_epw(path: Path, frame: pd.DataFrame) -> None:
    """A minimal EnergyPlus weather file (hourly, 35 fields a row) from a weather frame."""
    hourly = frame[["ghi", "dni", "dhi", "wind_speed", "temp_air"]].resample("1h").mean()
    lines = ["LOCATION,Lanzhou,GS,CHN,SYNTHETIC,528890,36.1056,103.7264,8.0,1520.0"]
    lines += [f"COMMENTS {k},made by tests/test_readme_runs.py" for k in range(7)]
    for stamp, row in hourly.iterrows():
        fields = [stamp.year, stamp.month, stamp.day, stamp.hour + 1, 60, "?", row["temp_air"], 0.0, 50, 84000,
                  0, 0, 300, row["ghi"], row["dni"], row["dhi"], 0, 0, 0, 0, 180, row["wind_speed"], 0, 0, 30,
                  77777, 9, 999999999, 0, 0.1, 0, 88, 0.2, 0, 0]
        lines.append(",".join(f"{v:.1f}" if isinstance(v, float) else str(v) for v in fields))
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def readme_files(tmp_path_factory):
    from hybridtrack.sensor import sensor_view
    from hybridtrack.sky import synthetic

    folder = tmp_path_factory.mktemp("readme")
    day = synthetic("lanzhou", "2021-06-21", weather="mixed", seed=1)
    logger = pd.DataFrame({"Timestamp": day.index.tz_localize(None).strftime("%Y-%m-%d %H:%M"),
                           "Direct Normal": day["dni"].round(1), "Global": day["ghi"].round(1),
                           "Diffuse": day["dhi"].round(1)})
    logger.to_csv(folder / "logger.csv", index=False)
    view = sensor_view(day)
    pd.DataFrame({"I_mA": view["intensity_ma"].round(2), "dI_mA": view["variation_ma"].round(2)}).to_csv(
        folder / "log.csv", index=False)
    write_epw(folder / "station.epw", synthetic("lanzhou", "2021-06-20", "2021-06-22", weather="sunny", seed=2))
    shutil.copy(ROOT / "examples" / "tuning" / "labels.csv", folder / "labels.csv")
    shutil.copytree(ROOT / "data", folder / "data")
    shutil.copytree(ROOT / "examples", folder / "examples")
    return folder


#: README commands the CLI refuses today, with why; strict, so a fix shows up as a failure to remove the entry.
KNOWN_BROKEN: dict[str, str] = {}


def marks(command: str) -> list:
    found = [pytest.mark.slow] if any(s in command for s in SLOW) else []
    found += [pytest.mark.xfail(reason=why, strict=True) for key, why in KNOWN_BROKEN.items() if key in command]
    return found


@pytest.mark.parametrize("command", [pytest.param(c, marks=marks(c)) for c in bash_commands()])
def test_readme_command_runs(command, readme_files, monkeypatch, capsys):
    monkeypatch.chdir(readme_files)
    status = main(shlex.split(command)[1:])
    assert status == 0, capsys.readouterr().err


def test_readme_python_runs_as_one_session(readme_files, monkeypatch):
    """The blocks in order, in one namespace, as a reader pasting them into one session would."""
    from hybridtrack.sensor import sensor_view
    from hybridtrack.sky import synthetic

    monkeypatch.chdir(readme_files)
    view = sensor_view(synthetic("lanzhou", "2021-06-21", weather="mixed", seed=1, freq="10min"))
    # the names the fuzzy block leaves to the reader: readings as Series and as arrays
    namespace = {"intensity_series": view["intensity_ma"], "variation_series": view["variation_ma"],
                 "i": view["intensity_ma"].to_numpy(), "v": view["variation_ma"].to_numpy()}
    for block in python_blocks():
        block = block.replace('tune(FuzzyConfig(), "labels.csv")',
                              'tune(FuzzyConfig(), "labels.csv", method="local", maxiter=5, restarts=0)')
        exec(compile(block, "README.md", "exec"), namespace)  # noqa: S102 - the README's own code
    assert np.isfinite(namespace["result"].summary["tracking_error_deg"]["rms"])
