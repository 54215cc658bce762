"""Long runs in day-long segments (hybridtrack.streaming): running metrics, the streamed log, what
carries across midnight, and how far a streamed run is from one simulate over the same weather."""

import dataclasses
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hybridtrack.cli import main
from hybridtrack.errors import HybridtrackError
from hybridtrack.metrics import HISTOGRAM_RESOLUTION, RunningSummary, summarize
from hybridtrack.simulation import SimulationConfig, simulate
from hybridtrack.streaming import day_seed, frame_days, read_log, recorded_days, stream, synthetic_days
from hybridtrack.world import Imperfections

SITE = "lanzhou"


@pytest.fixture(scope="module")
def streamed(tmp_path_factory):
    """Four climate days at 1 min, hybrid on a north-south trough, with every segment's Result."""
    parts = []
    source = synthetic_days(SITE, "2021-03-10", "2021-03-13", weather="climate", freq="1min", seed=3,
                            gusts_per_day=2.0)
    result = stream(source, tmp_path_factory.mktemp("stream"), strategy="hybrid", on_segment=parts.append)
    return result, parts


def _whole(parts):
    """The segments as one run: the concatenated log and the other inputs of `summarize`."""
    log = pd.concat([p.log for p in parts])
    events = pd.concat([p.events for p in parts], ignore_index=True)
    scoring = {"sun_up": np.concatenate([p.scoring["sun_up"] for p in parts]),
               "incidence": np.concatenate([p.scoring["incidence"] for p in parts]),
               "moves": sum(p.scoring["moves"] for p in parts), "travel": sum(p.scoring["travel"] for p in parts)}
    return log, events, scoring


def test_running_metrics_equal_summarize_on_the_concatenated_log(streamed):
    result, parts = streamed
    log, events, scoring = _whole(parts)
    exact = summarize(log, site=SITE, collector="trough-ns", strategy="hybrid", events=events, **scoring)
    # the running sums themselves, against one pass over the whole log
    whole = RunningSummary(site=SITE, collector="trough-ns", strategy="hybrid")
    whole.add(log, events=events, **scoring)
    running = RunningSummary(site=SITE, collector="trough-ns", strategy="hybrid")
    for part in parts:
        running.add(part.log, events=part.events, **part.scoring)
    for key, value in whole.sums.items():
        assert running.sums[key] == pytest.approx(value, rel=1e-9, abs=1e-9), key
    assert (running.captured, running.offered, running.travel) == pytest.approx(
        (whole.captured, whole.offered, whole.travel), rel=1e-9)
    assert (running.moves, running.steps, running.modes, running.sky, running.events) == \
        (whole.moves, whole.steps, whole.modes, whole.sky, whole.events)
    # the summary written: every key as summarize's, the p95 within half a bin
    summary = result.summary
    for key in exact:
        if key == "tracking_error_deg":
            for name in ("rms", "max", "mean"):
                assert summary[key][name] == pytest.approx(exact[key][name], abs=1e-5), name
            assert abs(summary[key]["p95"] - exact[key]["p95"]) <= HISTOGRAM_RESOLUTION / 2 + 1e-5
        elif isinstance(exact[key], float):
            assert summary[key] == pytest.approx(exact[key], abs=1e-5), key
        else:
            assert summary[key] == exact[key], key
    assert summary["streamed"]["segments"] == 4 and summary["steps"] == 4 * 1440
    assert summary["day_cycle"] == [entry for p in parts for entry in p.summary["day_cycle"]]
    on_disk = json.loads(result.files["summary"].read_text())
    assert on_disk["tracking_error_deg"] == summary["tracking_error_deg"]


def test_the_histogram_p95_is_within_half_a_bin_of_the_exact_quantile():
    rng = np.random.default_rng(0)
    for resolution in (0.001, 0.01):
        error = rng.gamma(2.0, 0.05, 5000)
        log = pd.DataFrame({"dni": rng.uniform(100, 900, 5000), "error": error, "mode": "sensor", "sky": "sunny",
                            "angle": np.zeros(5000)}, index=pd.date_range("2021-06-21", periods=5000, freq="1min",
                                                                         tz="UTC"))
        up, cosine = np.ones(5000, bool), np.ones(5000)
        exact = summarize(log, site=SITE, collector="trough-ns", strategy="hybrid", moves=0, travel=0.0,
                          events=pd.DataFrame(columns=["time", "from", "to", "reason"]), sun_up=up, incidence=cosine)
        running = RunningSummary(site=SITE, collector="trough-ns", strategy="hybrid", resolution=resolution)
        for part in np.array_split(np.arange(5000), 7):
            running.add(log.iloc[part], moves=0, travel=0.0, events=pd.DataFrame(columns=["time", "from", "to",
                                                                                           "reason"]),
                        sun_up=up[part], incidence=cosine[part])
        assert abs(running.p95() - exact["tracking_error_deg"]["p95"]) <= resolution / 2 + 1e-12


def test_the_parquet_log_reads_back_as_the_segments_logs_concatenated(streamed):
    result, parts = streamed
    log = result.log()
    expected = pd.concat([p.log for p in parts])
    pd.testing.assert_frame_equal(log, expected, check_freq=False)
    assert str(log.index.tz) == "Asia/Shanghai"
    for column in ("mode", "sky", "sensor_status"):
        assert list(log[column].cat.categories) == list(parts[0].log[column].cat.categories)
    days = list(result.days(columns=["error", "mode"]))
    assert len(days) == len(parts)
    pd.testing.assert_frame_equal(days[2], parts[2].log[["error", "mode"]], check_freq=False)
    pd.testing.assert_frame_equal(read_log(result.files["log"], day="2021-03-12", tz="Asia/Shanghai"), parts[2].log,
                                  check_freq=False)
    events = result.events()
    expected_events = pd.concat([p.events for p in parts], ignore_index=True)
    assert len(events) == len(expected_events) > 0
    assert list(events["reason"]) == list(expected_events["reason"])
    assert (events["time"] == expected_events["time"]).all()


def test_a_streamed_result_displays_its_summary_and_files(streamed):
    result, _ = streamed
    text, html = repr(result), result._repr_html_()
    assert "streamed run: lanzhou · trough-ns · hybrid · 2021-03-10 to 2021-03-13" in text
    assert "4 day-long segments" in text and "<table>" in html and "log.parquet" in html


def test_streamed_synthetic_days_are_seeded_by_seed_and_date():
    """Each day is its own draw: the same day's weather whatever span holds it."""
    from hybridtrack.sky import synthetic

    a = dict(synthetic_days(SITE, "2021-03-10", "2021-03-12", freq="10min", seed=4))
    b = dict(synthetic_days(SITE, "2021-03-11", "2021-03-11", freq="10min", seed=4))
    import datetime as dt

    day = dt.date(2021, 3, 11)
    pd.testing.assert_frame_equal(a[day], b[day])
    pd.testing.assert_frame_equal(a[day], synthetic(SITE, day, weather="climate", freq="10min",
                                                    seed=day_seed(4, day)))
    # synthetic over the span at once draws every day from one stream: another realisation
    whole = synthetic(SITE, "2021-03-10", "2021-03-12", weather="climate", freq="10min", seed=4)
    assert not np.allclose(whole.loc[a[day].index, "dni"], a[day]["dni"])
    assert day_seed(4, day) != day_seed(4, day + dt.timedelta(days=1)) != day_seed(5, day)


