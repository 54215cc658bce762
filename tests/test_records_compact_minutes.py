"""Ten-digit ``yymmddHHMM`` stamps are read as what they write, not as epoch seconds."""

import pandas as pd
import pytest

from hybridtrack.io import read_weather


def _write(tmp_path, stamps) -> str:
    path = tmp_path / "log.csv"
    rows = "".join(f"{stamp},{800 + k},{700 + k},100\n" for k, stamp in enumerate(stamps))
    path.write_text("time,ghi,dni,dhi\n" + rows)
    return str(path)


def test_compact_minutes_are_read_as_written_not_as_epoch_seconds(tmp_path):
    # read as epoch seconds, 1306211200 had been 2011-05-24 04:26:40 UTC: Nanjing's noon of 21 June 2013 two years off
    stamps = [f"13062111{m}" for m in range(50, 60)] + ["1306211200", "1306211201"]  # 12 rows, 11:50 to 12:01
    frame = read_weather(_write(tmp_path, stamps), tz="Asia/Shanghai")
    expected = pd.date_range("2013-06-21 11:50", "2013-06-21 12:01", freq="min", tz="Asia/Shanghai")
    pd.testing.assert_index_equal(frame.index, expected, check_names=False, check_freq=False)
    assert frame.attrs["validation"]["date_order"] == "written yymmddHHMM (20yy)"  # the report says how


@pytest.mark.parametrize("step", [60, 120, 300, 600, 900, 1800, 3600, 86400])
def test_epoch_seconds_at_a_loggers_step_stay_epoch_seconds(tmp_path, step):
    """The worst start: 1206010000 s (2008-03-27 UTC) is also a valid yymmddHHMM, 2012-06-01 00:00,
    and at 5-min steps stays one for eight rows (00:00 to 00:21); twelve rows are asked for."""
    first = 1206010000
    stamps = [str(first + k * step) for k in range(8)]
    frame = read_weather(_write(tmp_path, stamps))
    expected = pd.to_datetime([first + k * step for k in range(8)], unit="s", utc=True)
    pd.testing.assert_index_equal(frame.index.tz_convert("UTC"), expected, check_names=False, exact=False)
