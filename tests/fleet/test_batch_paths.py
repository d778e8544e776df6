"""Where a batch's paths are read: relative log and cache paths are the batch's, whichever
folder a Dask worker was started in; and the rows keep the order the logs were named in."""

from __future__ import annotations

import io
import json
import os
from pathlib import Path
from typing import Any

import pytest
from fleet_data import AVOID_MISSION

from tlmpc.cli import main

# a log that enters the lake (x from 8 at t=8) and one whose second sample is not a number
CROSSING = "t,x,y\n" + "".join(f"{t},{t},5\n" for t in range(12))
BROKEN = "t,x,y\n0,1,1\n1,nan,1\n"


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def rows_of(path: Path) -> list[dict[str, Any]]:
    rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]
    return [{k: v for k, v in row.items() if k not in ("seconds", "cached")} for row in rows]


def test_a_dask_worker_elsewhere_reads_relative_paths_in_the_batch_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from distributed import Client, LocalCluster

    (tmp_path / "avoid.yaml").write_text(AVOID_MISSION, encoding="utf-8")
    (tmp_path / "logs").mkdir()
    (tmp_path / "logs" / "crossing.csv").write_text(CROSSING, encoding="utf-8")
    (tmp_path / "logs" / "broken.csv").write_text(BROKEN, encoding="utf-8")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(tmp_path)
    batch = ("verify", "logs", "--mission", "avoid.yaml")
    code, _, _ = run_cli(*batch, "--jobs", "1", "--no-cache", "--results", "local.jsonl")
    assert code == 2
    local = rows_of(tmp_path / "local.jsonl")
    with (
        LocalCluster(
            n_workers=1,
            processes=True,
            threads_per_worker=1,
            dashboard_address=":0",  # any free port: 8787 may be taken
            worker_dashboard_address=":0",
        ) as cluster,
        Client(cluster) as client,
    ):
        # the worker works in another folder, as one started by `dask worker` elsewhere does
        client.run(os.chdir, str(elsewhere))
        flags = ("--dask", cluster.scheduler_address, "--cache", "cache")
        code, _, _ = run_cli(*batch, *flags, "--results", "dask.jsonl")
    assert code == 2
    assert rows_of(tmp_path / "dask.jsonl") == local
    assert [row["verdict"] for row in local] == ["error", "violated"]
    broken, crossing = local
    assert broken["error"]["message"].startswith("logs/broken.csv:3:3: error[V003]")
    assert crossing["first_violation"]["t"] == pytest.approx(8.0)
    # the worker stored both records in the batch's cache folder, none in its own
    assert len(list((tmp_path / "cache").rglob("*.json"))) == 2
    assert not (elsewhere / "cache").exists()


def test_a_log_named_twice_has_a_row_at_each_place_it_was_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "avoid.yaml").write_text(AVOID_MISSION, encoding="utf-8")
    folder = tmp_path / "logs"
    folder.mkdir()
    for name in ("a.csv", "b.csv", "c.csv"):
        (folder / name).write_text(CROSSING, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    named = ["logs/c.csv", "logs/b.csv", "logs/c.csv", "logs"]
    code, _, _ = run_cli(
        "verify", *named, "--mission", "avoid.yaml", "--no-cache", "--results", "r.jsonl"
    )
    assert code == 1
    expected = ["logs/c.csv", "logs/b.csv", "logs/c.csv", "logs/a.csv", "logs/b.csv", "logs/c.csv"]
    assert [row["log"] for row in rows_of(tmp_path / "r.jsonl")] == expected
