"""Files and encodings: the bytes of a file, unpacked (``.gz``, ``.zip``) and decoded to text.

Text is decoded as UTF-8 (with or without a byte-order mark), UTF-16 (with a byte-order mark,
or without one when every other byte is NUL, as Windows tools write it), and otherwise as
Windows-1252 / Latin-1, the encoding of older loggers' degree signs. The encoding used is
returned so that the validation report can say it.
"""

from __future__ import annotations

import gzip
import io
import zipfile
import zlib
from pathlib import Path

from .. import params
from ..errors import HybridtrackError

__all__ = ["input_path", "read_bytes", "unpack", "decode", "file_text", "read_text", "read_toml", "write_toml", "WEATHER_SUFFIXES"]

#: In a zip of several files, the one weather file among them is read (EnergyPlus ships .epw with .stat, .ddy).
WEATHER_SUFFIXES = (".epw", ".csv", ".tm2", ".tmy", ".dat", ".tsv", ".txt")


def input_path(value, what: str = "file") -> Path:
    """`value` as a Path to read (`params.path`: ``~`` expanded; no NUL, nothing empty)."""
    return params.path(value, f"a {what}")


#: The largest config file read, bytes: a run's, a fuzzy system's or a sweep's TOML is a few kB;
#: ``--config /dev/zero`` had been read until the memory ran out.
MAX_CONFIG_BYTES = 16 * 2**20


def read_bytes(path: Path, what: str = "file", limit: int | None = None) -> bytes:
    """The raw bytes of `path`, or one clear error: missing, a folder, not readable, or more than
    `limit` bytes (by default the memory budget, `hybridtrack.budget.memory_budget`): a device
    that never ends (``/dev/zero``) is refused at the limit, not read until the memory runs out."""
    from ..budget import memory_budget

    path = input_path(path, what)
    limit = memory_budget() if limit is None else int(limit)
    try:
        with open(path, "rb") as stream:
            raw = _read_up_to(stream, limit)
        if raw is _BINARY:
            raise HybridtrackError(f"{path}: looks binary, not a text {what} (a device or a stream of binary data?)")
        if raw is None:
            raise HybridtrackError(f"{path}: larger than {limit / 2**20:,.0f} MiB, more than a {what} can be "
                                   f"(a device that never ends?)")
        return raw
    except FileNotFoundError:
        raise HybridtrackError(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise HybridtrackError(f"{path}: is a folder, not a {what}") from None
    except PermissionError:
        raise HybridtrackError(f"{path}: not readable (permission denied)") from None
    except OSError as exc:
        raise HybridtrackError(f"{path}: cannot be read ({exc.strerror or exc})") from None


#: What `_read_up_to` returns for a stream whose first piece is binary.
_BINARY = b"\x00binary"


def _binary_start(piece: bytes, full: bool) -> bool:
    """Whether a stream's first `piece` (of the largest size asked, if `full`) is binary data: NUL
    bytes within its text, or nothing but NUL bytes all through a full piece (``/dev/zero``). A
    packed file, UTF-16 text and a Parquet file are left to their readers, and so is text followed
    by NUL padding (a logger card's unwritten tail)."""
    head = piece[:4096]
    if head[:2] in (b"\x1f\x8b", b"\xff\xfe", b"\xfe\xff") or head[:4] in (b"PK\x03\x04", b"PAR1") or _looks_utf16(head):
        return False
    if b"\x00" in head.rstrip(b"\x00"):
        return True
    return full and not piece.strip(b"\x00")


def _read_up_to(stream, limit: int) -> bytes | None:
    """All of `stream`, or None past `limit` bytes: a regular file of that size at once, anything
    else (a pipe, a device) in pieces, so that no buffer of the limit's size is asked for. A
    stream whose first piece is binary (`_binary_start`) gives `_BINARY` at once: ``/dev/zero``
    and ``/dev/urandom`` had been read to the memory limit (12 GB, 45 and 87 seconds) before
    their refusal."""
    import os
    import stat

    status = os.fstat(stream.fileno())
    if stat.S_ISREG(status.st_mode) and status.st_size <= limit:
        return stream.read()
    pieces, size = [], 0
    while size <= limit:
        asked = min(2**24, limit + 1 - size)
        piece = stream.read(asked)
        if not piece:
            return b"".join(pieces)
        if not pieces and _binary_start(piece, len(piece) == asked):
            return _BINARY
        pieces.append(piece)
        size += len(piece)
    return None


def _unpacked(path: Path, stream) -> bytes:
    """All of a packed file's `stream`, refused past the memory budget (a file of zeros packs a
    thousand to one: a few MB had unpacked without a bound)."""
    from ..budget import memory_budget

    limit = memory_budget()
    content = stream.read(limit + 1)
    if len(content) > limit:
        raise HybridtrackError(f"{path}: unpacks to more than {limit / 2**20:,.0f} MiB, more than a file can be")
    return content


def unpack(path: Path, raw: bytes) -> tuple[bytes, str | None]:
    """The content of a gzip or zip file (by its magic bytes), and how it was packed. A damaged
    one (zlib's own error among them, which had ended in a traceback) is refused in one line."""
    if raw[:2] == b"\x1f\x8b":
        try:
            with gzip.GzipFile(fileobj=io.BytesIO(raw)) as stream:
                return _unpacked(path, stream), "gzip"
        except (OSError, EOFError, gzip.BadGzipFile, zlib.error) as exc:
            raise HybridtrackError(f"{path}: a damaged gzip file ({exc})") from None
    if raw[:4] == b"PK\x03\x04":
        try:
            with zipfile.ZipFile(io.BytesIO(raw)) as archive:
                members = [m for m in archive.infolist() if not m.is_dir() and not m.filename.startswith("__MACOSX")]
                _refuse_office(path, archive, [m.filename for m in members])
                weather = [m for m in members if m.filename.lower().endswith(WEATHER_SUFFIXES)]
                if len(members) > 1 and len(weather) == 1:  # EnergyPlus zips: .epw with .stat and .ddy
                    members = weather
                if len(members) != 1:
                    names = ", ".join(m.filename for m in members) or "nothing"
                    raise HybridtrackError(f"{path}: a zip archive must hold exactly one file; it holds {names}")
                with archive.open(members[0]) as stream:
                    return _unpacked(path, stream), f"zip member {members[0].filename}"
        except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, NotImplementedError, zlib.error) as exc:
            raise HybridtrackError(f"{path}: a damaged or unsupported zip file ({exc})") from None
    return raw, None


