"""Fleet verification benchmark: per-core throughput, 1 vs 2 workers, the 24 h log's memory,
and the streamed verifier against a numpy floor.

Workload: the patrol mission (``specs/patrol.yaml``: ``G F alpha & G F bravo & G F charlie &
G !lake``) and logs of a robot driving its loop at 0.5 m/s, sampled at 50 Hz.

* **floor**: the 1 h log (180,000 poses) read with ``np.loadtxt``, labelled with
  ``shapely.contains_xy`` (one call per region) and checked (each ``G F`` region visited, the
  lake never entered) -- the least any verifier must do with the same samples; against it the
  streamed verifier in the same process (CPU seconds, best of ``--rounds``) and the whole-log
  one, and ``tlmpc verify`` of the log from the shell (CPU of the child).
* **throughput**: ``--logs`` 10-minute logs verified with ``--jobs 1`` and ``--jobs 2``
  (fresh ``tlmpc`` processes, no cache): wall seconds, CPU seconds, poses per CPU second.
* **memory**: the 24 h log (4.32M poses) verified by ``tlmpc verify`` in a child process: its
  peak resident memory (``ru_maxrss``) and CPU seconds.

Run: ``python bench/bench_fleet.py [--logs 40] [--rounds 3] [--no-24h]``.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench.tables import markdown_table  # noqa: E402

MISSION = ROOT / "specs" / "patrol.yaml"
WAYPOINTS = np.array([[2, 2], [12, 2], [12, 7], [7, 9], [2, 7], [2, 2]], dtype=float)


def write_log(path: Path, hours: float, hz: float = 50.0, phase: float = 0.0) -> int:
    """The patrol loop at 0.5 m/s for ``hours``, sampled at ``hz``; returns the pose count."""
    count = int(hours * 3600 * hz)
    lengths = np.linalg.norm(np.diff(WAYPOINTS, axis=0), axis=1)
    along = np.concatenate([[0.0], np.cumsum(lengths)])
    with open(path, "w", encoding="utf-8") as stream:
        stream.write("t,x,y\n")
        for start in range(0, count, 500_000):
            t = np.arange(start, min(count, start + 500_000)) / hz
            s = (0.5 * t + phase) % along[-1]
            leg = np.searchsorted(along, s, side="right") - 1
            f = (s - along[leg]) / lengths[leg]
            p = WAYPOINTS[leg] + f[:, None] * (WAYPOINTS[leg + 1] - WAYPOINTS[leg])
            np.savetxt(stream, np.column_stack([t, p]), fmt="%.3f", delimiter=",")
    return count


def floor(path: Path) -> float:
    """CPU seconds to read, label and check the samples with numpy and shapely alone."""
    import shapely
    import yaml

    began = time.process_time()
    samples = np.loadtxt(path, delimiter=",", skiprows=1)
    mission = yaml.safe_load(MISSION.read_text())
    verdicts = {}
    for name, shape in mission["regions"].items():
        if isinstance(shape, dict):
            x0, y0, x1, y1 = shape["rect"]
            shape = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
        inside = shapely.contains_xy(shapely.Polygon(shape), samples[:, 1], samples[:, 2])
        verdicts[name] = bool(inside.any())
    assert not verdicts["lake"]
    return time.process_time() - began


def streamed(path: Path) -> float:
    from tlmpc.fleet.stream import verify_log
    from tlmpc.verify.trace_input import mission_document

    document = mission_document(path, MISSION)
    began = time.process_time()
    verify_log(path, document)
    return time.process_time() - began


def whole(path: Path) -> float:
    from tlmpc.verify import from_csv, verify_trace

    began = time.process_time()
    verify_trace(from_csv(path, MISSION, None))
    return time.process_time() - began


def child(argv: list[str]) -> dict[str, float]:
    """Run ``tlmpc`` in a fresh process: wall and CPU seconds, peak resident MB."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    began = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "tlmpc", *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        check=False,
    )
    wall = time.perf_counter() - began
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall": wall, "cpu": cpu, "peak_mb": after.ru_maxrss / 1024}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--logs", type=int, default=40, help="10-minute logs for throughput")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--no-24h", action="store_true", help="skip the 24 h log")
    args = parser.parse_args()
    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        hour = work / "hour.csv"
        poses = write_log(hour, 1.0)
        floors = min(floor(hour) for _ in range(args.rounds))
        fast = min(streamed(hour) for _ in range(args.rounds))
        slow = min(whole(hour) for _ in range(args.rounds))
        shell = min(
            (
                child(["verify", str(hour), "--mission", str(MISSION), "--no-cache", "--jobs", "1"])
                for _ in range(args.rounds)
            ),
            key=lambda r: r["cpu"],
        )
        rows.append(
            {
                "measure": "1 h log, 50 Hz (180,000 poses), in-process CPU s",
                "numpy floor": f"{floors:.3f}",
                "streamed": f"{fast:.3f} ({fast / floors:.1f} x floor)",
                "whole-log": f"{slow:.3f} ({slow / floors:.1f} x floor)",
                "shell (tlmpc verify, CPU s)": f"{shell['cpu']:.2f}",
            }
        )
        print(markdown_table(rows))
        print()
        logs = work / "logs"
        logs.mkdir()
        for index in range(args.logs):
            write_log(logs / f"log{index:03d}.csv", 1 / 6, phase=index * 1.7)
        total = args.logs * int(3600 / 6 * 50)
        timing = []
        for jobs in (1, 2):
            result = child(
                ["verify", str(logs), "--mission", str(MISSION), "--no-cache", "--jobs", str(jobs)]
            )
            timing.append(
                {
                    "workers": jobs,
                    "logs": args.logs,
                    "wall s": f"{result['wall']:.2f}",
                    "CPU s": f"{result['cpu']:.2f}",
                    "logs / wall s": f"{args.logs / result['wall']:.1f}",
                    "poses / CPU s": f"{total / result['cpu']:,.0f}",
                }
            )
        speedup = float(timing[0]["wall s"]) / float(timing[1]["wall s"])
        print(markdown_table(timing))
        print(f"\nspeed-up 1 -> 2 workers (wall): {speedup:.2f}; load average {os.getloadavg()}")
        if not args.no_24h:
            day = work / "day.csv"
            write_log(day, 24.0)
            result = child(["verify", str(day), "--mission", str(MISSION)])
            print()
            print(
                markdown_table(
                    [
                        {
                            "log": "24 h, 50 Hz (4,320,000 poses)",
                            "peak MB": f"{result['peak_mb']:.0f}",
                            "CPU s": f"{result['cpu']:.2f}",
                            "wall s": f"{result['wall']:.2f}",
                            "poses / CPU s": f"{4_320_000 / result['cpu']:,.0f}",
                        }
                    ]
                )
            )
        del poses


if __name__ == "__main__":
    main()
