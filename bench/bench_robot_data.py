"""Robot-data benchmark: real nav2 maps (with keepout masks) imported, checked, compiled, verified.

For each map in the shared data folder (``$TLMPC_SHARED_DATA``, else ``<repo>/../shared/data``;
skipped when absent): ``tlmpc import-map`` (with the keepout and speed masks where the map has
them), ``tlmpc check``, ``tlmpc compile`` (which verifies its trace) with the task "avoid keepout,
visit a goal", each in a fresh interpreter (wall time); the workspace area against the map's
free cells (all of them, and the main piece's against the free piece the robot is in), and
how many further free pieces the workspace keeps.  Then each form of the
real Jackal bag (ROS 1, ROS 2 sqlite3, ROS 2 MCAP, the bare .mcap file) and a CSV written from
it are verified against a mission, and the verdicts and trajectories compared.

Run: ``python bench/bench_robot_data.py [--radius R]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench.tables import markdown_table  # noqa: E402
from tlmpc.importers.maps import ImportedMap  # noqa: E402

MAPS = (
    ("depot", "depot_keepout", "depot_speed"),
    ("warehouse", "warehouse_keepout", "warehouse_speed"),
    ("tb3_sandbox", None, None),
    ("smoothers_world", None, None),
)


def shared_data() -> Path:
    """The shared data folder (environment override, else beside the repository)."""
    override = os.environ.get("TLMPC_SHARED_DATA")
    return Path(override) if override else ROOT.parent / "shared" / "data"


def _tlmpc(*argv: str) -> tuple[float, subprocess.CompletedProcess[str]]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    started = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "tlmpc", *argv], capture_output=True, text=True, env=env, check=False
    )
    return time.perf_counter() - started, done


def _goal(imported: ImportedMap) -> tuple[float, float, float, float]:
    """A 1 m square of free space far from the start (the region to visit)."""
    from shapely.geometry import Point, Polygon
    from shapely.ops import polylabel

    from tlmpc.importers.mission import default_start
    from tlmpc.importers.polygonize import polygons

    free: Any = Polygon(imported.boundary, imported.holes)
    for name in imported.groups.get("keepout", ()):
        free = free.difference(Polygon(imported.regions[name]))
    start = Point(default_start(imported))
    away = free.difference(start.buffer(0.25 * (free.area**0.5)))
    piece = max(polygons(away) or polygons(free), key=lambda p: p.area)
    centre = polylabel(piece, tolerance=0.05)
    return centre.x - 0.5, centre.y - 0.5, centre.x + 0.5, centre.y + 0.5


def map_rows(data: Path, radius: float, work: Path) -> list[dict[str, Any]]:
    """Import, check, compile and verify each real map."""
    from shapely.geometry import Polygon

    from tlmpc.importers.maps import ImportSettings, free_geometry, import_map
    from tlmpc.importers.occupancy import read_map
    from tlmpc.importers.polygonize import polygons

    rows = []
    for name, keepout, speed in MAPS:
        maps = data / "maps"
        if not (maps / f"{name}.yaml").is_file():
            continue
        masks: list[str] = []
        if keepout:
            masks += ["--keepout", str(maps / f"{keepout}.yaml")]
        if speed:
            masks += ["--speed", str(maps / f"{speed}.yaml")]
        settings = ImportSettings(radius=radius)
        keep_path = maps / f"{keepout}.yaml" if keepout else None
        speed_path = maps / f"{speed}.yaml" if speed else None
        started = time.perf_counter()
        draft = import_map(maps / f"{name}.yaml", settings, keepout=keep_path, speed=speed_path)
        seconds_import = time.perf_counter() - started
        goal = _goal(draft)
        mission = work / f"{name}.yaml"
        tasks = ["--task", "visit goal"] + (["--task", "avoid keepout"] if keepout else [])
        _, done = _tlmpc(
            "import-map",
            str(maps / f"{name}.yaml"),
            *masks,
            "--radius",
            str(radius),
            "--region",
            "goal",
            *(repr(v) for v in goal),
            *tasks,
            "-o",
            str(mission),
        )
        assert done.returncode == 0, done.stderr
        seconds_check, checked = _tlmpc("check", str(mission))
        seconds_compile, compiled = _tlmpc(
            "compile", str(mission), "-o", str(work / name), "--force", "--until", "verify"
        )
        verdict = (
            json.loads((work / name / "verdict.json").read_text())
            if compiled.returncode == 0
            else {}
        )
        grid = read_map(maps / f"{name}.yaml")
        imported = import_map(maps / f"{name}.yaml", ImportSettings(radius=0.0))
        main_piece = max(polygons(free_geometry(grid)), key=lambda p: p.area).area
        summary = (
            json.loads((work / name / "summary.json").read_text())
            if compiled.returncode == 0
            else {}
        )
        triangles = next(
            (
                s["sizes"]["triangles"]
                for s in summary.get("stages", [])
                if s["name"] == "abstraction"
            ),
            "",
        )
        ok_check = "ok" if checked.returncode == 0 else "FAIL"
        ok_compile = "ok" if compiled.returncode == 0 else "FAIL"
        ratio_all = 100 * imported.workspace_area / imported.free_cells_area
        # the main piece alone against the largest exact free piece (the robot's, at r=0)
        ratio_piece = 100 * Polygon(imported.boundary, imported.holes).area / main_piece
        rows.append(
            {
                "map": name,
                "cells": f"{grid.shape[1]}x{grid.shape[0]}",
                "import s (in-process)": f"{seconds_import:.2f}",
                "check s": f"{seconds_check:.2f} ({ok_check})",
                "compile+verify s": f"{seconds_compile:.2f} ({ok_compile})",
                "verdict": "satisfied" if verdict.get("satisfied") else "VIOLATED/none",
                "area / free cells (r=0)": f"{ratio_all:.2f}%",
                "main piece / robot's free piece (r=0)": f"{ratio_piece:.2f}%",
                "further pieces (r=0 / r)": f"{len(imported.components)} / {len(draft.components)}",
                "triangles": triangles,
            }
        )
    return rows


def bag_rows(data: Path, work: Path) -> list[dict[str, Any]]:
    """Every form of the Jackal bag, and a CSV written from it, against one mission."""
    import numpy as np

    from tlmpc.importers.logs import read_log

    bags = data / "bags"
    forms = {
        "ROS 1 .bag": bags / "jackal_odometry.bag",
        "ROS 2 sqlite3": bags / "jackal_odometry_ros2_sqlite3",
        "ROS 2 MCAP": bags / "jackal_odometry_ros2_mcap",
        ".mcap file": bags / "jackal_odometry_ros2_mcap" / "rl_test2_mcap.mcap",
    }
    if not forms["ROS 1 .bag"].exists():
        return []
    reference = read_log(forms["ROS 1 .bag"]).samples
    csv = work / "jackal.csv"
    csv.write_text("time,x,y\n" + "".join(f"{t!r},{x!r},{y!r}\n" for t, x, y in reference.tolist()))
    forms["CSV"] = csv
    mission = work / "jackal_mission.yaml"
    mission.write_text(
        "version: 1\nworkspace: {boundary: {rect: [-20, -20, 20, 20]}}\n"
        "regions:\n  near_start: {rect: [-1, -1, 1, 1]}\n  far: {rect: [3, -2, 6, 2]}\n"
        "robot: {start: [0, 0]}\ntask: [visit far then return to near_start]\n"
    )
    rows = []
    for label, path in forms.items():
        seconds, done = _tlmpc("verify", str(path), "--mission", str(mission), "--json")
        verdict = (json.loads(done.stdout)["result"] or {}) if done.stdout else {}
        samples = read_log(path).samples
        rows.append(
            {
                "log": label,
                "samples": len(samples),
                "same trajectory": bool(np.array_equal(samples, reference)),
                "exit": done.returncode,
                "robustness": verdict.get("robustness"),
                "verify s": f"{seconds:.2f}",
            }
        )
    return rows


def main() -> None:
    """Print the two tables."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--radius", type=float, default=0.0)
    args = parser.parse_args()
    data = shared_data()
    if not data.is_dir():
        print(f"no shared data at {data}: nothing to measure")
        return
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        print(markdown_table(map_rows(data, args.radius, work)))
        print()
        print(markdown_table(bag_rows(data, work)))


if __name__ == "__main__":
    main()