#: The ``mimetype`` an OpenDocument spreadsheet (LibreOffice Calc's ``.ods``) starts with.
_ODS_MIMETYPE = b"application/vnd.oasis.opendocument.spreadsheet"


def _refuse_office(path: Path, archive: zipfile.ZipFile, names: list[str]) -> None:
    """Refuse an Office file (a zip with ``[Content_Types].xml``) or an OpenDocument one (a zip
    with a ``mimetype`` and ``content.xml``): an Excel workbook, and later a LibreOffice one, had
    been told that a zip archive must hold one file, naming its XML parts."""
    if "[Content_Types].xml" in names:
        kind = ("an Excel workbook: save it as CSV (File > Save As > CSV)" if "xl/workbook.xml" in names
                else "an Office document, not a table")
        raise HybridtrackError(f"{path}: {kind}")
    if {"mimetype", "content.xml"} <= set(names):
        kind = ("an OpenDocument spreadsheet: save it as CSV (File > Save As > Text CSV)"
                if archive.read("mimetype").startswith(_ODS_MIMETYPE) else "an OpenDocument file, not a table")
        raise HybridtrackError(f"{path}: {kind}")


def _looks_utf16(raw: bytes) -> str | None:
    """'utf-16-le' or 'utf-16-be' for BOM-less UTF-16 text (NUL in every other byte), else None."""
    sample = raw[:4096]
    if len(sample) < 4:
        return None
    even, odd = sample[0::2], sample[1::2]
    if odd.count(0) > 0.9 * len(odd) and even.count(0) < 0.1 * len(even):
        return "utf-16-le"
    if even.count(0) > 0.9 * len(even) and odd.count(0) < 0.1 * len(odd):
        return "utf-16-be"
    return None


def _without_padding(raw: bytes, wide: bool) -> tuple[bytes, int]:
    """`raw` without the NUL bytes after its text (a logger card's unwritten tail), and how many:
    a Campbell TOA5 file so padded had been refused at its last line, a cell of NULs quoted whole.
    In UTF-16 (`wide`) the last character's NUL half is kept."""
    kept = len(raw.rstrip(b"\x00"))
    kept += kept % 2 if wide else 0
    return raw[:kept], len(raw) - kept


