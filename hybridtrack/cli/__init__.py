"""The ``hybridtrack`` command line.

Every command has ``--help``. A mistake a user can make (bad file, column, site, date or
parameter) prints one line, ``hybridtrack: error: ...``, and exits with status 2.

Results are written as `hybridtrack.outputs` says: never through a symbolic link, never over an
existing file without ``--force``, and in full even when the reader of the printout has gone
(``| head``).

Each module of this package registers the commands of one concern with `base.command`;
importing them here is what puts them on the command line.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import signal
import sys
import threading
from collections.abc import Iterator, Sequence

from .. import __version__
from ..errors import HybridtrackError
from ..outputs import reader_may_leave, removing_empty_folders, replacing
from . import sun, fuzzy, fuzzyfiles, records, runs, ablate, validate, rules, init, field, sweep, faults  # noqa: F401, I001  (each registers its commands, in this order)
from ..launch import EXIT_INTERRUPTED
from .base import _COMMANDS, _HELP, EXIT_TERMINATED, EXIT_USAGE

__all__ = ["main", "build_parser", "EXIT_USAGE"]


class _StoreOnce(argparse._StoreAction):
    """argparse's store, refusing an option given twice: argparse keeps the last, so ``--site
    lanzhou ... --site nanjing`` (an edited command line, a script's default then the user's) ran
    Nanjing without a word. Options that add up (``--map``, ``--spread``) append instead."""

    def __call__(self, parser, namespace, values, option_string=None):
        given = namespace.__dict__.setdefault("_options_given", {})
        if option_string is not None and self.dest in given:
            parser.error(f"{option_string} is given twice ({given[self.dest]!r}, then {values!r}); give it once")
        given[self.dest] = values
        super().__call__(parser, namespace, values, option_string)


class OneLineParser(argparse.ArgumentParser):
    """argparse's parser, whose refusals are one line (``hybridtrack: error: ...``) and status 2,
    like every other refusal, instead of the usage block and the error; an option that takes one
    value is refused when given twice (`_StoreOnce`)."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        # argparse takes '-1e9' and '-inf' for options, not values (its negative numbers are only
        # '-12' and '-1.5'): '--altitude -1e3' had been refused as '--altitude: expected one argument'
        self._negative_number_matcher = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$|^-(?i:inf|infinity)$")
        self.register("action", None, _StoreOnce)
        self.register("action", "store", _StoreOnce)

    def error(self, message: str):
        command = f"{self.prog}: " if " " in self.prog else ""  # the top parser's name is the error's prefix already
        raise HybridtrackError(f"{command}{message} (see {self.prog} --help)")


