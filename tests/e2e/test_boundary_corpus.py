"""Adversarial missions at the edges: boundary starts, closed-convention handovers, scales.

Every compile must end in a plan (exit 0) or a "no plan" (exit 1), never an internal error.
Every compiled output passes the independent check of ``tests/oracles/trace_check.py``
(vertex conditions in rationals, exact flow, speed bound, the task by its definition under the
mission's convention).  Every verdict under the right-continuous convention is the face-graph
oracle's (Spot and shapely, starting from every face whose closure holds the start); every
"no plan" under the closed convention is confirmed by the elementary fact that forces it.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pytest
import shapely
from face_graph import face_graph, satisfiable_on
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from trace_check import check_output

from tlmpc.abstraction import build_abstraction
from tlmpc.api import compile as compile_mission
from tlmpc.base.errors import NoPlanError, TlmpcError
from tlmpc.ltl.parser import parse_ltl
from tlmpc.ltl.printer import to_spin
from tlmpc.mission import load_mission_text

BASE: dict[str, Any] = {
    "version": 1,
    "name": "edges",
    "workspace": {"boundary": [[0, 0], [10, 0], [10, 10], [0, 10]]},
    "regions": {
        "a": [[2, 2], [5, 2], [5, 8], [2, 8]],
        "b": [[5, 2], [8, 2], [8, 8], [5, 8]],
    },
    "robot": {"start": [5, 5], "max_speed": 1.0},
    "ltl": "F a",
}


def mission(
    ltl: str,
    start: tuple[float, float],
    *,
    boundary: str = "right",
    regions: dict[str, Any] | None = None,
    speed: float = 1.0,
    options: dict[str, Any] | None = None,
) -> dict[str, Any]:
    document = copy.deepcopy(BASE)
    document["ltl"] = ltl
    document["robot"] = {"start": list(start), "max_speed": speed}
    if regions is not None:
        document["regions"] = regions
    document["options"] = {"boundary": boundary, **(options or {})}
    return document


def face_oracle(document: dict[str, Any]) -> bool:
    """Whether some trajectory satisfies the task (right-continuous convention)."""
    graph = face_graph(
        [tuple(p) for p in document["workspace"]["boundary"]],
        [],
        {n: [tuple(p) for p in r] for n, r in document["regions"].items()},
        tuple(document["robot"]["start"]),
        on_boundary=True,
    )
    return bool(satisfiable_on(graph, to_spin(parse_ltl(document["ltl"]))))


def compiled(document: dict[str, Any]) -> dict[str, Any] | None:
    """The artifacts, or None for "no plan"; any other failure fails the test."""
    failure: TlmpcError | None = None
    try:
        result = compile_mission(document, until="verify")
    except TlmpcError as exc:
        failure = exc
    if failure is None:
        return dict(result.artifacts)
    assert isinstance(failure, NoPlanError), [d.format() for d in failure.diagnostics]
    return None


def checked(document: dict[str, Any], size: float = 10.0) -> dict[str, Any] | None:
    artifacts = compiled(document)
    if artifacts is not None:
        check_output(artifacts, float(document["robot"]["max_speed"]), size)
    return artifacts


RIGHT_CASES = [
    # start on the edge shared by a and b
    ("F(a & F b)", (5, 5)),
    ("b & F a", (5, 5)),
    ("a & F b", (5, 5)),
    ("a & G !b", (5, 5)),
    ("G !a & F b", (5, 5)),
    ("G !a & G !b & F a", (5, 5)),
    # on a corner of a (a triangulation vertex) and of both regions
    ("a & F b", (2, 2)),
    ("!a & !b & F(a & F b)", (5, 2)),
    ("b & F a & G !(a & b)", (5, 8)),
    # on the workspace boundary
    ("F b", (0, 5)),
    ("G !a & F b", (0, 5)),
]


@pytest.mark.parametrize(("ltl", "start"), RIGHT_CASES)
def test_right_convention_boundary_starts(ltl: str, start: tuple[float, float]) -> None:
    document = mission(ltl, start)
    assert (checked(document) is not None) == face_oracle(document), ltl


CLOSED_CASES = [
    # (task, start, plan expected)
    ("G !(a & b) & F b", (3, 5), True),  # must route around the shared edge
    ("F(a & b)", (3, 5), True),  # the handover instant is in both
    ("F(a & b) & F(!a & !b)", (3, 5), True),
    ("F(a & F b)", (5, 5), True),
    ("a & b & F !a", (5, 5), True),  # the start point is in both closures
    ("a & F(b & !a)", (2, 2), True),
]


@pytest.mark.parametrize(("ltl", "start", "expected"), CLOSED_CASES)
def test_closed_convention_handovers(ltl: str, start: tuple[float, float], expected: bool) -> None:
    assert (checked(mission(ltl, start, boundary="closed")) is not None) is expected


def test_closed_start_on_a_forbidden_boundary_has_no_plan() -> None:
    """Under the closed convention a start on a's boundary is in a at t = 0."""
    document = mission("G !a & F b", (5, 5), boundary="closed")
    a = shapely.Polygon(document["regions"]["a"])
    assert shapely.intersects(a, shapely.Point(5, 5))  # the fact that forbids every plan
    with pytest.raises(NoPlanError) as caught:
        compile_mission(document, until="verify")
    assert caught.value.diagnostics[0].code == "P002"
    # the same start under the right-continuous convention moves into b at once
    assert checked(mission("G !a & F b", (5, 5))) is not None


