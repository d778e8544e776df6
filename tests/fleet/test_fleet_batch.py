"""Batch verification of a generated fleet: verdicts and first violations against the
analytic oracle, the same records with one process, two, and a Dask cluster, and the cache."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pytest
from fleet_data import Planted, generate, write_missions

from tlmpc.cli import main

LOGS = 36


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def records(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


def comparable(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [{k: v for k, v in row.items() if k not in ("seconds", "cached")} for row in rows]


@pytest.fixture(scope="module")
def fleet(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, list[Planted]]:
    folder = tmp_path_factory.mktemp("fleet")
    planted = generate(folder / "logs", LOGS)
    mapping = write_missions(folder)
    return folder, mapping, planted


def check_against_oracle(rows: list[dict[str, Any]], planted: list[Planted]) -> None:
    by_log = {row["log"]: row for row in rows}
    assert len(by_log) == len(planted)
    for expected in planted:
        row = by_log[str(expected.path)]
        assert row["verdict"] == expected.verdict, expected.path
        first = row["first_violation"]
        if expected.first_t is None:
            assert first is None
            continue
        assert first["conjunct"] == expected.conjunct
        assert first["t"] == pytest.approx(expected.first_t, rel=1e-9, abs=1e-6)
        assert first["x"] == pytest.approx(expected.first_x, abs=1e-9)
        assert first["y"] == pytest.approx(expected.first_y, abs=1e-9)


def test_jobs_one_two_and_dask_agree_with_the_oracle(
    fleet: tuple[Path, Path, list[Planted]], tmp_path: Path
) -> None:
    from distributed import Client, LocalCluster

    folder, mapping, planted = fleet
    logs = str(folder / "logs")
    outputs = []
    for flags in (["--jobs", "1"], ["--jobs", "2"]):
        results = tmp_path / f"r{flags[1]}.jsonl"
        code, out, _ = run_cli(
            "verify",
            logs,
            "--mission",
            str(mapping),
            "--no-cache",
            "--results",
            str(results),
            *flags,
        )
        assert code == 1  # some logs are violated
        assert out.count("\n") >= LOGS
        outputs.append(records(results))
    with (
        LocalCluster(
            n_workers=1,
            processes=False,
            threads_per_worker=2,
            dashboard_address=":0",  # any free port: 8787 may be taken
            protocol="tcp://",
        ) as cluster,
        Client(cluster),
    ):
        results = tmp_path / "dask.jsonl"
        code, _, _ = run_cli(
            "verify",
            logs,
            "--mission",
            str(mapping),
            "--no-cache",
            "--results",
            str(results),
            "--dask",
            cluster.scheduler_address,
        )
        assert code == 1
        outputs.append(records(results))
    check_against_oracle(outputs[0], planted)
    assert comparable(outputs[0]) == comparable(outputs[1]) == comparable(outputs[2])
    verdicts = {row["verdict"] for row in outputs[0]}
    assert verdicts == {"satisfied", "violated", "inconclusive"}


def test_a_second_run_reads_everything_from_the_cache(
    fleet: tuple[Path, Path, list[Planted]], tmp_path: Path
) -> None:
    folder, mapping, planted = fleet
    cache = tmp_path / "cache"
    first, second = tmp_path / "first.jsonl", tmp_path / "second.jsonl"
    base = ["verify", str(folder / "logs"), "--mission", str(mapping), "--cache", str(cache)]
    run_cli(*base, "--jobs", "2", "--results", str(first))
    code, out, _ = run_cli(*base, "--jobs", "1", "--results", str(second), "--json")
    assert code == 1
    summary = json.loads(out)["result"]["summary"]
    assert summary["cached"] == LOGS
    assert summary["verified"] == 0
    assert all(row["cached"] for row in records(second))
    assert not any(row["cached"] for row in records(first))
    assert comparable(records(first)) == comparable(records(second))
    # A changed log is verified again, and only it.
    changed = planted[0].path
    changed.write_text(changed.read_text(encoding="utf-8") + "\n", encoding="utf-8")
    code, out, _ = run_cli(*base, "--jobs", "1", "--json")
    summary = json.loads(out)["result"]["summary"]
    assert summary["verified"] == 1
    assert summary["cached"] == LOGS - 1
    # A mission that means something else is verified again for its logs; a comment is not.
    avoid = folder / "avoid.yaml"
    original = avoid.read_text(encoding="utf-8")
    avoid.write_text("# reviewed\n" + original, encoding="utf-8")
    code, out, _ = run_cli(*base, "--jobs", "1", "--json")
    assert json.loads(out)["result"]["summary"]["verified"] == 0
    avoid.write_text(original.replace("12.0, 7.0]", "12.0, 7.5]"), encoding="utf-8")
    try:
        code, out, _ = run_cli(*base, "--jobs", "1", "--json")
    finally:
        avoid.write_text(original, encoding="utf-8")
    assert json.loads(out)["result"]["summary"]["verified"] == sum(
        1 for p in planted if p.task == "avoid"
    )


def test_parquet_results_hold_the_same_rows(
    fleet: tuple[Path, Path, list[Planted]], tmp_path: Path
) -> None:
    import pyarrow.parquet as pq

    folder, mapping, _planted = fleet
    jsonl, parquet = tmp_path / "r.jsonl", tmp_path / "r.parquet"
    for target in (jsonl, parquet):
        run_cli(
            "verify",
            str(folder / "logs"),
            "--mission",
            str(mapping),
            "--jobs",
            "1",
            "--cache",
            str(tmp_path / "c"),
            "--results",
            str(target),
        )
    table = pq.read_table(parquet).to_pylist()
    rows = records(jsonl)
    assert [r["log"] for r in table] == [r["log"] for r in rows]
    assert [r["verdict"] for r in table] == [r["verdict"] for r in rows]
    assert [r["first_violation"] for r in table] == [r["first_violation"] for r in rows]


def test_exit_codes_and_errors(tmp_path: Path) -> None:
    folder = tmp_path / "logs"
    planted = generate(folder, 12)
    mapping = write_missions(tmp_path)
    satisfied = [p.path for p in planted if p.verdict == "satisfied"]
    assert satisfied
    code, out, _ = run_cli("verify", *map(str, satisfied), "--mission", str(mapping), "--no-cache")
    assert code == 0
    assert "satisfied" in out
    broken = folder / "broken.csv"
    broken.write_text("t,x,y\n0,1,1\n1,nan,1\n", encoding="utf-8")
    code, out, _ = run_cli(
        "verify",
        str(folder),
        "--mission",
        str(tmp_path / "avoid.yaml"),
        "--no-cache",
        "--jobs",
        "1",
    )
    assert code == 2
    assert "broken.csv: ERROR" in out
    assert "V003" in out
    # a log no rule of the mapping matches
    code, out, _ = run_cli(
        "verify", str(broken), str(planted[0].path), "--mission", str(mapping), "--no-cache"
    )
    assert code == 2
    assert "F004" in out
    code, _, _err = run_cli("verify", str(tmp_path / "empty"), "--mission", str(mapping))
    assert code == 2


def test_no_logs_and_missing_distributed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import sys

    (tmp_path / "none").mkdir()
    mapping = write_missions(tmp_path)
    code, _, err = run_cli("verify", str(tmp_path / "none"), "--mission", str(mapping))
    assert code == 2
    assert "F005" in err
    generate(tmp_path / "logs", 1)
    monkeypatch.setitem(sys.modules, "distributed", None)
    code, _, err = run_cli(
        "verify", str(tmp_path / "logs"), "--mission", str(mapping), "--dask", "tcp://127.0.0.1:1"
    )
    assert code == 2
    assert "F001" in err
    assert "tlmpc[fleet]" in err


def test_the_json_envelope_of_a_batch_is_valid(
    fleet: tuple[Path, Path, list[Planted]], tmp_path: Path
) -> None:
    from tlmpc.io.report import cli_output_errors

    folder, mapping, _ = fleet
    code, out, err = run_cli(
        "verify",
        str(folder / "logs"),
        "--mission",
        str(mapping),
        "--jobs",
        "1",
        "--json",
        "--cache",
        str(tmp_path / "c"),
    )
    assert code == 1
    document = json.loads(out)
    assert cli_output_errors(document) == []
    assert len(document["result"]["logs"]) == LOGS
    assert err.count("\n") >= LOGS  # the per-log lines go to stderr with --json


@pytest.mark.slow
def test_a_held_out_fleet_of_three_hundred_logs(tmp_path: Path) -> None:
    from distributed import Client, LocalCluster

    planted = generate(tmp_path / "logs", 300, seed=11)
    mapping = write_missions(tmp_path)
    base = ["verify", str(tmp_path / "logs"), "--mission", str(mapping)]
    rows = []
    for flags in (["--jobs", "1"], ["--jobs", "2"]):
        results = tmp_path / f"r{flags[1]}.jsonl"
        code, _, _ = run_cli(*base, *flags, "--no-cache", "--results", str(results))
        assert code == 1
        rows.append(records(results))
    with (
        LocalCluster(
            n_workers=1,
            processes=False,
            threads_per_worker=2,
            dashboard_address=":0",  # any free port: 8787 may be taken
            protocol="tcp://",
        ) as cluster,
        Client(cluster),
    ):
        results = tmp_path / "dask.jsonl"
        flags = ["--dask", cluster.scheduler_address, "--cache", str(tmp_path / "cache")]
        code, _, _ = run_cli(*base, *flags, "--results", str(results))
        assert code == 1
        rows.append(records(results))
    check_against_oracle(rows[0], planted)
    assert comparable(rows[0]) == comparable(rows[1]) == comparable(rows[2])
    code, out, _ = run_cli(*base, "--jobs", "2", "--cache", str(tmp_path / "cache"), "--json")
    assert json.loads(out)["result"]["summary"]["verified"] == 0


def test_first_violation_is_the_earliest(tmp_path: Path) -> None:
    """The shipped log enters the hazard at 18.89 s, again at 32.32 s, and a hole at 33.96 s
    (the verifier lists the hole first)."""
    root = Path(__file__).resolve().parents[2]
    results = tmp_path / "r.jsonl"
    code, _, _ = run_cli(
        "verify",
        str(root / "specs" / "logs" / "hazard-crossing.csv"),
        "--mission",
        str(root / "specs" / "reach-avoid.yaml"),
        "--no-cache",
        "--results",
        str(results),
    )
    assert code == 1
    (row,) = records(results)
    assert row["violations"][0]["conjunct"] == "workspace"
    first = row["first_violation"]
    assert first["conjunct"] == "G !hazard"
    assert first["t"] == pytest.approx(18.0 + 8.0 / 9.0)
    assert (first["x"], first["y"]) == (8.0, 2.0)


def test_a_cached_error_names_its_own_log(tmp_path: Path) -> None:
    # two logs with the same bytes, one bad sample: each record is told about its own file,
    # from the cache or not
    write_missions(tmp_path)  # (its missions: avoid.yaml among them)
    logs = tmp_path / "logs"
    logs.mkdir()
    for name in ("first.csv", "second.csv"):
        (logs / name).write_text("t,x,y\n0,1,1\n1,nan,1\n", encoding="utf-8")
    argv = ("verify", str(logs), "--mission", str(tmp_path / "avoid.yaml"), "--jobs", "1")
    cache = ("--cache", str(tmp_path / "cache"))
    for run in range(2):
        results = tmp_path / f"run{run}.jsonl"
        code, _, _ = run_cli(*argv, *cache, "--results", str(results))
        assert code == 2
        rows = records(results)
        assert [Path(r["log"]).name for r in rows] == ["first.csv", "second.csv"]
        for row in rows:
            assert row["verdict"] == "error"
            assert row["error"]["message"].startswith(row["log"] + ":"), row
        assert [r["cached"] for r in rows] == [run == 1, run == 1]
