"""Inputs an adversary feeds the command line and the file readers, each found to break once: a
wrong file or flag is one line naming it and where, status 2, never a traceback (nor a hang)."""

from __future__ import annotations

import pytest

from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.io import read_weather

HEADER = "time,ghi,dni,dhi,wind_speed\n"
ROWS = "".join(f"2021-06-05 {h:02d}:00,{g},{d},{f},2.0\n" for h, g, d, f in
               ((6, 40, 300, 20), (9, 600, 800, 90), (12, 950, 900, 100), (15, 700, 820, 95), (18, 200, 500, 60)))


def refused(path, kwargs, flags, capsys) -> str:
    """The API's message for `path`, after checking that ``hybridtrack check`` prints the same
    one line with status 2."""
    with pytest.raises(HybridtrackError) as error:
        read_weather(path, **kwargs)
    message = str(error.value)
    assert "\n" not in message
    assert main(["check", str(path), *flags]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {message}\n"
    return message


def test_a_stamp_of_millions_of_characters_is_refused_at_once_and_quoted_cut(tmp_path, capsys):
    # a corrupted logger line of 5 million digits in the time column: the date parser had taken
    # minutes over it (a hang), and the message then quoted all 5 million characters
    path = tmp_path / "record.csv"
    path.write_text(HEADER + ROWS + "9" * 5_000_000 + ",1,1,1,1\n" + ROWS.replace("-05 ", "-06 "))
    message = refused(path, {"tz": "UTC"}, ["--tz", "UTC"], capsys)
    assert message == (f"{path}: line 7, column 'time': '99999999999999999999'... (5,000,000 characters) is not a "
                       "time stamp (longer than 80 characters)")


@pytest.mark.parametrize("argv, message", [
    # --tz "$TZ" with TZ unset: sun had run in UTC without a word
    (["sun", "--lat", "10", "--lon", "10", "--tz", "", "--date", "2021-06-21"],
     "--tz is empty: give an IANA time zone such as Asia/Shanghai, or leave --tz out (an unset shell variable?)"),
    # and the site's clock had been dropped for the file's
    (["check", "f.csv", "--lat", "36", "--lon", "103", "--tz", "UTC", "--site-tz", " "],
     "--site-tz is empty: give an IANA time zone such as Asia/Shanghai, or leave --site-tz out (an unset shell "
     "variable?)"),
    # a file's zone no one knows had been refused without naming the flag
    (["check", "f.csv", "--tz", "Mars/Olympus"],
     "--tz: unknown time zone 'Mars/Olympus' (use an IANA name such as 'Asia/Shanghai')"),
    (["replay", "f.csv", "--site", "lanzhou", "--tz", "Asia/Shanghia"],
     "--tz: unknown time zone 'Asia/Shanghia' (use an IANA name such as 'Asia/Shanghai')"),
    # pandas reads a bare number as nanoseconds: refused as 5.4e12 steps needing 10,800,000 GB
    (["sun", "--site", "lanzhou", "--date", "2021-06-21", "--freq", "10"],
     "--freq: step '10' has no unit; write it with one, such as '10min' or '10s'"),
    (["check", "f.csv", "--freq", "1.5"], "--freq: step '1.5' has no unit; write it with one, such as '1.5min' or "
                                          "'1.5s'"),
    # argparse took -1e9 for an option: '--altitude: expected one argument'; now the range names it
    (["sun", "--lat", "10", "--lon", "10", "--tz", "UTC", "--altitude", "-1e9", "--date", "2021-06-21"],
     "--altitude -1000000000.0 m is outside [-500, 9000] m"),
    (["sun", "--lat", "-inf", "--lon", "10", "--tz", "UTC", "--date", "2021-06-21"],
     "--lat -inf is outside [-90, 90] degrees"),
])
def test_a_zone_or_step_flag_is_refused_by_its_flag(argv, message, capsys):
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.err == f"hybridtrack: error: {message}\n"
    assert captured.out == ""


def test_a_negative_number_in_exponent_form_is_read_as_a_value(capsys):
    # -1e2 is the longitude -100, as -100 is: argparse had refused it as an option
    assert main(["sun", "--lat", "40", "--lon", "-1e2", "--tz", "America/Denver", "--date", "2021-06-21",
                 "--freq", "6h"]) == 0
    assert "custom (40.0000°, -100.0000°)" in capsys.readouterr().out


def test_stamps_of_24_00_read_as_the_next_midnight_are_said_in_the_report(tmp_path, capsys):
    # a reading of the file, not written down: 'changes: none', and the time line said nothing
    path = tmp_path / "h24.csv"
    path.write_text("time,ghi,dni,dhi\n2021-06-05 22:00,0,0,0\n2021-06-05 23:00,0,0,0\n2021-06-05 24:00,0,0,0\n"
                    "2021-06-06 01:00,0,0,0\n2021-06-06 24:00,0,0,0\n")
    frame = read_weather(path, tz="UTC")
    assert list(frame.index.strftime("%d %H")) == ["05 22", "05 23", "06 00", "06 01", "07 00"]
    assert main(["check", str(path), "--tz", "UTC"]) == 0
    time_line = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("  time:"))
    assert time_line.endswith("; 2 stamps of 24:00 read as 00:00 of the next day (lines 4, 6)")


