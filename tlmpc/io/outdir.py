"""Atomic output directories: all artifacts appear together, or none do.

Artifacts are written into a fresh temporary directory beside ``OUT`` (same file system, so
the final rename is atomic) and swapped into place only when every one was written.  A failed
or interrupted run removes its temporary directory and leaves ``OUT`` exactly as it was.

Safety rules, each of which guards a way user data was once lost:

* A directory is a tlmpc output only when it holds the marker file :data:`MARKER` (written by
  tlmpc into every output); file names are never used to guess.
* One run at a time per ``OUT``: a lock file beside it (``.OUT.tlmpc-lock``, removed when the
  run ends) makes a second run stop with U032 instead of racing.
* Temporary folders have unique names (``.OUT.tlmpc-new-XXXX``, ``.OUT.tlmpc-old-XXXX``); those
  left by a killed run are cleaned up by the next run (an ``-old`` one is restored when ``OUT``
  itself is missing, since it is the previous output).
* The swap is one ``renameat2(RENAME_EXCHANGE)`` on Linux; elsewhere two renames with SIGINT,
  SIGTERM and SIGHUP deferred in between, so Ctrl-C cannot strand ``OUT`` half-way.
* A signal that lands in the ``finally`` removing the lock or the staging folder, before the
  removal, cannot strand them either: both are on record from the moment they exist, and the
  command line removes what is still on record once its run is over.
* ``-o`` must not be a symbolic link or anything but a directory; files written by ``export -o``
  and ``plot`` must be regular files (or not exist yet).
* Every operating-system error on the output path becomes a U033 diagnostic with a hint.
* Directories and files get the usual permissions (``0777``/``0666`` minus the umask).
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import signal
import stat
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

from tlmpc.base import settled
from tlmpc.base.errors import UsageError, error
from tlmpc.io.artifacts import ARTIFACT_SCHEMAS, artifact_pieces, dumps

#: The marker file every output directory holds; its first line starts with MARKER_FORMAT.
MARKER = ".tlmpc-output"
MARKER_FORMAT = "tlmpc.io.outdir/"
_MARKER_TEXT = MARKER_FORMAT + "1\n"

#: Every file name ``tlmpc compile`` may write (used by ``--force`` and documentation only).
KNOWN_ARTIFACTS = frozenset({*ARTIFACT_SCHEMAS, "automaton.hoa", "plan.png", "plan.svg"})
#: What tlmpc itself writes into an output: its artifacts, its marker, ``tlmpc view``'s page.
_OWN_NAMES = frozenset({*KNOWN_ARTIFACTS, MARKER, "view.html"})


def foreign_entries(out: Path) -> list[str]:
    """The entries of the tlmpc output ``out`` that tlmpc did not write (a note, a log the user
    put there): replacing the output whole would delete them."""
    try:
        return sorted(entry.name for entry in out.iterdir() if entry.name not in _OWN_NAMES)
    except OSError:
        return []


def _holds_foreign(out: Path, names: list[str]) -> UsageError:
    shown = ", ".join(names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5 else "")
    return UsageError(
        error(
            "U012",
            f"{out} is a tlmpc output that also holds files tlmpc did not write ({shown}); "
            "replacing it would delete them",
            hint="move them out of it, or pass --force to replace the artifacts one by one "
            "and keep them",
            file=str(out),
        )
    )


_HINTS = {
    errno.EACCES: "you have no permission to write there; choose another -o",
    errno.EPERM: "the operation is not permitted there; choose another -o",
    errno.EROFS: "the file system is read-only; choose another -o",
    errno.ENOSPC: "the disk is full; free some space or choose another -o",
    errno.EDQUOT: "your disk quota is exhausted; free some space or choose another -o",
    errno.EXDEV: "OUT is on another file system than its parent (a mount point?); "
    "choose a directory inside it",
    errno.EBUSY: "OUT is busy (a mount point?); choose a directory inside it",
    errno.ENAMETOOLONG: "the path is too long; choose a shorter -o",
    errno.ENOTDIR: "a part of the path is not a directory",
    errno.EISDIR: "a directory is in the way",
}


def io_error(exc: OSError, path: Path, action: str) -> UsageError:
    """A U033 diagnostic for an operating-system error while writing output at ``path``."""
    reason = exc.strerror or str(exc)
    hint = _HINTS.get(exc.errno or 0, "check the path, its permissions and the free space")
    return UsageError(error("U033", f"cannot {action} {path}: {reason}", hint=hint, file=str(path)))


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _absolute(path: Path) -> Path:
    """``path`` made absolute without resolving symbolic links (``-o .`` names the cwd)."""
    return Path(os.path.abspath(path))


def _is_marker(path: Path) -> bool:
    try:
        if not stat.S_ISREG(os.lstat(path).st_mode):
            return False
        with path.open("rb") as stream:
            return stream.read(64).startswith(MARKER_FORMAT.encode())
    except OSError:
        return False


def is_tlmpc_output(directory: Path) -> bool:
    """True when ``directory`` is empty or holds tlmpc's marker file (a previous output)."""
    try:
        if not any(directory.iterdir()):
            return True
    except OSError:
        return False
    return _is_marker(directory / MARKER)


