"""The one exception type for mistakes a user can make."""

from __future__ import annotations


class HybridtrackError(ValueError):
    """A problem with user input: a file, column, unit, timestamp, site or parameter.

    The message is a single line that says what is wrong and where (file, row, column),
    so that the command-line interface can print it as it is and exit with status 2.
    """
