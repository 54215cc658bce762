"""Fuzzy systems by file name: ``.fis`` (MATLAB), ``.fcl`` (IEC 61131-7), ``.toml`` (classifier config)."""

from __future__ import annotations

from pathlib import Path

from ..errors import HybridtrackError
from .system import MamdaniSystem

__all__ = ["FORMATS", "read_system", "write_system", "file_format"]

#: File suffixes and what they hold.
FORMATS = {".fis": "MATLAB Fuzzy Logic Toolbox v2", ".fcl": "IEC 61131-7 Fuzzy Control Language",
           ".toml": "hybridtrack sky classifier config"}


def file_format(path) -> str:
    """The suffix of a fuzzy system file, lower case, one of `FORMATS`; else `HybridtrackError`."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise HybridtrackError(f"{path}: unknown fuzzy system format {path.suffix or '(no suffix)'!r}; "
                               f"use {', '.join(FORMATS)}")
    return suffix


def read_system(path, *, resolution=None) -> MamdaniSystem:
    """Read a fuzzy system from a ``.fis``, ``.fcl`` or classifier ``.toml`` file."""
    from ..io.files import input_path

    path = input_path(path, "fuzzy system file")
    suffix = file_format(path)
    if suffix == ".fis":
        from .fis import read_fis_system

        return read_fis_system(path, resolution=resolution)
    if suffix == ".fcl":
        from .fcl import read_fcl

        return read_fcl(path, resolution=resolution)
    from .config import FuzzyConfig

    config = FuzzyConfig.from_toml(path)
    return config.system() if resolution is None else config.replace(resolution=tuple(resolution)).system()


def write_system(system: MamdaniSystem, path) -> Path:
    """Write a system as ``.fis``, ``.fcl`` or (two inputs, one output) classifier ``.toml``."""
    from ..outputs import output_path

    path = output_path(path)
    suffix = file_format(path)
    if suffix == ".fis":
        from .fis import write_fis

        return write_fis(system, path)
    if suffix == ".fcl":
        from .fcl import write_fcl

        return write_fcl(system, path)
    from .system import config_from_system

    return config_from_system(system, where=str(path)).to_toml(path)