def test_a_line_short_of_fields_mid_file_is_counted_and_refused_when_strict(tmp_path, capsys):
    # a logger that lost power mid-line and wrote on in a new line: '...,06:00,64' had been read
    # as a GHI of 64 W/m² and its missing cells as NaN, with 'changes: none'
    path = tmp_path / "cut.csv"
    lines = ROWS.splitlines()
    lines[1] = "2021-06-05 09:00,60"  # file line 3: 2 of 5 fields
    path.write_text(HEADER + "\n".join(lines) + "\n")
    frame = read_weather(path, tz="UTC")
    assert frame.attrs["validation"]["short_rows"]["lines"] == [3]
    assert frame.loc["2021-06-05 09:00", "ghi"].item() == 60 and frame.loc["2021-06-05 09:00", ["dni", "dhi"]].isna().all()
    assert main(["check", str(path), "--tz", "UTC"]) == 0
    out = capsys.readouterr().out
    assert "  changes: 1\n    padded with NaN (lines short of fields): count 1, lines 3, why fewer fields than the header's 5" in out
    assert "verdict: clean" not in out
    message = refused(path, {"tz": "UTC", "strict": True}, ["--tz", "UTC", "--strict"], capsys)
    assert message == f"{path}: line 3: a line with fewer fields than the header (strict)"


def test_rows_that_leave_out_only_a_trailing_column_not_read_are_not_short(tmp_path):
    path = tmp_path / "notes.csv"
    rows = ROWS.replace(",2.0\n", ",2.0,ok\n").splitlines()
    rows[2] = rows[2].removesuffix(",ok")  # file line 4 leaves the note out
    path.write_text("time,ghi,dni,dhi,wind_speed,note\n" + "\n".join(rows) + "\n")
    assert "short_rows" not in read_weather(path, tz="UTC").attrs["validation"]


@pytest.mark.skipif(not __import__("os").path.exists("/dev/zero"), reason="needs /dev/zero and /dev/urandom")
@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_a_device_of_binary_data_is_refused_at_its_first_piece(device, monkeypatch, capsys):
    # it had been read to the memory limit (12 GB, 45 s for /dev/zero) and refused as too large;
    # with the limit at 64 MiB that is the message the old reader gives
    monkeypatch.setattr("hybridtrack.budget.memory_budget", lambda: 64 * 2**20)
    message = refused(device, {"tz": "UTC"}, ["--tz", "UTC"], capsys)
    assert message == f"{device}: looks binary, not a text file (a device or a stream of binary data?)"


