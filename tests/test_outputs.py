"""Outputs kept (issue 11, item 5) and runs sized before they start (item 4).

Results are written in full even when the reader of the printout has gone, never through a
symbolic link, never over an existing file without ``--force``, and their JSON is strict.
"""

import datetime as dt
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError, budget, sites
from hybridtrack.cli import main
from hybridtrack.collectors import Collector
from hybridtrack.outputs import claim, replacing, strict_json
from hybridtrack.simulation import Result, SimulationConfig

REPO = Path(__file__).resolve().parents[1]
RECORD = str(REPO / "data" / "nanjing-2013-cloudy.csv")
SHORT = ["simulate", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10min"]
RUN_FILES = ("log.parquet", "events.csv", "summary.json", "report.png")


def strict(text: str):
    """Parse JSON, refusing NaN and Infinity as any strict parser would."""
    def refuse(constant):
        raise ValueError(f"not JSON: {constant}")
    return json.loads(text, parse_constant=refuse)


# -- strict JSON ----------------------------------------------------------------------------------

def test_strict_json_writes_null_for_every_missing_or_non_finite_number():
    value = {"a": math.nan, "b": [math.inf, -math.inf, np.float64(2.5), np.int64(3)], "c": None, "d": np.bool_(True)}
    assert strict_json(value) == '{"a": null, "b": [null, null, 2.5, 3], "c": null, "d": true}'


def test_a_summary_with_nan_is_saved_as_strict_json(tmp_path):
    log = pd.DataFrame({"error": [0.1, 0.2]}, index=pd.date_range("2021-06-21", periods=2, freq="min", tz="UTC"))
    result = Result(log, {"rms": math.nan, "max": math.inf, "steps": 2}, pd.DataFrame({"event": []}),
                    sites.get("lanzhou"), Collector(), SimulationConfig())
    written = result.save(tmp_path / "run", plot=False, log_format="csv")
    assert strict(written["summary"].read_text()) == {"rms": None, "max": None, "steps": 2}


def test_classify_json_is_strict_when_no_rule_fires(tmp_path, capsys):
    # an infinite reading is refused at the door now; a gap between triangular terms gives NaN
    from hybridtrack.fuzzy import FuzzyConfig

    data = FuzzyConfig.default().to_dict()
    data["inputs"]["intensity"]["terms"] = {"weak": {"shape": "trimf", "params": [0.0, 0.0, 1.0]},
                                            "medium": {"shape": "trimf", "params": [4.0, 5.0, 6.0]},
                                            "strong": {"shape": "trimf", "params": [9.0, 10.0, 10.0]}}
    gappy = FuzzyConfig.from_dict(data).to_toml(tmp_path / "gappy.toml")
    assert main(["classify", "--config", str(gappy), "--intensity", "97.5", "--variation", "1", "--json"]) == 0
    printed = strict(capsys.readouterr().out)  # 97.5 mA is 2.5 on the universe: between weak and medium
    assert printed["score"] is None and printed["weather"] == "unknown" and printed["intensity"] == 97.5


# -- a closed pipe does not lose the results ------------------------------------------------------

class ClosedPipe:
    """Standard output whose reader has gone: every write and flush raises BrokenPipeError."""

    def write(self, text):
        raise BrokenPipeError(32, "Broken pipe")

    def flush(self):
        raise BrokenPipeError(32, "Broken pipe")


@pytest.mark.parametrize("args, files", [
    (SHORT, RUN_FILES),
    (["replay", RECORD, "--site", "nanjing"], RUN_FILES),
    (["demo"], RUN_FILES),
    (["field", "trough", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10min", "--count", "2"],
     ("collectors.csv", "events.csv", "summary.json", "field_map.png", "log.nc")),
    (["compare", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10min"],
     ("comparison.json", "comparison.png", "hybrid/summary.json", "sensor/log.parquet")),
], ids=["simulate", "replay", "demo", "field", "compare"])
def test_results_are_written_when_the_reader_has_gone(tmp_path, monkeypatch, args, files):
    out = tmp_path / "out"
    monkeypatch.setattr(sys, "stdout", ClosedPipe())
    assert main(args + ["--out", str(out)]) == 0
    for name in files:
        assert (out / name).stat().st_size > 0, name


def test_replay_into_head_writes_out_through_a_real_pipe(tmp_path):
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    child = subprocess.Popen([sys.executable, "-m", "hybridtrack", "replay", RECORD, "--site", "nanjing",
                              "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    first = child.stdout.readline()  # `| head -1`: one line, then the reader goes
    child.stdout.close()
    error = child.stderr.read().decode()
    assert child.wait() == 0 and first.startswith(RECORD.encode())
    assert "Traceback" not in error and "Exception ignored" not in error
    assert strict((out / "summary.json").read_text())["steps"] == len(pd.read_csv(RECORD))  # every row, 4 × 901


# -- existing files: refused without --force, named either way -------------------------------------

def test_existing_results_are_refused_without_force_and_named(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text("the user's own\n")
    assert main(SHORT + ["--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (f"hybridtrack: error: would replace 1 existing file: {out / 'summary.json'}; give --force to "
                   "replace it, or write elsewhere\n")
    assert (out / "summary.json").read_text() == "the user's own\n" and not (out / "log.parquet").exists()


def test_force_replaces_and_says_which(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(SHORT + ["--out", str(out)]) == 0
    capsys.readouterr()
    assert main(SHORT + ["--out", str(out), "--force"]) == 0
    last = capsys.readouterr().out.splitlines()[-1]
    assert last == "replaced (--force): " + ", ".join(str(out / name) for name in RUN_FILES)


# -- files an earlier run wrote and this one does not: removed with --force, and said -------------

FIELD = ["field", "trough", "--count", "2", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "30min"]
ABLATE = ["ablate", "--sites", "lanzhou", "--seasons", "summer", "--seeds", "1", "--collectors", "fresnel",
          "--policies", "hybrid"]
TRADEOFF = ABLATE + ["--tradeoff", "--deadbands", "0.1"]


def _removals(out: str) -> list[str]:
    """The lines of standard output that say a file of an earlier run was removed."""
    return [line for line in out.splitlines() if ": removed, from an earlier run (" in line]


def _run_twice(first: list, again: list, out: Path, capsys) -> str:
    """Run `first` into `out`, put a file of the user's there, run `again` with --force; its standard
    output (where the files it replaced and removed are said, as the files it wrote are)."""
    assert main(first + ["--out", str(out)]) == 0
    (out / "notes.txt").write_text("the user's own\n")
    capsys.readouterr()
    assert main(again + ["--out", str(out), "--force"]) == 0
    return capsys.readouterr().out


@pytest.mark.parametrize("first, again, left_out, reason, kept", [
    # a log.nc beside a --no-log field's collectors.csv had been read as that field's log
    (FIELD, FIELD + ["--no-log"], "log.nc", "--no-log", ("collectors.csv", "events.csv", "field_map.png",
                                                         "summary.json")),
    (SHORT, SHORT + ["--stream"], "report.png", "--stream", ("log.parquet", "events.csv", "summary.json")),
    (ABLATE, TRADEOFF, "ablation.png", "--tradeoff", ("runs.csv", "table.csv", "tradeoff.png")),
    (TRADEOFF, ABLATE, "tradeoff.png", "without --tradeoff", ("runs.csv", "table.csv", "ablation.png")),
])
def test_force_removes_the_file_an_earlier_run_wrote_and_this_one_does_not(tmp_path, capsys, first, again, left_out,
                                                                           reason, kept):
    out = tmp_path / "out"
    err = _run_twice(first, again, out, capsys)
    assert _removals(err) == [f"{out / left_out}: removed, from an earlier run ({reason})"]
    assert sorted(p.name for p in out.iterdir()) == sorted([*kept, "notes.txt"])
    assert (out / "notes.txt").read_text() == "the user's own\n"  # a name no run writes is never touched


def test_replay_stream_with_force_removes_an_earlier_runs_report(tmp_path, capsys):
    day = tmp_path / "day.csv"
    assert main(["sky", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10min", "--out", str(day)]) == 0
    replay = ["replay", str(day), "--site", "lanzhou"]
    out = tmp_path / "out"
    err = _run_twice(replay, replay + ["--stream"], out, capsys)
    assert _removals(err) == [f"{out / 'report.png'}: removed, from an earlier run (--stream)"]
    assert sorted(p.name for p in out.iterdir()) == ["events.csv", "log.parquet", "notes.txt", "summary.json"]


def test_compare_with_force_removes_the_oracles_run_it_leaves_out(tmp_path, capsys):
    """A file without a true sky leaves hybrid-oracle out; its folder from a synthetic comparison had stayed."""
    record = tmp_path / "no-sky.csv"
    pd.read_csv(RECORD).drop(columns="sky").to_csv(record, index=False)
    synthetic = ["compare", "--site", "nanjing", "--date", "2013-03-20", "--freq", "30min"]
    out = tmp_path / "out"
    err = _run_twice(synthetic, ["compare", str(record), "--site", "nanjing", "--step", "30min"], out, capsys)
    oracle = out / "hybrid-oracle"
    assert _removals(err) == [f"{oracle / name}: removed, from an earlier run (hybrid-oracle left out)"
                              for name in ("events.csv", "log.parquet", "summary.json")]
    # the folder it emptied goes too (an empty hybrid-oracle/ had stayed, to be read as a run)
    assert f"{oracle}: removed, emptied of an earlier run's files (hybrid-oracle left out)" in err.splitlines()
    assert not oracle.exists() and "hybrid-oracle" not in strict((out / "comparison.json").read_text())


def test_force_leaves_a_left_out_runs_folder_holding_the_users_files(tmp_path, capsys):
    record = tmp_path / "no-sky.csv"
    pd.read_csv(RECORD).drop(columns="sky").to_csv(record, index=False)
    out = tmp_path / "out"
    assert main(["compare", "--site", "nanjing", "--date", "2013-03-20", "--freq", "30min", "--out", str(out)]) == 0
    (out / "hybrid-oracle" / "mine.txt").write_text("the user's own\n")
    assert main(["compare", str(record), "--site", "nanjing", "--step", "30min", "--out", str(out), "--force"]) == 0
    assert sorted(p.name for p in (out / "hybrid-oracle").iterdir()) == ["mine.txt"]


def test_without_force_a_file_an_earlier_run_left_is_refused_and_kept(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "log.nc").write_text("an earlier field's log\n")
    assert main(FIELD + ["--no-log", "--out", str(out)]) == 2
    printed = capsys.readouterr()
    assert printed.err == (f"hybridtrack: error: would leave 1 file of an earlier run beside this run's results: "
                           f"{out / 'log.nc'} (not written: --no-log); give --force to remove it, or write elsewhere\n")
    assert printed.out == "" and [p.name for p in out.iterdir()] == ["log.nc"]


def test_a_failed_force_run_leaves_the_earlier_runs_files_and_says_no_removal(tmp_path, monkeypatch, capsys):
    from hybridtrack.fields import FieldResult

    out = tmp_path / "out"
    assert main(FIELD + ["--out", str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def full_disk(self, folder, metric="rms"):
        raise HybridtrackError(f"{folder}/collectors.csv: cannot write (No space left on device)")

    monkeypatch.setattr(FieldResult, "save", full_disk)
    capsys.readouterr()
    assert main(FIELD + ["--no-log", "--out", str(out), "--force"]) == 2
    assert _removals(capsys.readouterr().err) == []
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # log.nc is still the one beside its field


def test_a_file_of_an_earlier_run_that_cannot_be_removed_is_refused_before_the_run(tmp_path, monkeypatch, capsys):
    """A folder whose files may be rewritten but not removed (no write permission on the folder)."""
    out = tmp_path / "out"
    assert main(FIELD + ["--out", str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    access = os.access
    monkeypatch.setattr(os, "access", lambda path, mode: access(path, mode) and Path(path) != out)
    capsys.readouterr()
    assert main(FIELD + ["--no-log", "--out", str(out), "--force"]) == 2
    printed = capsys.readouterr()
    assert printed.err == (f"hybridtrack: error: {out / 'log.nc'}: from an earlier run, and cannot be removed (no "
                           f"permission in {out}); remove it, or write elsewhere\n")
    assert printed.out == "" and {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_demo_run_twice_replaces_its_own_folder_but_not_another(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["demo"]) == 0
    capsys.readouterr()
    assert main(["demo"]) == 0
    assert capsys.readouterr().out.rstrip().endswith("(replacing those of an earlier run)")
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "events.csv").write_text("the user's own\n")
    assert main(["demo", "--out", str(mine)]) == 2
    assert "would replace 1 existing file" in capsys.readouterr().err
    assert (mine / "events.csv").read_text() == "the user's own\n"


def test_the_api_replaces_unless_asked_not_to(tmp_path):
    path = tmp_path / "run.toml"
    path.write_text("seed = 1\n")
    SimulationConfig().to_toml(path)  # as open() would
    assert "seed = 0" in path.read_text()
    with replacing(False), pytest.raises(HybridtrackError, match="would replace 1 existing file"):
        SimulationConfig(seed=2).to_toml(path)
    with replacing(True) as replaced:
        claim([path, tmp_path / "new.toml"])
    assert replaced == [path]


# -- symbolic links --------------------------------------------------------------------------------

def test_a_link_planted_in_out_is_refused_and_nothing_is_written(tmp_path, capsys):
    out, victim = tmp_path / "out", tmp_path / "elsewhere.json"
    out.mkdir()
    (out / "summary.json").symlink_to(victim)
    assert main(SHORT + ["--out", str(out), "--force"]) == 2
    assert capsys.readouterr().err == (f"hybridtrack: error: {out / 'summary.json'} is a symbolic link; results are "
                                       "never written through one (remove it or write elsewhere)\n")
    assert not victim.exists() and not (out / "log.parquet").exists()


def test_an_out_folder_that_is_a_link_is_refused(tmp_path, capsys):
    target, out = tmp_path / "target", tmp_path / "out"
    target.mkdir()
    out.symlink_to(target, target_is_directory=True)
    assert main(["sky", "--site", "lanzhou", "--date", "2021-06-21", "--out", str(out / "sky.csv")]) == 2
    assert f"{out} is a symbolic link" in capsys.readouterr().err and not list(target.iterdir())


# -- the size of a run, before anything is made ----------------------------------------------------

def test_the_budget_is_half_the_available_memory_up_to_16_gib(monkeypatch):
    monkeypatch.setattr(budget, "available_memory", lambda: 2_000_000_000)
    assert budget.memory_budget() == 1_000_000_000
    monkeypatch.setattr(budget, "available_memory", lambda: 2**40)
    assert budget.memory_budget() == 16 * 2**30


def test_a_refusal_names_a_coarser_step_and_a_shorter_span(monkeypatch):
    # budget 1e9 bytes = 500,000 steps of 2,000 bytes; ten days at 1 s are 864,000 steps (1.728e9 bytes).
    # At 2 s they are 864,000 / 2 = 432,000 steps, 0 to 863,998 s (0.864e9 bytes): they fit.
    # At 1 s, 499,999 s = 5.787 days fit.
    monkeypatch.setattr(budget, "available_memory", lambda: 2_000_000_000)
    first = pd.Timestamp("2021-06-21", tz="UTC")
    last = first + pd.Timedelta(days=10) - pd.Timedelta(seconds=1)
    with pytest.raises(HybridtrackError) as error:
        budget.check_steps(first, last, "1s", what="ten days")
    assert str(error.value) == ("ten days: 864,000 steps of 1s would need about 1.7 GB of memory, over the 1.0 GB a run "
                                "may use; use a step of 2s or a span of at most 5.8 days at this step; or stream it to "
                                "disk a day at a time, in bounded memory (hybridtrack simulate --stream, "
                                "hybridtrack.streaming.stream)")
    assert budget.check_steps(first, last, "2s") == 432_000


def test_simulate_refuses_a_year_at_one_second_before_allocating(capsys):
    assert main(["simulate", "--site", "lanzhou", "--date", "2021-01-01", "--days", "365", "--freq", "1s"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("hybridtrack: error: 2021-01-01 to 2021-12-31: 31,536,000 steps of 1s would need about "
                          "63.1 GB of memory") and err.count("\n") == 1


def test_a_frame_too_long_for_memory_is_refused_by_simulate(monkeypatch):
    from hybridtrack.simulation import simulate
    from hybridtrack.sky import synthetic

    frame = synthetic("lanzhou", "2021-06-21", freq="10min")  # 144 steps x 2,000 bytes = 288,000 bytes
    monkeypatch.setattr(budget, "available_memory", lambda: 500_000)  # a budget of 250,000 bytes
    with pytest.raises(HybridtrackError, match="the weather frame: 144 steps of 10min would need about 288 kB of memory, over the 250 kB"):
        simulate(frame, "lanzhou")


@pytest.mark.slow
def test_bytes_per_step_covers_the_measured_peak_of_a_run():
    """The slope of simulate's peak traced memory between a 2-day and an 8-day run at 30 s."""
    import tracemalloc

    from hybridtrack.simulation import simulate
    from hybridtrack.sky import synthetic

    def peak(days, collector):
        first = dt.date(2021, 6, 21)
        tracemalloc.start()
        frame = synthetic("lanzhou", first, first + dt.timedelta(days=days - 1), freq="30s", seed=1)
        simulate(frame, "lanzhou", collector=collector)
        size = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        return len(frame), size

    peak(1, "trough-ns")  # imports and caches out of the way
    for collector in ("trough-ns", "heliostat"):
        (n1, p1), (n2, p2) = peak(2, collector), peak(8, collector)
        assert 0 < (p2 - p1) / (n2 - n1) <= budget.BYTES_PER_STEP


def test_an_out_that_is_a_file_or_under_one_is_one_line(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("the user's own\n")
    assert main(SHORT + ["--out", str(afile)]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {afile} is a file, not a folder\n"
    assert main(SHORT + ["--out", str(afile / "sub")]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {afile / 'sub'}: cannot make the folder (Not a directory)\n"
    assert afile.read_text() == "the user's own\n"


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full, a device that is always full")
def test_a_full_standard_output_is_one_line_that_names_it():
    # printed 'hybridtrack: error: cannot use: No space left on device', naming nothing
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    with open("/dev/full", "w") as full:
        child = subprocess.run([sys.executable, "-m", "hybridtrack", "faults", "list"], stdout=full,
                               stderr=subprocess.PIPE, env=env)
    assert child.returncode == 2
    assert child.stderr.decode() == "hybridtrack: error: standard output: cannot write (No space left on device)\n"


class FullDevice:
    """Standard output on a full disk, unbuffered: every write raises ENOSPC, and a flush has nothing
    to write (tqdm flushes standard output as a bar starts)."""

    def write(self, text):
        import errno

        raise OSError(errno.ENOSPC, "No space left on device")

    def flush(self):
        pass


@pytest.mark.parametrize("args, files", [
    (SHORT, RUN_FILES),
    # each printed before writing: a full standard output lost their files (found by helper-2)
    (["replay", RECORD, "--site", "nanjing"], RUN_FILES),
    (["sky", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "30min", "--plot", "{out}/sky.png"], ("sky.png",)),
    (["sun", "--site", "lanzhou", "--date", "2021-06-21", "--plot", "{out}/sun.png"], ("sun.png",)),
    (["field", "trough", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10min", "--count", "2"],
     ("collectors.csv", "summary.json", "log.nc")),
    (["compare", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10min"],
     ("comparison.json", "comparison.png", "hybrid/summary.json")),
], ids=["simulate", "replay", "sky", "sun", "field", "compare"])
def test_a_full_standard_output_is_one_line_but_keeps_the_run_it_computed(tmp_path, monkeypatch, capsys, args,
                                                                           files):
    """The summary was printed before the files were written: a full standard output threw the run away."""
    out = tmp_path / "out"
    out.mkdir()
    monkeypatch.setattr(sys, "stdout", FullDevice())
    plotted = any("{out}" in arg for arg in args)
    args = [arg.replace("{out}", str(out)) for arg in args] + ([] if plotted else ["--out", str(out), "--force"])
    assert main(args) == 2
    error = capsys.readouterr().err.splitlines()[-1]  # after the field's progress bar
    assert error == "hybridtrack: error: standard output: cannot write (No space left on device)"
    for name in files:
        assert (out / name).stat().st_size > 0, name


def test_a_standard_output_closed_before_the_start_is_a_reader_that_left(tmp_path):
    """``>&-``: Python's sys.stdout is None, and every command ended in an AttributeError traceback."""
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    for args in (["--version"], SHORT + ["--out", str(out)]):
        child = subprocess.run([sys.executable, "-m", "hybridtrack", *args], stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, env=env, preexec_fn=lambda: os.close(1))
        assert child.returncode == 0 and child.stderr.decode() == "", child.stderr.decode()
    assert (out / "summary.json").stat().st_size > 0


# -- a failed write leaves no half file --------------------------------------------------------------

def _half_then_full(target):
    """A writer that gets half way and finds the disk full."""
    import errno

    Path(target).write_text("half a fi")
    raise OSError(errno.ENOSPC, "No space left on device")


def test_a_write_that_fails_leaves_no_half_file_and_keeps_the_old_one(tmp_path):
    from hybridtrack.outputs import write

    new, old = tmp_path / "new.csv", tmp_path / "old.csv"
    old.write_text("the earlier result\n")
    old.chmod(0o640)
    for path in (new, old):
        with pytest.raises(HybridtrackError, match=rf"^{path}: cannot write \(No space left on device\)$"):
            write(path, _half_then_full)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.csv"] and old.read_text() == "the earlier result\n"
    write(old, lambda target: target.write_text("the new result\n"))
    assert old.read_text() == "the new result\n" and (old.stat().st_mode & 0o777) == 0o640


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full, a device that is always full")
def test_a_device_is_written_in_place_not_replaced():
    from hybridtrack.outputs import write

    with pytest.raises(HybridtrackError, match=r"^/dev/full: cannot write \(No space left on device\)$"):
        write("/dev/full", lambda target: Path(target).write_text("x" * 10_000))
    assert Path("/dev/full").is_char_device() and not list(Path("/dev").glob(".hybridtrack-*"))


def test_a_run_whose_log_cannot_be_written_leaves_nothing_behind(tmp_path, monkeypatch, capsys):
    """A full disk while writing log.parquet left a truncated log, and a retry needed --force."""
    out = tmp_path / "out"
    monkeypatch.setattr(pd.DataFrame, "to_parquet", lambda self, path, *a, **k: _half_then_full(path))
    assert main(SHORT + ["--out", str(out)]) == 2
    assert capsys.readouterr().err == (f"hybridtrack: error: {out / 'log.parquet'}: cannot write "
                                       "(No space left on device)\n")
    assert not out.exists()  # the folder the command made, and nothing in it
    monkeypatch.undo()
    assert main(SHORT + ["--out", str(out)]) == 0 and pd.read_parquet(out / "log.parquet").shape[0] == 144



def test_an_api_save_refused_after_claiming_its_folder_leaves_no_folder(tmp_path, monkeypatch):
    """`FieldResult.save` with a metric the map cannot draw, and `Result.save` on a full disk, had
    made the folders they were given and left them empty (the command line removed its own)."""
    from hybridtrack import simulate, simulate_field
    from hybridtrack.fields import TroughLoop
    from hybridtrack.sky import synthetic

    frame = synthetic("lanzhou", "2021-06-21", freq="10min", weather="sunny", seed=1)
    field = simulate_field(frame, "lanzhou", TroughLoop(count=2))
    with pytest.raises(HybridtrackError, match="no collector metric 'bogus'"):
        field.save(tmp_path / "field" / "deep", metric="bogus")
    run = simulate(frame, "lanzhou")
    monkeypatch.setattr(pd.DataFrame, "to_parquet", lambda self, path, *a, **k: _half_then_full(path))
    with pytest.raises(HybridtrackError, match="No space left on device"):
        run.save(tmp_path / "run")
    assert list(tmp_path.iterdir()) == []  # nor the folder above the one asked for
    (tmp_path / "mine").mkdir()
    with pytest.raises(HybridtrackError, match="No space left on device"):  # the same full disk, not another refusal
        run.save(tmp_path / "mine")
    assert (tmp_path / "mine").is_dir()  # a folder that was there before stays

@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full, a device that is always full")
@pytest.mark.parametrize("args", [["--version"], ["--help"], ["sweep", "--help"], ["field", "--help"]])
def test_help_and_version_to_a_full_standard_output_are_one_line(args):
    """argparse swallows the failed write: these exited 0 without a word."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    with open("/dev/full", "w") as full:
        child = subprocess.run([sys.executable, "-m", "hybridtrack", *args], stdout=full, stderr=subprocess.PIPE,
                               env=env)
    assert child.returncode == 2
    assert child.stderr.decode() == "hybridtrack: error: standard output: cannot write (No space left on device)\n"


def test_a_name_at_the_length_limit_and_a_packed_files_member_keep_their_own_names(tmp_path):
    """The partial file had been named '.NAME.xxxxxxxx.partial.SUFFIX': 18 bytes more, past the
    255-byte limit for a name the old code wrote, and inside a zip as the member's name."""
    import zipfile

    from hybridtrack.outputs import write

    longest = tmp_path / ("a" * 251 + ".csv")
    write(longest, lambda path: path.write_text("x\n"))
    assert longest.read_text() == "x\n"
    packed = tmp_path / "t.csv.zip"
    write(packed, lambda path: pd.DataFrame({"a": [1]}).to_csv(path, index=False))
    assert zipfile.ZipFile(packed).namelist() == ["t.csv"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([longest.name, "t.csv.zip"])  # no staging left


def test_files_written_together_are_replaced_all_or_none(tmp_path):
    """A failed --force run had left some files of the new run beside the rest of the old one."""
    from hybridtrack.outputs import together, write

    first, second = tmp_path / "log.csv", tmp_path / "report.png"
    for path in (first, second):
        path.write_text("old run\n")
    with pytest.raises(HybridtrackError, match="No space left on device"), together():
        write(first, lambda path: path.write_text("new run\n"))
        write(second, _half_then_full)
    assert first.read_text() == second.read_text() == "old run\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["log.csv", "report.png"]
    with together():
        for path in (first, second):
            write(path, lambda path: path.write_text("new run\n"))
    assert first.read_text() == second.read_text() == "new run\n"


def test_a_folder_that_takes_no_new_file_still_lets_a_writable_file_be_rewritten(tmp_path, monkeypatch):
    """The staging folder cannot be made there: an existing file that may be written is rewritten in
    place, as before; a new file is refused naming why."""
    import tempfile

    from hybridtrack.outputs import write

    def no_new_file(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    existing = tmp_path / "x.csv"
    existing.write_text("old\n")
    monkeypatch.setattr(tempfile, "mkdtemp", no_new_file)
    write(existing, lambda path: path.write_text("new\n"))
    assert existing.read_text() == "new\n"
    with pytest.raises(HybridtrackError, match=r"new.csv: cannot write \(its folder takes no new file\)"):
        write(tmp_path / "new.csv", lambda path: path.write_text("new\n"))


@pytest.mark.parametrize("closed", ["closed", "full"])
def test_a_closed_or_full_standard_error_loses_no_run_and_keeps_the_status(tmp_path, closed):
    """A progress bar on a closed (``2>&-``) or full standard error ended a streamed run and a field
    with an AttributeError or OSError (status 1, nothing written); a refusal ended with status 1."""
    if closed == "full" and not os.path.exists("/dev/full"):
        pytest.skip("needs /dev/full, a device that is always full")
    env = {**os.environ, "PYTHONPATH": str(REPO)}

    def run(*args):
        with open("/dev/full" if closed == "full" else os.devnull, "w") as sink:
            return subprocess.run([sys.executable, "-m", "hybridtrack", *args], stdout=subprocess.DEVNULL, stderr=sink,
                                  env=env, preexec_fn=(lambda: os.close(2)) if closed == "closed" else None).returncode

    day = ["--site", "lanzhou", "--date", "2021-06-21", "--freq", "30min"]
    assert run("simulate", *day, "--stream", "--out", str(tmp_path / "streamed")) == 0
    assert run("field", "trough", "--count", "2", *day, "--out", str(tmp_path / "field")) == 0
    assert (tmp_path / "streamed" / "summary.json").stat().st_size > 0
    assert (tmp_path / "field" / "collectors.csv").stat().st_size > 0
    assert run("simulate", "--site", "lanzhou", "--date", "2021-02-30") == 2


def _unwritable_folders(tmp_path):
    """Folders that take no new file here: one without write permission (not for root, whom
    permissions do not stop) and sysfs's, which refuses new files to root too."""
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    folders = [locked] if os.geteuid() != 0 else []
    if os.path.isdir("/sys/kernel"):
        try:
            Path("/sys/kernel", ".hybridtrack-probe").touch()
        except OSError:
            folders.append(Path("/sys/kernel"))
    return folders


def test_a_folder_that_takes_no_new_file_is_refused_before_the_run(tmp_path, capsys):
    """A read-only --out was found only when the results were written: a sweep lost its runs."""
    folders = _unwritable_folders(tmp_path)
    if not folders:
        pytest.skip("no folder here refuses new files to this user")
    for folder in folders:
        with pytest.raises(HybridtrackError, match=rf"^{folder}: cannot write there \("):
            claim([folder / "summary.json"])
        assert main(SHORT + ["--out", str(folder)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"{folder}: cannot write there" in err
    (tmp_path / "locked").chmod(0o700)


def test_a_run_that_opens_the_lock_as_its_holder_lets_go_holds_the_folder_still(tmp_path, monkeypatch):
    """The holder removes its lock file as it ends: a run that had opened that file just before
    locked a file no longer in the folder, and a third run then took the folder beside it."""
    import hybridtrack.outputs as outputs

    lock = tmp_path / outputs.LOCK_NAME
    take = outputs._lock
    calls = []

    def holder_ends_first(descriptor, folder, mode):
        calls.append(mode)
        if len(calls) == 1:
            lock.unlink()  # the run that held the folder ended between this run's open and its lock
        take(descriptor, folder, mode)

    monkeypatch.setattr(outputs, "_lock", holder_ends_first)
    with outputs.held(tmp_path):
        assert lock.exists()
        monkeypatch.setattr(outputs, "_lock", take)
        with pytest.raises(HybridtrackError, match="another run is writing there now"):
            with outputs.held(tmp_path):
                pass
    assert len(calls) == 2 and not lock.exists()


def test_a_folder_whose_lock_is_let_go_at_every_attempt_is_refused_in_one_line(tmp_path, monkeypatch):
    import hybridtrack.outputs as outputs

    def let_go_each_time(descriptor, folder, mode):
        (tmp_path / outputs.LOCK_NAME).unlink()

    monkeypatch.setattr(outputs, "_lock", let_go_each_time)
    with pytest.raises(HybridtrackError, match="other runs keep taking and letting go of the folder"):
        with outputs.held(tmp_path):
            pass


def test_a_path_from_the_home_folder_is_read_and_written_there(tmp_path, monkeypatch, capsys):
    """'~/x' was made as a folder named '~' here, while pandas wrote into the home folder's: no
    save could succeed. The command line gets '--csv=~/x' unexpanded (the shell expands '~' only
    at a word's start)."""
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.chdir(tmp_path)
    (tmp_path / "home").mkdir()
    SimulationConfig(seed=5).to_toml("~/config.toml")
    assert SimulationConfig.from_toml("~/config.toml").seed == 5
    assert main(["sun", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "1h", "--csv=~/sun.csv"]) == 0
    assert f"wrote {20 - 5 + 1} rows to {tmp_path / 'home' / 'sun.csv'}" in capsys.readouterr().out  # 05:00-20:00 hourly
    assert sorted(p.name for p in (tmp_path / "home").iterdir()) == ["config.toml", "sun.csv"]
    assert not (tmp_path / "~").exists()


@pytest.mark.parametrize("path, message", [
    ("x\x00y", "holds a NUL character"),  # Python's ValueError: embedded null byte
    ("a" * 300, r"cannot write there \(File name too long\)"),  # OSError
])
def test_a_path_no_file_system_takes_is_refused_in_one_line(tmp_path, path, message):
    with pytest.raises(HybridtrackError, match=message):
        SimulationConfig().to_toml(tmp_path / path if "\x00" not in path else str(tmp_path) + "/" + path)
    with pytest.raises(HybridtrackError, match="config file must be a path|no such config file|cannot be read"):
        SimulationConfig.from_toml(str(tmp_path) + "/" + path)
