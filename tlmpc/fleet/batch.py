"""Many logs at once: find them, pair each with its mission, verify them in parallel.

* :func:`discover` expands folders into the logs they hold (CSV files, bag files, ROS 2 bag
  directories), sorted, so a batch has one order on every machine.
* :func:`missions_for` pairs every log with a mission: one mission file for all, or a mapping
  file (``tlmpc.fleet-missions/1``) from log name patterns to missions.
* :func:`run` verifies the jobs in this process (``jobs=1``), in a local process pool, or on a
  Dask cluster, and yields each log's record as it finishes.
* :func:`batch_exit` is the batch's one exit code.
"""

from __future__ import annotations

import contextlib
import fnmatch
import os
import signal
from collections.abc import Generator, Iterator, Mapping, Sequence
from concurrent.futures import (
    FIRST_COMPLETED,
    CancelledError,
    Future,
    ProcessPoolExecutor,
    wait,
)
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tlmpc.base.errors import (
    EXIT_INCONCLUSIVE,
    EXIT_INTERNAL,
    EXIT_NEGATIVE,
    EXIT_OK,
    EXIT_USAGE,
    TlmpcError,
    UsageError,
    error,
)
from tlmpc.fleet.job import Job, Options, error_fields, run_job, working_folder

MAPPING_FORMAT = "tlmpc.fleet-missions/1"


def _is_bag_dir(path: Path) -> bool:
    return (path / "metadata.yaml").is_file()


def discover(paths: Sequence[Path]) -> list[Path]:
    """The logs the paths name: a file as it is; a folder (not a bag directory) searched
    recursively for CSV and bag files and ROS 2 bag directories, sorted by path.

    Symbolic links to folders are followed (a robot's log folder linked in from another
    disk is searched like any other); a folder already searched (a link loop, or a second
    link to one folder) is searched once."""
    from tlmpc.importers.logs import CSV_SUFFIXES

    found: list[Path] = []
    for path in paths:
        if not path.is_dir() or _is_bag_dir(path):
            found.append(path)
            continue
        inside: list[Path] = []
        searched: set[tuple[int, int]] = set()
        _first_visit(path, searched)
        for folder, names, files in os.walk(path, followlinks=True):
            here = Path(folder)
            bags = [n for n in names if not n.startswith(".") and _is_bag_dir(here / n)]
            inside.extend(here / n for n in bags)
            names[:] = [
                n
                for n in sorted(names)
                if n not in bags and not n.startswith(".") and _first_visit(here / n, searched)
            ]
            inside.extend(
                here / f
                for f in files
                if Path(f).suffix.lower() in (*CSV_SUFFIXES, ".bag", ".mcap")
                and not f.startswith(".")
            )
        # (a .db3 file is read through its bag directory, found above)
        found.extend(sorted(inside, key=lambda p: p.as_posix()))
    return found


def _identity(folder: Path) -> tuple[int, int] | None:
    """The folder's device and inode (what a link to it shares), None when it cannot be
    looked at."""
    try:
        info = folder.stat()
    except OSError:
        return None
    return info.st_dev, info.st_ino


def _first_visit(folder: Path, searched: set[tuple[int, int]]) -> bool:
    """Whether ``folder`` was not searched yet (and is now counted as searched)."""
    identity = _identity(folder)
    if identity is None:
        return True  # os.walk cannot list it either
    if identity in searched:
        return False
    searched.add(identity)
    return True


@dataclass(frozen=True, slots=True)
class MissionRule:
    """Logs whose path (or file name) matches ``pattern`` are checked against ``mission``."""

    pattern: str
    mission: Path


def read_mapping(path: Path) -> list[MissionRule] | None:
    """The rules of a mapping file, or None when ``path`` is a mission file."""
    import yaml

    try:
        document = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return None  # the mission loader reports it
    if not isinstance(document, dict) or document.get("format") != MAPPING_FORMAT:
        return None
    rules = document.get("missions")
    if not isinstance(rules, list) or not all(
        isinstance(r, dict) and isinstance(r.get("logs"), str) and isinstance(r.get("mission"), str)
        for r in rules
    ):
        raise UsageError(
            error(
                "F003",
                "`missions` must be a list of {logs: PATTERN, mission: FILE}",
                hint="for example: missions: [{logs: 'husky*/*.csv', mission: patrol.yaml}]",
                file=str(path),
            )
        )
    return [MissionRule(r["logs"], path.parent / r["mission"]) for r in rules]


