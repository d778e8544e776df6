"""Point contacts: tlmpc plans exactly when some trajectory in the plane satisfies the task,
under both conventions, also when that trajectory must pass a single point where regions
(or faces) touch only at a corner.

The oracle is tests/oracles/face_graph.py (shapely faces and point contacts, Spot's automaton;
under the closed convention the instant graph of its module doc).  Maps are rectangles on a
small integer grid, so corners touch often; starts are at half-integer points, inside a face.
Every plan's trace also passes the independent check of tests/oracles/trace_check.py.
"""

from __future__ import annotations

import json
from typing import Any

import pytest
import shapely
from face_graph import face_graph, satisfiable_closed, satisfiable_on
from face_maps import FaceMap, face_maps
from hypothesis import HealthCheck, assume, example, given, reject, settings
from hypothesis import strategies as st
from strategies import formulas
from trace_check import check_output

from tlmpc.api import compile as compile_mission
from tlmpc.base.errors import InvalidInputError, NoPlanError, TlmpcError
from tlmpc.ltl.ast import Formula, Not, Prop, Release, Until
from tlmpc.ltl.parser import parse_ltl
from tlmpc.ltl.printer import to_spin, to_text

SIZE = 6
BOUNDARY = [(0.0, 0.0), (float(SIZE), 0.0), (float(SIZE), float(SIZE)), (0.0, float(SIZE))]


def rect(x0: int, y0: int, x1: int, y1: int) -> list[tuple[float, float]]:
    return [
        (float(x0), float(y0)),
        (float(x1), float(y0)),
        (float(x1), float(y1)),
        (float(x0), float(y1)),
    ]


@st.composite
def rectangles(draw: st.DrawFn) -> list[tuple[float, float]]:
    x0 = draw(st.integers(1, SIZE - 2))
    y0 = draw(st.integers(1, SIZE - 2))
    x1 = draw(st.integers(x0 + 1, SIZE - 1))
    y1 = draw(st.integers(y0 + 1, SIZE - 1))
    return rect(x0, y0, x1, y1)


def document(
    regions: dict[str, list[tuple[float, float]]],
    start: tuple[float, float],
    task: Formula,
    boundary: str,
) -> dict[str, Any]:
    return {
        "version": 1,
        "name": "contacts",
        "workspace": {"boundary": [list(p) for p in BOUNDARY]},
        "regions": {n: [list(p) for p in r] for n, r in regions.items()},
        "robot": {"start": list(start), "max_speed": 1.0},
        "ltl": to_text(task),
        "options": {"boundary": boundary},
    }


def oracle(
    regions: dict[str, list[tuple[float, float]]],
    start: tuple[float, float],
    task: Formula,
    boundary: str,
) -> bool:
    graph = face_graph(BOUNDARY, [], regions, start)
    if boundary == "closed":
        return satisfiable_closed(graph, task)
    return satisfiable_on(graph, to_spin(task))


def tlmpc_plans(mission: dict[str, Any]) -> bool:
    failure: TlmpcError | None = None
    try:
        result = compile_mission(mission, until="verify")
    except TlmpcError as exc:
        failure = exc
    if failure is not None:
        assert isinstance(failure, NoPlanError), [d.format() for d in failure.diagnostics]
        return False
    check_output(dict(result.artifacts), 1.0, float(SIZE))
    return True


def agree(
    regions: dict[str, list[tuple[float, float]]],
    start: tuple[float, float],
    task: Formula,
    boundary: str,
) -> bool:
    expected = oracle(regions, start, task, boundary)
    found = tlmpc_plans(document(regions, start, task, boundary))
    assert found == expected, (to_text(task), boundary, regions, start)
    return found


#: Tasks whose runs often need a point contact: staying within touching regions, or being
#: in two of them at once (under closed, possibly only at a corner).
CONTACT_TASKS = (
    "F(a & b)",
    "G(a | b) & F b",
    "G(a | b | c) & F c",
    "G(a | b) & G F a & G F b",
    "F(a & b & c)",
    "G !c & F(a & b)",
    "G(a | b) & F(b & F a)",
    "G !(a & b) & F a & F b",
)