def check_destination(out: Path, *, force: bool) -> None:
    """Refuse (exit 2) an ``-o`` that is a link, not a directory, or someone else's folder."""
    out = _absolute(out)
    if out.is_symlink():
        raise UsageError(
            error(
                "U030",
                f"{out} is a symbolic link; refusing to write through it or replace it",
                hint="pass the directory it points to, or choose another -o",
                file=str(out),
            )
        )
    if out.parent == out:
        raise UsageError(
            error(
                "U011",
                f"{out} cannot be an output directory",
                hint="choose another -o",
                file=str(out),
            )
        )
    if not out.exists():
        if not out.parent.is_dir():
            raise UsageError(
                error(
                    "U010",
                    f"the parent directory of {out} does not exist",
                    hint="create it first, or choose another -o",
                    file=str(out),
                )
            )
        return
    if not out.is_dir():
        raise UsageError(
            error(
                "U011",
                f"{out} exists and is not a directory",
                hint="choose another -o",
                file=str(out),
            )
        )
    if not force and not is_tlmpc_output(out):
        raise UsageError(
            error(
                "U012",
                f"{out} is not empty and is not a tlmpc output (it has no {MARKER} file)",
                hint="choose another -o, or pass --force to add the artifacts to it "
                "(other files in it are kept)",
                file=str(out),
            )
        )


def refuse_deleting_foreign(out: Path, *, force: bool) -> None:
    """Refuse (U012) to replace the tlmpc output ``out`` whole while it holds entries tlmpc
    did not write (with ``force`` they are kept: the artifacts go in one by one)."""
    out = _absolute(out)
    if force or not out.is_dir() or out.is_symlink() or not is_tlmpc_output(out):
        return
    foreign = foreign_entries(out)
    if foreign:
        raise _holds_foreign(out, foreign)


def refuse_overwriting(out: Path, names: list[str], source: Path | None = None) -> None:
    """Refuse (U031) when writing ``names`` into ``out`` would replace ``source`` (the
    mission being compiled) or an entry that is not a regular file (with ``--force``)."""
    out = _absolute(out)
    source_id: os.stat_result | None = None
    if source is not None:
        with contextlib.suppress(OSError):
            source_id = os.stat(source)
    if source is not None:
        # realpath, not Path.resolve(): the latter raises RuntimeError on a link loop
        # (Python < 3.13), which the reader of the mission reports as U001 afterwards
        with contextlib.suppress(OSError):
            if Path(os.path.realpath(out)) in Path(os.path.realpath(source)).parents:
                raise UsageError(
                    error(
                        "U031",
                        f"the mission being compiled is inside {out}, which would be replaced",
                        hint="choose an -o outside the mission's folder",
                        file=str(source),
                    )
                )
    for name in names:
        target = out / name
        try:
            info = os.lstat(target)
        except FileNotFoundError:
            continue
        except OSError as exc:
            raise io_error(exc, target, "inspect") from None
        if source_id is not None and (info.st_dev, info.st_ino) == (
            source_id.st_dev,
            source_id.st_ino,
        ):
            raise UsageError(
                error(
                    "U031",
                    f"writing {name} into {out} would overwrite the mission being compiled",
                    hint="choose another -o",
                    file=str(source),
                )
            )
        if not stat.S_ISREG(info.st_mode) and not is_tlmpc_output(out):
            raise UsageError(
                error(
                    "U031",
                    f"{target} exists and is not a regular file; refusing to replace it",
                    hint="move it away, or choose another -o",
                )
            )


def _lock_name(out: Path) -> Path:
    return out.parent / f".{out.name}.tlmpc-lock"