def match(rules: Sequence[MissionRule], log: Path) -> Path | None:
    """The mission of the first rule whose pattern matches the log's path, or the path's last
    parts: ``husky*/*.csv`` matches ``logs/husky1/run.csv`` however the folder holding
    ``husky1`` was named on the command line (``logs/``, ``./logs``, an absolute path), and
    ``*.csv`` the file name alone."""
    parts = log.as_posix().split("/")
    tails = ["/".join(parts[start:]) for start in range(len(parts))]
    for rule in rules:
        if any(fnmatch.fnmatchcase(tail, rule.pattern) for tail in tails):
            return rule.mission
    return None


def missions_for(logs: Sequence[Path], mission: Path | None) -> dict[Path, Path | None]:
    """Each log's mission file (None: no rule of the mapping file matches it, or no
    ``mission`` was given: a batch of ``trace.json`` files needs none)."""
    if mission is None:
        return dict.fromkeys(logs)
    rules = read_mapping(mission)
    if rules is None:
        return dict.fromkeys(logs, mission)
    return {log: match(rules, log) for log in logs}


def make_jobs(
    logs: Sequence[Path],
    missions: Mapping[Path, Path | None],
    options: Options,
    cache: Path | None,
) -> tuple[list[Job], list[dict[str, Any]]]:
    """A job per log, each mission read once; logs without a usable mission become error
    records right away."""
    from tlmpc.importers.logs import is_log
    from tlmpc.verify.trace_input import load_log_mission, positions_document

    documents: dict[Path, dict[str, Any] | TlmpcError] = {}
    # relative paths are the batch's: a Dask worker resolves them against this folder
    folder = working_folder()
    if cache is not None and folder is not None:
        cache = Path(folder) / cache
    jobs: list[Job] = []
    failed: list[dict[str, Any]] = []
    for log in logs:
        if not is_log(log):
            # a trace.json carries its own task and map: no mission applies to it
            jobs.append(
                Job(
                    log=str(log),
                    mission=None,
                    document={},
                    options=options,
                    cache=None if cache is None else str(cache),
                    folder=folder,
                )
            )
            continue
        mission = missions.get(log)
        if mission is None:
            failed.append(
                error_record(
                    log,
                    None,
                    UsageError(
                        error(
                            "F004",
                            "no rule of the mission mapping matches this log",
                            hint="add a rule whose `logs` pattern matches its path or name",
                            file=str(log),
                        )
                    ),
                )
            )
            continue
        if mission not in documents:
            # read once for all its logs, so its diagnostics name the mission, never a log
            try:
                documents[mission] = positions_document(load_log_mission(mission))
            except TlmpcError as exc:
                documents[mission] = exc
        document = documents[mission]
        if isinstance(document, TlmpcError):
            failed.append(error_record(log, mission, document))
            continue
        jobs.append(
            Job(
                log=str(log),
                mission=str(mission),
                document=document,
                options=options,
                cache=None if cache is None else str(cache),
                folder=folder,
            )
        )
    return jobs, failed


def error_record(log: Path, mission: Path | None, exc: TlmpcError) -> dict[str, Any]:
    """The record of a log that could not be verified."""
    return {
        "log": str(log),
        "mission": None if mission is None else str(mission),
        **error_fields(exc),
        "seconds": 0.0,
        "cached": False,
    }


class _InternalError(TlmpcError):
    """A log's verification met a tlmpc bug (I000, exit 3): its record carries it."""

    exit_code = EXIT_INTERNAL


def _internal(job: Job, exc: BaseException) -> dict[str, Any]:
    """The record of a log whose verification raised ``exc`` (a bug, never the log's fault):
    an ``error`` record with I000, so the batch goes on and exits 3."""
    return _job_error(
        job,
        _InternalError(
            error(
                "I000",
                f"internal error: {type(exc).__name__}: {exc}",
                hint="please report it with the log that caused it",
                file=job.log,
            )
        ),
    )


