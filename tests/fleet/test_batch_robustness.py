"""A batch of logs on hostile ground: special files and linked folders in the log folder, names
that are not UTF-8, outputs that cannot be written, a reactive mission, a log too large for a
view, a stop from the terminal; and a line printed for each log as soon as it is verified."""

from __future__ import annotations

import io
import json
import os
import select
import signal
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main
from tlmpc.fleet.batch import discover

ROOT = Path(__file__).resolve().parents[2]
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
#: through o before a: violated; staying near the start: inconclusive
VIOLATED = "t,x,y\n0,1,1\n1,3,3\n2,7,7\n"
INCONCLUSIVE = "t,x,y\n0,1,1\n1,1.5,1.5\n"


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture
def mission(tmp_path: Path) -> Path:
    path = tmp_path / "m1.yaml"
    path.write_text(MISSION, encoding="utf-8")
    return path


def test_each_line_is_printed_as_its_log_finishes(
    tmp_path: Path, mission: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from tlmpc.fleet.job import run_job

    logs = tmp_path / "logs"
    logs.mkdir()
    for k in range(5):
        (logs / f"r{k}.csv").write_text(INCONCLUSIVE, encoding="utf-8")
    out = io.StringIO()
    printed_before: list[int] = []

    def watched(job: Any) -> dict[str, Any]:
        printed_before.append(out.getvalue().count("\n"))
        return run_job(job)

    monkeypatch.setattr("tlmpc.fleet.batch.run_job", watched)
    code = main(["verify", str(logs), "--mission", str(mission), "--no-cache", "--jobs", "1"], out)
    assert code == 4
    # when a log's verification starts, the line of every log before it is out
    assert printed_before == [0, 1, 2, 3, 4]


def test_special_files_named_like_logs_are_error_records_with_the_cache(
    tmp_path: Path, mission: Path
) -> None:
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "a.csv").write_text(VIOLATED, encoding="utf-8")
    os.mkfifo(logs / "pipe.csv")
    (logs / "zero.csv").symlink_to("/dev/zero")
    argv = ["verify", str(logs), "--mission", str(mission), "--jobs", "1"]
    env = {**os.environ, "TLMPC_CACHE_DIR": str(tmp_path / "cache")}
    for _ in range(2):  # the cache's hash reads no special file either
        done = subprocess.run(
            [sys.executable, "-m", "tlmpc", *argv, "--results", str(tmp_path / "r.jsonl")],
            capture_output=True,
            text=True,
            timeout=120,
            env=env,
        )
        assert done.returncode == 2, done.stderr
        rows = {
            Path(r["log"]).name: r
            for r in map(json.loads, (tmp_path / "r.jsonl").read_text().splitlines())
        }
        assert rows["a.csv"]["verdict"] == "violated"
        assert rows["pipe.csv"]["error"]["code"] == "M050"
        assert "FIFO" in rows["pipe.csv"]["error"]["message"]
        assert rows["zero.csv"]["error"]["code"] == "M050"
        assert "device" in rows["zero.csv"]["error"]["message"]