@contextlib.contextmanager
def output_lock(out: Path) -> Iterator[None]:
    """Hold the lock of ``out`` for one run; a second run gets U032 instead of a race.

    The lock file is removed when the run ends; after taking the lock we check that the file
    we locked is still the one at the path (another run may have removed it meanwhile).
    """
    out = _absolute(out)
    lock = _lock_name(out)
    fd: int | None = None
    try:
        # a signal while the lock is taken is delivered once ``fd`` says whether we hold it
        # and the lock is on record, so the lock file never outlives a run that Ctrl-C or
        # SIGTERM ended (should the signal cut the ``finally`` short, the command line
        # releases what is on record: :func:`release_leftovers`)
        with _signals_blocked():
            fd = _take_lock(out, lock)
            _hold(_HELD_LOCKS, lock, fd)
        yield
    finally:
        if fd is not None:
            _release_lock(lock, fd)


def _release_lock(lock: Path, fd: int) -> None:
    """Remove ``lock`` if it is still the file ``fd`` locked, then close ``fd``."""
    with contextlib.suppress(OSError):
        if os.path.samestat(os.fstat(fd), os.stat(lock, follow_symlinks=False)):
            os.unlink(lock)
    # off the record before the close: a descriptor number is never closed twice
    _HELD_LOCKS.pop(lock, None)
    os.close(fd)


def _take_lock(out: Path, lock: Path) -> int:
    """Create (or open) ``lock`` and hold its exclusive lock; return its descriptor."""
    import fcntl

    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666)
        except OSError as exc:
            if exc.errno == errno.ENOENT and not out.parent.is_dir():
                raise UsageError(
                    error(
                        "U010",
                        f"the parent directory of {out} does not exist",
                        hint="create it first, or choose another -o",
                        file=str(out),
                    )
                ) from None
            raise io_error(exc, lock, "create the lock file") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            raise UsageError(
                error(
                    "U032",
                    f"another tlmpc run is writing {out}",
                    hint=f"wait for it to finish (if none is running, delete {lock})",
                )
            ) from None
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock, follow_symlinks=False))
        except OSError:
            same = False
        if same:
            return fd
        os.close(fd)  # the file was replaced while we waited: lock the new one


def clean_stale(out: Path) -> list[str]:
    """Remove temporary folders that killed runs left beside ``out`` (call under the lock).

    A ``-new`` folder is an unfinished output; an ``-old`` folder is a previous output that a
    run killed mid-swap had moved aside: restored when ``OUT`` is missing, else removed.
    Returns what was done, one line each.
    """
    out = _absolute(out)
    done: list[str] = []
    prefix = f".{out.name}.tlmpc-"
    try:
        entries = sorted(out.parent.iterdir())
    except OSError:
        return done
    for entry in entries:
        kind = entry.name[len(prefix) : len(prefix) + 4]
        if not entry.name.startswith(prefix) or kind not in ("new-", "old-"):
            continue
        if entry.is_symlink() or not entry.is_dir():
            continue
        if not is_tlmpc_output(entry):
            done.append(f"left {entry} alone: it is not a tlmpc output")
            continue
        try:
            if kind == "old-" and not os.path.lexists(out):
                os.rename(entry, out)
                done.append(f"restored {out} from {entry.name}, left by an interrupted run")
            else:
                shutil.rmtree(entry)
                done.append(f"removed {entry.name}, left by an interrupted run")
        except OSError as exc:
            done.append(f"could not clean {entry}: {exc.strerror or exc}")
    return done


def _write(path: Path, content: Any) -> None:
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif isinstance(content, str):
        path.write_text(content, encoding="utf-8")
    elif isinstance(content, Iterator):  # the pieces of a large document's text
        with path.open("w", encoding="utf-8") as stream:
            for piece in content:
                stream.write(piece)
    else:
        path.write_text(dumps(content), encoding="utf-8")


@contextlib.contextmanager
def staging_directory(out: Path) -> Iterator[Path]:
    """A new temporary directory beside ``out`` holding the marker; removed on exit unless
    it was committed."""
    out = _absolute(out)
    staging: Path | None = None
    try:
        # a signal while the folder is made is delivered once ``staging`` names it
        with _signals_blocked():
            staging = _new_staging(out)
            _hold(_HELD_STAGING, staging, None)
        yield staging
    finally:
        if staging is not None:
            _remove_staging(staging)


def _remove_staging(staging: Path) -> None:
    shutil.rmtree(staging, ignore_errors=True)
    _HELD_STAGING.pop(staging, None)


