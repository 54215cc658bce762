"""An OpenDocument spreadsheet (LibreOffice Calc's .ods) is named as one, as an Excel workbook is.

It had been refused as "a zip archive must hold exactly one file; it holds mimetype,
content.xml, ..." (found by a helper replaying messy files).
"""

from __future__ import annotations

import zipfile

import pytest

from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.io import read_text, read_weather


def _opendocument(path, mimetype: str):
    """A zip laid out as the OpenDocument standard (ODF 1.2, part 3, section 3.3) lays out a
    document: ``mimetype`` first and stored, then the content and the manifest."""
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("mimetype", mimetype, compress_type=zipfile.ZIP_STORED)
        archive.writestr("content.xml", "<office:document-content/>")
        archive.writestr("styles.xml", "<office:document-styles/>")
        archive.writestr("META-INF/manifest.xml", "<manifest:manifest/>")
    return path


def test_a_spreadsheet_is_named_with_how_to_save_it_as_csv(tmp_path, capsys):
    path = _opendocument(tmp_path / "logger.ods", "application/vnd.oasis.opendocument.spreadsheet")
    with pytest.raises(HybridtrackError, match="an OpenDocument spreadsheet: save it as CSV"):
        read_weather(path, tz="UTC")
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "OpenDocument spreadsheet" in err and "mimetype" not in err


def test_another_opendocument_file_is_no_table(tmp_path):
    path = _opendocument(tmp_path / "notes.odt", "application/vnd.oasis.opendocument.text")
    with pytest.raises(HybridtrackError, match="an OpenDocument file, not a table"):
        read_text(path)
