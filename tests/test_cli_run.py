import json

import pandas as pd
import pytest

from hybridtrack.cli import main
from hybridtrack.control import STRATEGIES


def test_demo_prints_the_summary_and_writes_the_report(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "Lanzhou linear Fresnel row" in printed and "energy capture" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["site"] == "lanzhou" and summary["collector"] == "fresnel" and summary["stow_events"] >= 1
    assert (out / "report.png").stat().st_size > 50_000 and (out / "events.csv").exists()


@pytest.mark.parametrize("site, collector", [("lanzhou", "fresnel"), ("nanjing", "trough-ns"),
                                             ("nanjing", "heliostat"), ("lanzhou", "trough-ew")])
def test_simulate_both_sites_every_collector(tmp_path, capsys, site, collector):
    out = tmp_path / "run"
    assert main(["simulate", "--site", site, "--date", "2021-03-20", "--weather", "mixed", "--collector", collector,
                 "--seed", "2", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["collector"] == collector and summary["steps"] == 1440
    assert "tracking error RMS" in capsys.readouterr().out


def test_simulate_two_days_with_a_config_and_strategy(tmp_path, capsys):
    config = tmp_path / "run.toml"
    config.write_text("seed = 3\n[imperfections]\nclock_error = -120.0\n[controller]\ndwell = '10min'\n")
    assert main(["simulate", "--site", "nanjing", "--date", "2013-06-20", "--days", "2", "--weather", "sunny,cloudy",
                 "--strategy", "astronomical", "--config", str(config)]) == 0
    out = capsys.readouterr().out
    assert "nanjing, 2013-06-20 (2 days, sunny,cloudy), trough-ns, astronomical" in out
    assert "2,880" in out


def test_simulate_runs_the_config_files_strategy_when_no_flag_gives_one(tmp_path, capsys):
    """--strategy's default had replaced the file's controller.strategy with hybrid."""
    config = tmp_path / "run.toml"
    config.write_text('[controller]\nstrategy = "sensor"\n')
    assert main(["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10min", "--config", str(config),
                 "--out", str(tmp_path / "out")]) == 0
    assert capsys.readouterr().out.splitlines()[0].endswith("trough-ns, sensor")
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["strategy"] == "sensor"


def test_replay_a_shipped_record(tmp_path, capsys):
    out = tmp_path / "replay"
    assert main(["replay", "data/nanjing-2013-cloudy.csv", "--site", "nanjing", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    # the file itself: four days of 05:00-20:00 at 1 min, 4 × 901
    rows = len(pd.read_csv("data/nanjing-2013-cloudy.csv"))
    assert f"data/nanjing-2013-cloudy.csv: {rows} rows read" in printed and "replay of" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["steps"] == rows and summary["sky_share"]["cloudy"] > 0.3


def test_replay_a_messy_logger_file_by_coordinates(tmp_path, capsys):
    times = pd.date_range("2021-06-21 06:00", "2021-06-21 19:00", freq="5min")
    raw = tmp_path / "logger.csv"
    pd.DataFrame({"Stamp": times.strftime("%d.%m.%Y %H:%M"), "Direct Normal": 750.0, "Global": 850.0,
                  "Wind": 3.0}).to_csv(raw, sep=";", index=False)
    out = tmp_path / "r"
    assert main(["replay", str(raw), "--lat", "36.1", "--lon", "103.7", "--tz", "Asia/Shanghai",
                 "--map", "time=Stamp", "--map", "dni=Direct Normal", "--map", "ghi=Global",
                 "--map", "wind_speed=Wind", "--collector", "trough-ns", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "resampled: linear in time from 5min to 1min" in printed
    assert json.loads((out / "summary.json").read_text())["steps"] == 13 * 60 + 1  # 06:00-19:00 at 1 min, both ends


def test_compare_runs_every_strategy_side_by_side(tmp_path, capsys):
    out = tmp_path / "cmp"
    assert main(["compare", "--site", "lanzhou", "--date", "2021-06-21", "--weather", "mixed", "--seed", "3",
                 "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    header = next(line for line in printed.splitlines() if "hybrid" in line and "astronomical" in line)
    assert header.split() == list(STRATEGIES)
    data = json.loads((out / "comparison.json").read_text())
    assert data["hybrid"]["tracking_error_deg"]["rms"] < data["astronomical"]["tracking_error_deg"]["rms"]
    assert (out / "comparison.png").stat().st_size > 50_000 and (out / "sensor" / "summary.json").exists()


@pytest.mark.parametrize("args, message", [
    (["simulate", "--site", "atlantis", "--date", "2021-06-21"], "unknown site 'atlantis'"),
    (["simulate", "--site", "lanzhou", "--date", "2021-02-29"], "date '2021-02-29' does not exist"),
    (["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--config", "nope.toml"], "nope.toml: no such config"),
    (["replay", "nope.csv", "--site", "lanzhou"], "nope.csv: no such file"),
    (["replay", "data/lanzhou-2021-sunny.csv"], "no site: give --site NAME"),
    (["compare", "--site", "lanzhou"], "give a recorded FILE, or --date"),
])
def test_run_commands_bad_input_one_line_status_2(capsys, args, message):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def test_a_config_files_seed_is_the_runs_unless_seed_is_given(tmp_path, capsys):
    """--seed's default 0 overrode the file's seed without a word."""
    config = tmp_path / "seeded.toml"
    config.write_text("seed = 3\n")
    day = ["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10min"]

    def printed(*flags):
        assert main(day + list(flags)) == 0
        return capsys.readouterr().out

    by_file, by_flag = printed("--config", str(config)), printed("--seed", "3")
    assert by_file == by_flag
    assert printed("--config", str(config), "--seed", "0") == printed() != by_file