@pytest.fixture(scope="module")
def busy_and_idle(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder with a long random walk (a worker busy for seconds) and a short log (the
    other worker done at once, then waiting for work)."""
    import numpy as np

    logs = tmp_path_factory.mktemp("stop") / "logs"
    logs.mkdir()
    rng = np.random.default_rng(3)
    count = 1_200_000

    def walk() -> Any:  # reflected into the workspace: it crosses o and a again and again
        z = 5.0 + np.cumsum(rng.normal(0.0, 0.05, count))
        return 0.1 + 9.8 * np.abs((z - 0.1) / 9.8 % 2 - 1)

    rows = np.column_stack([np.arange(count) * 0.01, walk(), walk()])
    np.savetxt(logs / "big.csv", rows, fmt="%.2f,%.4f,%.4f", header="t,x,y", comments="")
    (logs / "small.csv").write_text(INCONCLUSIVE, encoding="utf-8")
    (logs.parent / "m1.yaml").write_text(MISSION, encoding="utf-8")
    return logs


@pytest.mark.slow
@pytest.mark.parametrize(
    ("kind", "code", "word"), [("SIGINT", 130, "interrupted"), ("SIGTERM", 143, "terminated")]
)
def test_a_stopped_parallel_batch_prints_no_traceback(
    busy_and_idle: Path, kind: str, code: int, word: str
) -> None:
    logs = busy_and_idle
    cache = logs.parent / f"cache-{kind}"
    argv = ["verify", str(logs), "--mission", str(logs.parent / "m1.yaml"), "--cache", str(cache)]
    process = subprocess.Popen(
        [sys.executable, "-m", "tlmpc", *argv, "--jobs", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,  # a process group of its own, as a terminal's job
    )
    assert process.stdout is not None
    # the short log's line (or, should lines not come as logs finish, a moment): one worker
    # is inside the long log, the other waits for work
    select.select([process.stdout], [], [], 3.0)
    # the signal goes to every process of the group, as Ctrl-C or `kill -- -PGID` sends it
    os.killpg(process.pid, getattr(signal, kind))
    _, err = process.communicate(timeout=120)
    assert process.returncode == code
    assert err.decode() == f"tlmpc: {word}\n"
    # the workers were stopped, not left to finish: only the short log's record was stored
    assert len(list(cache.rglob("*.json"))) == 1


def test_signals_are_held_while_the_pool_forks_its_workers() -> None:
    from tlmpc.fleet.batch import _signals_held

    before = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    with _signals_held():
        held = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    assert {signal.SIGINT, signal.SIGTERM} <= held
    assert signal.pthread_sigmask(signal.SIG_BLOCK, []) == before


def test_names_that_are_not_utf8_reach_the_report_and_parquet(
    tmp_path: Path, mission: Path
) -> None:
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "ok.csv").write_text(INCONCLUSIVE, encoding="utf-8")
    odd = Path(os.fsdecode(bytes(logs) + b"/run-caf\xe9.csv"))
    odd.write_text(VIOLATED, encoding="utf-8")
    report = tmp_path / "report" / "fleet.html"
    results = tmp_path / "r.parquet"
    code, _, err = run_cli(
        "verify", str(logs), "--mission", str(mission), "--no-cache", "--report", str(report),
        "--results", str(results),
    )  # fmt: skip
    assert code == 1, err
    page = report.read_text(encoding="utf-8")
    assert "run-caf\\xe9.csv" in page  # the byte, shown
    hrefs: list[str] = []

    class Links(HTMLParser):
        def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
            hrefs.extend(v or "" for k, v in attrs if tag == "a" and k == "href")

    Links().feed(page)
    assert len(hrefs) == 2
    assert all((report.parent / h).is_file() for h in hrefs)
    import pyarrow.parquet as pq

    names = pq.read_table(results).column("log").to_pylist()
    assert sorted(Path(n).name for n in names) == ["ok.csv", "run-caf\\xe9.csv"]


def test_a_reactive_mission_is_blamed_on_every_record(tmp_path: Path) -> None:
    guard = tmp_path / "guard.yaml"
    guard.write_text((ROOT / "specs" / "reactive" / "guard.yaml").read_text(), encoding="utf-8")
    logs = tmp_path / "logs"
    logs.mkdir()
    for day in ("monday", "tuesday"):
        (logs / f"{day}.csv").write_text("t,x,y,person\n0,1,1,0\n", encoding="utf-8")
    results = tmp_path / "r.jsonl"
    code, _, _ = run_cli(
        "verify", str(logs), "--mission", str(guard), "--no-cache", "--results", str(results)
    )
    assert code == 2
    for row in map(json.loads, results.read_text().splitlines()):
        assert row["error"]["message"].startswith(f"{guard}: error[U110]"), row


def test_a_log_too_large_for_a_view_is_not_offered_one(
    tmp_path: Path, mission: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import tlmpc.verify.trace_input as trace_input

    monkeypatch.setattr(trace_input, "MAX_CSV_ROWS", 6)  # a long log, at the test's scale
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "long.csv").write_text(
        "t,x,y\n" + "".join(f"{k},1,1\n" for k in range(10)), encoding="utf-8"
    )
    (logs / "short.csv").write_text(INCONCLUSIVE, encoding="utf-8")
    report = tmp_path / "r.html"
    code, _, _ = run_cli(
        "verify", str(logs), "--mission", str(mission), "--no-cache", "--report", str(report)
    )
    assert code == 4
    page = report.read_text(encoding="utf-8")
    # the oracle: what `tlmpc view --log` does with each log
    refused = run_cli("view", "--log", str(logs / "long.csv"), "--mission", str(mission),
                      "-o", str(tmp_path / "v.html"))  # fmt: skip
    assert refused[0] == 2
    assert "U038" in refused[2]
    assert "tlmpc view --log" not in page
    assert "no view: the CSV trace is too large" in page


@pytest.mark.parametrize(
    ("flag", "name", "make"),
    [
        ("--report", "fleet.html", lambda d: (d / "fleet.views").write_text("my notes\n")),
        ("--report", "fleet.html", lambda d: (d / "fleet.views").symlink_to(d / "logs")),
        ("--report", "rdir", lambda d: (d / "rdir").mkdir()),
        ("--results", "notes.txt/r.jsonl", lambda d: (d / "notes.txt").write_text("x\n")),
        ("--results", "gone/day/r.jsonl", lambda d: (d / "gone").symlink_to(d / "nowhere")),
        ("--results", "r.jsonl", lambda d: (d / "r.jsonl").symlink_to(d / "elsewhere")),
    ],
)
def test_an_output_that_cannot_be_written_is_refused_before_any_log(
    tmp_path: Path, mission: Path, flag: str, name: str, make: Any
) -> None:
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "a.csv").write_text(VIOLATED, encoding="utf-8")
    make(tmp_path)
    code, out, err = run_cli(
        "verify", str(logs), "--mission", str(mission), "--no-cache", flag, str(tmp_path / name)
    )
    assert code == 2
    assert out == ""  # no log was verified
    assert "error[F007]" in err
    assert "hint:" in err
    assert "Traceback" not in err
    if name.startswith("gone/"):  # a link to nothing where the folder would be
        assert "gone is not a folder" in err


def test_linked_folders_are_searched_once_each(tmp_path: Path, mission: Path) -> None:
    store = tmp_path / "store" / "husky"
    store.mkdir(parents=True)
    (store / "run1.csv").write_text(VIOLATED, encoding="utf-8")
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "local.csv").write_text(INCONCLUSIVE, encoding="utf-8")
    (logs / "husky").symlink_to(store)
    (logs / "loop").symlink_to(logs)  # a link back up
    (logs / "twin").symlink_to(store)  # a second link to the same folder
    found = discover([logs])
    # the oracle: each log file under the tree, once, whatever the links
    real = sorted({os.path.realpath(p) for p in found})
    assert len(found) == len(real) == 2
    assert real == sorted(os.path.realpath(p) for p in (store / "run1.csv", logs / "local.csv"))
    code, _, _ = run_cli("verify", str(logs), "--mission", str(mission), "--no-cache")
    assert code == 1  # the linked robot's violated log counts
