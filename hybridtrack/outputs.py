"""Where results go: never through a symbolic link, never over a file unasked, JSON strictly.

Every function that writes a result file first passes the paths it is about to write to
`claim`, all at once, before anything is written:

* a path that is a symbolic link, or lies in a folder that is one, is refused: a link planted
  in an output folder would send the result somewhere else;
* a path that exists already is replaced only under the current `replacing` policy. The
  command line refuses unless ``--force`` is given, and names the files it would replace (or,
  with ``--force``, the files it replaced); from Python the files are replaced as `open` would,
  unless the call runs inside ``with replacing(False):``.

`write` writes a whole file in a hidden folder beside it and moves it into place only when it
is complete (inside `together`, a result's files all at once), so a failure (a full disk, an
interrupt) leaves no half file and keeps any file it would have replaced; `write_in_place` is for
a file that grows as a run goes (a streamed log). Folders `claim` made are removed again, if still empty, when the command fails
(`removing_empty_folders`).

`strict_json` writes JSON that any parser reads: a missing or non-finite number is ``null``,
never ``NaN`` or ``Infinity``.
"""

from __future__ import annotations

import contextlib
import contextvars
import json
import math
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import numpy as np

from . import params
from .errors import HybridtrackError

__all__ = ["claim", "remove_earlier", "held", "output_folder", "replacing", "removing_empty_folders", "write", "write_in_place", "together", "strict_json",
           "plain_numbers", "reader_may_leave"]

_FORCE: contextvars.ContextVar[bool] = contextvars.ContextVar("hybridtrack_force", default=True)
_REPLACED: contextvars.ContextVar[list | None] = contextvars.ContextVar("hybridtrack_replaced", default=None)
_MADE: contextvars.ContextVar[list | None] = contextvars.ContextVar("hybridtrack_made", default=None)
_GROUP: contextvars.ContextVar[list | None] = contextvars.ContextVar("hybridtrack_group", default=None)


@contextlib.contextmanager
def replacing(force: bool) -> Iterator[list[Path]]:
    """Within the block, existing files are replaced only if `force`; yields the files replaced.

    Parameters
    ----------
    force : bool
        False refuses to write over any existing file (`claim` raises `HybridtrackError`).

    Yields
    ------
    list of Path
        Filled with each existing file `claim` let through, in order.
    """
    replaced: list[Path] = []
    force_token, replaced_token = _FORCE.set(bool(force)), _REPLACED.set(replaced)
    try:
        yield replaced
    finally:
        _FORCE.reset(force_token)
        _REPLACED.reset(replaced_token)


@contextlib.contextmanager
def removing_empty_folders() -> Iterator[None]:
    """Within the block, the folders `claim` makes are removed again if the block fails while they
    are still empty: a command refused after claiming its ``--out``, or a ``save`` refused after
    claiming its folder (a plot of a metric there is not), leaves no empty folder behind. Also a
    decorator, for the API's writers."""
    made: list[Path] = []
    token = _MADE.set(made)
    try:
        yield
    except BaseException:
        for folder in reversed(made):  # the innermost first
            with contextlib.suppress(OSError):  # one that holds anything stays
                folder.rmdir()
        raise
    finally:
        _MADE.reset(token)


def claim(paths: Iterable, *, folders: Iterable = (), earlier: Iterable = ()) -> list[Path]:
    """Check the files about to be written, all before any is, and make their folders.

    Parameters
    ----------
    paths : iterable of path
        Files to write.
    folders : iterable of path
        Folders a run writes as one (a streamed run's segments), claimed as a file is: one that
        exists is replaced only as an existing file would be, and is named once.
    earlier : iterable of path
        Files this write leaves out that another writes (a log not kept, a plot not drawn): one
        there is an earlier write's, which would be read as this one's. Such a regular file is
        replaced as an existing file would be: refused under ``replacing(False)``, else removed
        by `remove_earlier` once the new files are in place.

    Returns
    -------
    list of Path

    Raises
    ------
    HybridtrackError
        If a path or its folder is a symbolic link, a path is a folder, or files exist and
        the policy (`replacing`) does not allow replacing them; the message names them all.
    """
    paths = [output_path(p) for p in paths]
    for path in paths:
        try:
            _refuse_links_and_folders(path)
        except OSError as exc:  # a name longer than the file system takes, a folder that cannot be read
            raise HybridtrackError(f"{path}: cannot write there ({exc.strerror or exc})") from None
    folders = [output_path(folder) for folder in folders]
    for folder in folders:
        if folder.is_symlink():
            raise HybridtrackError(f"{folder} is a symbolic link; results are never written through one "
                                   "(remove it or write elsewhere)")
    existing = [path for path in (*paths, *folders) if path.exists()]
    refused = existing + earlier_files(earlier)
    if refused and not _FORCE.get():
        some = len(refused) > 1
        raise HybridtrackError(f"would replace {len(refused)} existing file{'s' if some else ''}: "
                               f"{', '.join(map(str, refused))}; give --force to replace {'them' if some else 'it'}, "
                               "or write elsewhere")
    replaced = _REPLACED.get()  # the command line names what it removes itself (`cli.base.leaving_out`)
    if replaced is not None:
        replaced.extend(p for p in existing if p not in replaced)
    for folder in dict.fromkeys(path.parent for path in paths):
        _refuse_held(folder)
        _make_folder(folder)
        _refuse_unwritable(folder, [path for path in paths if path.parent == folder])
    return paths


