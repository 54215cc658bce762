"""Work shared inside a reuse block: computed once per key, the same numbers, never shared between runs' arrays."""

import contextvars
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd
import pytest

from hybridtrack.reuse import Content, Same, reuse_work, same_object, shared


def counted():
    calls = []

    def compute():
        calls.append(1)
        return np.arange(4.0)

    return calls, compute


def test_a_piece_is_computed_once_per_key_inside_the_block_and_every_time_outside():
    calls, compute = counted()
    frame = pd.DataFrame({"dni": [1.0, 2.0]})
    with reuse_work():
        for _ in range(3):
            np.testing.assert_array_equal(shared(("piece", Same(frame), 1.5), compute), np.arange(4.0))
        assert len(calls) == 1
        shared(("piece", Same(frame), 2.5), compute)  # another scalar: another piece
        shared(("piece", Same(frame.copy()), 1.5), compute)  # an equal frame that is not the same object
        assert len(calls) == 3
        with reuse_work():  # a block inside shares the outer memory
            shared(("piece", Same(frame), 1.5), compute)
        assert len(calls) == 3
    shared(("piece", Same(frame), 1.5), compute)
    shared(("piece", Same(frame), 1.5), compute)
    assert len(calls) == 5


def test_arrays_are_matched_by_their_values_and_handed_out_read_only():
    calls, compute = counted()
    with reuse_work():
        first = shared(("piece", Content(np.linspace(0.0, 1.0, 11))), compute)
        with pytest.raises(ValueError, match="read-only"):
            first[0] = 99.0  # a run that writes into what it was handed
        second = shared(("piece", Content(np.linspace(0.0, 1.0, 11))), compute)
        shared(("piece", Content(np.linspace(0.0, 1.0, 12))), compute)
        shared(("piece", Content(np.linspace(0.0, 1.0, 11).astype(np.float32))), compute)
    assert second[0] == 0.0 and len(calls) == 3


def test_arrays_that_differ_where_the_hash_does_not_look_are_different_keys():
    """`Content` hashes a sample of the values; two years' scans that differ in one unsampled value
    must still be two pieces, and a write into the caller's array after the look-up must not
    change the key it made."""
    calls, compute = counted()
    minutes = np.arange(525_600, dtype=float)
    other = minutes.copy()
    other[1] += 0.5  # the sample takes every 513th value: not this one
    with reuse_work():
        shared(("piece", Content(minutes)), compute)
        minutes[:] = -1.0  # the caller reuses its array
        shared(("piece", Content(other)), compute)
        shared(("piece", Content(np.arange(525_600, dtype=float))), compute)
    assert len(calls) == 2


def test_frames_tuples_and_dicts_come_back_as_copies_or_read_only():
    frame = pd.DataFrame({"a": [1.0, 2.0]})
    with reuse_work():
        got = shared(("x",), lambda: (frame, {"alarm": np.zeros(2)}, "text"))
        got[0].loc[0, "a"] = 5.0
        with pytest.raises(ValueError, match="read-only"):
            got[1]["alarm"][0] = 5.0
        again = shared(("x",), lambda: None)
    assert again[0].loc[0, "a"] == 1.0 and again[1]["alarm"][0] == 0.0 and again[2] == "text"


def test_threads_given_a_copy_of_the_context_share_one_memory():
    calls, lock = [], threading.Lock()

    def compute():
        with lock:
            calls.append(1)
        return np.ones(3)

    with reuse_work():
        shared(("piece",), compute)
        contexts = [contextvars.copy_context() for _ in range(16)]  # copied here, run there
        with ThreadPoolExecutor(4) as pool:
            answers = list(pool.map(lambda context: context.run(shared, ("piece",), compute), contexts))
    assert len(calls) == 1 and all((a == 1.0).all() for a in answers)


def test_the_memory_keeps_the_pieces_used_most_recently():
    """A field whose collectors each have their own clock adds pieces with every run: they must not
    pile up, while the pieces every run uses stay."""
    calls, compute = counted()
    with reuse_work(entries=3):
        for run in range(10):
            shared(("every run's",), compute)
            shared(("this run's", run), compute)
        assert len(calls) == 11  # the shared piece once, each run's own once
        shared(("this run's", 9), compute)
        shared(("this run's", 8), compute)
        assert len(calls) == 11
        shared(("this run's", 0), compute)  # long forgotten
        assert len(calls) == 12


def test_a_piece_without_a_key_is_computed_every_time_and_not_kept():
    """A heliostat's own geometry (no key) would only push the field's shared pieces out of the memory."""
    calls, compute = counted()
    with reuse_work(entries=2):
        shared(("field's",), compute)
        shared(None, compute)
        shared(None, compute)
        assert len(calls) == 3
        shared(("field's",), compute)  # still kept
        assert len(calls) == 3


def test_the_same_object_is_handed_to_every_request_for_it():
    """A frame the runs key their own pieces on by identity (a field's clear day before the run) is
    handed as the very object, computed once."""
    calls = []

    def day():
        calls.append(1)
        return pd.DataFrame({"dni": [800.0, 810.0]})

    with reuse_work():
        first, second = same_object(("clear day", 1), day), same_object(("clear day", 1), day)
        other = same_object(("clear day", 2), day)
    assert first is second and other is not first and len(calls) == 2
    assert same_object(("clear day", 1), day) is not first  # outside a block: computed again


def _in_threads(*calls) -> list:
    """Each call on a thread of its own, each in a copy of this context; the threads still running
    after 30 s (a wait that would never end) are left behind as daemons and counted."""
    answers = [None] * len(calls)

    def run(k, context, call):
        answers[k] = context.run(call)

    threads = [threading.Thread(target=run, args=(k, contextvars.copy_context(), call), daemon=True)
               for k, call in enumerate(calls)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=30)
    assert not any(thread.is_alive() for thread in threads), "a thread still waits"
    return answers


def test_threads_asking_at_once_wait_for_one_computation_and_a_failed_one_is_not_kept():
    calls, started = [], threading.Barrier(4)

    def slow():
        calls.append(1)
        time.sleep(0.2)
        return np.ones(3)

    def ask():
        started.wait()
        return shared(("piece",), slow)

    with reuse_work():
        answers = _in_threads(*[ask] * 4)
        assert len(calls) == 1 and all((a == 1.0).all() for a in answers)

        def failing():
            raise ValueError("no sun")

        with pytest.raises(ValueError, match="no sun"):
            shared(("broken",), failing)
        assert (shared(("broken",), lambda: np.zeros(2)) == 0.0).all()  # computed anew, not waited for


def test_a_piece_that_asks_for_itself_or_for_another_under_way_does_not_wait_forever():
    """A thread computing a piece computes any piece under way that it asks for rather than waiting
    for it: waiting could close a circle (the piece itself, or two threads each computing a piece
    that asks for the other's)."""
    with reuse_work():
        assert _in_threads(lambda: shared(("outer",), lambda: shared(("outer",), lambda: 1.0) + 1.0)) == [2.0]
        assert shared(("outer",), lambda: 0.0) == 2.0  # the outer answer is the one kept

        both_started = threading.Barrier(2)

        def piece(mine, other):
            def compute():
                both_started.wait()  # each is under way before either asks for the other's
                return shared((other,), lambda: np.array([1.0])) + 1.0
            return lambda: shared((mine,), compute)

        answers = _in_threads(piece("a", "b"), piece("b", "a"))
    assert all(float(a[0]) in (2.0, 3.0) for a in answers)  # 3: the other's piece was kept by then
