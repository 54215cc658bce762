"""A refused flag value is named by its flag, before any file is read (found by a helper
replaying messy files: ``step '0min' must be positive`` named no flag, and ``check`` said it
only after reading the whole file)."""

from __future__ import annotations

import pytest

from hybridtrack.cli import main


@pytest.mark.parametrize("args, message", [
    (["check", "no-such-file.csv", "--freq", "0min"], "--freq: step '0min' must be positive"),
    (["check", "no-such-file.csv", "--freq", "soon"], "--freq: step 'soon' is not a duration"),
    (["sun", "--date", "2021-02-30"], "--date: date '2021-02-30' does not exist"),
    (["sun", "--date", "2021-06-21", "--start", "7"], "--start: clock time '7' is not HH:MM"),
    (["sun", "--date", "2021-06-21", "--end", "25:00"], "--end: clock time '25:00' is not HH:MM"),
    (["sun", "--date", "2021-06-21", "--freq=-5min"], "--freq: step '-5min' must be positive"),
])
def test_the_refusal_names_the_flag(capsys, args, message):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err