def earlier_files(paths: Iterable) -> list[Path]:
    """The regular files among `paths` (`claim`'s ``earlier``); a folder or a symbolic link of such
    a name is nothing a write made, and is left as it is."""
    return [path for path in map(output_path, paths) if path.is_file() and not path.is_symlink()]


def remove_earlier(paths: Iterable) -> list[Path]:
    """Remove `earlier_files` of `paths`, once a write's own files are in place; return them.

    Raises
    ------
    HybridtrackError
        If one cannot be removed: it names the file, and says the files beside it are new.
    """
    removed = earlier_files(paths)
    for path in removed:
        try:
            path.unlink(missing_ok=True)
        except OSError as exc:
            raise HybridtrackError(f"{path}: from an earlier run, and cannot be removed ({exc.strerror or exc}); "
                                   "the results beside it are this run's") from None
    return removed


def _refuse_unwritable(folder: Path, paths: list[Path]) -> None:
    """Refuse a folder that takes no new file (read-only, no permission), unless each of `paths`
    can be written where it is (`write` rewrites such a file in place): found only when the
    results were written, a sweep's finished runs were lost with the error."""
    try:
        descriptor, probe = tempfile.mkstemp(prefix=".hybridtrack-probe-", dir=folder)
    except OSError as exc:
        if all(p.exists() and (not p.is_file() or os.access(p, os.W_OK)) for p in paths):
            return
        raise HybridtrackError(f"{folder}: cannot write there ({exc.strerror or exc})") from None
    os.close(descriptor)
    with contextlib.suppress(OSError):
        os.unlink(probe)