def test_closed_handover_needed_but_forbidden_has_no_plan() -> None:
    """a and b fill the workspace and meet along one edge: reaching b from a crosses it, and
    every instant on it is in a & b."""
    regions = {
        "a": [[0, 0], [5, 0], [5, 10], [0, 10]],
        "b": [[5, 0], [10, 0], [10, 10], [5, 10]],
    }
    document = mission("G !(a & b) & F b", (2, 5), boundary="closed", regions=regions)
    free = shapely.Polygon(document["workspace"]["boundary"])
    a, b = shapely.Polygon(regions["a"]), shapely.Polygon(regions["b"])
    assert shapely.union(a, b).equals(free)  # no way around
    assert shapely.intersection(a, b).length == 10  # they meet along the whole edge
    assert compiled(document) is None
    assert checked(mission("G !(a & b) & F b", (2, 5), regions=regions)) is not None


@pytest.mark.parametrize("speed", [1e-9, 1e-3, 1e6])
@pytest.mark.parametrize("boundary", ["right", "closed"])
def test_extreme_speeds_from_a_shared_edge(speed: float, boundary: str) -> None:
    assert checked(mission("F(a & F b)", (5, 5), boundary=boundary, speed=speed)) is not None


def test_needle_triangles_without_quality() -> None:
    regions = {
        "a": [[1, 1], [9, 1], [9, 1.001], [1, 1.001]],
        "b": [[1, 9], [9, 8.999], [9, 9], [1, 9]],
    }
    document = mission("F(a & F b)", (1, 1), regions=regions, options={"min_angle": None})
    assert checked(document) is not None


def _mesh_points(document: dict[str, Any]) -> list[tuple[float, float]]:
    """Vertices and edge midpoints of the mission's mesh, away from the outer boundary."""
    built = build_abstraction(load_mission_text(_yaml(document), "m.yaml"))
    points: list[tuple[float, float]] = []
    for corners in built.vertices[built.triangles]:
        for i in range(3):
            p, q = corners[i], corners[(i + 1) % 3]
            points.append((float(p[0]), float(p[1])))
            points.append((float((p[0] + q[0]) / 2), float((p[1] + q[1]) / 2)))
    return sorted({p for p in points if 0 < p[0] < 10 and 0 < p[1] < 10})


def _yaml(document: dict[str, Any]) -> str:
    import yaml

    return yaml.safe_dump(document)


MESH_POINTS = _mesh_points(mission("F a", (1.3, 0.7)))
TASKS = ["F(a & F b)", "b & F a", "G !a & F b", "F a & G !b", "!a U b", "G F a & G F b"]


