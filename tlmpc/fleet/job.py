"""One log's verification as a unit of work: what a worker process or a Dask task runs.

A :class:`Job` carries everything the worker needs (the log's path, its mission already read
into a sample-less trace document, the options), so a worker never reads a mission again and
the job pickles to a few kilobytes.  :func:`run_job` returns the log's *record*, a plain JSON
object (see docs/verify.md, "Many logs"), and never raises for a bad log: an unreadable log is
a record whose verdict is ``error``.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from tlmpc.base.errors import TlmpcError
from tlmpc.base.version import __version__
from tlmpc.fleet.cache import Cache, content_digest
from tlmpc.verify import Verdict


@dataclass(frozen=True, slots=True, kw_only=True)
class Options:
    """How every log of a batch is read and its end interpreted (the ``tlmpc verify`` flags)."""

    boundary: str | None = None
    topic: str | None = None
    columns: tuple[str, str, str] | None = None
    transform: tuple[float, float, float] | None = None
    frame: str | None = None
    assume_stay: bool = False
    loop_from: float | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Job:
    """Verify ``log`` (the path as the user gave it) against ``document`` (its mission;
    ``mission`` None: a ``trace.json``, verified against its own task and map).

    ``folder`` is the batch's working folder, which a relative ``log`` is relative to: a Dask
    worker started in another folder reads the log there (see :func:`log_path`)."""

    log: str
    mission: str | None
    document: Mapping[str, Any] = field(repr=False)
    options: Options = Options()
    cache: str | None = None
    folder: str | None = None


def working_folder() -> str | None:
    """This process's working folder, None when it no longer exists."""
    try:
        return os.getcwd()
    except OSError:
        return None


def log_path(job: Job) -> Path:
    """Where this process reads ``job.log``: the path as given, unless it is relative and this
    process works in another folder than the batch did (a Dask worker started elsewhere),
    then that path under the batch's folder."""
    given = Path(job.log)
    if given.is_absolute() or job.folder is None or working_folder() == job.folder:
        return given
    return Path(job.folder) / given


def job_key(job: Job, log_digest: str, *, named: bool = False) -> str:
    """The cache key: the log's bytes, the mission as read, the options and tlmpc's version;
    ``named``: the log's path too (the key of an error record, whose messages name the log:
    another log with the same bytes must not be told about this one)."""
    import hashlib

    payload = json.dumps(
        {
            "tlmpc": __version__,
            "mission": job.document,
            "options": asdict(job.options),
            "log": log_digest,
            **({"path": job.log} if named else {}),
        },
        sort_keys=True,
        separators=(",", ":"),
    )
    return hashlib.sha256(payload.encode()).hexdigest()


def _first_violation(verdict: Verdict, start: float) -> dict[str, Any] | None:
    """The earliest violation with a time (t from the log's start), else the first one."""
    if verdict.outcome != "violated" or not verdict.violations:
        return None
    timed = [v for v in verdict.violations if v.time is not None]
    chosen = min(timed, key=lambda v: v.time or 0.0) if timed else verdict.violations[0]
    x, y = chosen.position if chosen.position is not None else (None, None)
    return {
        "t": None if chosen.time is None else chosen.time - start,
        "x": x,
        "y": y,
        "conjunct": chosen.conjunct,
    }


def record_of(verdict: Verdict, start: float) -> dict[str, Any]:
    """The record fields a verdict gives (``log``, ``seconds`` and ``cached`` aside)."""
    return {
        "verdict": verdict.outcome,
        "formula": verdict.formula,
        "conjuncts": [{"conjunct": r.conjunct, "verdict": r.outcome} for r in verdict.conjuncts],
        "first_violation": _first_violation(verdict, start),
        "violations": [
            {
                "conjunct": v.conjunct,
                "t": None if v.time is None else v.time - start,
                "x": None if v.position is None else v.position[0],
                "y": None if v.position is None else v.position[1],
            }
            for v in verdict.violations
        ],
        "robustness": verdict.robustness,
        "start": start,
        "samples": int(verdict.stats.get("samples", 0)),
        "error": None,
    }


def error_fields(exc: TlmpcError) -> dict[str, Any]:
    """The record fields of a log that could not be verified (its diagnostics)."""
    return {
        "verdict": "error",
        "formula": None,
        "conjuncts": [],
        "first_violation": None,
        "violations": [],
        "robustness": None,
        "start": None,
        "samples": 0,
        "error": {
            "code": exc.diagnostics[0].code if exc.diagnostics else "U000",
            "message": "; ".join(d.format() for d in exc.diagnostics),
            "exit_code": exc.exit_code,
        },
    }


def verify_job(job: Job) -> dict[str, Any]:
    """The record of ``job`` without the cache (raises nothing for a bad log)."""
    from tlmpc.fleet.stream import verify_log
    from tlmpc.importers.logs import is_log

    options = job.options
    path = log_path(job)
    try:
        if not is_log(path):
            # a trace.json carries its own task and map: read as `tlmpc verify TRACE` reads it
            verdict = _verify_trace_file(path, options)
            # checked against no mission file: the report draws it on no mission's map
            return {**record_of(verdict, float(verdict.stats["start_time"])), "mission": None}
        streamed = verify_log(
            path,
            job.document,
            convention=options.boundary,
            topic=options.topic,
            columns=options.columns,
            transform=options.transform,
            frame=options.frame,
            assume_stay=options.assume_stay,
            loop_from=options.loop_from,
        )
    except TlmpcError as exc:
        fields = error_fields(exc)
        if path != Path(job.log):
            # the readers name the path they read; the record names the log as the batch was
            # given it, as in a process working in the batch's folder
            fields["error"]["message"] = fields["error"]["message"].replace(str(path), job.log)
        return fields
    return record_of(streamed.verdict, streamed.start_time)


def _verify_trace_file(path: Path, options: Options) -> Verdict:
    """The verdict of a ``trace.json`` in a batch (whole: a compiled trace is small)."""
    from tlmpc.verify import declare_ending, read_trace, verify_trace

    trace = read_trace(path, None, options.boundary)
    trace = declare_ending(trace, assume_stay=options.assume_stay, loop_from=options.loop_from)
    return verify_trace(trace)


def run_job(job: Job) -> dict[str, Any]:
    """The record of ``job``: from the cache when the same log, mission, options and version
    were verified before, else verified now (and stored)."""
    began = time.perf_counter()
    cache = Cache(Path(job.cache)) if job.cache is not None else None
    digest = None
    if cache is not None:
        try:
            digest = content_digest(log_path(job))
        except (OSError, TlmpcError):
            digest = None  # unreadable, or not a file to read: verify_job says why
        if digest is not None:
            # a verdict is the same for every log with these bytes; an error names its log
            stored = cache.get(job_key(job, digest)) or cache.get(job_key(job, digest, named=True))
            if stored is not None:
                return {"log": job.log, "mission": job.mission, **stored, "cached": True}
    record = verify_job(job)
    record["seconds"] = time.perf_counter() - began
    if cache is not None and digest is not None:
        cache.put(job_key(job, digest, named=record["verdict"] == "error"), record)
    return {"log": job.log, "mission": job.mission, **record, "cached": False}


def finite(value: Any) -> Any:
    """``value`` with non-finite floats written as the strings ``inf``/``-inf`` (strict JSON)."""
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [finite(v) for v in value]
    return value
