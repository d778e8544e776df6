"""A batch whose work fails under it: a log that meets a tlmpc bug, a worker process that dies,
a Dask cluster that is lost or cannot be spoken to.  Each is a record of its own (or a
diagnostic), never a traceback that loses the records of the logs already verified."""

from __future__ import annotations

import io
import json
import os
import signal
from concurrent.futures import CancelledError
from pathlib import Path
from typing import Any

import pytest

import tlmpc.fleet.job as job_module
from tlmpc.cli import main
from tlmpc.fleet.batch import discover

MISSION = """\
version: 1
name: m1
workspace:
  boundary: {rect: [0, 0, 10, 10]}
regions:
  a: {rect: [6, 6, 8, 8]}
  o: {rect: [2, 2, 4, 4]}
robot: {start: [1, 1], max_speed: 1.0}
ltl: "!o U a"
"""
#: through o before a: violated; staying near the start: inconclusive (by construction)
VIOLATED = "t,x,y\n0,1,1\n1,3,3\n2,7,7\n"
INCONCLUSIVE = "t,x,y\n0,1,1\n1,1.5,1.5\n"


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def _fleet(tmp_path: Path) -> tuple[Path, Path, dict[str, str]]:
    """Six logs of known verdicts, one of them named ``bad.csv``."""
    mission = tmp_path / "m1.yaml"
    mission.write_text(MISSION, encoding="utf-8")
    logs = tmp_path / "logs"
    logs.mkdir()
    expected: dict[str, str] = {}
    for k in range(5):
        text, verdict = (VIOLATED, "violated") if k % 2 else (INCONCLUSIVE, "inconclusive")
        (logs / f"r{k}.csv").write_text(text, encoding="utf-8")
        expected[str(logs / f"r{k}.csv")] = verdict
    (logs / "bad.csv").write_text(INCONCLUSIVE, encoding="utf-8")
    return mission, logs, expected


def _records(path: Path) -> dict[str, dict[str, Any]]:
    return {r["log"]: r for r in map(json.loads, path.read_text().splitlines())}


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_a_log_that_meets_a_bug_is_an_internal_error_record(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, jobs: str
) -> None:
    mission, logs, expected = _fleet(tmp_path)
    verify = job_module.verify_job

    def buggy(job: job_module.Job) -> dict[str, Any]:
        if job.log.endswith("bad.csv"):
            raise RuntimeError("a bug met while verifying this log")
        return verify(job)

    # (inherited by the pool's forked workers)
    monkeypatch.setattr(job_module, "verify_job", buggy)
    results = tmp_path / "r.jsonl"
    code, out, err = run_cli(
        "verify", str(logs), "--mission", str(mission), "--no-cache", "--jobs", jobs,
        "--results", str(results),
    )  # fmt: skip
    assert code == 3, err
    assert "Traceback" not in err
    records = _records(results)
    bad = records.pop(str(logs / "bad.csv"))
    assert bad["verdict"] == "error"
    assert bad["error"]["code"] == "I000"
    assert bad["error"]["exit_code"] == 3
    assert "RuntimeError: a bug met while verifying this log" in bad["error"]["message"]
    assert {log: r["verdict"] for log, r in records.items()} == expected
    assert "bad.csv: ERROR:" in out
    assert "error[I000]" in out


def test_a_worker_that_dies_costs_only_its_own_log(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    mission, logs, expected = _fleet(tmp_path)
    verify = job_module.verify_job

    def dying(job: job_module.Job) -> dict[str, Any]:
        if job.log.endswith("bad.csv"):
            os.kill(os.getpid(), signal.SIGKILL)  # as the system's out-of-memory killer would
        return verify(job)

    monkeypatch.setattr(job_module, "verify_job", dying)
    results = tmp_path / "r.jsonl"
    code, _out, err = run_cli(
        "verify", str(logs), "--mission", str(mission), "--no-cache", "--jobs", "2",
        "--results", str(results),
    )  # fmt: skip
    assert code == 3, err
    assert "Traceback" not in err
    records = _records(results)
    bad = records.pop(str(logs / "bad.csv"))
    assert bad["error"]["code"] == "I000"
    assert "ended abruptly" in bad["error"]["message"]
    # every other log was verified, though its worker's pool broke under it
    assert {log: r["verdict"] for log, r in records.items()} == expected


class _LostFuture:
    """A task of a lost cluster: cancelled, or finished with a result that cannot be fetched
    any more (distributed raises its FutureCancelledError, a CancelledError)."""

    def __init__(self, status: str) -> None:
        self.status = status

    def result(self) -> Any:
        raise CancelledError("scheduler-connection-lost")


class _LostCluster:
    """A client whose scheduler went away: every task comes back cancelled or unfetchable."""

    def __init__(self) -> None:
        self.submitted = 0

    def submit(self, *args: Any, **kwargs: Any) -> _LostFuture:
        self.submitted += 1
        return _LostFuture("cancelled" if self.submitted % 2 else "finished")

    def close(self) -> None:
        pass


def test_a_lost_dask_cluster_is_an_error_record_per_log(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    distributed = pytest.importorskip("distributed")
    import tlmpc.fleet.batch as batch

    mission, logs, _ = _fleet(tmp_path)
    monkeypatch.setattr(batch, "dask_client", lambda address: _LostCluster())
    monkeypatch.setattr(distributed, "as_completed", iter)
    results = tmp_path / "r.jsonl"
    code, _, err = run_cli(
        "verify", str(logs), "--mission", str(mission), "--no-cache", "--dask",
        "tcp://127.0.0.1:8786", "--results", str(results),
    )  # fmt: skip
    assert code == 2, err
    assert "Traceback" not in err
    records = _records(results)
    assert len(records) == 6
    assert {r["error"]["code"] for r in records.values()} == {"F002"}


@pytest.mark.parametrize("address", ["tls://127.0.0.1:1", "ucx://127.0.0.1:1"])
def test_a_scheduler_address_that_cannot_be_used_is_f002(tmp_path: Path, address: str) -> None:
    pytest.importorskip("distributed")
    mission, logs, _ = _fleet(tmp_path)
    code, _, err = run_cli("verify", str(logs), "--mission", str(mission), "--dask", address)
    assert code == 2, err
    assert "error[F002]" in err
    assert "Traceback" not in err


def test_a_hidden_bag_directory_is_not_searched(tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    for name in (".old-bag", "bag"):
        (logs / name).mkdir(parents=True)
        (logs / name / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    (logs / "run.csv").write_text(INCONCLUSIVE)
    assert discover([logs]) == [logs / "bag", logs / "run.csv"]


def test_a_job_for_a_pool_broken_since_the_last_wait_joins_the_recovery() -> None:
    from concurrent.futures.process import BrokenProcessPool

    from tlmpc.fleet.batch import _submit
    from tlmpc.fleet.job import Job

    class _Broken:
        def submit(self, *args: Any) -> Any:
            raise BrokenProcessPool("a worker died")

    job = Job(log="a.csv", mission="m.yaml", document={})
    running: dict[Any, Job] = {}
    _submit(_Broken(), running, iter([job, job]), 4)  # type: ignore[arg-type]
    # the job is not lost: it waits, failed, for the pool's recovery to run it alone
    assert list(running.values()) == [job]
    assert isinstance(next(iter(running)).exception(), BrokenProcessPool)
