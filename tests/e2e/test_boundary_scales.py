"""Boundary starts at every scale, under both conventions, checked independently.

Two regions sharing an edge, scaled from micrometres to thousands of kilometres, moved up to
1e8 from the origin, with max_speed from 1e-9 to 1e6; the start is a vertex of the mesh or a
point on one of its edges (a region corner, the shared edge, the workspace boundary, or a
triangulation edge inside a region).  Every compiled output passes the independent check of
``tests/oracles/trace_check.py`` (vertex conditions in rationals, exact flow by scipy's expm,
speed bound, the task by its definition under the mission's convention).  Under the
right-continuous convention every verdict is the face-graph oracle's; under the closed one the
tasks drawn always have a plan (none forbids a handover), so a "no plan" fails.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import yaml
from face_graph import face_graph, satisfiable_on
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from trace_check import check_output

from tlmpc.abstraction import build_abstraction
from tlmpc.api import compile as compile_mission
from tlmpc.base.errors import NoPlanError
from tlmpc.ltl.parser import parse_ltl
from tlmpc.ltl.printer import to_spin
from tlmpc.mission import load_mission_text

UNIT_REGIONS = {
    "a": [[2, 2], [5, 2], [5, 8], [2, 8]],
    "b": [[5, 2], [8, 2], [8, 8], [5, 8]],
}
RIGHT_TASKS = ["F(a & F b)", "b & F a", "G !a & F b", "a & G !b", "!a U b", "G F a & G F b"]
CLOSED_TASKS = ["F(a & F b)", "F(a & b)", "G F a & G F b", "F(b & F !b)"]


def _unit_mesh_points() -> list[tuple[float, float]]:
    """Vertices and edge midpoints of the unit map's mesh (10 x 10)."""
    document = _document((1.0, 0.7), 10.0, (0.0, 0.0), 1.0, "F a", "right")
    built = build_abstraction(load_mission_text(yaml.safe_dump(document), "m.yaml"))
    points: set[tuple[float, float]] = set()
    for corners in built.vertices[built.triangles]:
        for i in range(3):
            p, q = corners[i], corners[(i + 1) % 3]
            points.add((float(p[0]), float(p[1])))
            points.add((float((p[0] + q[0]) / 2), float((p[1] + q[1]) / 2)))
    return sorted(points)


def _document(
    start: tuple[float, float],
    size: float,
    offset: tuple[float, float],
    speed: float,
    ltl: str,
    boundary: str,
) -> dict[str, Any]:
    def move(point: Sequence[float]) -> list[float]:
        return [offset[0] + size * point[0] / 10, offset[1] + size * point[1] / 10]

    return {
        "version": 1,
        "name": "edge-scales",
        "workspace": {"boundary": [move(p) for p in [[0, 0], [10, 0], [10, 10], [0, 10]]]},
        "regions": {n: [move(p) for p in r] for n, r in UNIT_REGIONS.items()},
        "robot": {"start": move(start), "max_speed": speed},
        "ltl": ltl,
        "options": {"boundary": boundary},
    }


UNIT_POINTS = _unit_mesh_points()


def _face_oracle(document: dict[str, Any]) -> bool:
    graph = face_graph(
        [tuple(p) for p in document["workspace"]["boundary"]],
        [],
        {n: [tuple(p) for p in r] for n, r in document["regions"].items()},
        tuple(document["robot"]["start"]),
        on_boundary=True,
    )
    return bool(satisfiable_on(graph, to_spin(parse_ltl(document["ltl"]))))


@settings(
    deadline=None,
    max_examples=max(6, settings().max_examples // 10),
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    start=st.sampled_from(UNIT_POINTS),
    size_exponent=st.integers(-5, 6),
    speed_exponent=st.integers(-9, 6),
    offset_exponent=st.integers(0, 8),
    closed=st.booleans(),
    task=st.integers(0, 100),
)
def test_boundary_starts_are_sound_at_any_scale(
    start: tuple[float, float],
    size_exponent: int,
    speed_exponent: int,
    offset_exponent: int,
    closed: bool,
    task: int,
) -> None:
    size, speed = 10.0**size_exponent, 10.0**speed_exponent
    # Float64 holds a map of this size this far out only down to ~1e-10 of its size.
    reach = min(10.0**offset_exponent, size * 1e6) if offset_exponent else 0.0
    tasks = CLOSED_TASKS if closed else RIGHT_TASKS
    ltl = tasks[task % len(tasks)]
    document = _document(
        start, size, (reach, -reach / 2), speed, ltl, "closed" if closed else "right"
    )
    try:
        result = compile_mission(document, until="verify")
    except NoPlanError:
        assert not closed, ("a closed-convention task without a plan", ltl, start)
        assert not _face_oracle(document), ("no plan, yet a trajectory exists", ltl, start)
        return
    check_output(dict(result.artifacts), speed, size)
    if not closed:
        assert _face_oracle(document), ("a plan, yet no trajectory exists", ltl, start)
