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
    stamps = ["1306211159", "1306211200", "1306211201"]
    frame = read_weather(_write(tmp_path, stamps), tz="Asia/Shanghai")
    expected = pd.DatetimeIndex(["2013-06-21 11:59", "2013-06-21 12:00", "2013-06-21 12:01"]).tz_localize("Asia/Shanghai")
    pd.testing.assert_index_equal(frame.index, expected, check_names=False)
    assert frame.attrs["validation"]["date_order"] == "written yymmddHHMM (20yy)"  # the report says how


@pytest.mark.parametrize("step", [60, 3600, 86400])
def test_epoch_seconds_at_any_step_stay_epoch_seconds(tmp_path, step):
    first = 1624248000  # 2021-06-21 04:00 UTC
    stamps = [str(first + k * step) for k in range(3)]
    frame = read_weather(_write(tmp_path, stamps))
    expected = pd.to_datetime([first + k * step for k in range(3)], unit="s", utc=True)
    pd.testing.assert_index_equal(frame.index.tz_convert("UTC"), expected, check_names=False, exact=False)