def test_a_stream_of_text_with_nul_padding_after_it_is_still_read(tmp_path):
    import os
    import threading

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    text = (HEADER + ROWS).encode() + b"\0" * 5000

    def feed():
        with open(fifo, "wb") as stream:
            stream.write(text)

    writer = threading.Thread(target=feed)
    writer.start()
    frame = read_weather(fifo, tz="UTC")
    writer.join()
    assert len(frame) == 5 and frame.attrs["validation"]["padding"]["count"] == 5000


@pytest.mark.parametrize("flags, message", [
    (["--workers", "0"], "--workers must be a whole number within [1, 1,024], got 0"),
    (["--workers", "-3"], "--workers must be a whole number within [1, 1,024], got -3"),
    (["--scheduler", ""], "--scheduler must be an address such as 'tcp://host:8786', got ''; leave it out for a "
                          "local cluster (an unset shell variable?)"),
])
def test_a_sweeps_where_flags_are_refused_by_their_flag(tmp_path, capsys, flags, message):
    # 'workers must be ...' and 'scheduler must be ...' had named no flag, unlike field's
    sweep = tmp_path / "s.toml"
    sweep.write_text('[base]\nsite = "lanzhou"\nstart = 2021-06-19\ndays = 1\nfreq = "30min"\n[grid]\nseed = [0, 1]\n')
    assert main(["sweep", str(sweep), "--out", str(tmp_path / "out"), *flags]) == 2
    captured = capsys.readouterr()
    assert captured.err == f"hybridtrack: error: {message}\n" and captured.out == ""
    assert not (tmp_path / "out").exists()


def test_a_column_name_of_a_million_characters_is_not_matched_and_is_quoted_cut(tmp_path, capsys):
    # matched against every alias (3 s a million characters) and printed whole in 'not read'
    path = tmp_path / "long.csv"
    path.write_text(HEADER.rstrip("\n") + ",x" + "h" * 999_999 + "\n" + ROWS.replace("\n", ",1\n"))
    frame = read_weather(path, tz="UTC")
    assert frame.attrs["validation"]["not_read"] == ["'xhhhhhhhhhhhhhhhhhhh'... (1,000,000 characters)"]
    assert main(["check", str(path), "--tz", "UTC"]) == 0
    assert "  not read: 'xhhhhhhhhhhhhhhhhhhh'... (1,000,000 characters)\n" in capsys.readouterr().out
    path.write_text("y" * 500_000 + ",ghi\n1,2\n3,4\n")
    message = refused(path, {"tz": "UTC"}, ["--tz", "UTC"], capsys)
    assert message.endswith("; columns are 'yyyyyyyyyyyyyyyyyyyy'... (500,000 characters), ghi")


