"""``hybridtrack init [DIR]``: a commented run config, a fuzzy config and a rule table to start from."""

from __future__ import annotations

import argparse
import dataclasses
import re
import shlex
from pathlib import Path

from ..errors import HybridtrackError
from ..outputs import claim, write
from .base import add_force_argument, command

RUN, FUZZY, RULES = "run.toml", "fuzzy.toml", "test_site.rules.csv"

#: The published checks of the classifier (docs/physics.md §4), as the example rule table.
PUBLISHED_CHECKS = ((246.0, 27.0, "sunny"), (200.1, 84.6, "cloudy"), (200.1, 93.6, "cloudy"),
                    (143.4, 45.0, "overcast"))


def parameter_notes(cls) -> dict[str, str]:
    """Each parameter's description from a numpydoc ``Parameters`` section, joined on one line."""
    doc = cls.__doc__ or ""
    section = re.search(r"Parameters\n\s*-+\n(.*?)(?:\n\s*\n\s*[A-Z][a-z]+\n\s*-+\n|\Z)", doc, re.S)
    notes, names, text = {}, [], []
    for line in (section.group(1) if section else "").splitlines():
        header = re.match(r"^\s{4}(\w[\w, ]*?)\s*:\s*(.*)$", line)
        if header and not line.startswith(" " * 8):
            for name in names:
                notes[name] = " ".join(text)
            names = [n.strip() for n in header.group(1).split(",")]
            text = [f"({header.group(2).strip()})"] if header.group(2).strip() else []
        elif line.strip():
            text.append(line.strip())
    for name in names:
        notes[name] = " ".join(text)
    return notes


def _value(key: str, value) -> str:
    import tomli_w

    return tomli_w.dumps({key: value}).strip()


def _wrapped(note: str, width: int = 96) -> list[str]:
    import textwrap

    return [f"# {line}" for line in textwrap.wrap(note, width)] if note else []


def commented_run_config() -> str:
    """`SimulationConfig`'s defaults as TOML, each key under its description."""
    from ..simulation import UNREAD, SimulationConfig

    config = SimulationConfig()
    data = config.to_dict()
    lines = ["# hybridtrack run config: the defaults, each with what it means.",
             "# Use it with: hybridtrack simulate ... --config run.toml   (unknown keys are refused)", ""]
    top = parameter_notes(SimulationConfig)
    sections = [f.name for f in dataclasses.fields(config) if dataclasses.is_dataclass(getattr(config, f.name))]
    for name in (f.name for f in dataclasses.fields(config) if f.name not in sections):
        lines += _wrapped(top.get(name, "")) + [_value(name, data[name]), ""]
    for section in sections:
        part = getattr(config, section)
        notes = parameter_notes(type(part))
        lines.append(f"[{section}]")
        for field in dataclasses.fields(part):
            unread = UNREAD.get((section, field.name))
            note = f"Not read by a run (leave it as it is); a run reads {unread}." if unread else \
                notes.get(field.name, "")
            lines += _wrapped(note) + [_value(field.name, data[section][field.name])]
        lines.append("")
    return "\n".join(lines)


def commented_fuzzy_config() -> str:
    """The published classifier as TOML, with a header that explains its parts."""
    import tomli_w

    from ..fuzzy import FuzzyConfig

    header = [
        "# hybridtrack fuzzy sky classifier: the published system (docs/physics.md section 4).",
        "# inputs: raw_range (mA) is mapped linearly onto universe (0-10) and clipped; terms use",
        "#   scikit-fuzzy's parameter order (gaussmf: mean, sigma; trimf: a, b, c; trapmf: a, b, c, d).",
        "# output: the weather score's terms; bands: the score range that names each label.",
        "# rules: one table per rule, input = term, weather = output term (AND = min).",
        "# Use it with: hybridtrack classify --config fuzzy.toml ...; tune it with hybridtrack tune.",
        "",
    ]
    return "\n".join(header) + tomli_w.dumps(FuzzyConfig.default().to_dict())


def example_rule_table() -> str:
    """A rule table of the published checks, run against ``fuzzy.toml`` by pytest."""
    rows = "\n".join(f"{i:g},{v:g},{w}" for i, v, w in PUBLISHED_CHECKS)
    return ("# Expected classifier behaviour, one reading a row (pytest collects test_*.rules.csv files).\n"
            "# Columns: intensity and variation (mA, inside the config's raw ranges), weather, and optionally\n"
            "# score and tolerance. The rows are the published checks of the classifier.\n"
            f"# config: {FUZZY}\n"
            f"intensity,variation,weather\n{rows}\n")


def _init_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("dir", nargs="?", default=".", help="folder to write into (default: here)")
    add_force_argument(parser)


@command("init", "write a commented run config, a fuzzy config and an example rule table to start from",
         _init_arguments)
def _init(args: argparse.Namespace) -> int:
    if not args.dir.strip():  # Path("") is here: ``init "$DIR"`` with DIR unset had written into the current folder
        raise HybridtrackError("DIR is empty: give a folder to write into, or leave it out to write here "
                               "(an unset shell variable?)")
    folder = Path(args.dir)
    files = {RUN: commented_run_config(), FUZZY: commented_fuzzy_config(), RULES: example_rule_table()}
    if folder.exists() and not folder.is_dir():
        raise HybridtrackError(f"{folder} is a file, not a folder")
    claim(folder / name for name in files)
    for name, text in files.items():
        write(folder / name, lambda file, text=text: file.write_text(text, encoding="utf-8"))
    print(f"wrote {', '.join(str(folder / name) for name in files)}")
    print(f"try: hybridtrack simulate --site lanzhou --date 2021-06-21 --config {shlex.quote(str(folder / RUN))}")
    return 0