def test_the_mount_fit_and_the_clock_watch_carry_across_midnight(tmp_path):
    """A clock gaining a minute a day over four clear days: the watch's readings carry from day to
    day, so the drift (which needs 1.5 days of readings, more than a segment) is alarmed, once, and
    measured as one simulate over the four days measures it (+60.7 ± 1.7 s a day); the fit's
    updates grow from segment to segment."""
    parts = []
    config = SimulationConfig(imperfections=Imperfections(clock_drift=60.0, clock_error=0.0, commissioned_days_ago=0.0),
                              seed=1)
    source = synthetic_days(SITE, "2021-06-21", "2021-06-24", weather="sunny", freq="1min", seed=1)
    result = stream(source, tmp_path, config=config, on_segment=parts.append)
    updates = [p.memory["updates"] for p in parts]
    assert updates == sorted(updates) and updates[-1] > updates[0] > 0
    readings = [p.summary["clock"]["readings"] for p in parts]
    # the second day's watch holds the first day's readings too (later days add few: once the clock
    # is off by minutes the disagreement monitor distrusts the sensor, as in one simulate over the days)
    assert readings == sorted(readings) and readings[1] > 1.5 * readings[0]
    clock = result.summary["clock"]
    assert clock["days"] > 1.5
    assert clock["drift_s_per_day"] == pytest.approx(60.0, abs=max(6.0, 4 * clock["drift_std_s_per_day"]))
    alarms = [r for r in result.events()["reason"] if "clock drifting" in r]
    assert len(alarms) == 1  # latched: raised once across the segments


def test_the_carried_clock_watch_runs_the_same_on_both_engines(tmp_path):
    """The kernel packs the readings carried in (`kernel.bridge`) as the reference keeps them."""
    config = SimulationConfig(imperfections=Imperfections(clock_drift=60.0, clock_error=0.0, commissioned_days_ago=0.0),
                              seed=1)
    runs = []
    for engine in ("reference", "compiled"):
        parts = []
        source = synthetic_days(SITE, "2021-06-21", "2021-06-22", weather="sunny", freq="2min", seed=1)
        stream(source, tmp_path / engine, config=dataclasses.replace(config, engine=engine), on_segment=parts.append)
        runs.append(parts[-1])
    reference, compiled = runs
    assert reference.summary["clock"] == compiled.summary["clock"]
    assert np.allclose(reference.memory["clock"]["x"], compiled.memory["clock"]["x"], atol=1e-9)
    assert list(reference.events["reason"]) == list(compiled.events["reason"])
    np.testing.assert_allclose(reference.log["angle"], compiled.log["angle"], atol=1e-9)


def test_a_streamed_run_against_one_simulate_on_the_same_weather(tmp_path):
    """What is identical: the weather, the world's truth, the first morning's warm start. What is
    not: each segment after the first draws its own sensor noise (seed from (seed, day)), and the
    controller restarts its moment-to-moment state (mode, filters, windows) at each midnight. So
    the streamed run is another noise realisation of the same days: its RMS and energy capture
    differ from the monolithic run's by about as much as the monolithic run's own differ between
    two seeds (docs/long-runs.md gives the figures); the bound is twice that spread, at least
    0.005° RMS and 0.001 of energy capture."""
    source = synthetic_days(SITE, "2021-03-10", "2021-03-13", weather="climate", freq="1min", seed=3)
    frame = pd.concat([f for _, f in source])
    streamed_run = stream(frame_days(frame, SITE), tmp_path, strategy="hybrid")
    mono = [simulate(frame, SITE, strategy="hybrid", config=SimulationConfig(seed=s)) for s in (0, 1)]
    pd.testing.assert_series_equal(streamed_run.log(["target_true"])["target_true"], mono[0].log["target_true"],
                                   check_freq=False)
    assert streamed_run.summary["steps"] == mono[0].summary["steps"]

    def rms(s):
        return s["tracking_error_deg"]["rms"]

    seed_rms = abs(rms(mono[0].summary) - rms(mono[1].summary))
    seed_energy = abs(mono[0].summary["energy_capture"] - mono[1].summary["energy_capture"])
    assert abs(rms(streamed_run.summary) - rms(mono[0].summary)) <= max(2 * seed_rms, 0.005)
    assert abs(streamed_run.summary["energy_capture"] - mono[0].summary["energy_capture"]) <= \
        max(2 * seed_energy, 0.001)
    assert streamed_run.summary["moves"] == pytest.approx(mono[0].summary["moves"], rel=0.05)


def test_one_day_streamed_is_the_same_run_as_one_simulate(tmp_path):
    """With a single segment nothing is restarted or redrawn (the first day's noise is the run's
    seed's): the streamed run is the in-memory one, its log bit for bit, its events and every key
    of its summary the same, the p95 within half a bin of the running histogram it is read from."""
    (_, frame), = synthetic_days(SITE, "2021-03-10", "2021-03-10", weather="climate", freq="1min", seed=3,
                                 gusts_per_day=2.0)
    streamed = stream(frame_days(frame, SITE), tmp_path, strategy="hybrid")
    mono = simulate(frame, SITE, strategy="hybrid")
    pd.testing.assert_frame_equal(streamed.log(), mono.log, check_freq=False)
    events = streamed.events()
    assert len(events) == len(mono.events) > 2
    assert list(events["reason"]) == list(mono.events["reason"]) and (events["time"] == mono.events["time"]).all()
    for key, value in mono.summary.items():
        if key == "tracking_error_deg":
            for name in ("rms", "max", "mean"):
                assert streamed.summary[key][name] == value[name], name
            assert abs(streamed.summary[key]["p95"] - value["p95"]) <= HISTOGRAM_RESOLUTION / 2 + 1e-5
        else:
            assert streamed.summary[key] == value, key


def test_a_recorded_parquet_or_csv_frame_streams_in_chunks(tmp_path):
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-03-10", "2021-03-11", weather="mixed", freq="5min", seed=2)
    frame.to_parquet(tmp_path / "weather.parquet")
    frame.to_csv(tmp_path / "weather.csv", index_label="time")
    results = {}
    for name in ("weather.parquet", "weather.csv"):
        source = recorded_days(tmp_path / name, SITE, chunk_rows=100)  # days arrive over several chunks
        days = list(source)
        assert [len(f) for _, f in days] == [288, 288]
        np.testing.assert_allclose(pd.concat([f for _, f in days])["dni"], frame["dni"])
        results[name] = stream(source, tmp_path / name.replace(".", "-"))
    memory = stream(frame_days(frame, SITE), tmp_path / "memory")
    for result in results.values():
        assert result.summary["tracking_error_deg"] == memory.summary["tracking_error_deg"]


def test_bad_input_is_refused_in_one_line(tmp_path, capsys):
    from hybridtrack.sky import synthetic

    part = synthetic(SITE, "2021-03-10", weather="sunny", freq="10min").iloc[30:100]
    with pytest.raises(HybridtrackError, match="needs at least one whole local day"):
        frame_days(part, SITE)
    part.to_parquet(tmp_path / "part.parquet")
    with pytest.raises(HybridtrackError, match="needs at least one whole local day"):
        stream(recorded_days(tmp_path / "part.parquet", SITE), tmp_path / "part")
    (tmp_path / "a-file").write_text("")
    with pytest.raises(HybridtrackError, match="cannot make the folder"):
        stream(synthetic_days(SITE, "2021-03-10", freq="10min"), tmp_path / "a-file" / "out")
    with pytest.raises(HybridtrackError, match="is not a positive duration|not a duration|step"):
        synthetic_days(SITE, "2021-03-10", freq="soon")
    with pytest.raises(HybridtrackError, match="ends .* before it starts"):
        synthetic_days(SITE, "2021-03-10", "2021-03-01")
    with pytest.raises(HybridtrackError, match="reads .parquet or .csv"):
        recorded_days(tmp_path / "a-file", SITE)
    base = ["simulate", "--site", SITE, "--date", "2021-03-10", "--freq", "10min", "--stream"]
    for extra, said in ((["--out", str(tmp_path / "a-file" / "out")], "cannot make the folder"),
                        ([], "give --out FOLDER"), (["--weather", "sunny,cloudy", "--out", str(tmp_path / "w")],
                                                    "not a per-day list"),
                        (["--days", "0", "--out", str(tmp_path / "d")], "--days must be between 1 and 3660")):
        assert main(base + extra) == 2
        err = capsys.readouterr().err
        assert said in err and err.count("\n") == 1 and "Traceback" not in err, err