def _job_error(job: Job, exc: TlmpcError) -> dict[str, Any]:
    """The error record of ``job`` (its mission None for a ``trace.json``)."""
    return error_record(Path(job.log), None if job.mission is None else Path(job.mission), exc)


def _worker_died(job: Job) -> dict[str, Any]:
    """The record of a log whose worker process ended while verifying it, alone in its pool
    (killed by a signal, or by the system for want of memory)."""
    return _internal(
        job,
        BrokenProcessPool(
            "the worker process verifying this log ended abruptly (killed by a signal, or "
            "out of memory)"
        ),
    )


def _local(jobs: Sequence[Job]) -> Generator[dict[str, Any], None, None]:
    for job in jobs:
        try:
            yield run_job(job)
        except Exception as exc:  # one log's bug must not lose the others' records
            yield _internal(job, exc)


def _pool(jobs: Sequence[Job], workers: int) -> Generator[dict[str, Any], None, None]:
    # At most a few jobs in flight per worker: a million logs never sit in memory as futures.
    limit = 4 * workers
    queue = iter(jobs)
    pool = _start_pool(workers)
    finished = False
    try:
        running: dict[Future[dict[str, Any]], Job] = {}
        _submit(pool, running, queue, limit)
        while running:
            done, _ = wait(running, return_when=FIRST_COMPLETED)
            if any(isinstance(f.exception(), BrokenProcessPool) for f in done):
                # A worker died (killed, or out of memory): every job in flight fails with it,
                # whichever worker had it.  Each of those runs again alone, so only the log
                # whose worker dies again is told so; the rest go on in a new pool.
                done, _ = wait(running)
                broken = [f for f in done if isinstance(f.exception(), BrokenProcessPool)]
                lost = [running.pop(f) for f in broken]
                for future in [f for f in done if f in running]:
                    yield _record(running.pop(future), future)
                pool.shutdown(wait=True, cancel_futures=True)
                for job in lost:
                    yield _alone(job)
                pool = _start_pool(workers)
            else:
                for future in done:
                    yield _record(running.pop(future), future)
            _submit(pool, running, queue, limit)
        finished = True
    finally:
        if not finished:  # interrupted, or the caller stopped early: no log is finished
            _stop_workers(pool)
        pool.shutdown(wait=True, cancel_futures=True)


def _start_pool(workers: int) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(max_workers=workers, initializer=_worker_start)


def _submit(
    pool: ProcessPoolExecutor,
    running: dict[Future[dict[str, Any]], Job],
    queue: Iterator[Job],
    limit: int,
) -> None:
    """Fill the pool up to ``limit`` jobs in flight."""
    # a worker is forked by a submit: it starts with the signals held
    with _signals_held():
        while len(running) < limit:
            job = next(queue, None)
            if job is None:
                return
            try:
                running[pool.submit(run_job, job)] = job
            except BrokenProcessPool as exc:  # a worker died since the last wait: as above
                failed: Future[dict[str, Any]] = Future()
                failed.set_exception(exc)
                running[failed] = job
                return


def _record(job: Job, future: Future[dict[str, Any]]) -> dict[str, Any]:
    exc = future.exception()
    return _internal(job, exc) if exc is not None else future.result()


def _alone(job: Job) -> dict[str, Any]:
    """``job`` verified in a pool of its own (see :func:`_pool`)."""
    pool = _start_pool(1)
    try:
        with _signals_held():
            future = pool.submit(run_job, job)
        if isinstance(future.exception(), BrokenProcessPool):
            return _worker_died(job)
        return _record(job, future)
    except BaseException:  # interrupted: its worker stops now, as the pool's do
        _stop_workers(pool)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


#: The signals that end a run: the parent's to handle, never a worker's.
_ENDING = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """Hold Ctrl-C and SIGTERM in this thread (a process forked meanwhile starts with them
    held); they are delivered when the block ends."""
    held = signal.pthread_sigmask(signal.SIG_BLOCK, _ENDING)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