def _new_staging(out: Path) -> Path:
    try:
        staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.tlmpc-new-", dir=out.parent))
    except OSError as exc:
        raise io_error(exc, out.parent, "create a temporary directory in") from None
    try:
        os.chmod(staging, 0o777 & ~_umask())
        (staging / MARKER).write_text(_MARKER_TEXT, encoding="utf-8")
    except OSError as exc:
        shutil.rmtree(staging, ignore_errors=True)
        raise io_error(exc, staging, "write") from None
    return staging


def write_artifacts(staging: Path, artifacts: Mapping[str, Any]) -> None:
    """Write each artifact (JSON document, text or bytes) into ``staging``."""
    # A large value several documents hold (the regions) is encoded once; each text is
    # written as soon as it is made, so that only one is held at a time, and a document
    # holding arrays (the mesh) a block of rows at a time.
    for name, content in artifact_pieces(artifacts):
        try:
            _write(staging / name, content)
        except OSError as exc:
            raise io_error(exc, staging / name, "write") from None


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux ``renameat2``); False when the system cannot."""
    import ctypes  # here, not at the top: only a recompile over an earlier output needs it

    try:
        # The interpreter's own symbols include the C library's; searching for libc by name
        # (ctypes.util.find_library) would run ldconfig in a subprocess first.
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        try:
            import ctypes.util

            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            renameat2 = libc.renameat2
        except (OSError, AttributeError):
            return False
    renameat2.argtypes = [
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_uint,
    ]
    renameat2.restype = ctypes.c_int
    result = renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if result == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), str(b))


#: The lock files (with their descriptors) and staging folders the main thread holds.  Each
#: is put on record in the same signal-deferred block that makes it, and removed by the
#: ``finally`` of the block that made it; but no ``finally`` can keep a signal from landing
#: before its first line, so what a signal left on record is released by
#: :func:`release_leftovers` once the run's handlers no longer raise.  Other threads keep
#: nothing on record: signal handlers run only in the main thread, so a ``finally`` there
#: always runs whole.
_HELD_LOCKS: dict[Path, int] = {}
_HELD_STAGING: dict[Path, None] = {}


def _hold(record: dict[Path, Any], path: Path, value: Any) -> None:
    import threading

    if threading.current_thread() is threading.main_thread():
        record[path] = value


def held() -> frozenset[Path]:
    """The lock files and staging folders on record now (those of enclosing runs)."""
    return frozenset(_HELD_LOCKS) | frozenset(_HELD_STAGING)


def release_leftovers(keep: frozenset[Path] = frozenset()) -> None:
    """Remove the staging folders and lock files a signal kept their blocks from removing,
    all but ``keep`` (what :func:`held` said before the run: an enclosing run's, still held).

    Call it when the run is over and signals no longer raise (the command line does, after
    giving back its handlers); it does nothing when nothing was left.
    """
    import threading

    if threading.current_thread() is not threading.main_thread():
        return
    for staging in [path for path in _HELD_STAGING if path not in keep]:
        _remove_staging(staging)
    for lock, fd in [(path, fd) for path, fd in _HELD_LOCKS.items() if path not in keep]:
        _release_lock(lock, fd)


@contextlib.contextmanager
def _signals_blocked() -> Iterator[None]:
    """Defer SIGINT, SIGTERM, SIGHUP and SIGALRM until the block ends, then deliver them.

    Python-level handlers run only in the main thread between bytecodes, so swapping them
    for a recorder defers the signal whichever thread the kernel delivered it to.
    """
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []
    # SIGALRM too: the command line's alarm delivers again a signal a finaliser swallowed
    kinds = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGALRM)
    previous = {kind: signal.getsignal(kind) for kind in kinds}
    for kind in kinds:
        signal.signal(kind, lambda number, frame: received.append(number))
    try:
        yield
    finally:
        for kind, handler in previous.items():
            signal.signal(kind, handler)
        for number in received:
            signal.raise_signal(number)


def commit(staging: Path, out: Path, *, force: bool) -> None:
    """Move the staged artifacts to ``out`` atomically.

    A previous tlmpc output (or an empty directory) is swapped out whole; a foreign directory
    (accepted only with ``force``) receives the files one by one and keeps its other files.
    """
    out = _absolute(out)
    try:
        _commit(staging, out, force=force)
    except OSError as exc:
        raise io_error(exc, out, "write the output to") from None


def _commit(staging: Path, out: Path, *, force: bool) -> None:
    if out.is_symlink():
        raise UsageError(
            error("U030", f"{out} became a symbolic link; nothing was written", file=str(out))
        )
    marked = out.exists() and is_tlmpc_output(out)
    foreign = foreign_entries(out) if marked else []
    if out.exists() and (not marked or foreign):
        # checked before compiling too; a race must not lose user files
        if not force:
            if foreign:
                raise _holds_foreign(out, foreign)
            raise UsageError(
                error("U012", f"{out} changed and is no longer a tlmpc output", file=str(out))
            )
        written = [p.name for p in staging.iterdir() if p.name != MARKER]
        refuse_overwriting(out, written)
        # a previous output's artifacts this run did not write would be taken for its own
        stale = [out / name for name in sorted(KNOWN_ARTIFACTS - set(written))] if marked else []
        with _signals_blocked():  # the files arrive all together, like a swapped output
            for item in staging.iterdir():
                if item.name != MARKER:
                    os.replace(item, out / item.name)
            for path in stale:
                if path.is_file() and not path.is_symlink():
                    path.unlink()
            settled.settle()
        return
    with _signals_blocked():
        _swap(staging, out)
        # the output is in place: a signal deferred until here, or later, is late
        settled.settle()


def _swap(staging: Path, out: Path) -> None:
    """Put ``staging`` at ``out`` (a previous output or an empty directory, if any, goes)."""
    if not out.exists():
        os.rename(staging, out)
        return
    if _exchange(staging, out):
        shutil.rmtree(staging, ignore_errors=True)  # now the previous output
        return
    backup = Path(tempfile.mkdtemp(prefix=f".{out.name}.tlmpc-old-", dir=out.parent))
    os.rename(out, backup)  # replaces the empty directory mkdtemp made
    try:
        os.rename(staging, out)
    except OSError:
        os.rename(backup, out)
        raise
    shutil.rmtree(backup, ignore_errors=True)


def replace_file(path: Path, data: bytes) -> None:
    """Write ``path`` beside itself and rename, so a reader never sees half a file and a
    failed write leaves the old file as it was.

    Refuses (U034) a target that is a symbolic link or exists and is not a regular file (a
    device, a directory, a FIFO), and turns I/O errors into U033.  A replaced file keeps its
    permissions; a new one gets ``0666`` minus the umask.
    """
    replace_files({path: data})


def replace_files(contents: Mapping[Path, bytes]) -> None:
    """:func:`replace_file` for several files that belong together: every target is checked
    and every new file written beside its target before the first is renamed into place, so
    a refused target (U034) or a failed write (U033) leaves all of them as they were."""
    targets = [(_absolute(path), data) for path, data in contents.items()]
    modes = [_replaceable_mode(path) for path, _ in targets]
    # the data is in memory: a signal waits for the few system calls below, so it finds
    # either the old files or the new ones and never a temporary file beside them
    with _signals_blocked():
        written: list[tuple[str, Path]] = []
        try:
            for (path, data), mode in zip(targets, modes, strict=True):
                written.append((_written_beside(path, data, mode), path))
            for temporary, path in written:
                try:
                    os.replace(temporary, path)
                except OSError as exc:
                    raise io_error(exc, path, "write") from None
        finally:
            for temporary, _ in written:
                Path(temporary).unlink(missing_ok=True)


def _replaceable_mode(path: Path) -> int:
    """The permissions a new ``path`` gets (its own when it is a regular file); U034 when it
    exists and is a link or not a regular file."""
    try:
        info: os.stat_result | None = os.lstat(path)
    except FileNotFoundError:
        info = None
    except OSError as exc:
        raise io_error(exc, path, "inspect") from None
    if info is not None and not stat.S_ISREG(info.st_mode):
        kind = "a symbolic link" if stat.S_ISLNK(info.st_mode) else "not a regular file"
        raise UsageError(
            error(
                "U034",
                f"{path} is {kind}; refusing to replace it",
                hint="choose another output file",
                file=str(path),
            )
        )
    return stat.S_IMODE(info.st_mode) if info is not None else 0o666 & ~_umask()


def _written_beside(path: Path, data: bytes, mode: int) -> str:
    """A temporary file beside ``path`` holding ``data`` with ``mode``; its name."""
    try:
        handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    except OSError as exc:
        raise io_error(exc, path.parent, "create a temporary file in") from None
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
        os.chmod(temporary, mode)
    except OSError as exc:
        Path(temporary).unlink(missing_ok=True)
        raise io_error(exc, path, "write") from None
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return temporary