def _refuse_held(folder: Path) -> None:
    """Refuse a folder a streamed run is writing now (`held`): a run with --force had written its
    files there, and the streamed run then replaced them with its own as it finished."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        return
    try:
        descriptor = os.open(folder / LOCK_NAME, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError:  # no lock there (or none that could be one): nobody holds the folder
        return
    try:
        _lock(descriptor, folder, fcntl.LOCK_SH)
    finally:
        os.close(descriptor)


def _lock(descriptor: int, folder, mode: int) -> None:
    """Take `folder`'s lock (`held`) in `mode`, shared or exclusive, without waiting; refuse the
    folder if another run holds it."""
    import fcntl

    try:
        fcntl.flock(descriptor, mode | fcntl.LOCK_NB)
    except BlockingIOError:
        raise HybridtrackError(f"{folder}: another run is writing there now; wait for it to finish, or write "
                               "elsewhere") from None


def _refuse_links_and_folders(path: Path) -> None:
    """Refuse a file to write that is a folder, or that is or lies in a symbolic link."""
    for candidate in (path.parent, path):
        if candidate.is_symlink():
            raise HybridtrackError(f"{candidate} is a symbolic link; results are never written through one "
                                   "(remove it or write elsewhere)")
    if path.is_dir():
        raise HybridtrackError(f"{path} is a folder; a result file would go there")


def output_folder(folder) -> Path:
    """`folder` as a Path, refused unless it is a non-empty path: ``save(None)`` raised a
    TypeError, and ``save("")`` wrote into the working folder (the command line refuses an empty
    ``--out`` too)."""
    return output_path(folder, "the output folder")


def output_path(value, what: str = "a file to write") -> Path:
    """`value` as a Path to write (`params.path`: ``~`` expanded; no NUL, nothing empty)."""
    return params.path(value, what)


#: The hidden file a run that writes a folder over its whole span holds locked (`held`).
LOCK_NAME = ".hybridtrack.lock"
#: Times `held` opens the lock file again when the run that held it let it go meanwhile.
LOCK_ATTEMPTS = 5


@contextlib.contextmanager
def held(folder) -> Iterator[None]:
    """Hold `folder` for this run alone while the block runs (call it after `claim`).

    A run whose files grow as it goes (a streamed log) is refused a folder another run is
    writing now: two streamed runs into one folder had appended to one Parquet file and left it
    unreadable, and the later one removed the first one's summary. The lock is the operating
    system's (``flock``) on a hidden file, so a run killed outright holds nothing; where there is
    no ``flock`` (Windows) the folder is not held.
    """
    try:
        import fcntl  # noqa: F401 - only POSIX has it; `_locked_file` takes the lock with it
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    path = Path(folder) / LOCK_NAME
    descriptor = _locked_file(path, folder)
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            path.unlink()
        os.close(descriptor)


def _locked_file(path: Path, folder) -> int:
    """An open descriptor of the lock file at `path`, locked for this run alone. A run that ends
    removes its lock file: one that had opened that file just before then would lock a file no
    longer in the folder, beside a third run that locks the new one. So the lock taken must be on
    the file that is at `path` afterwards; if it is not, the folder was just let go: open it again."""
    import fcntl

    for _ in range(LOCK_ATTEMPTS):
        try:
            descriptor = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise HybridtrackError(f"{path}: cannot write ({exc.strerror or exc})") from None
        try:
            _lock(descriptor, folder, fcntl.LOCK_EX)
            if _same_file(descriptor, path):
                return descriptor
        except BaseException:
            os.close(descriptor)
            raise
        os.close(descriptor)
    raise HybridtrackError(f"{folder}: other runs keep taking and letting go of the folder; write elsewhere")


def _same_file(descriptor: int, path: Path) -> bool:
    """Whether `descriptor` is the file now at `path`."""
    try:
        here = os.stat(path)
    except OSError:
        return False
    mine = os.fstat(descriptor)
    return (mine.st_dev, mine.st_ino) == (here.st_dev, here.st_ino)


def _make_folder(folder: Path) -> None:
    if folder.exists() and not folder.is_dir():
        raise HybridtrackError(f"{folder} is a file, not a folder")
    missing = [candidate for candidate in (folder, *folder.parents) if not candidate.exists()][::-1]
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise HybridtrackError(f"{folder}: cannot make the folder ({exc.strerror or exc})") from None
    made = _MADE.get()
    if made is not None:
        made.extend(missing)


def write(path, writer: Callable[[Path], object]) -> Path:
    """Write the whole file `path` with ``writer(partial)``, where ``partial`` is a new file of the
    same name in a hidden folder beside it, moved to `path` once `writer` has returned (inside
    `together`, once every file of the block is written).

    A failure (a full disk, an interrupt) removes the partial file: no half-written `path` is left,
    and a file `path` held already is kept. The new file takes an existing one's permissions; its
    name is the target's own, so a name at the length limit fits and a packed file (``.zip``,
    ``.gz``) names its member after it. A path that is not a regular file (a device) is written
    in place, and so is an existing file that may be rewritten in a folder that takes no new file.

    Raises
    ------
    HybridtrackError
        If writing fails with an `OSError` (a full disk, no permission); it names `path`.
    """
    path = output_path(path)
    if path.exists() and not path.is_file():
        return write_in_place(path, writer)
    try:
        staging = Path(tempfile.mkdtemp(prefix=".hybridtrack-", dir=path.parent))
    except PermissionError:
        if path.is_file() and os.access(path, os.W_OK):
            return write_in_place(path, writer)
        raise HybridtrackError(f"{path}: cannot write (its folder takes no new file)") from None
    except OSError as exc:
        raise HybridtrackError(f"{path}: cannot write ({exc.strerror or exc})") from None
    partial, group = staging / path.name, _GROUP.get()
    try:
        with _naming(path):
            if path.exists():
                partial.touch()
                shutil.copymode(path, partial)
            writer(partial)
            if group is None:
                os.replace(partial, path)
            else:
                group.append((partial, path))
                staging = None  # moved, or removed, when the group ends
    finally:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
    return path


@contextlib.contextmanager
def together() -> Iterator[None]:
    """Within the block, the files `write` writes are moved into place together when the block
    ends without an error, and none of them is if it fails: a result's files are all of one run
    (a failed ``--force`` run leaves the earlier run's files whole, not half replaced)."""
    pending: list[tuple[Path, Path]] = []
    token = _GROUP.set(pending)
    try:
        yield
        for partial, path in pending:
            with _naming(path):
                os.replace(partial, path)
    finally:
        _GROUP.reset(token)
        for partial, _ in pending:
            shutil.rmtree(partial.parent, ignore_errors=True)


def write_in_place(path, writer: Callable[[Path], object]) -> Path:
    """Call ``writer(path)`` on `path` itself, for a file that grows as a run goes (a streamed log);
    a failure to write becomes a `HybridtrackError` that names `path`."""
    path = output_path(path)
    with _naming(path):
        writer(path)
    return path


@contextlib.contextmanager
def _naming(path: Path) -> Iterator[None]:
    """An `OSError` in the block becomes a one-line `HybridtrackError` naming `path`."""
    try:
        yield
    except OSError as exc:
        raise HybridtrackError(f"{path}: cannot write ({exc.strerror or exc})") from None


def plain_numbers(value):
    """`value` with numpy scalars as Python numbers and every NaN or infinity as None."""
    if isinstance(value, dict):
        return {key: plain_numbers(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain_numbers(item) for item in value]
    if isinstance(value, np.ndarray):
        return plain_numbers(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def strict_json(value, **options) -> str:
    """JSON text with ``null`` for a missing or non-finite number; `options` go to `json.dumps`."""
    return json.dumps(plain_numbers(value), allow_nan=False, **options)


class _PipeSafe:
    """A text stream that, once its reader has gone, discards what is written instead of raising.
    Any other failure to write (a full disk) is remembered, and what follows is discarded too, so
    that the command still writes its files; `reader_may_leave` then ends it as a
    `HybridtrackError` naming standard output."""

    def __init__(self, stream):
        self._stream = stream
        self.failure: OSError | None = None

    def _discard(self) -> None:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), self._stream.fileno())

    def _failed(self, exc: OSError) -> None:
        self.failure = self.failure or exc
        self._discard()  # what is left in the buffer would fail again at exit, outside the one line

    def error(self) -> HybridtrackError:
        """The one line for the failure remembered."""
        return HybridtrackError(f"standard output: cannot write ({self.failure.strerror or self.failure})")

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._discard()
        except OSError as exc:
            self._failed(exc)
        return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._discard()
        except OSError as exc:
            self._failed(exc)

    def __getattr__(self, name):
        return getattr(self._stream, name)


class _Unheard:
    """Standard error that may not be written (closed, on a full disk, its reader gone): what
    fails to go there is dropped, since there is nowhere left to say so, and the run goes on."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except (OSError, ValueError):
            self._silence()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except (OSError, ValueError):
            self._silence()

    def _silence(self) -> None:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), self._stream.fileno())  # nothing fails again at exit

    def __getattr__(self, name):
        return getattr(self._stream, name)


@contextlib.contextmanager
def reader_may_leave() -> Iterator[None]:
    """Within the block, a closed standard output (``| head``) ends the printing, not the work:
    the command goes on and writes its files. A standard output that cannot be written (a full
    disk) ends the printing too; the command goes on, and the block then ends in a
    `HybridtrackError` naming standard output."""
    original, errors = sys.stdout, sys.stderr
    # a standard output or error closed before the start (``>&-``, ``2>&-``) is None: what is
    # printed there goes nowhere, as after a reader that left; a progress bar on a closed or full
    # standard error had ended a streamed run or a field with an AttributeError or OSError
    sinks = [open(os.devnull, "w") for stream in (original, errors) if stream is None]
    guarded = sys.stdout = _PipeSafe(original if original is not None else sinks[0])
    sys.stderr = _Unheard(errors if errors is not None else sinks[-1])
    try:
        yield
        guarded.flush()
    except SystemExit:  # --help and --version end so, printed or not
        guarded.flush()
        if guarded.failure is None:
            raise
    finally:
        sys.stdout, sys.stderr = original, errors
        for sink in sinks:
            sink.close()
    if guarded.failure is not None:  # the command ran and wrote its files; what it printed was lost
        raise guarded.error()