def _refuse_nul(path: Path, raw: bytes) -> None:
    """Refuse NUL bytes inside 8-bit text: binary data, or a damaged file, named by its line."""
    at = raw.find(b"\x00")
    if at < 0:
        return
    if at < 4096:
        raise HybridtrackError(f"{path}: looks binary, not a text table")
    line = raw.count(b"\n", 0, at) + 1
    raise HybridtrackError(f"{path}: line {line}: NUL bytes inside the text (a damaged file?)")


def decode(path: Path, raw: bytes, report: dict | None = None) -> tuple[str, str]:
    """Text and the encoding it was read in; binary data is refused. Given a `report` (a weather
    file's), NUL padding after the text is dropped and counted in it (``padding``)."""
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        encoding = "utf-16"
    else:
        encoding = _looks_utf16(raw if report is None else raw.rstrip(b"\x00")) or ""
    padding = 0
    if report is not None:
        raw, padding = _without_padding(raw, bool(encoding))
    text, encoding = _decoded(path, raw, encoding)
    if padding:
        line = text.count("\n") + 1
        report["padding"] = {"count": padding, "lines": [line]}
    return text, encoding


def _decoded(path: Path, raw: bytes, encoding: str) -> tuple[str, str]:
    """`raw` as text: in `encoding` if given, else UTF-8, Windows-1252 or Latin-1."""
    if encoding:
        try:
            return raw.decode(encoding).lstrip("\ufeff"), encoding.upper()
        except UnicodeDecodeError as exc:
            raise HybridtrackError(f"{path}: not valid UTF-16 text (byte {exc.start})") from None
    if raw[:4] == b"PAR1":  # a frame written already (hybridtrack check --out x.parquet)
        raise HybridtrackError(f"{path}: a Parquet file, not a text table: replay it with --stream, or read it "
                               "with pandas.read_parquet")
    _refuse_nul(path, raw)
    try:
        return raw.decode("utf-8-sig"), "UTF-8"
    except UnicodeDecodeError:
        pass
    try:
        return raw.decode("cp1252"), "Windows-1252"
    except UnicodeDecodeError:
        return raw.decode("latin-1"), "Latin-1"


def file_text(path, what: str = "file", report: dict | None = None) -> tuple[str, str]:
    """The text of a (possibly packed) file and a note of how it was read, e.g. ``'gzip, UTF-16'``;
    NUL padding after the text is dropped and counted in `report` (see `decode`)."""
    path = input_path(path, what)
    raw, packing = unpack(path, read_bytes(path, what))
    text, encoding = decode(path, raw, report)
    if not text.strip():
        raise HybridtrackError(f"{path}: the file is empty")
    return text, ", ".join(part for part in (packing, encoding) if part)


def read_text(path) -> str:
    """A text file's contents, or one clear error: missing, a folder, binary, empty.

    Packed (gzip, zip) and UTF-16 or Latin-1 files are read too (see `decode`).
    """
    return file_text(path)[0]


def _tomllib():
    try:
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    return tomllib


def read_toml(path, what: str = "config", *, if_empty: str = "leave it out for the defaults") -> dict:
    """A TOML file as a dict, or one clear error naming the file (missing, empty, not UTF-8, bad
    TOML). A file of comments alone is read, as an empty table: someone wrote it. An empty file
    is told `if_empty`: to be left out, for a file the command can do without (a config); what it
    needs, for one it cannot (a sweep)."""
    tomllib = _tomllib()
    path = input_path(path, f"{what} file")
    raw = read_bytes(path, f"{what} file", MAX_CONFIG_BYTES)
    mark = 3 if raw.startswith(b"\xef\xbb\xbf") else 0  # a byte-order mark, as Windows editors save UTF-8
    try:
        text = raw[mark:].decode("utf-8")
    except UnicodeDecodeError as exc:
        raise HybridtrackError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start + mark})") from None
    if not text.strip():  # a write cut short, or `> run.toml` by mistake: it had run the defaults unsaid
        raise HybridtrackError(f"{path}: the {what} file is empty; {if_empty}")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise HybridtrackError(f"{path}: not valid TOML: {exc}") from None


def write_toml(data: dict, path) -> Path:
    """Write a dict as TOML, creating folders; `read_toml` reads it back equal."""
    import tomli_w

    from ..outputs import claim, removing_empty_folders, write

    with removing_empty_folders():  # a write that fails leaves no folder it made
        path, = claim([path])
        write(path, lambda target: target.write_text(tomli_w.dumps(data), encoding="utf-8"))
    return path