def _worker_start() -> None:
    """A pool worker's first act: Ctrl-C is ignored and SIGTERM ends it at once, quietly.

    The parent ends the run and stops its workers (:func:`_stop_workers`); the handlers a
    forked worker inherits would raise inside multiprocessing's loop instead, which prints
    a traceback per worker."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _ENDING)


def _stop_workers(pool: ProcessPoolExecutor) -> None:
    """End the pool's workers now (each would finish its log first)."""
    # ProcessPoolExecutor has no public way to reach its processes before Python 3.14
    # (terminate_workers); its map of them has kept this name since Python 3.2.
    processes: Mapping[int, Any] = getattr(pool, "_processes", None) or {}
    for process in list(processes.values()):
        with contextlib.suppress(OSError, ValueError):
            process.terminate()


def dask_client(address: str) -> Any:
    """A ``distributed.Client`` connected to ``address`` (F001 without the extra, F002 when
    the scheduler cannot be reached)."""
    try:
        from distributed import Client
    except ImportError:
        raise UsageError(
            error(
                "F001",
                "--dask needs the `distributed` package, which is not installed",
                hint="install the fleet extra: pip install 'tlmpc[fleet]'",
                file="<command line>",
            )
        ) from None
    try:
        return Client(address, timeout="10s")
    # (TypeError, ImportError: a protocol distributed knows but cannot use here, such as
    # tls:// without a security configuration or ucx:// without its package)
    except (OSError, TimeoutError, ValueError, TypeError, ImportError) as exc:
        raise UsageError(
            error(
                "F002",
                f"cannot reach the Dask scheduler at {address}: {exc}",
                hint="start one with `dask scheduler` and workers with `dask worker ADDRESS`",
                file="<command line>",
            )
        ) from None


def _dask(jobs: Sequence[Job], client: Any) -> Generator[dict[str, Any], None, None]:
    from distributed import as_completed

    futures = {client.submit(run_job, job, pure=False): job for job in jobs}
    for future in as_completed(futures):
        yield _dask_record(futures[future], future)


def _dask_record(job: Job, future: Any) -> dict[str, Any]:
    """The record of a finished Dask task: its own, an internal error's, or (the cluster lost
    before the task ended, or before its result could be fetched) an F002 record."""
    try:
        if future.status == "error":
            return _internal(job, future.exception())
        return dict(future.result())
    except CancelledError:  # distributed's FutureCancelledError: the scheduler went away
        pass
    return _job_error(
        job,
        UsageError(
            error(
                "F002",
                "the Dask cluster was lost before this log was verified (the connection to "
                "its scheduler ended)",
                hint="run the batch again once the scheduler is back: the cache keeps the "
                "logs already verified",
                file=job.log,
            )
        ),
    )


def run(
    jobs: Sequence[Job], *, workers: int = 1, client: Any = None
) -> Generator[dict[str, Any], None, None]:
    """Each job's record as it finishes: on ``client`` (a ``distributed.Client``) when given,
    else in this process (``workers`` 1) or a pool of ``workers`` processes.  Closing the
    generator before its end stops the pool's workers at once."""
    if client is not None:
        return _dask(jobs, client)
    if workers <= 1 or len(jobs) <= 1:
        return _local(jobs)
    return _pool(jobs, min(workers, len(jobs)))


def batch_exit(records: Sequence[Mapping[str, Any]]) -> int:
    """3 if a log met an internal error, else 2 if one could not be read, else 1 if one is
    violated, else 4 if one is inconclusive, else 0."""
    codes = [
        (r["error"] or {}).get("exit_code", EXIT_USAGE) if r["verdict"] == "error" else 0
        for r in records
    ]
    verdicts = {r["verdict"] for r in records}
    if EXIT_INTERNAL in codes:
        return EXIT_INTERNAL
    if "error" in verdicts:
        return EXIT_USAGE
    if "violated" in verdicts:
        return EXIT_NEGATIVE
    if "inconclusive" in verdicts:
        return EXIT_INCONCLUSIVE
    return EXIT_OK


def no_logs(paths: Sequence[Path]) -> UsageError:
    """F005: the folders hold no log."""
    return UsageError(
        error(
            "F005",
            "no logs found in " + ", ".join(str(p) for p in paths),
            hint="logs are .csv/.tsv/.txt files, .bag/.mcap files or ROS 2 bag directories",
            file=str(paths[0]) if paths else None,
        )
    )