def test_a_streamed_replay_of_a_file_shorter_than_a_day_is_refused_before_its_bar_and_notes(tmp_path, monkeypatch,
                                                                                             capsys):
    # a file of 06:00 to 18:00 had been simulated to its end, then refused for holding no whole
    # local day; read ahead in the run, it was refused after the wind's note and the progress bar
    import hybridtrack.simulation

    def ran(*args, **kwargs):
        raise AssertionError("a segment was simulated")

    monkeypatch.setattr(hybridtrack.simulation, "simulate", ran)
    path = tmp_path / "half-day.csv"
    path.write_text("time,dni\n" + "".join(f"2021-06-05T{h:02d}:00:00+08:00,500\n" for h in range(6, 19)))
    out = tmp_path / "run"
    assert main(["replay", str(path), "--site", "nanjing", "--stream", "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == ("hybridtrack: error: a streamed run needs at least one whole local day at nanjing; this "
                            "span has none (run it without --stream; hybridtrack.simulate from Python)\n")
    assert not out.exists()


@pytest.mark.parametrize("argv", [["simulate", "--site", "atlantis", "--date", "2021-06-21"],
                                  ["sun", "--site", "atlantis", "--date", "2021-06-21"],
                                  ["check", "f.csv", "--site", "atlantis"],
                                  ["replay", "f.csv", "--site", "atlantis"]])
def test_an_unknown_site_is_refused_naming_the_flag(argv, capsys):
    # 'unknown site 'atlantis'' had named no flag, as ablate's --sites had not
    assert main(argv) == 2
    assert capsys.readouterr().err == ("hybridtrack: error: --site: unknown site 'atlantis'; known sites: delingha, "
                                       "kunming, lanzhou, nanjing\n")


def _packed(kind: str, text: str) -> bytes:
    import gzip
    import io
    import zipfile

    if kind == "gzip":
        return gzip.compress(text.encode())
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("log.csv", text)
    return buffer.getvalue()


@pytest.mark.parametrize("kind, name, damage, message", [
    # zlib's own error had escaped both readers: "zlib.error: Error -3 while decompressing data" and a traceback
    ("gzip", "log.csv.gz", lambda raw: raw[:30] + b"\xff" * 20 + raw[50:],
     "log.csv.gz: a damaged gzip file (Error -3 while decompressing data"),
    ("zip", "log.zip", lambda raw: raw[:60] + b"\xff" * 20 + raw[80:],
     "log.zip: a damaged or unsupported zip file (Error -3 while decompressing data"),
    ("gzip", "log.csv", lambda raw: raw[:-30], "log.csv: a damaged gzip file (Compressed file ended before"),
])
def test_a_damaged_packed_file_is_one_line(tmp_path, capsys, kind, name, damage, message):
    path = tmp_path / name
    path.write_bytes(damage(_packed(kind, HEADER + ROWS * 20)))
    assert refused(path, {"tz": "Asia/Shanghai"}, ["--tz", "Asia/Shanghai"], capsys).startswith(f"{tmp_path}/{message}")


@pytest.mark.parametrize("kind", ["gzip", "zip"])
def test_a_packed_file_that_unpacks_past_the_memory_budget_is_refused_not_unpacked(tmp_path, capsys, monkeypatch,
                                                                                   kind):
    """A few MB of packed zeros unpack a thousand times larger; they had been unpacked without a bound.
    The budget is made 1 MiB here, the file 3 MiB unpacked (a little of it packed)."""
    import hybridtrack.budget

    monkeypatch.setattr(hybridtrack.budget, "memory_budget", lambda: 2**20)
    text = HEADER + ROWS * (3 * 2**20 // len(ROWS))
    path = tmp_path / ("log.csv.gz" if kind == "gzip" else "log.zip")
    path.write_bytes(_packed(kind, text))
    assert path.stat().st_size < 2**20
    assert refused(path, {"tz": "Asia/Shanghai"}, ["--tz", "Asia/Shanghai"], capsys) == (
        f"{path}: unpacks to more than 1 MiB, more than a file can be")


def test_a_streamed_files_unwritten_tail_is_quoted_cut(tmp_path, capsys):
    """A logger card's NUL padding after the last line (the record reader drops it) is the streamed
    reader's last time cell: quoted whole, a megabyte of it had been one line of 4 MB."""
    path = tmp_path / "card.csv"
    path.write_bytes(("time,dni\n" + "".join(f"2021-06-21T{h:02d}:00:00+08:00,0\n" for h in range(24))).encode()
                     + b"\x00" * 2**20)
    assert main(["replay", str(path), "--site", "lanzhou", "--stream", "--out", str(tmp_path / "run")]) == 2
    assert capsys.readouterr().err == (
        f"hybridtrack: error: {path}: row 26, column 'time': '{chr(92)}x00{chr(92)}x00{chr(92)}x00{chr(92)}x00"
        f"{(chr(92) + 'x00') * 16}'... (1,048,576 characters) is not an ISO 8601 time stamp (a streamed file is read "
        "as written: convert a record once with hybridtrack check FILE --out clean.parquet "
        "(hybridtrack.io.read_weather(...).to_parquet(...) from Python))\n")
