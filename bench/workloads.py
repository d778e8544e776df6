"""Mission generators for the benchmarks (written as YAML, compiled like a user's file)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml


def grid_of_rooms(n: int, *, room: float = 0.5, pitch: float = 1.0) -> dict[str, Any]:
    """An n x n grid of square rooms in a square; start in one corner room, visit two far ones.

    With triangulation quality off the constrained Delaunay triangulation has exactly
    2 V - 6 = 8 n^2 + 2 triangles (V = 4 + 4 n^2 vertices, a 4-vertex hull).
    """
    size = n * pitch
    offset = (pitch - room) / 2.0
    regions = {}
    for i in range(n):
        for j in range(n):
            x0 = i * pitch + offset
            y0 = j * pitch + offset
            regions[f"r{i}_{j}"] = {"rect": [x0, y0, x0 + room, y0 + room]}
    far = n - 1
    return {
        "version": 1,
        "name": f"grid-{n}x{n}",
        "workspace": {"boundary": {"rect": [0.0, 0.0, size, size]}},
        "regions": regions,
        "robot": {"start": [pitch / 2.0, pitch / 2.0], "max_speed": 1.0},
        "task": [f"visit r{far}_{far // 3} and r{far // 3}_{far}"],
        "options": {"min_angle": None, "max_area": None},
    }


def sequence_avoiding(rooms: int = 10, obstacles: int = 50) -> dict[str, Any]:
    """Visit ``rooms`` rooms in order while avoiding ``obstacles`` small obstacle regions."""
    columns = 10
    regions: dict[str, Any] = {}
    for k in range(rooms):
        x0 = 1.0 + 4.0 * (k % 5)
        y0 = 1.0 + 8.0 * (k // 5)
        regions[f"room{k}"] = {"rect": [x0, y0, x0 + 1.5, y0 + 1.5]}
    for k in range(obstacles):
        x0 = 0.6 + 2.0 * (k % columns)
        y0 = 4.0 + 0.9 * (k // columns) + (0.35 if (k // columns) % 2 else 0.0)
        regions[f"obs{k}"] = {"rect": [x0, y0, x0 + 0.5, y0 + 0.3]}
    sequence = " then ".join(f"room{k}" for k in range(rooms))
    avoid = ", ".join(f"obs{k}" for k in range(obstacles))
    return {
        "version": 1,
        "name": f"sequence-{rooms}-avoid-{obstacles}",
        "workspace": {"boundary": {"rect": [0.0, 0.0, 21.0, 18.0]}},
        "regions": regions,
        "robot": {"start": [1.7, 1.7], "max_speed": 1.0},
        "task": [f"visit {sequence}", f"avoid {avoid}"],
    }


def write_mission(document: dict[str, Any], directory: Path) -> Path:
    """Write ``document`` as ``<name>.yaml`` in ``directory`` and return the path."""
    path = directory / f"{document['name']}.yaml"
    path.write_text(yaml.safe_dump(document, sort_keys=False), encoding="utf-8")
    return path


def grid_task(n: int, task: str, count: int) -> dict[str, Any]:
    """The ``n x n`` grid of rooms (:func:`grid_of_rooms`) with a harder task over ``count``
    rooms spread over the map: ``"cover"`` visits them all while avoiding the room in the
    middle, ``"patrol"`` visits each of them again and again."""
    document = grid_of_rooms(n)
    rooms = spread_rooms(n, count)
    if task == "cover":
        middle = f"r{n // 2}_{n // 2}"
        document["task"] = [f"visit {' and '.join(rooms)}", f"avoid {middle}"]
    elif task == "patrol":
        document["task"] = [f"patrol {', '.join(rooms)}"]
    else:
        raise ValueError(f"unknown task {task!r}")
    document["name"] = f"grid-{n}x{n}-{task}-{count}"
    return document


def spread_rooms(n: int, count: int) -> list[str]:
    """``count`` rooms of the ``n x n`` grid spread over it (a deterministic pseudo-random
    choice: a linear congruential walk, so the bench needs no seeded generator), never the
    start room nor the middle one."""
    chosen: list[str] = []
    state = 12345
    taken = {(0, 0), (n // 2, n // 2)}
    while len(chosen) < count:
        state = (state * 1103515245 + 12345) % (1 << 31)
        i, j = state % n, (state // n) % n
        if (i, j) in taken:
            continue
        taken.add((i, j))
        chosen.append(f"r{i}_{j}")
    return chosen
