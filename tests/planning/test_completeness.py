"""Completeness: tlmpc finds a plan exactly when the face-graph oracle says a trajectory exists.

The oracle (tests/oracles/face_graph.py) uses shapely's polygonize and Spot's automaton; it
shares no code with tlmpc's triangulation, translation or product.  Every plan must also pass
the compiler's own self-check (the verifier on the simulated trajectory), and an explanation
must never blame a region that the task only forbids.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from pathlib import Path

import pytest
from face_graph import face_graph, satisfiable_on
from face_maps import FaceMap, face_maps
from hypothesis import HealthCheck, assume, event, given, settings
from shapely.geometry import Point, Polygon

from tlmpc.base.errors import InvalidInputError, NoPlanError
from tlmpc.ltl.parser import parse_ltl
from tlmpc.pipeline.stages import compile_mission
from tlmpc.planning.complete import bounce_triangles
from tlmpc.planning.explain import _positive_props
from tlmpc.planning.model import Witness

BLAME = re.compile(r"region '([a-z]+)' (?:cannot be reached|can only be reached|has no free)")


def _tlmpc_verdict(mission: FaceMap, tmp: Path, record: Callable[[str], None]) -> tuple[bool, str]:
    path = tmp / "mission.yaml"
    path.write_text(mission.yaml())
    try:
        result = compile_mission(path, until="verify")
    except NoPlanError as exc:
        record(f"no plan ({exc.diagnostics[0].code})")
        return False, "\n".join(d.format() for d in exc.diagnostics)
    verdict = result.artifacts["verdict.json"]
    assert verdict["satisfied"], "every plan's trace verifies"
    refined = "triangles after U-turn splits" in result.reports[3].sizes
    record("plan on a refined mesh" if refined else "plan without refinement")
    return True, ""


def _oracle_verdict(mission: FaceMap) -> bool:
    graph = face_graph(mission.boundary, mission.holes, mission.regions, mission.start)
    return bool(satisfiable_on(graph, mission.ltl))


def _check_explanation(mission: FaceMap, text: str) -> None:
    needed = set(_positive_props(parse_ltl(mission.ltl)))
    for name in BLAME.findall(text):
        assert name in needed, f"blames {name!r}, which the task only forbids:\n{text}"
    assert "<input>" not in text, "explanations point at the mission file"


def _start_is_clear(mission: FaceMap) -> bool:
    point = Point(mission.start)
    free = Polygon(mission.boundary, mission.holes)
    lines = [free.boundary, *(Polygon(p).boundary for p in mission.regions.values())]
    return free.contains(point) and all(line.distance(point) > 1e-4 for line in lines)


def _agree(mission: FaceMap, tmp: Path, record: Callable[[str], None] = lambda _: None) -> bool:
    expected = _oracle_verdict(mission)
    found, explanation = _tlmpc_verdict(mission, tmp, record)
    assert found == expected, f"tlmpc {'found' if found else 'found no'} plan for {mission}"
    if not found:
        _check_explanation(mission, explanation)
    return found


@pytest.mark.slow
@settings(
    max_examples=max(10, settings().max_examples // 4),
    suppress_health_check=[
        HealthCheck.function_scoped_fixture,
        HealthCheck.too_slow,
        HealthCheck.filter_too_much,
    ],
)
@given(mission=face_maps())
def test_plan_exactly_when_the_face_graph_has_a_lasso(mission: FaceMap, tmp_path: Path) -> None:
    assume(_start_is_clear(mission))
    try:
        _agree(mission, tmp_path, event)
    except InvalidInputError:
        assume(False)  # the generator drew a layout the mission checks refuse


def _held_out(
    boundary: Sequence[tuple[float, float]],
    holes: Sequence[Sequence[tuple[float, float]]],
    regions: dict[str, tuple[float, float, float, float]],
    start: tuple[float, float],
    ltl: str,
) -> FaceMap:
    def rect(r: tuple[float, float, float, float]) -> list[tuple[float, float]]:
        x0, y0, x1, y1 = r
        return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]

    return FaceMap(
        "held-out",
        [(float(x), float(y)) for x, y in boundary],
        [[(float(x), float(y)) for x, y in hole] for hole in holes],
        {n: rect(r) for n, r in regions.items()},
        start,
        ltl,
    )


DEAD_END = [(0, 0), (10, 0), (10, 4), (6, 4), (6, 10), (5, 10), (5, 4), (0, 4)]
BAY = [(0, 0), (6, 0), (6, 2), (3.2, 2), (3.2, 5), (3.0, 5), (3.0, 2), (0, 2)]  # 0.2 wide
SPIRAL_HOLES = [
    [(1, 1), (7, 1), (7, 1.5), (1.5, 1.5), (1.5, 6), (1, 6)],
    [(2.5, 2.5), (6, 2.5), (6, 7), (2, 7), (2, 6.5), (5.5, 6.5), (5.5, 3), (2.5, 3)],
]
POCKET = [(0, 0), (8, 0), (8, 8), (0, 8)]
POCKET_HOLES = [
    [
        (2, 2),
        (6, 2),
        (6, 6),
        (4.2, 6),
        (4.2, 5.5),
        (5.5, 5.5),
        (5.5, 2.5),
        (2.5, 2.5),
        (2.5, 5.5),
        (3.8, 5.5),
        (3.8, 6),
        (2, 6),
    ]
]
HELD_OUT = {
    "dead end, issue example": _held_out(
        DEAD_END, [], {"tip": (5, 9, 6, 10), "base": (0, 0, 2, 2)}, (9, 1), "F(tip & F base)"
    ),
    "corridor patrol": _held_out(
        DEAD_END, [], {"tip": (5, 9, 6, 10), "base": (0, 0, 2, 2)}, (9, 1), "G F tip & G F base"
    ),
    "bay 0.2 wide, in and out": _held_out(
        BAY, [], {"end": (3.0, 4.8, 3.2, 5), "home": (0, 0, 1, 1)}, (5, 1), "G F end & G F home"
    ),
    "bay blocked by a forbidden sliver": _held_out(
        BAY,
        [],
        {"end": (3.0, 4.8, 3.2, 5), "home": (0, 0, 1, 1), "c": (3.0, 3, 3.2, 3.05)},
        (5, 1),
        "G !c & G F end & G F home",
    ),
    "spiral centre and back": _held_out(
        [(0, 0), (8, 0), (8, 8), (0, 8)],
        SPIRAL_HOLES,
        {"centre": (3, 3.5, 5, 6), "door": (0, 0, 0.5, 0.5)},
        (7.5, 7.5),
        "F(centre & F door)",
    ),
    "pocket in and out forever": _held_out(
        POCKET,
        POCKET_HOLES,
        {"inside": (3, 3, 5, 5), "out": (7, 7, 8, 8)},
        (0.5, 0.5),
        "G F inside & G F out",
    ),
    "impossible order": _held_out(
        DEAD_END,
        [],
        {"tip": (5, 9, 6, 10), "base": (0, 0, 2, 2)},
        (9, 1),
        "!tip U base & F tip & G(base -> G !tip)",
    ),
    "moat around the goal": _held_out(
        POCKET,
        POCKET_HOLES,
        {"goal": (3, 3, 5, 5), "moat": (3.8, 5.5, 4.2, 6)},
        (0.5, 0.5),
        "F goal & G(!moat | goal)",
    ),
    "safety only": _held_out(
        DEAD_END, [], {"tip": (5, 9, 6, 10), "base": (0, 0, 2, 2)}, (9, 1), "G !tip & G !base"
    ),
    "safety only, starting inside": _held_out(
        DEAD_END, [], {"tip": (5, 9, 6, 10), "base": (0, 0, 2, 2)}, (1, 1), "G !base"
    ),
}


@pytest.mark.parametrize("name", sorted(HELD_OUT))
def test_held_out_missions_agree_with_the_face_graph(name: str, tmp_path: Path) -> None:
    _agree(HELD_OUT[name], tmp_path)


def test_the_dead_end_mission_compiles(tmp_path: Path) -> None:
    assert _agree(HELD_OUT["dead end, issue example"], tmp_path)


def test_bounces_are_found_in_the_prefix_at_the_junction_and_across_the_wrap() -> None:
    def witness(prefix: tuple[int, ...], cycle: tuple[int, ...]) -> Witness:
        return Witness(
            prefix=prefix,
            cycle=cycle,
            prefix_states=(0,) * len(prefix),
            cycle_states=(0,) * len(cycle),
            word=((),) * (len(prefix) + len(cycle)),
            cost=0.0,
            metric="hops",
            beta=1.0,
            prefix_cost=0.0,
            cycle_cost=0.0,
        )

    assert bounce_triangles(witness((0, 1, 0, 2), (3,))) == [1]
    assert bounce_triangles(witness((0, 1), (2, 1, 5))) == [2]  # prefix 1 -> 2 -> 1
    assert bounce_triangles(witness((0,), (1, 2))) == [1, 2]  # a two-triangle cycle
    assert bounce_triangles(witness((0,), (1, 2, 3, 2))) == [1, 3]  # 2,1,2 across the wrap
    assert bounce_triangles(witness((0, 1, 2), (3, 4, 5))) == []
    assert bounce_triangles(witness((), (7,))) == []
