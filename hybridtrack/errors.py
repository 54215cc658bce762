"""The one exception type for mistakes a user can make."""

from __future__ import annotations


class HybridtrackError(ValueError):
    """A problem with user input: a file, column, unit, timestamp, site or parameter.

    The message is a single line that says what is wrong and where (file, row, column),
    so that the command-line interface can print it as it is and exit with status 2.
    """


def blamed(check, given: dict, error: str) -> list:
    """The keys of `given` whose values ``check(given)``'s refusal, `error`, came from.

    Parameters
    ----------
    check : callable
        Takes a dict of some of `given`'s items (the others left at their defaults) and raises
        `HybridtrackError` to refuse them.
    given : dict
        The values given (flags, a sweep's grid values), by key.
    error : str
        The message of ``check(given)``'s refusal.

    Returns
    -------
    list
        The keys whose value alone is refused with `error`; else the keys without which `given`
        is not refused with `error` (values refused only together are each named); none if
        `check` refuses with `error` even without any of `given` (the refusal is not theirs).
    """

    def refusal(values: dict) -> str | None:
        try:
            check(values)
        except HybridtrackError as exc:
            return str(exc)
        return None

    if refusal({}) == error:
        return []
    alone = [key for key in given if refusal({key: given[key]}) == error]
    return alone or [key for key in given if refusal({k: v for k, v in given.items() if k != key}) != error]


def quoted_cut(text: str, longest: int) -> str:
    """`text` quoted as a message shows it: cut to its first 20 characters, with its length, when
    longer than `longest` (a corrupted cell or header of millions of characters)."""
    return repr(text) if len(text) <= longest else f"{text[:20]!r}... ({len(text):,} characters)"
