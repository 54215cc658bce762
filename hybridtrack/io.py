"""Reading user files: tables of readings and cases, with errors that say where."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from .errors import HybridtrackError

__all__ = ["read_table"]


def _text(path: Path) -> str:
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise HybridtrackError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise HybridtrackError(f"{path}: is a folder, not a file") from None
    if b"\x00" in raw[:4096]:
        raise HybridtrackError(f"{path}: looks binary, not a text table")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise HybridtrackError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    if not text.strip():
        raise HybridtrackError(f"{path}: the file is empty")
    return text


def read_table(path) -> pd.DataFrame:
    """A small table from CSV (comma, semicolon or tab) or TOML (``[[case]]`` rows).

    Lines starting with ``#`` in a CSV are comments. Column names are stripped and lowered.
    """
    import io

    path = Path(path)
    text = _text(path)
    if path.suffix.lower() == ".toml":
        try:
            import tomllib
        except ModuleNotFoundError:  # pragma: no cover - Python 3.10
            import tomli as tomllib
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise HybridtrackError(f"{path}: not valid TOML: {exc}") from None
        rows = data.get("case", data.get("cases"))
        if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
            raise HybridtrackError(f"{path}: expected an array of [[case]] tables")
        frame = pd.DataFrame(rows)
    else:
        try:
            frame = pd.read_csv(io.StringIO(text), sep=None, engine="python", comment="#", skipinitialspace=True)
        except (pd.errors.ParserError, pd.errors.EmptyDataError, ValueError) as exc:
            raise HybridtrackError(f"{path}: cannot read as CSV: {str(exc).splitlines()[0]}") from None
    frame.columns = [str(c).strip().lower() for c in frame.columns]
    if frame.empty:
        raise HybridtrackError(f"{path}: the table has no rows")
    frame.attrs["source"] = str(path)
    return frame
