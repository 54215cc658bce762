"""The ``hybridtrack`` command's entry point (and ``python -m hybridtrack``'s).

It loads the command line itself, so that a Ctrl-C while the command's libraries load (pandas,
matplotlib, pvlib: about a second) is one line and the shell's status, as it is once the command
runs, not the traceback of an import; and once the command is done it lets the interpreter end
without one: a Ctrl-C while Dask's workers are shut down at exit had printed a traceback from
a weak reference's callback after every file was written.
"""

from __future__ import annotations

import contextlib
import signal
import sys

#: The shell's status for a run stopped by SIGINT (128 + 2), as `hybridtrack.cli` returns it.
EXIT_INTERRUPTED = 130


def main() -> int:
    """Load and run the command line; return its exit status."""
    try:
        from .cli import main as run
    except KeyboardInterrupt:
        with contextlib.suppress(OSError, ValueError):
            print("\nhybridtrack: interrupted while starting; nothing was done", file=sys.stderr, flush=True)
        return EXIT_INTERRUPTED
    status = run()
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # done: what is left is the interpreter's own clean-up
    return status