def test_the_in_memory_refusal_names_the_streamed_run(capsys):
    assert main(["simulate", "--site", SITE, "--date", "2021-01-01", "--days", "365", "--freq", "1s"]) == 2
    err = capsys.readouterr().err
    assert "hybridtrack simulate --stream" in err and err.count("\n") == 1


def test_the_command_streams_and_survives_a_closed_pipe(tmp_path):
    """``--stream`` prints the summary and writes its three files; a reader that leaves (``| head``)
    ends the printing, not the run."""
    command = [sys.executable, "-m", "hybridtrack", "simulate", "--site", SITE, "--date", "2021-03-10", "--days", "2",
               "--freq", "5min", "--stream", "--out", str(tmp_path / "run")]
    reader = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    reader.stdout.close()  # nobody reads
    _, err = reader.communicate(timeout=300)
    assert reader.returncode == 0, err.decode()[-500:]
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["steps"] == 2 * 288 and summary["streamed"]["segments"] == 2
    done = subprocess.run(command + ["--force"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "streamed in 2 day-long segments" in done.stdout


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="the peak is read from Linux's /proc")
def test_days_at_one_second_stream_in_bounded_memory(tmp_path):
    """One day and four days at 1 s, each in a fresh process: the peak RSS of four days is that of
    one (memory does not grow with the span), and the summary is finite. The peak is the child's
    VmHWM: its ru_maxrss starts at this (pytest's) process's peak, inherited through the exec."""
    script = (
        "import json, sys\n"
        "from hybridtrack.streaming import stream, synthetic_days\n"
        "days = synthetic_days('lanzhou', '2021-03-10', sys.argv[2], weather='climate', freq='1s', seed=1)\n"
        "r = stream(days, sys.argv[1])\n"
        "peak = next(int(l.split()[1]) * 1024 for l in open('/proc/self/status') if l.startswith('VmHWM:'))\n"
        "print(json.dumps({'peak': peak, 's': r.summary}))\n")
    warm = ("from hybridtrack import simulate\nfrom hybridtrack.simulation import SimulationConfig\n"
            "from hybridtrack.sky import synthetic\n"
            "simulate(synthetic('lanzhou', '2021-03-10'), 'lanzhou', config=SimulationConfig(engine='compiled'))\n")
    subprocess.run([sys.executable, "-c", warm], check=True, timeout=1200)  # a compile's memory is not the run's
    reports = {}
    for last in ("2021-03-10", "2021-03-13"):
        done = subprocess.run([sys.executable, "-c", script, str(tmp_path / last), last], capture_output=True,
                              text=True, timeout=1200)
        assert done.returncode == 0, done.stderr[-2000:]
        reports[last] = json.loads(done.stdout.strip().splitlines()[-1])
    one, four = reports.values()
    assert four["s"]["steps"] == 4 * 86_400
    assert four["peak"] <= 1.15 * one["peak"] + 50 * 2**20, (one["peak"], four["peak"])
    assert four["peak"] < 1.5 * 2**30, (one["peak"], four["peak"])
    error = four["s"]["tracking_error_deg"]
    assert all(np.isfinite(error[k]) for k in ("rms", "p95", "max", "mean"))
    assert 0.9 < four["s"]["energy_capture"] <= 1.0


@pytest.mark.parametrize("cells, message", [
    ("2021-06-21T00:00:00+08:00,0\n2021-06-21T00:01:00+08:00,abc\n", r"row 3, column 'dni': 'abc' is not a number"),
    ("2021-06-21T00:00:00+08:00,0\n21/06/2021 00:01,5\n",
     r"row 3, column 'time': '21/06/2021 00:01' is not an ISO 8601 time stamp"),
    # what the reader would repair (sort, drop, clip, flag) is refused instead, as nothing may change unsaid
    ("2021-06-21T00:01:00+08:00,0\n2021-06-21T00:00:00+08:00,0\n", r"row 3: time 2021-06-21 00:00:00\+08:00 repeats or goes back"),
    ("2021-06-21T00:00:00+08:00,0\n2021-06-21T00:00:00+08:00,0\n", r"row 3: time .* repeats or goes back"),
    ("2021-06-21T00:00:00+08:00,0\n2021-06-21T00:01:00+08:00,-3\n", r"row 3, column 'dni': -3 is outside 0\.\.1400 W/m²"),
    ("2021-06-21T00:00:00+08:00,0\n2021-06-21T00:01:00+08:00,inf\n", r"row 3, column 'dni': inf is outside"),
    ("2021-06-21T00:00:00+08:00,0\n2021-06-21T00:01:00+08:00,1e6\n", r"row 3, column 'dni': 1e\+06 is outside"),
    ("".join(f"2021-06-21T{h:02d}:00:00+08:00,{0.9 * (6 <= h <= 18)}\n" for h in range(24)),
     r"column 'dni': dni is at most 0\.9 over 23 hours; the values look like kW/m² read as W/m²: convert"),
])
def test_a_bad_cell_in_a_streamed_file_is_named_and_nothing_is_left_behind(tmp_path, capsys, cells, message):
    """A streamed file is read as written: a cell that is not what its column holds is refused by
    row and column, and a run refused before its first day leaves no files to --force past."""
    path = tmp_path / "weather.csv"
    path.write_text("time,dni\n" + cells)
    assert main(["replay", str(path), "--site", SITE, "--stream", "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("hybridtrack: error: ") and str(path) in err
    assert re.search(message, err), err
    assert not (tmp_path / "run").exists()  # not even the folder the command made for it


@pytest.mark.parametrize("chunk_rows", [3, 24, 200_000])
def test_kw_per_m2_is_refused_whatever_the_chunks_it_is_read_in(tmp_path, chunk_rows):
    """The magnitude is judged over a day of rows, not over each chunk: chunks of six hours or
    less had each been too short to judge, and a kW/m² file ran as a month of overcast."""
    path = tmp_path / "weather.csv"
    path.write_text("time,dni\n" + "".join(f"2021-06-{d}T{h:02d}:00:00+08:00,{0.9 * (6 <= h <= 18)}\n"
                                            for d in (21, 22) for h in range(24)))
    with pytest.raises(HybridtrackError, match=r"column 'dni': dni is at most 0\.9 over \d+ hours; the values look "
                                               r"like kW/m² read as W/m²"):
        list(recorded_days(path, SITE, chunk_rows=chunk_rows))


def test_what_a_stream_keeps_as_read_is_counted_in_its_summary_and_said(tmp_path, capsys):
    """A streamed file is not repaired, but nothing in it passes unsaid: a missing reading and a
    missing day are counted as the record reader counts them (it had said neither)."""
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-06-20", "2021-06-23", weather="sunny", freq="15min", seed=1)
    frame.loc["2021-06-20 13:30+08:00", "dni"] = np.nan
    kept = frame[frame.index.date != pd.Timestamp("2021-06-22").date()]  # the third day missing
    kept.to_csv(tmp_path / "weather.csv", index_label="time")
    assert main(["replay", str(tmp_path / "weather.csv"), "--site", SITE, "--stream", "--out",
                 str(tmp_path / "run")]) == 0
    said = capsys.readouterr().out
    assert "kept as read: 1 missing dni reading (the first at 2021-06-20 13:30:00+08:00)" in said
    assert "kept as read: 1 gap in the time steps, the longest 1455min (the first after 2021-06-21 23:45:00+08:00)" \
        in said
    report = json.loads((tmp_path / "run" / "summary.json").read_text())["streamed"]["kept_as_read"]
    assert report == {"missing": {"dni": {"count": 1, "first": "2021-06-20 13:30:00+08:00"}},
                      "gaps": {"count": 1, "longest": "1455min", "first_after": "2021-06-21 23:45:00+08:00"}}


def test_a_day_at_a_coarser_step_is_no_gap_at_each_step(tmp_path):
    """A 1-minute day then a 15-minute day: each step is judged against its own day's step (the
    first day's had counted 95 gaps of 15 minutes, helper-32); a day missing after them is one."""
    from hybridtrack.sky import synthetic

    first = synthetic(SITE, "2021-06-20", weather="sunny", freq="1min", seed=1)
    second = synthetic(SITE, "2021-06-21", weather="sunny", freq="15min", seed=1)
    fourth = synthetic(SITE, "2021-06-23", weather="sunny", freq="15min", seed=1)
    result = stream(frame_days(pd.concat([first, second, fourth]), SITE), tmp_path / "run")
    assert result.kept_as_read.report()["gaps"] == {"count": 1, "longest": "1455min",
                                                    "first_after": "2021-06-21 23:45:00+08:00"}


def test_an_unknown_zone_for_a_streamed_files_stamps_is_refused_by_name(tmp_path):
    with pytest.raises(HybridtrackError, match="recorded_days: tz: unknown time zone 'Mars/X'"):
        recorded_days(tmp_path / "weather.csv", SITE, tz="Mars/X")


def test_a_lone_stamp_on_a_day_joins_its_neighbour_and_every_step_runs(tmp_path):
    """A logger's day export runs 00:00 to the next 00:00 inclusive: the last stamp is alone on its
    local day (a run needs two steps). It joins the day before; a lone first stamp joins the day
    after. Nothing is dropped: the streamed log has every stamp of the file."""
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-06-20", "2021-06-22", weather="sunny", freq="10min", seed=1)
    span = frame.iloc[143:289]  # 2021-06-20 23:50 (alone) to 2021-06-22 00:00 (alone)
    span.to_csv(tmp_path / "weather.csv", index_label="time")
    days = list(recorded_days(tmp_path / "weather.csv", SITE))
    assert [(str(day), len(part)) for day, part in days] == [("2021-06-21", 146)]
    result = stream(recorded_days(tmp_path / "weather.csv", SITE), tmp_path / "run")
    assert (read_log(tmp_path / "run" / "log.parquet").index == span.index).all()
    assert result.summary["steps"] == len(span)


def test_a_naive_stamp_the_clock_change_skips_is_refused_by_its_row(tmp_path, capsys):
    """New York's 2021-03-14 02:00-02:59 does not exist: the reader drops it and counts it; a stream
    does not repair, so it names the row instead of passing on pandas' advice."""
    path = tmp_path / "weather.csv"
    stamps = pd.date_range("2021-03-14 01:58", periods=4, freq="1min")  # 01:58, 01:59, 02:00, 02:01
    path.write_text("time,dni\n" + "".join(f"{t:%Y-%m-%d %H:%M:%S},0\n" for t in stamps))
    assert main(["replay", str(path), "--site", SITE, "--tz", "America/New_York", "--stream",
                 "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "row 4, column 'time': 2021-03-14 02:00:00 does not exist or is ambiguous in America/New_York" in err, err


def test_stamps_whose_offset_changes_are_instants_and_a_semicolon_file_streams(tmp_path):
    """A logger on local time writes its offset as daylight saving changes it: the stamps are
    instants, read as the reader reads them (kept in order, not refused). A semicolon-separated
    file (a European locale's CSV) streams as the comma-separated one does."""
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-03-10", "2021-03-11", weather="mixed", freq="10min", seed=2)
    frame.to_csv(tmp_path / "comma.csv", index_label="time")
    frame.to_csv(tmp_path / "semicolon.csv", index_label="time", sep=";")
    shifted = [(t.tz_convert("Europe/Berlin") if k % 2 else t.tz_convert("UTC")).isoformat()
               for k, t in enumerate(frame.index)]  # +01:00 and +00:00 by turns
    frame.set_axis(shifted).to_csv(tmp_path / "offsets.csv", index_label="time")
    expected = pd.concat([day for _, day in recorded_days(tmp_path / "comma.csv", SITE)])
    for name in ("semicolon.csv", "offsets.csv"):
        days = pd.concat([day for _, day in recorded_days(tmp_path / name, SITE, chunk_rows=50)])
        assert (days.index == expected.index).all(), name  # the same instants
        np.testing.assert_array_equal(days["dni"].to_numpy(), expected["dni"].to_numpy())


@pytest.mark.parametrize("name, text, message", [
    ("header.csv", "time,dni\n", "header.csv: holds no time steps"),
    ("no-dni.csv", "time,ghi\n2021-06-21T00:00:00+08:00,0\n", "no column 'dni' (the columns are 'time', 'ghi')"),
    ("dead-dni.csv", "time,dni,ghi\n2021-06-21T00:00:00+08:00,,0\n2021-06-21T00:01:00+08:00,,0\n",
     "column 'dni' holds no number"),
    # a decimal comma and a unit in the header had been sent to derive DNI from GHI and DHI (helper-35)
    ("comma.csv", "time;dni;ghi\n2021-06-21T00:00:00+08:00;;0\n2021-06-21T00:01:00+08:00;0,5;0\n",
     "comma.csv: row 3, column 'dni': '0,5' is not a number (a decimal comma, or a unit in the cell?)"),
    ("nan.csv", "time,dni\n2021-06-21T00:00:00+08:00,NaN\n2021-06-21T00:01:00+08:00,inf\n",
     "column 'dni' holds no number"),  # had been "'NaN' is not a number" (helper-36)
    ("unit.csv", "time,dni [kW/m2]\n2021-06-21T00:00:00+08:00,0.5\n",
     "no column 'dni' (the columns are 'time', 'dni [kW/m2]'): a streamed file names its columns as a weather frame "
     "does, in its units"),
    ("folder.csv", None, "is a folder, not a weather file"),
])
def test_an_empty_or_folder_streamed_file_is_one_line(tmp_path, capsys, name, text, message):
    path = tmp_path / name
    path.write_text(text) if text is not None else path.mkdir()
    assert main(["replay", str(path), "--site", SITE, "--stream", "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("hybridtrack: error: ") and message in err, err


def test_a_streamed_file_without_wind_is_tracked_through_as_in_memory(tmp_path, capsys):
    """A wind column with no reading is missing wind, as `replay` reads a file in memory: tracked
    through and said, not a day in wind stow."""
    frame = synthetic_days(SITE, "2021-06-21", "2021-06-21", weather="sunny", freq="10min", seed=1)
    day = next(iter(frame))[1].assign(wind_speed=np.nan)
    path = tmp_path / "weather.csv"
    day.rename_axis("time").to_csv(path)
    assert main(["replay", str(path), "--site", SITE, "--stream", "--out", str(tmp_path / "run")]) == 0
    assert "wind: MISSING in this file; replayed as tracking through" in capsys.readouterr().out
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["energy_capture"] > 0.9 and summary["mode_share"].get("stow_wind", 0.0) == 0.0


@pytest.mark.parametrize("flags, named", [
    (["--step", "30min"], "--step is not taken"),  # had run at the file's own 10 minutes without a word
    (["--dayfirst"], "--dayfirst/--monthfirst is not taken"),
    (["--lenient", "--decomposition", "dirint"], "--decomposition, --lenient are not taken"),
    (["--map", "dni=DNI", "--units", "dni=kW/m2"], "--map, --units are not taken"),
])
def test_a_streamed_replay_refuses_the_record_readers_flags_it_would_not_take(tmp_path, capsys, flags, named):
    frame = synthetic_days(SITE, "2021-06-21", "2021-06-21", weather="sunny", freq="10min", seed=1)
    path = tmp_path / "weather.csv"
    next(iter(frame))[1].rename_axis("time").to_csv(path)
    run = tmp_path / "run"
    assert main(["replay", str(path), "--site", SITE, "--stream", "--out", str(run), *flags]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and named in err[0] and "run it without --stream" in err[0]
    assert not run.exists()


def test_a_failed_forced_rerun_leaves_the_earlier_run_whole(tmp_path, capsys):
    """--force replaces a finished run when the new one finishes; if the new run stops, the folder
    must not pair its partial log with the old run's summary.json: the old run is left as it was."""
    out = tmp_path / "run"
    good, bad = tmp_path / "good.csv", tmp_path / "bad.csv"
    day = next(iter(synthetic_days(SITE, "2021-06-21", "2021-06-21", weather="sunny", freq="10min", seed=1)))[1]
    day.rename_axis("time").to_csv(good)
    bad.write_text(good.read_text() + "2021-06-22T00:00:00+08:00" + ",x" * len(day.columns) + "\n")
    assert main(["replay", str(good), "--site", SITE, "--stream", "--out", str(out)]) == 0
    finished = {path.name: path.read_bytes() for path in out.iterdir()}
    assert sorted(finished) == ["events.csv", "log.parquet", "summary.json"]
    assert main(["replay", str(bad), "--site", SITE, "--stream", "--out", str(out), "--force"]) == 2
    assert {path.name: path.read_bytes() for path in out.iterdir()} == finished


def _two_days():
    return synthetic_days(SITE, "2021-06-21", "2021-06-22", weather="sunny", freq="30min", seed=1)


def test_a_write_that_fails_mid_run_keeps_the_days_before_it_whole(tmp_path, monkeypatch):
    """A full disk on the second day had cut the one Parquet file mid-segment, and every finished
    day was removed with it. Each day's log is now a file of its own, written whole: the first
    day stays readable, and the events file holds that day's events and no more."""
    import errno

    import pyarrow.parquet as pq

    real, calls, days = pq.ParquetWriter.write_table, [], []

    def full_on_the_second_day(self, table, *args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, table, *args, **kwargs)

    monkeypatch.setattr(pq.ParquetWriter, "write_table", full_on_the_second_day)
    with pytest.raises(HybridtrackError, match=r"log.partial.parquet/00001.parquet: cannot write \(No space left"):
        stream(_two_days(), tmp_path / "run", on_segment=days.append)
    run = tmp_path / "run"
    assert sorted(p.name for p in run.iterdir()) == ["events.partial.csv", "log.partial.parquet"]
    pd.testing.assert_frame_equal(read_log(run / "log.partial.parquet"), days[0].log, check_freq=False)
    events = pd.read_csv(run / "events.partial.csv")
    # each day wakes and stows: the second day's events were written, then cut back off with its log
    assert len(days[0].events) > 0 and len(events) == len(days[0].events)
    monkeypatch.undo()
    assert stream(_two_days(), run).summary["streamed"]["segments"] == 2  # the API replaces, as --force does
    assert sorted(p.name for p in run.iterdir()) == ["events.csv", "log.parquet", "summary.json"]


def test_a_stopped_run_keeps_its_finished_days_under_partial_names_only(tmp_path):
    """Ctrl-C after the second day: the days done are whole and readable, and nothing looks finished."""
    days = []

    def stop_on_the_second_day(result):
        days.append(result.log)
        if len(days) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        stream(_two_days(), tmp_path / "run", on_segment=stop_on_the_second_day)
    assert sorted(path.name for path in (tmp_path / "run").iterdir()) == ["events.partial.csv", "log.partial.parquet"]
    pd.testing.assert_frame_equal(read_log(tmp_path / "run" / "log.partial.parquet"), pd.concat(days), check_freq=False)


def test_sigterm_ends_a_streamed_command_as_ctrl_c_does(tmp_path):
    """``kill``, a batch scheduler's stop: the run died mid-write with an unreadable
    log.partial.parquet (no Parquet footer), status 143 and not a word."""
    import os
    import signal
    import time

    out = tmp_path / "run"
    child = subprocess.Popen([sys.executable, "-m", "hybridtrack", "simulate", "--site", SITE, "--date", "2021-06-20",
                              "--days", "30", "--freq", "10s", "--stream", "--out", str(out)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             preexec_fn=lambda: signal.signal(signal.SIGTERM, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while not (out / "log.partial.parquet").exists() and time.monotonic() < deadline and child.poll() is None:
        time.sleep(0.05)
    time.sleep(1.0)  # the first day written (a tenth of that), later ones under way
    child.send_signal(signal.SIGTERM)
    error = child.stderr.read().decode().replace("\r", "\n").splitlines()
    assert child.wait(timeout=60) == 143
    assert error[-1].startswith("hybridtrack: terminated; ") and not any("Traceback" in line for line in error)
    log = read_log(out / "log.partial.parquet")
    assert len(log) % 8640 == 0 and len(log) >= 8640  # whole days of 10-second steps
    assert sorted(p.name for p in out.iterdir()) == ["events.partial.csv", "log.partial.parquet"]


def test_a_streamed_run_killed_outright_leaves_its_finished_days_readable(tmp_path):
    """SIGKILL (the out-of-memory killer, a job's hard time limit) gives the run no last word: the
    one Parquet file it appended to had no footer, and every finished day was lost with it."""
    import os
    import signal
    import time

    out = tmp_path / "run"
    child = subprocess.Popen([sys.executable, "-m", "hybridtrack", "simulate", "--site", SITE, "--date", "2021-06-20",
                              "--days", "30", "--freq", "10s", "--stream", "--out", str(out)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    first = out / "log.partial.parquet" / "00000.parquet"
    deadline = time.monotonic() + 120
    while not first.exists() and time.monotonic() < deadline and child.poll() is None:
        time.sleep(0.05)
    time.sleep(1.0)  # a later day under way, perhaps mid-write
    os.kill(child.pid, signal.SIGKILL)
    assert child.wait(timeout=60) == -signal.SIGKILL
    log = read_log(out / "log.partial.parquet")
    assert len(log) % 8640 == 0 and len(log) >= 8640  # whole days of 10-second steps
    assert log.index.is_monotonic_increasing and log.index.is_unique


def test_read_log_refuses_what_is_no_streamed_log_by_name(tmp_path, streamed):
    """Each was pyarrow's or pandas' own error (FileNotFoundError, ArrowInvalid, DateParseError), and
    an unknown column gave a frame of no columns."""
    cut = tmp_path / "cut.parquet"
    cut.write_bytes(b"PAR1" + b"\0" * 100)  # a log cut short: no footer
    for path, message in [(tmp_path / "none.parquet", "cannot read as a streamed log"), (tmp_path, "cannot read as"),
                          (cut, "cannot read as a streamed log")]:
        with pytest.raises(HybridtrackError, match=message):
            read_log(path)
    log = streamed[0].files["log"]
    with pytest.raises(HybridtrackError, match="no column 'nope' in the log"):
        read_log(log, columns=["error", "nope"])
    with pytest.raises(HybridtrackError, match="day 'xx' is not a date"):
        read_log(log, day="xx")
    # each was a TypeError, a ZoneInfoNotFoundError, letters read as columns or a wrong 'no segment' (helper-2)
    for arguments, message in [(dict(columns="mode"), "columns must be a list of names"),
                               (dict(day="2021-03-11", tz="Not/AZone"), "unknown time zone 'Not/AZone'"),
                               (dict(day="2021-03-11", tz=5), "tz must be a time zone's name"),
                               (dict(day=""), "day '' is not a date"),
                               (dict(day="2021-03-11 13:00"), "is not a date")]:
        with pytest.raises(HybridtrackError, match=message):
            read_log(log, **arguments)
    with pytest.raises(HybridtrackError, match="path must be a file's path, got None"):
        read_log(None)
    assert read_log(log, day="2021-03-11", tz="Asia/Shanghai").index[0].day == 11


@pytest.mark.parametrize("resolution, message", [
    (1e-9, r"resolution = 1e-09 is outside \[0.00018, 1\]"),  # numpy was asked for 1.3 TiB of bins
    (0.0, "is outside"), (2.0, "is outside"), (float("nan"), "must be a finite number")])
def test_the_histograms_resolution_is_refused_outside_its_range_before_anything_is_written(tmp_path, resolution,
                                                                                          message):
    with pytest.raises(HybridtrackError, match=message):
        stream(_two_days(), tmp_path / "run", resolution=resolution)
    assert not (tmp_path / "run").exists()


def test_a_second_streamed_run_into_the_folder_another_is_writing_is_refused(tmp_path):
    """Two streamed runs into one --out appended to one log.partial.parquet (unreadable after), and
    the later removed the first one's summary, which had said it wrote it."""
    days = []

    def second_run_meanwhile(result):
        days.append(result)
        if len(days) == 1:
            with pytest.raises(HybridtrackError, match="another run is writing there now"):
                stream(_two_days(), tmp_path / "run", on_segment=None)
            with pytest.raises(HybridtrackError, match="another run is writing there now"):  # any run, not only
                result.save(tmp_path / "run", plot=False)                                  # a streamed one

    first = stream(_two_days(), tmp_path / "run", on_segment=second_run_meanwhile)
    assert len(days) == 2 and len(read_log(first.files["log"])) == sum(len(d.log) for d in days)
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == ["events.csv", "log.parquet", "summary.json"]
    again = stream(_two_days(), tmp_path / "run")  # the lock went with the run that held it: replaced, as open would
    assert again.files["summary"].exists() and not (tmp_path / "run" / ".hybridtrack.lock").exists()


@pytest.mark.parametrize("arguments, message", [(dict(progress="yes"), "progress must be a callable"),
                                                (dict(on_segment=5), "on_segment must be a callable")])
def test_callbacks_that_are_not_callable_are_refused_before_anything_is_written(tmp_path, arguments, message):
    """They raised a TypeError after the first day, leaving its partial files (found by helper-2)."""
    with pytest.raises(HybridtrackError, match=message):
        stream(_two_days(), tmp_path / "run", **arguments)
    assert not (tmp_path / "run").exists()


def test_progress_true_shows_a_bar_and_false_none_as_a_fields_does(tmp_path, capsys):
    """`stream(progress=False)` had been refused where `simulate_field(progress=False)` is taken,
    and a field refused the callable simulate and stream take: all three take both."""
    from hybridtrack.sky import synthetic

    day = synthetic("lanzhou", "2021-06-21", weather="sunny", freq="30min", seed=1)
    quiet = simulate(day, "lanzhou", progress=False).summary
    assert capsys.readouterr().err == ""
    shown = simulate(day, "lanzhou", progress=True).summary
    assert "/48.0 [" in capsys.readouterr().err and shown == quiet  # a bar over the 48 steps, gone when done
    stream(_two_days(), tmp_path / "quiet", progress=False)
    assert capsys.readouterr().err == ""
    stream(_two_days(), tmp_path / "shown", progress=True)
    assert "streaming" in capsys.readouterr().err
    from hybridtrack.fields import TroughLoop, simulate_field

    counted = []
    simulate_field(day, "lanzhou", TroughLoop(count=3), progress=counted.append)  # a callable, as simulate's
    assert counted == [1, 1, 1] and capsys.readouterr().err == ""
    with pytest.raises(HybridtrackError, match="progress must be a callable .*, True, False or None, got 'yes'"):
        simulate_field(day, "lanzhou", TroughLoop(count=3), progress="yes")


@pytest.mark.parametrize("options, message", [
    # a TypeError out of the first day, after the run had claimed its folder
    ({"colour": "red"}, r"synthetic_days: unknown option 'colour'; it takes climate, gust_peak, gusts_per_day, "
                        r"wind_mean"),
    ({"gusts_per_day": -1}, r"gusts_per_day = -1 is outside \[0, 200\]"),
    ({"weather": "sunny", "end": "2021-06-21", "seed": 0, "gust_peak": "strong"}, r"gust_peak"),
])
def test_a_synthetic_sources_options_are_checked_when_it_is_made(tmp_path, options, message):
    end = options.pop("end", None)
    with pytest.raises(HybridtrackError, match=message):
        synthetic_days("lanzhou", "2021-06-21", end, freq="30min", **options)


@pytest.mark.parametrize("order", [slice(None, None, -1), np.r_[144:288, 0:144]])
def test_a_frame_out_of_order_is_refused_as_such(order):
    """A frame backwards, or its days swapped, was refused as spanning less than a whole day
    ("the frame spans 2021-06-21 23:50 to 2021-06-20 00:00"): true of no day in it."""
    from hybridtrack.sky import synthetic

    frame = synthetic("lanzhou", "2021-06-20", "2021-06-21", weather="sunny", freq="10min", seed=1)
    with pytest.raises(HybridtrackError, match="the weather frame's time goes back at row [0-9]+ .2021-06-2"):
        frame_days(frame.iloc[order], "lanzhou")


def test_a_span_with_no_whole_day_is_refused_before_any_of_it_runs(tmp_path, monkeypatch):
    """A recorded file of an evening and the next morning (no whole local day) had run both
    segments, then been refused; now it is refused before the first runs."""
    import hybridtrack.simulation as simulation
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-03-10", "2021-03-11", weather="sunny", freq="10min")
    evening_and_morning = frame.loc["2021-03-10 18:00":"2021-03-11 09:00"]
    evening_and_morning.to_parquet(tmp_path / "part.parquet")
    ran = []
    monkeypatch.setattr(simulation, "simulate", lambda *a, **k: ran.append(1))
    with pytest.raises(HybridtrackError, match="needs at least one whole local day"):
        stream(recorded_days(tmp_path / "part.parquet", SITE), tmp_path / "part")
    assert ran == [] and not (tmp_path / "part").exists()


def test_a_span_of_part_days_is_refused_holding_one_day_at_a_time(tmp_path):
    """A logger that records only by day gives a part day each day: the span is refused, its days
    read one at a time and let go (read ahead and held, every day had been in memory at once)."""
    import gc
    import weakref

    from hybridtrack import sites
    from hybridtrack.sky import synthetic
    from hybridtrack.streaming import DaySource

    alive = []

    def days():
        for k in range(5):
            date = pd.Timestamp("2021-03-10") + pd.Timedelta(days=k)
            day = synthetic(SITE, date, weather="sunny", freq="10min").between_time("06:00", "18:00")
            gc.collect()
            alive.append(sum(ref() is not None for ref in refs))  # the days before this one still held
            refs.append(weakref.ref(day))
            yield date.date(), day

    refs = []
    source = DaySource(sites.get(SITE), "daytime only", None, None, days)
    with pytest.raises(HybridtrackError, match="needs at least one whole local day"):
        stream(source, tmp_path / "run")
    assert len(alive) == 5 and max(alive) <= 1, alive  # the day before at most, while the next is read
    assert not (tmp_path / "run").exists()


def test_a_streamed_file_without_dhi_counts_every_reading_missing(tmp_path, capsys):
    """The run takes a file's absent DHI as no diffuse light at every step, as a NaN reading: each
    is counted (a file without the column had run with nothing counted, helper-35)."""
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-06-20", "2021-06-21", weather="mixed", freq="15min", seed=1)
    frame.drop(columns=["dhi"]).to_csv(tmp_path / "weather.csv", index_label="time")
    assert main(["replay", str(tmp_path / "weather.csv"), "--site", SITE, "--stream", "--out",
                 str(tmp_path / "run")]) == 0
    assert f"kept as read: {len(frame)} missing dhi readings (the first at 2021-06-20 00:00:00+08:00)" \
        in capsys.readouterr().out
    report = json.loads((tmp_path / "run" / "summary.json").read_text())["streamed"]["kept_as_read"]
    assert report["missing"]["dhi"] == {"count": len(frame), "first": "2021-06-20 00:00:00+08:00"}


@pytest.mark.parametrize("chunk_rows", [50, 200_000])
def test_a_morning_in_kw_per_m2_is_refused_in_a_streamed_file_as_the_reader_refuses_it(tmp_path, chunk_rows):
    """A logger whose unit changed within a day (the second day's morning in kW/m², its afternoon
    in W/m²) had streamed as a dark morning: the day's W/m² top kept the span's judgement quiet.
    Its hours in kW/m² are refused naming the first of their lines, whatever the chunks."""
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-06-20", "2021-06-22", weather="sunny", freq="10min", seed=1)[["ghi", "dni", "dhi"]]
    morning = (frame.index.day == 21) & (frame.index.hour < 12)
    frame.loc[morning, ["ghi", "dni", "dhi"]] /= 1000.0
    frame.round(4).to_csv(tmp_path / "changed.csv", index_label="time")
    with pytest.raises(HybridtrackError, match=r"changed\.csv: line (\d+), column 'ghi': ghi reads .* through \d+ hours "
                                               r"of a high sun, while the same day reads .* look like kW/m²") as caught:
        list(recorded_days(tmp_path / "changed.csv", SITE, chunk_rows=chunk_rows))
    line = int(re.search(r"line (\d+),", str(caught.value)).group(1))
    named = (tmp_path / "changed.csv").read_text().splitlines()[line - 1].split(",")
    assert named[0].startswith("2021-06-21") and 0.02 <= float(named[1]) <= 1.5  # a morning line in kW/m²


def test_a_streamed_file_of_clear_and_overcast_days_in_watts_streams(tmp_path):
    """The streamed day judgement leaves W/m² days of any sky alone, a last day cut short included."""
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-06-20", "2021-06-23 14:00", weather=["sunny", "overcast", "mixed", "cloudy"],
                      freq="10min", seed=2)[["ghi", "dni", "dhi"]]
    frame.round(3).to_csv(tmp_path / "watts.csv", index_label="time")
    days = list(recorded_days(tmp_path / "watts.csv", SITE, chunk_rows=70))
    assert sum(len(day) for _, day in days) == len(frame)


def test_a_naive_stamp_beside_stamps_with_an_offset_is_refused_not_read_as_utc(tmp_path):
    """pandas reads a column of stamps with and without offsets as UTC: a Berlin record whose first
    line carried its offset had streamed an hour late, without a word (helper-39)."""
    path = tmp_path / "mixed.csv"
    path.write_text("time,dni\n2021-01-10T00:00:00+01:00,0\n2021-01-10 00:10:00,0\n2021-01-10 00:20:00,0\n")
    with pytest.raises(HybridtrackError, match=r"mixed\.csv: row 3, column 'time': '2021-01-10 00:10:00' has no UTC "
                                               r"offset, but other stamps in the column have one"):
        list(recorded_days(path, SITE, tz="Europe/Berlin"))


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_streamed_files_column_given_twice_is_refused_as_the_reader_refuses_it(tmp_path, suffix):
    """A CSV's second ``dni`` had been read as ``dni.1`` and dropped without a word (an all-zero
    first one ran), and a Parquet file's had ended in pandas' TypeError (helper-39)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = tmp_path / f"twice{suffix}"
    stamps = ["2021-06-21T12:00:00+08:00", "2021-06-21T12:01:00+08:00"]
    if suffix == ".csv":
        path.write_text("time,dni,dhi,dni\n" + "".join(f"{t},0,100,800\n" for t in stamps))
    else:
        pq.write_table(pa.Table.from_arrays([pa.array(stamps), pa.array([0.0, 0.0]), pa.array([800.0, 800.0])],
                                            names=["time", "dni", "dni"]), path)
    with pytest.raises(HybridtrackError, match=rf"twice\{suffix}: column 'dni' appears more than once in the header"):
        recorded_days(path, SITE)


def test_a_streamed_day_in_kw_per_m2_among_days_in_watts_is_refused_by_its_line(tmp_path):
    """Judged a day at a time, the day had passed the reader's check (it needs two days together)
    and the run refused it naming only the frame's date (helper-39); it is named by line."""
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-06-19", "2021-06-21", weather="sunny", freq="10min", seed=1)[["ghi", "dni", "dhi"]]
    frame.loc[frame.index.day == 20] /= 1000.0
    frame.round(5).to_csv(tmp_path / "day.csv", index_label="time")
    with pytest.raises(HybridtrackError, match=r"day\.csv: line (\d+), column 'ghi': ghi is at most [\d.]+ while the "
                                               r"clear sky reaches \d+ W/m²; .* the file's other days are in W/m²") as e:
        list(recorded_days(tmp_path / "day.csv", SITE, chunk_rows=100))
    line = int(re.search(r"line (\d+),", str(e.value)).group(1))
    assert (tmp_path / "day.csv").read_text().splitlines()[line - 1].startswith("2021-06-20")


@pytest.mark.parametrize("chunk_rows", [37, 200_000])
def test_a_streamed_record_across_a_daylight_saving_change_reads_whatever_the_chunks(tmp_path, chunk_rows):
    """pandas writes a Berlin frame's stamps with +01:00 and then +02:00: a piece of one offset
    after a piece of both had joined into no zone, an AttributeError (helper-40)."""
    from hybridtrack import sites
    from hybridtrack.sky import synthetic

    berlin = sites.custom(52.5, 13.4, "Europe/Berlin", name="berlin")
    frame = synthetic(berlin, "2021-03-27", "2021-03-29", weather="sunny", freq="5min", seed=0)[["ghi", "dni", "dhi"]]
    frame.to_csv(tmp_path / "dst.csv", index_label="time")
    days = list(recorded_days(tmp_path / "dst.csv", berlin, chunk_rows=chunk_rows))
    assert [str(day) for day, _ in days] == ["2021-03-27", "2021-03-28", "2021-03-29"]
    read = pd.concat([piece for _, piece in days])
    assert (read.index == frame.index).all() and len(read) == len(frame)


def test_a_streamed_piece_without_offsets_after_pieces_with_them_is_refused_whatever_the_chunks(tmp_path):
    """Stamps of both kinds in one piece are refused; in two pieces one had been localised without a
    word, so the verdict turned on the pieces' size (helper-40)."""
    path = tmp_path / "later.csv"
    path.write_text("time,dni\n2021-01-10T00:00:00+01:00,0\n2021-01-10T00:10:00+01:00,0\n2021-01-10 00:20:00,0\n")
    with pytest.raises(HybridtrackError, match=r"later\.csv: row 4, column 'time': 2021-01-10 00:20:00 has no UTC "
                                               r"offset, but the stamps before it have one"):
        list(recorded_days(path, SITE, tz="Europe/Berlin", chunk_rows=2))


def test_empty_padding_columns_of_a_streamed_csv_are_not_a_column_given_twice(tmp_path):
    """Two trailing separators (a spreadsheet's padding) had been refused as a column 'nan' given twice."""
    path = tmp_path / "padded.csv"
    path.write_text("time,dni,,\n2021-06-21T12:00:00+08:00,800,,\n2021-06-21T12:01:00+08:00,800,,\n")
    assert sum(len(day) for _, day in recorded_days(path, SITE)) == 2


@pytest.mark.parametrize("chunk_rows", [50, 289, 200_000])
def test_a_dni_only_file_with_an_overcast_day_streams_whatever_the_chunks(tmp_path, chunk_rows):
    """DNI alone is judged on the whole file, as the reader judges it, before the first day: judged
    on each span, an overcast day's pyrheliometer noise (0-0.9 W/m²) had been refused at small
    pieces and streamed at large ones (helper-40)."""
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-06-19", "2021-06-21", weather="sunny", freq="10min", seed=1)[["dni"]]
    dull = frame.index.day == 20
    frame.loc[dull, "dni"] = np.tile([0.0, 0.4, 0.9], int(dull.sum()) // 3 + 1)[:int(dull.sum())]
    frame.round(3).to_csv(tmp_path / "dni.csv", index_label="time")
    assert sum(len(day) for _, day in recorded_days(tmp_path / "dni.csv", SITE, chunk_rows=chunk_rows)) == len(frame)


def _oracle_frame() -> pd.DataFrame:
    """Three mixed days at 30 min with their true sky as text, a day's label 'foggy' on the third."""
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-06-20", "2021-06-22", weather="mixed", freq="30min", seed=2)
    frame = frame[["ghi", "dni", "dhi", "wind_speed", "sky"]].assign(sky=lambda f: f["sky"].astype(str))
    frame.loc[frame.index[[110, 120]], "sky"] = "foggy"  # 2021-06-22 07:00 and 12:00
    frame.loc[frame.index[5], "sky"] = np.nan  # a missing label is unknown, which the oracle takes
    return frame


def test_a_streamed_files_sky_label_the_oracle_cannot_read_is_refused_before_the_first_day(tmp_path, capsys):
    """A streamed replay had run and written two days before the run of the third refused its label
    by a time stamp; the non-streamed replay refuses it by the file's line and column before any
    run. The sky column alone is read first, a chunk at a time."""
    frame = _oracle_frame()
    frame.to_csv(tmp_path / "w.csv", index_label="time")
    lines = (tmp_path / "w.csv").read_text().splitlines()
    first = next(n for n, line in enumerate(lines, 1) if line.endswith(",foggy"))
    assert first == 110 + 2  # the header is line 1
    assert main(["replay", str(tmp_path / "w.csv"), "--site", SITE, "--stream", "--strategy", "hybrid-oracle",
                 "--out", str(tmp_path / "run")]) == 2
    assert capsys.readouterr().err == (f"hybridtrack: error: {tmp_path / 'w.csv'}: line {first}, column 'sky': 'foggy' "
                                       "is no sky label (2 such in the file); the hybrid-oracle policy reads 'sunny', "
                                       "'cloudy', 'overcast', 'unknown' (a streamed file is read as written)\n")
    assert not (tmp_path / "run").exists()


def test_a_streamed_parquet_files_or_frames_bad_sky_label_or_no_sky_is_refused_before_any_day(tmp_path):
    frame = _oracle_frame()
    frame.to_parquet(tmp_path / "w.parquet")
    written = []
    with pytest.raises(HybridtrackError, match=r"w\.parquet: row 111, column 'sky': 'foggy' is no sky label \(2 such"):
        stream(recorded_days(tmp_path / "w.parquet", SITE, chunk_rows=7), tmp_path / "p", strategy="hybrid-oracle",
               on_segment=written.append)
    with pytest.raises(HybridtrackError, match=r"the frame's 'sky' column at 2021-06-22 07:00:00\+08:00: 'foggy' is no "
                                               "sky label"):
        stream(frame_days(frame, SITE), tmp_path / "f", strategy="hybrid-oracle", on_segment=written.append)
    frame.drop(columns="sky").to_csv(tmp_path / "nosky.csv", index_label="time")
    with pytest.raises(HybridtrackError, match=r"nosky\.csv: no column 'sky': the hybrid-oracle policy reads"):
        stream(recorded_days(tmp_path / "nosky.csv", SITE), tmp_path / "n", strategy="hybrid-oracle",
               on_segment=written.append)
    assert written == [] and not any((tmp_path / name).exists() for name in "pfn")
    good = frame.assign(sky=frame["sky"].replace("foggy", "cloudy"))
    good.to_csv(tmp_path / "good.csv", index_label="time")
    recorded_days(tmp_path / "good.csv", SITE).check_true_sky()  # a missing label is no refusal


def test_a_streamed_run_says_which_days_began_with_the_tracker_awake(tmp_path, capsys):
    """Cut at midnight, a streamed run restarts the controller and the collector from stow: hidden
    at a midnight at night stow, not under a midnight sun (Longyearbyen, June: a slew of 48° from
    stow at each cut, with nothing said; helper-44)."""
    from hybridtrack import sites
    from hybridtrack.streaming import AwakeAtMidnightWarning

    polar = sites.custom(78.2, 15.6, "Arctic/Longyearbyen")
    with pytest.warns(AwakeAtMidnightWarning, match="2 streamed day"):
        result = stream(synthetic_days(polar, "2024-06-20", "2024-06-22", weather="sunny", freq="10min", seed=1),
                        tmp_path / "polar")
    assert result.summary["streamed"]["awake_at_midnight"]["count"] == 2
    assert result.summary["streamed"]["awake_at_midnight"]["first"] == "2024-06-21"
    at_cuts = result.log(columns=["mode"]).loc[lambda log: log.index.strftime("%H:%M") == "00:00", "mode"]
    assert (at_cuts.iloc[1:] != "stow_night").all()  # awake: the restart is what the note says, not a night

    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error", AwakeAtMidnightWarning)  # a night at each cut: nothing to say
        quiet = stream(synthetic_days(SITE, "2021-06-20", "2021-06-21", weather="sunny", freq="10min", seed=1),
                       tmp_path / "lanzhou")
    assert "awake_at_midnight" not in quiet.summary["streamed"]
    assert main(["simulate", "--lat", "78.2", "--lon", "15.6", "--tz", "Arctic/Longyearbyen", "--date", "2024-06-20",
                 "--days", "2", "--weather", "sunny", "--freq", "10min", "--stream",
                 "--out", str(tmp_path / "cli")]) == 0
    out, err = capsys.readouterr()
    assert "awake at midnight: 1 day(s), the first 2024-06-21: the tracker was awake at midnight" in out
    assert "Warning" not in err


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_a_stuck_anemometer_stays_stuck_across_a_streamed_runs_midnights(tmp_path, engine):
    """The wind guard's judgement is carried (`Result.memory`'s ``anemometer_stuck_at``): each
    streamed day had judged the same frozen reading again, tracking three hours of daylight on it."""
    source = frame_days(_stuck_wind_days(), SITE)
    config = dataclasses.replace(SimulationConfig(), engine=engine)
    result = stream(source, tmp_path / engine, config=config)
    events = pd.read_csv(result.files["events"])
    assert events["reason"].str.contains("anemometer stuck at 3.00 m/s").sum() == 1
    assert not events["reason"].str.contains("anemometer moving again").any()
    day_two = result.log(columns=["mode"], day="2021-06-22")["mode"]
    assert (day_two.between_time("05:00", "20:00") == "stow_wind").all()


def _stuck_wind_days():
    from hybridtrack.sky import synthetic

    frame = synthetic(SITE, "2021-06-21", "2021-06-22", weather="sunny", seed=1, freq="5min")
    wind = np.clip(frame["wind_speed"].to_numpy(), 0.0, 11.0)
    wind[frame.index.hour >= 8] = 3.0
    wind[frame.index >= pd.Timestamp("2021-06-22", tz=frame.index.tz)] = 3.0
    return frame.assign(wind_speed=wind)


@pytest.mark.parametrize("value", [float("nan"), float("inf"), [3.0, 3.0], None, True, "3.0", -5.0, 1e300])
def test_a_carried_anemometer_judgement_must_be_one_finite_reading(value):
    from hybridtrack.sky import synthetic

    day = synthetic(SITE, "2021-06-21", weather="sunny", seed=1, freq="30min")
    memory = {**simulate(day, SITE).memory, "anemometer_stuck_at": value}
    with pytest.raises(HybridtrackError, match="anemometer_stuck_at must be one anemometer reading"):
        simulate(synthetic(SITE, "2021-06-22", weather="sunny", seed=1, freq="30min"), SITE, warm_start=memory)
