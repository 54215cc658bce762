"""Work that runs on one weather frame share, done once inside a `reuse_work` block.

A field's collectors stand under one sky. The true sun where it may be up, the light in the sun
sensor's view (its clear sky and circumsolar light included), the controller's clock and the sun its plan computes from that clock
are the same for every collector that shares the frame, the site, the field controller's clock
and its sun model; only the mount, the sensor's own noise and what the controller does with them
differ. Inside ``with reuse_work():`` each such piece is computed by the first run that asks for it
and handed to every later run that asks with the same inputs.

A request names its inputs in a key. Scalars are compared by value; a frame or an index by identity
(`Same`), since the runs of a field are handed the same frame object; an array by its values
(`Content`: a copy, a hash of a sample, and a byte-for-byte compare where the hashes match). Every request gets read-only views of the
answer's arrays and its own copy of its frames, so a run that wrote into one could not change another's.
The memory is shared by the threads of a field (`contextvars.copy_context`) and guarded by a lock;
it keeps the pieces used most recently (`ENTRIES`) and is dropped when the block ends.
"""

from __future__ import annotations

import threading
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Callable, Iterator, TypeVar

import numpy as np
import pandas as pd

from .sun import reuse_positions

__all__ = ["Content", "Same", "reuse_work", "shared", "same_object", "ENTRIES"]

T = TypeVar("T")
#: Pieces a `reuse_work` block keeps: the ones every run shares are used by each run and stay (ten
#: for a field of rows or troughs on one axis line, and some ten small ones of the clear day before
#: the run); a field whose collectors each have their own clock adds five per run (its plan and
#: what follows from it), which must not pile up (a year's plan is some 40 MB) but only outlive
#: the runs on the other threads.
ENTRIES = 32
_MEMORY: ContextVar[tuple[threading.Lock, dict, int, dict] | None] = ContextVar("hybridtrack_reuse_work", default=None)


class Same:
    """A key part that matches only the very same object (a frame, an index); it holds the object,
    so its identity cannot pass to another while the memory lasts."""

    __slots__ = ("value",)

    def __init__(self, value) -> None:
        self.value = value

    def __eq__(self, other) -> bool:
        return isinstance(other, Same) and other.value is self.value

    def __hash__(self) -> int:
        return id(self.value)


@contextmanager
def reuse_work(entries: int = ENTRIES) -> Iterator[None]:
    """Within this block, `shared` computes each piece once per key, keeping the `entries` pieces
    used most recently, and `hybridtrack.sun.solar_position` answers from its own memory
    (`hybridtrack.sun.reuse_positions`). A block inside another shares the outer block's memory."""
    if _MEMORY.get() is not None:
        yield
        return
    token = _MEMORY.set((threading.Lock(), {}, max(int(entries), 1), {}))
    try:
        with reuse_positions():
            yield
    finally:
        _MEMORY.reset(token)


def shared(key: tuple | None, compute: Callable[[], T]) -> T:
    """``compute()``, or its earlier answer for the same `key` inside a `reuse_work` block; a key
    of None is a piece no other run will ask for (`hybridtrack.mounting.geometry_key`), computed
    and not kept.

    A thread that asks for a piece another thread is computing waits for that answer rather than
    computing it too (a field's threads start together and ask for the same pieces at once); if
    that computation fails, the waiting thread computes the piece itself. A thread that is itself
    computing a piece never waits (it computes the other piece too): a piece whose computation
    asks for another, or for itself, cannot close a circle of threads waiting on each other.
    """
    memory = _MEMORY.get()
    if memory is None or key is None:
        return compute()
    lock, answers, entries, computing = memory
    with lock:
        if key in answers:
            answers[key] = answers.pop(key)  # the most recently used last
            return _handed(answers[key])
        underway = computing.get(key)
        if underway is None:
            computing[key] = done = threading.Event()
    if underway is None:
        return _compute_and_keep(key, compute, memory, done)
    if _BUSY.depth:
        return compute()
    underway.wait()
    return shared(key, compute)  # found now, unless that computation failed


class _Held:
    """An answer `_handed` passes on as it is (`same_object`)."""

    __slots__ = ("value",)

    def __init__(self, value) -> None:
        self.value = value


def same_object(key: tuple, compute: Callable[[], T]) -> T:
    """`shared`, handing every request the very object computed, not a copy: for a frame the runs
    only read and key their own shared pieces on by identity (`Same`), as a field's runs do the
    field's frame (the clear day before the run, `hybridtrack.commissioning.clear_day`)."""
    return shared(key, lambda: _Held(compute())).value


class _Busy(threading.local):
    """How many pieces this thread is computing (`shared`), one inside another."""

    depth = 0


_BUSY = _Busy()


def _compute_and_keep(key: tuple, compute: Callable[[], T], memory: tuple, done: threading.Event) -> T:
    """`compute` a piece this thread has marked as under way, keep it, and wake those waiting."""
    lock, answers, entries, computing = memory
    _BUSY.depth += 1
    try:
        answer = compute()
        with lock:
            answers[key] = answer
            for oldest in list(answers)[:-entries]:
                del answers[oldest]
            return _handed(answer)
    finally:
        _BUSY.depth -= 1
        with lock:
            del computing[key]
        done.set()


def _handed(answer):
    """What a request gets, so that no run can write into another's: a read-only view of each of
    the answer's arrays (a write raises; a copy of a year's array took a millisecond, some 35 ms
    a Fresnel row-year), a copy of each frame (in tuples and dicts too); an index, a number or a
    string as it is."""
    if isinstance(answer, np.ndarray):
        view = answer.view()
        view.flags.writeable = False
        return view
    if isinstance(answer, (pd.DataFrame, pd.Series)):
        return answer.copy()
    if isinstance(answer, tuple):
        return tuple(_handed(part) for part in answer)
    if isinstance(answer, dict):
        return {key: _handed(value) for key, value in answer.items()}
    return answer


class Content:
    """A key part that matches an array of the same shape, type and bytes. When the key is first
    looked up (outside a `reuse_work` block it never is) it takes a copy of the values, so that
    a later write into the caller's array cannot change the key, and hashes a sample of them;
    keys whose hashes match compare their copies byte for byte. A year's scans (4 MB) cost
    0.8 ms so, where a digest of all their bytes (BLAKE2) took 6 ms, twice a collector."""

    __slots__ = ("_values", "_kept", "_hash")

    def __init__(self, values) -> None:
        self._values, self._kept, self._hash = values, None, None

    def _bytes(self) -> np.ndarray:
        """The kept copy's bytes, as 8-byte words where they divide evenly (a faster compare)."""
        if self._kept is None:
            kept = np.array(self._values, order="C")
            raw = kept.reshape(-1).view(np.uint8)
            self._kept = (kept.shape, kept.dtype.str, raw.view(np.uint64) if raw.size % 8 == 0 else raw)
            self._values = None
        return self._kept[2]

    def __eq__(self, other) -> bool:
        if not isinstance(other, Content):
            return False
        mine, theirs = self._bytes(), other._bytes()  # of one type where shape and type agree
        return self._kept[:2] == other._kept[:2] and np.array_equal(mine, theirs)

    def __hash__(self) -> int:
        if self._hash is None:
            raw = self._bytes()
            sample = raw[::max(1, raw.size // 1024)]
            self._hash = hash((*self._kept[:2], sample.tobytes(), raw[-1:].tobytes()))
        return self._hash