@st.composite
def corner_maps(draw: st.DrawFn) -> tuple[dict[str, list[tuple[float, float]]], tuple[int, int]]:
    """Three rectangles, the second often put corner to corner with the first; the start in
    a random cell, or in a cell of the first rectangle."""
    a = draw(rectangles())
    if draw(st.booleans()):
        x, y = a[2]  # a's upper right corner
        width, height = draw(st.integers(1, 2)), draw(st.integers(1, 2))
        ix, iy = int(x), int(y)
        b = rect(ix, iy, min(ix + width, SIZE - 1), min(iy + height, SIZE - 1))
        if ix >= SIZE - 1 or iy >= SIZE - 1:
            b = draw(rectangles())
    else:
        b = draw(rectangles())
    regions = {"a": a, "b": b, "c": draw(rectangles())}
    if draw(st.booleans()):
        (x0, y0), (x1, y1) = a[0], a[2]
        start = (draw(st.integers(int(x0), int(x1) - 1)), draw(st.integers(int(y0), int(y1) - 1)))
    else:
        start = (draw(st.integers(0, SIZE - 1)), draw(st.integers(0, SIZE - 1)))
    return regions, start


@pytest.mark.slow
@settings(
    deadline=None,
    max_examples=max(8, settings().max_examples // 4),
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    layout=corner_maps(),
    task=st.one_of(
        formulas(("a", "b", "c"), max_leaves=5), st.sampled_from(CONTACT_TASKS).map(parse_ltl)
    ),
    boundary=st.sampled_from(["right", "closed"]),
)
def test_plans_exactly_when_a_trajectory_exists(
    layout: tuple[dict[str, list[tuple[float, float]]], tuple[int, int]],
    task: Formula,
    boundary: str,
) -> None:
    regions, start = layout
    agree(regions, (start[0] + 0.5, start[1] + 0.5), task, boundary)


CORNERS = {
    "a": rect(1, 1, 3, 3),
    "b": rect(3, 3, 5, 5),
    "c": rect(3, 1, 5, 2),
}

HELD_OUT = [
    # (task, start, convention, a trajectory exists)
    ("F(a & b)", (0.5, 0.5), "closed", True),  # only at the corner (3, 3)
    ("F(a & b)", (0.5, 0.5), "right", False),
    ("G(a | b) & F b", (1.5, 1.5), "right", True),
    ("G(a | b) & F b", (1.5, 1.5), "closed", True),
    ("G(a | b) & G F b & G F !b", (1.5, 1.5), "right", True),
    ("G !(a & b) & F(a & F b)", (0.5, 0.5), "closed", True),  # around, not through the corner
    ("G(a | b) & F c", (1.5, 1.5), "right", False),
    ("G !b & F(a & c)", (0.5, 0.5), "closed", True),  # a and c share an edge
]


@pytest.mark.parametrize(("ltl", "start", "boundary", "exists"), HELD_OUT)
def test_held_out_corner_missions(
    ltl: str, start: tuple[float, float], boundary: str, exists: bool
) -> None:
    a, b = shapely.Polygon(CORNERS["a"]), shapely.Polygon(CORNERS["b"])
    assert shapely.intersection(a, b).geom_type == "Point"
    assert agree(CORNERS, start, parse_ltl(ltl), boundary) is exists


def test_the_oracle_sees_a_pinch_of_the_free_space() -> None:
    """Two holes touching the boundary and each other at points split nothing: the faces on
    either side touch at the pinch, and a plan passes through it."""
    holes = [rect(0, 3, 3, 4), rect(3, 2, 6, 3)]  # meet at (3, 3); each on one wall
    regions = {"goal": rect(5, 5, 6, 6)}
    graph = face_graph(BOUNDARY, holes, regions, (0.5, 0.5))
    assert satisfiable_on(graph, "F goal")
    mission = document(regions, (0.5, 0.5), parse_ltl("F goal"), "right")
    mission["workspace"]["holes"] = [[list(p) for p in h] for h in holes]
    assert tlmpc_plans(mission)


@st.composite
def point_open_lassos(draw: st.DrawFn) -> tuple[list[frozenset[str]], list[bool], int]:
    """Words point, open, point, ..., ending in an open piece whose loop starts at a point,
    or ending in a point that holds forever (a stay)."""
    letters = st.frozensets(st.sampled_from(("a", "b")))
    pieces = draw(st.integers(1, 4))
    word = [draw(letters) for _ in range(2 * pieces)]
    is_point = [index % 2 == 0 for index in range(2 * pieces)]
    if draw(st.booleans()):
        word.append(draw(letters))
        is_point.append(True)
        return word, is_point, len(word) - 1
    loop = 2 * draw(st.integers(0, pieces - 1))
    return word, is_point, loop


def _spot_letter(letter: frozenset[str], just_after: bool) -> str:
    literals = [p if p in letter else f"!{p}" for p in ("a", "b")]
    literals.append("J" if just_after else "!J")
    return " & ".join(literals)


A_THEN_B = ([frozenset({"a"}), frozenset({"b"}), frozenset()], [True, False, True], 2)


@settings(deadline=None, max_examples=max(40, settings().max_examples))
@given(task=formulas(("a", "b"), max_leaves=4), lasso=point_open_lassos())
@example(task=Until(Prop("a"), Prop("b")), lasso=A_THEN_B)  # a only at the point: false
@example(task=Release(Not(Prop("a")), Not(Prop("b"))), lasso=A_THEN_B)  # its dual: true
def test_the_closed_oracles_rewrite_is_the_continuous_definition(
    task: Formula, lasso: tuple[list[frozenset[str]], list[bool], int]
) -> None:
    """The face-graph oracle's closed rewrite, decided by Spot on the instant word, agrees
    with the continuous-time definition (tests/oracles/continuous_ltl.py) on random lassos."""
    import warnings

    from continuous_ltl import closed_holds
    from face_graph import closed_rewrite

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import spot

    word, is_point, loop = lasso
    instants: list[str] = []
    start_of: list[int] = []
    for letter, point in zip(word, is_point, strict=True):
        start_of.append(len(instants))
        if point:
            instants.append(_spot_letter(letter, False))
        else:
            instants += [_spot_letter(letter, True), _spot_letter(letter, False)]
    cut = start_of[loop]
    text = "; ".join([*instants[:cut], "cycle{" + "; ".join(instants[cut:]) + "}"])
    automaton = spot.translate(closed_rewrite(task))
    accepted = bool(
        automaton.intersects(spot.parse_word(text, automaton.get_dict()).as_automaton())
    )
    assert accepted == closed_holds(task, word, is_point, loop, 0), (to_text(task), lasso)


@pytest.mark.slow
@settings(
    deadline=None,
    max_examples=max(4, settings().max_examples // 16),
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(generated=face_maps())
def test_closed_convention_on_corridor_maps(generated: FaceMap) -> None:
    """The completeness property's maps (corridors, dead ends, bays, pockets, holes) under the
    closed convention: tlmpc plans exactly when the instant-graph oracle finds a run."""
    point = shapely.Point(generated.start)
    free = shapely.Polygon(generated.boundary, generated.holes)
    lines = [free.boundary, *(shapely.Polygon(p).boundary for p in generated.regions.values())]
    assume(free.contains(point) and all(line.distance(point) > 1e-4 for line in lines))
    mission = json.loads(generated.yaml())
    mission["options"] = {"boundary": "closed"}
    try:
        compile_mission(mission, until="abstraction")
    except InvalidInputError:
        reject()  # a layout the mission checks refuse
    found = tlmpc_plans(mission)
    graph = face_graph(generated.boundary, generated.holes, generated.regions, generated.start)
    assert found == satisfiable_closed(graph, parse_ltl(generated.ltl)), generated
