"""``hybridtrack faults``: the fault library, each scenario through the shared safety check."""

from __future__ import annotations

import argparse

from ..errors import HybridtrackError
from .base import command


def _faults_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("action", choices=("list", "run"), help="list the scenarios, or run one (or all)")
    parser.add_argument("name", nargs="?", help="run: a scenario's name, or 'all'")
    parser.add_argument("--site", help="run it at this built-in site instead of the scenario's own")
    parser.add_argument("--markdown", action="store_true", help="print the table as Markdown")


@command("faults", "the fault library: list the scenarios, or run them through the safety check",
         _faults_arguments)
def _faults(args: argparse.Namespace) -> int:
    import pandas as pd

    from ..faults import SCENARIOS, run_scenario

    if args.action == "list":
        given = [what for what, value in ((f"a scenario's name ({args.name!r})", args.name), ("--site", args.site),
                                          ("--markdown", args.markdown)) if value not in (None, False)]
        if given:  # they had been dropped without a word
            raise HybridtrackError(f"{' and '.join(given)} {'goes' if len(given) == 1 else 'go'} with faults run, "
                                   "not faults list")
        width = max(map(len, SCENARIOS))  # 'encoder-frozen-overnight-gust' had run into its description
        for scenario in SCENARIOS.values():
            print(f"{scenario.name:{width}s}  {scenario.description}")
        return 0
    if not args.name:
        raise HybridtrackError("faults run needs a scenario's name, or 'all'")
    names = list(SCENARIOS) if args.name == "all" else [args.name]
    rows = []
    for name in names:
        outcome = run_scenario(name, args.site)
        rows.append(outcome.row())
        if len(names) > 1:
            print(f"{name}: {'safe' if outcome.safe else 'UNSAFE'}", flush=True)
    if args.markdown:
        print("| " + " | ".join(rows[0]) + " |")
        print("|" + "---|" * len(rows[0]))
        for row in rows:
            print("| " + " | ".join(str(value) for value in row.values()) + " |")
    else:
        print(pd.DataFrame(rows).set_index("scenario").to_string())
    unsafe = [row["scenario"] for row in rows if row["safe"] != "yes"]
    if unsafe:
        print(f"unsafe: {', '.join(unsafe)}")
    return 0 if not unsafe else 1
