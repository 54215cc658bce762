"""A save into a folder an earlier save wrote leaves none of the earlier files it does not write
itself (a log in the other format, a report not drawn, a field's log not kept): left there, they
had been read as the new run's."""

import os

import pytest

from hybridtrack import HybridtrackError, simulate, simulate_field
from hybridtrack.fields import FresnelField
from hybridtrack.outputs import replacing
from hybridtrack.sky import synthetic


@pytest.fixture(scope="module")
def day():
    return synthetic("lanzhou", "2021-06-21", weather="mixed", seed=1, freq="10min")


def test_a_runs_save_removes_the_earlier_saves_files_it_does_not_write(day, tmp_path):
    result = simulate(day, "lanzhou")
    result.save(tmp_path)
    assert sorted(os.listdir(tmp_path)) == ["events.csv", "log.parquet", "report.png", "summary.json"]
    result.save(tmp_path, plot=False, log_format="csv")
    assert sorted(os.listdir(tmp_path)) == ["events.csv", "log.csv", "summary.json"]
    result.save(tmp_path)
    assert sorted(os.listdir(tmp_path)) == ["events.csv", "log.parquet", "report.png", "summary.json"]


def test_an_earlier_file_is_refused_by_name_where_files_are_not_replaced(day, tmp_path):
    result = simulate(day, "lanzhou")
    result.save(tmp_path)
    (tmp_path / "events.csv").unlink()
    (tmp_path / "summary.json").unlink()
    (tmp_path / "log.parquet").rename(tmp_path / "log.csv")
    with replacing(False), pytest.raises(HybridtrackError, match=r"^would replace 2 existing files: .*log\.csv, "
                                                                  r".*report\.png; give --force"):
        result.save(tmp_path, plot=False)
    assert sorted(os.listdir(tmp_path)) == ["log.csv", "report.png"]  # nothing written, nothing removed


def test_a_field_saved_without_its_log_removes_the_earlier_log_but_no_folder_of_that_name(day, tmp_path):
    field = FresnelField(row_distances=[-4.0, 6.0])
    simulate_field(day, "lanzhou", field).save(tmp_path)
    lean = simulate_field(day, "lanzhou", field, keep_log=False)
    with pytest.raises(HybridtrackError, match="no collector metric"):  # a failed save keeps the earlier one whole
        lean.save(tmp_path, metric="nope")
    assert (tmp_path / "log.nc").is_file()
    lean.save(tmp_path)
    assert sorted(os.listdir(tmp_path)) == ["collectors.csv", "events.csv", "field_map.png", "summary.json"]
    (tmp_path / "log.nc").mkdir()  # not a file any save wrote
    lean.save(tmp_path)
    assert (tmp_path / "log.nc").is_dir()
