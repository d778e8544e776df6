"""``tlmpc verify`` on many logs: the batch's flags in, lines, summary and files out."""

from __future__ import annotations

import argparse
import itertools
import os
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TextIO

from tlmpc.base.errors import UsageError, error


def _workers(args: argparse.Namespace) -> int:
    if args.jobs is None:
        return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 1
    if args.jobs < 1:
        raise UsageError(
            error(
                "F008",
                f"--jobs {args.jobs}: the number of processes must be at least 1",
                file="<command line>",
            )
        )
    return int(args.jobs)


def run_batch(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Verify every log the arguments name; print a line each, then the summary."""
    from tlmpc.fleet.batch import (
        batch_exit,
        dask_client,
        discover,
        make_jobs,
        missions_for,
        no_logs,
        run,
    )
    from tlmpc.fleet.cache import default_cache_dir
    from tlmpc.fleet.job import Options
    from tlmpc.fleet.output import (
        check_output,
        line,
        ordered,
        summary,
        summary_table,
        write_results,
    )
    from tlmpc.importers.logs import is_log, parse_columns, parse_transform
    from tlmpc.io.report import Reporter

    report = Reporter.for_args(args, out, err)
    if args.dask is not None and args.jobs is not None:
        raise UsageError(
            error(
                "F008",
                "--jobs and --dask both given",
                hint="--jobs runs local processes; the Dask cluster has its own workers",
                file="<command line>",
            )
        )
    workers = _workers(args)
    if args.report is not None or args.group is not None:
        from tlmpc.fleet.report import group_pattern

        group_pattern(args.group)  # a bad --group fails before any log is verified
    options = Options(
        boundary=args.boundary,
        topic=args.topic,
        columns=parse_columns(args.columns) if args.columns else None,
        transform=parse_transform(args.transform) if args.transform else None,
        frame=args.frame,
        assume_stay=args.assume_stay,
        loop_from=args.loop_from,
    )
    logs = discover(args.trace)
    if not logs:
        raise no_logs(args.trace)
    if args.mission is None and any(is_log(log) for log in logs):
        # (a trace.json carries its own task and map: a batch of them needs no mission)
        raise UsageError(
            error(
                "V010",
                "verifying logs needs --mission (a mission file or a mission mapping)",
                file="<command line>",
            )
        )
    cache = None if args.no_cache else (args.cache or default_cache_dir())
    missions = missions_for(logs, args.mission)
    _refuse_overwriting(args.results, args.report, [*logs, args.mission, *missions.values()])
    # an output the batch could not write at its end is refused before any log is verified
    if args.results is not None:
        check_output(args.results)
    if args.report is not None:
        from tlmpc.fleet.report import check_report

        check_report(args.report)
    jobs, failed = make_jobs(logs, missions, options, cache)
    client = dask_client(args.dask) if args.dask is not None else None
    began = time.perf_counter()
    records: list[dict[str, Any]] = []
    results = run(jobs, workers=workers, client=client)
    try:
        for record in itertools.chain(failed, results):  # each line as its log finishes
            records.append(record)
            report.stream(line(record))
    finally:
        results.close()  # interrupted: the workers stop now, not after their logs
        if client is not None:
            client.close()
    wall = time.perf_counter() - began
    rows = ordered(records, [str(log) for log in logs])
    numbers = summary(rows, wall)
    if args.results is not None:
        write_results(args.results, rows)
    if args.report is not None:
        from tlmpc.fleet.report import write_report

        write_report(args.report, rows, jobs, group=args.group)
    code = batch_exit(rows)
    text = "summary:\n" + summary_table(numbers)
    from tlmpc.fleet.job import finite

    result = {"format": "tlmpc.fleet/1", "summary": numbers, "logs": finite(rows)}
    return report.finish(code, result, text)


def _refuse_overwriting(
    results: Path | None, report: Path | None, inputs: Sequence[Path | None]
) -> None:
    """Refuse (U043), before any log is verified, a results file or a report that names one
    of the batch's inputs (a log, the mission, a mission the mapping names) or each other."""
    from tlmpc.io.outputs import plain_name, refuse_input_as_output, same_file

    for flag, path in (("--results", results), ("--report", report)):
        if path is not None:
            refuse_input_as_output(path, inputs, flag)
    if results is not None and report is not None and same_file(results, report):
        raise UsageError(
            error(
                "U043",
                f"--report {plain_name(str(report))} is also the --results file; one would "
                "overwrite the other",
                hint="choose two different files",
                file=str(report),
            )
        )