@pytest.mark.slow
@settings(
    deadline=None,
    max_examples=max(6, settings().max_examples // 8),
    suppress_health_check=[HealthCheck.too_slow],
)
@given(start=st.sampled_from(MESH_POINTS), ltl=st.sampled_from(TASKS))
def test_starts_on_mesh_vertices_and_edges(start: tuple[float, float], ltl: str) -> None:
    document = mission(ltl, start)
    assert (checked(document) is not None) == face_oracle(document), (ltl, start)
    closed = mission(ltl, start, boundary="closed")
    checked(closed)


@pytest.mark.parametrize("hurry", [2.0, 1.00001])
def test_a_compiled_trace_faster_than_max_speed_fails_the_self_check(
    monkeypatch: pytest.MonkeyPatch, hurry: float
) -> None:
    """The verifier's speed check guards compiled traces too (the trace stays on its path and
    satisfies the task, only faster: its fastest chord at twice max_speed, or 1e-5 above it,
    far above the rounding of its samples)."""
    import dataclasses

    import tlmpc.simulate
    from tlmpc.pipeline.stages import SelfCheckError

    honest = tlmpc.simulate.simulate

    def hurried(*args: Any) -> Any:
        trace = honest(*args)
        # the fastest chord at ``hurry`` x max_speed (1 here)
        fastest = float((np.hypot(*np.diff(trace.points, axis=0).T) / np.diff(trace.times)).max())
        return dataclasses.replace(trace, times=trace.times * fastest / hurry)

    monkeypatch.setattr(tlmpc.simulate, "simulate", hurried)
    with pytest.raises(SelfCheckError) as caught:
        compile_mission(mission("F(a & F b)", (5, 5)), until="verify")
    assert "faster than max_speed" in caught.value.diagnostics[0].message


# --- corner contacts: regions that touch at a single point --------------------------------

CORNER_REGIONS = {
    "a": [[2, 2], [5, 2], [5, 5], [2, 5]],
    "b": [[5, 5], [8, 5], [8, 8], [5, 8]],
}
CORNER = (5.0, 5.0)

CORNER_CASES = [
    # (task, start, convention): each needs the robot at the corner point (5, 5)
    ("F(a & b)", (1, 1), "closed"),  # only the corner point is in both closures
    ("F(a & b) & G F !a", (3, 3), "closed"),
    ("G(a | b) & F b", (3, 3), "right"),  # from a into b without leaving a | b
    ("G(a | b) & F b", (3, 3), "closed"),
    ("a & G(a | b) & G F b & G F (a & !b)", (3, 3), "right"),  # back and forth through it
    ("G(a | b) & G F b & G F (a & !b)", (3.5, 3.5), "closed"),  # start inside a
    ("G(a | b) & F b", (5, 3.5), "right"),  # start on a's edge through the corner
    ("F(a & b)", (5, 3.5), "closed"),
    ("G(a | b) & G F b & G F (a & !b)", (5, 5), "right"),  # start on the corner itself
    ("G(a | b) & G F b & G F (a & !b)", (2, 2), "closed"),  # start on a's far corner
]


@pytest.mark.parametrize(("ltl", "start", "boundary"), CORNER_CASES)
def test_corner_contacts_are_planned_through_the_point(
    ltl: str, start: tuple[float, float], boundary: str
) -> None:
    """A plan exists (a trajectory through the corner satisfies the task: the elementary
    facts below) and its trace passes the independent check, sample at the corner included."""
    document = mission(ltl, start, boundary=boundary, regions=CORNER_REGIONS)
    a, b = (shapely.Polygon(CORNER_REGIONS[n]) for n in ("a", "b"))
    touching = shapely.intersection(a, b)
    assert touching.geom_type == "Point"  # they meet at the corner only ...
    assert (touching.x, touching.y) == CORNER
    artifacts = checked(document)
    assert artifacts is not None, ltl
    points = [tuple(p[1:]) for p in artifacts["trace.json"]["points"]]
    assert CORNER in points  # ... and the robot passes exactly through it (or starts there)
    kinds = [s.get("kind", "affine") for s in artifacts["controllers.json"]["steps"]]
    assert "vertex" in kinds or start == CORNER


def test_corner_contact_under_right_reads_the_next_label() -> None:
    """Under the right-continuous convention the corner instant is in the piece entered, so
    "a and b at once" stays impossible although a trajectory passes the corner."""
    document = mission("F(a & b)", (1, 1), regions=CORNER_REGIONS)
    assert not face_oracle(document)
    assert compiled(document) is None