def build_parser() -> argparse.ArgumentParser:
    """The parser with every registered command."""
    parser = OneLineParser(
        prog="hybridtrack",
        description="Weather-aware hybrid sun tracking for concentrating solar collectors.",
    )
    parser.add_argument("--version", action="version", version=f"hybridtrack {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, (add_arguments, run) in _COMMANDS.items():
        child = sub.add_parser(name, help=_HELP[name], description=_HELP[name])
        add_arguments(child)
        child.set_defaults(_run=run)
    return parser


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, a batch scheduler's or a container's stop), met as Ctrl-C is: what a
    command was writing is closed or removed, never left half-written."""


@contextlib.contextmanager
def _terminate_as_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM raises `Terminated` in the main thread (elsewhere, where no
    handler may be set, it keeps its default)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, frame):
        raise Terminated()

    previous = signal.signal(signal.SIGTERM, stop)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    args = None
    try:
        with _terminate_as_interrupt(), reader_may_leave():  # --help and --version print here too: a full standard output is one line
            args = build_parser().parse_args(argv)
            _refuse_empty_paths(args)
            _check_zones_and_steps(args)
            with replacing(getattr(args, "force", False)) as replaced, removing_empty_folders():
                status = args._run(args)
                if replaced:
                    print("replaced (--force): " + ", ".join(map(str, replaced)))
                return status
    except BrokenPipeError:  # the reader went away outside the printing (`| head`): not a mistake, just stop
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except HybridtrackError as exc:
        _tell(f"hybridtrack: error: {exc}")
        return EXIT_USAGE
    except KeyboardInterrupt as exc:  # Ctrl-C or SIGTERM: one line, no traceback; the shell's status for the signal
        what = str(exc) or "files already written are left as they are" + (
            " (the finished days in log.partial.parquet and events.partial.csv)" if getattr(args, "stream", False)
            else "")
        stopped = "terminated" if isinstance(exc, Terminated) else "interrupted"
        _tell(f"\nhybridtrack: {stopped}; {what}")
        return EXIT_TERMINATED if isinstance(exc, Terminated) else EXIT_INTERRUPTED
    except OSError as exc:
        name = f" {exc.filename}" if exc.filename else ""
        _tell(f"hybridtrack: error: cannot use{name}: {exc.strerror or exc}")
        return EXIT_USAGE


def _tell(line: str) -> None:
    """The command's last word on standard error, if it can be said: a closed one (``2>&-``) or a
    full one changes nothing of the exit status."""
    if sys.stderr is None:
        return
    with contextlib.suppress(OSError, ValueError):
        print(line, file=sys.stderr, flush=True)


#: The options that name a file or folder to write.
_OUTPUT_OPTIONS = ("out", "csv", "plot", "report", "json")
#: Every option and argument that names a file or folder, to write or to read.
_PATH_OPTIONS = (*_OUTPUT_OPTIONS, "target", "dir", "file", "config", "positions", "source", "labels", "classifier")
#: The options among them that name a file to read: an empty one is no file (the positional
#: arguments are refused as paths that are not there, and init's DIR by init).
_INPUT_OPTIONS = ("config", "positions", "labels", "classifier")


def _refuse_empty_paths(args) -> None:
    """Refuse an output option given an empty path (``--out "$DIR"`` with DIR unset), which would
    otherwise read as no output at all and write nothing without a word; and read a path that
    begins with ``~`` as the shell would have: ``--out=~/run`` reaches the program unexpanded
    (the shell expands ``~`` only at a word's start), and the run had made a folder named ``~``."""
    for name in _PATH_OPTIONS:
        value = getattr(args, name, None)
        if not isinstance(value, str):  # not given, or a flag of the same name (classify --json)
            continue
        if name in _OUTPUT_OPTIONS and not value.strip():
            raise HybridtrackError(f"--{name} is empty: give a file or folder to write (an unset shell variable?)")
        if name in _INPUT_OPTIONS and not value.strip():  # --config '' had run the defaults, seed 0, without a word
            raise HybridtrackError(f"--{name} is empty: give a file to read, or leave --{name} out (an unset shell "
                                   "variable?)")
        setattr(args, name, os.path.expanduser(value))


#: The options that name a time zone.
_ZONE_OPTIONS = ("tz", "site_tz")


def _check_zones_and_steps(args) -> None:
    """Refuse a time zone flag that is empty or no zone, and a step without its unit, by the flag.

    ``--tz ''`` (``--tz "$TZ"`` with TZ unset) had been read as no zone: ``sun --lat --lon --tz ''``
    ran in UTC without a word, and ``--site-tz ''`` was dropped for the file's zone. A zone no one
    knows was refused without naming ``--tz``. A step of a bare number (``--freq 10``) is read by
    pandas as nanoseconds, and had been refused as a step of 10ns needing 10,800,000 GB.
    """
    from ..params import refuse_unitless
    from ..times import check_tz

    for name in _ZONE_OPTIONS:
        value = getattr(args, name, None)
        if not isinstance(value, str):
            continue
        flag = "--" + name.replace("_", "-")
        if not value.strip():
            raise HybridtrackError(f"{flag} is empty: give an IANA time zone such as Asia/Shanghai, or leave {flag} "
                                   "out (an unset shell variable?)")
        check_tz(value, f"{flag}: ")
    freq = getattr(args, "freq", None)
    if isinstance(freq, str):
        refuse_unitless(freq, "--freq: step")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
