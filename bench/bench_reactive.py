"""Reactive missions: synthesis time and strategy size against workspace size and sensors.

A warehouse floor (40 m x 20 m, shelves as holes, seven named places) meshed ever finer
(``options.max_area``, or small pillars as holes) from 2k to about 100k triangles, with 1 to 6
sensors; each sensor ``s_k`` adds "if you sense s_k then visit place_k" and the assumption
"G F !s_k", beside a patrol of two places and "never enter aisle while s_1".  A grid of rooms
shows what does grow: the number of regions (faces).  CPU seconds of this process, the median
of ``--rounds`` runs (fresh mission objects, the BDD manager new each time).

"synthesis" is what the synthesize stage does now: solve, the symbolic strategy, its reachable
size counted symbolically, and the explicit machine only when it has at most 10,000
transitions.  "explicit" (with ``--explicit-up-to N`` sensors) is what the stage did before:
solve and build the explicit machine (every input at every reachable node), ``--explicit-rounds``
runs.  "nodes" and "transitions" are the explicit machine's (before merging), counted.

    python bench/bench_reactive.py [--rounds 3] [--quick] [--explicit-up-to 6]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))

from workloads import grid_of_rooms

from tlmpc.abstraction import build_abstraction
from tlmpc.mission import load_mission_text
from tlmpc.reactive.synthesize import mission_game, synthesize
from tlmpc.synth.solver import Game, solve
from tlmpc.synth.strategy import extract
from tlmpc.synth.symbolic import Encoding

PLACES = {
    "dock": [1, 1, 4, 4],
    "charger": [1, 16, 4, 19],
    "station_a": [36, 16, 39, 19],
    "station_b": [36, 1, 39, 4],
    "packing": [18, 1, 22, 3],
    "office": [18, 17, 22, 19],
    "aisle": [12, 8, 28, 12],
}


def warehouse(
    max_area: float | None, sensors: int, pitch: float | None = None, min_angle: float | None = 20
) -> dict[str, Any]:
    """The warehouse mission with ``sensors`` sensors, meshed with ``max_area``; with
    ``pitch``, small pillars every ``pitch`` metres away from the places and shelves (a finer
    mesh whose faces stay the same).  With a minimum angle Triangle's Steiner points are
    capped (about 34k triangles here); ``min_angle=None`` meshes down to ``max_area``."""
    shelves = [
        {"rect": [x, y, x + 6, y + 1.5]} for x in (6.0, 14.0, 22.0, 30.0) for y in (5.0, 13.5)
    ]
    boxes = [s["rect"] for s in shelves] + list(PLACES.values())
    pillars = []
    if pitch is not None:
        for i in range(1, int(40 / pitch)):
            for j in range(1, int(20 / pitch)):
                x, y = i * pitch, j * pitch
                clear = all(
                    not (b[0] - 0.3 < x < b[2] + 0.3 and b[1] - 0.3 < y < b[3] + 0.3) for b in boxes
                )
                if clear:
                    pillars.append({"rect": [x - 0.04, y - 0.04, x + 0.04, y + 0.04]})
    names = [f"s{k + 1}" for k in range(sensors)]
    goals = ["dock", "charger", "packing", "office", "station_a", "station_b"]
    task = [
        "visit station_a, station_b infinitely often",
        "never enter aisle while s1",
        *(f"if you sense {s} then visit {goals[k]}" for k, s in enumerate(names)),
    ]
    return {
        "version": 1,
        "name": f"warehouse-{sensors}",
        "workspace": {"boundary": {"rect": [0, 0, 40, 20]}, "holes": shelves + pillars},
        "regions": {name: {"rect": box} for name, box in PLACES.items()},
        "sensors": dict.fromkeys(names),
        "assumptions": [f"G F !{s}" for s in names],
        "robot": {"start": [2.5, 2.5]},
        "options": {"min_angle": min_angle, "max_area": max_area},
        "task": task,
    }


def rooms(n: int, sensors: int) -> dict[str, Any]:
    """An n x n grid of rooms: n^2 + 1 faces; sensor k sends the robot to a far room."""
    document = grid_of_rooms(n)
    names = [f"s{k + 1}" for k in range(sensors)]
    far = n - 1
    document["sensors"] = dict.fromkeys(names)
    document["assumptions"] = [f"G F !{s}" for s in names]
    document["task"] = [
        f"visit r{far}_{far}, r0_0 infinitely often",
        *(f"if you sense {s} then visit r{k % n}_{far}" for k, s in enumerate(names)),
    ]
    document.pop("ltl", None)
    document["options"] = {"min_angle": None}
    return document


def measure(document: dict[str, Any], rounds: int, explicit_rounds: int = 0) -> dict[str, Any]:
    """Median CPU seconds of the abstraction and of synthesis (and of the explicit
    extraction it replaced, with ``explicit_rounds``), and the sizes."""
    text = yaml.safe_dump(document, sort_keys=False)
    meshing: list[float] = []
    solving: list[float] = []
    explicit: list[float] = []
    row: dict[str, Any] = {}
    for _ in range(rounds):
        mission = load_mission_text(text, f"{document['name']}.yaml")
        started = time.process_time()
        abstraction = build_abstraction(mission)
        meshed = time.process_time()
        found = synthesize(mission, abstraction)
        solved = time.process_time()
        meshing.append(meshed - started)
        solving.append(solved - meshed)
        row = {
            "triangles": abstraction.num_triangles,
            "faces": found.game.faces.count,
            "realizable": found.realizable,
            "nodes": found.size.nodes if found.size else 0,
            "transitions": found.size.transitions if found.size else 0,
            "diagram": len(found.symbolic.diagram.nodes) if found.symbolic else 0,
            "listed": found.strategy is not None,
            "fixpoint": found.solution.cpre_count,
        }
    for _ in range(explicit_rounds):
        mission = load_mission_text(text, f"{document['name']}.yaml")
        abstraction = build_abstraction(mission)
        started = time.process_time()
        game = mission_game(mission, abstraction)
        solution = solve(Game.build(game.spec, Encoding(game.spec)))
        if solution.realizable:
            extract(solution)
        explicit.append(time.process_time() - started)
    row["mesh s"] = statistics.median(meshing)
    row["synthesis s"] = statistics.median(solving)
    row["explicit s"] = statistics.median(explicit) if explicit else None
    return row


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="up to 22k triangles and 4 sensors")
    parser.add_argument(
        "--explicit-up-to",
        type=int,
        default=0,
        metavar="N",
        help="also time the explicit extraction (the former stage) up to N sensors",
    )
    parser.add_argument("--explicit-rounds", type=int, default=1)
    parser.add_argument(
        "--only-large", action="store_true", help="only the two meshes of about 100k triangles"
    )
    args = parser.parse_args()
    print(
        "| workload | sensors | triangles | faces | mesh CPU s | synthesis CPU s |"
        " explicit CPU s (before) | explicit / synthesis | fixpoint steps | strategy nodes |"
        " transitions | diagram nodes | listed | realizable |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|")

    def show(name: str, sensors: int, row: dict[str, Any]) -> None:
        before = row["explicit s"]
        ratio = f"{before / row['synthesis s']:.1f}x" if before is not None else "-"
        print(
            f"| {name} | {sensors} | {row['triangles']:,} | {row['faces']} | "
            f"{row['mesh s']:.3f} | {row['synthesis s']:.3f} | "
            f"{'-' if before is None else f'{before:.3f}'} | {ratio} | {row['fixpoint']} | "
            f"{row['nodes']:,} | {row['transitions']:,} | {row['diagram']:,} | "
            f"{'yes' if row['listed'] else 'no'} | {row['realizable']} |",
            flush=True,
        )

    def explicit_rounds(sensors: int) -> int:
        return args.explicit_rounds if sensors <= args.explicit_up_to else 0

    meshes: list[tuple[str, float | None, float | None, float | None]] = [
        ("warehouse, max_area 0.5", 0.5, None, 20),
        ("warehouse, pillars every 1 m", None, 1.0, 20),
        ("warehouse, max_area 0.05", 0.05, None, 20),
    ]
    if not args.quick:
        meshes += [
            ("warehouse, pillars every 0.35 m", None, 0.35, 20),
            ("warehouse, max_area 0.011, no angle bound", 0.011, None, None),
            ("warehouse, pillars every 0.18 m", None, 0.18, 20),
        ]
    if args.only_large:
        meshes = meshes[-2:]
    for name, area, pitch, angle in meshes:
        document = warehouse(area, 2, pitch, angle)
        show(name, 2, measure(document, args.rounds, explicit_rounds(2)))
    if args.only_large:
        return 0
    for sensors in range(1, 5 if args.quick else 7):
        show(
            "warehouse, max_area 0.5",
            sensors,
            measure(warehouse(0.5, sensors), args.rounds, explicit_rounds(sensors)),
        )
    for n in (4, 8) if args.quick else (4, 8, 12):
        show(f"{n}x{n} rooms", 2, measure(rooms(n, 2), args.rounds))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
