"""An independent check of a compiled output: controllers, trajectory, and the task.

Shares no code with tlmpc's control, simulation or verifier:

* vertex conditions in exact rational arithmetic (outward normals left unnormalised, so no
  square roots): every vertex velocity pushes strictly out through the exit facet and strictly
  into the two other facets, and its squared speed is within the bound;
* a vertex passage step (pursuit of a corner): the corner is exactly one of the triangle's
  vertices, the step's samples run straight to it at exactly max_speed and its last sample is
  the corner itself, and the next step leaves through the edge opposite the corner (or stays);
* the flow of each step's affine field by scipy's matrix exponential against the samples;
* the speed between consecutive samples;
* the task, on the piece word of the piecewise-linear trajectory cut at every region boundary
  with shapely, under the mission's convention: the definition-level lasso evaluator under the
  right-continuous one, the continuous-time definition under the closed one.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

import numpy as np
import shapely
from continuous_ltl import Word, closed_holds
from lasso_ltl import holds
from scipy.linalg import expm

from tlmpc.ltl.parser import parse_ltl


def check_pursuit(step: dict[str, Any], following: dict[str, Any], max_speed: float) -> None:
    """A vertex passage: its corner is one of its triangle's vertices and of the next step's
    triangle, whose field leaves through the edge opposite that corner (or stays)."""
    target = [Fraction(c) for c in step["target"]]
    corners = [[Fraction(c) for c in v] for v in step["vertices"]]
    assert target in corners, step["step"]
    assert step["exit_edge"] is None
    assert not step["stay"]
    following_corners = [[Fraction(c) for c in v] for v in following["vertices"]]
    assert target in following_corners, (step["step"], "the next triangle lacks the corner")
    if not following["stay"]:
        assert following["exit_edge"] == following_corners.index(target), step["step"]
    # Every corner reaches the target within the stated bound at max_speed.
    farthest = max(float(np.hypot(*(np.asarray(v) - step["target"]))) for v in step["vertices"])
    assert step["exit_time_bound"] >= farthest / max_speed * (1 - 1e-12)


def check_vertex_conditions(step: dict[str, Any], max_speed: float) -> None:
    """The step's vertex velocities realise it (exactly, up to 1e-9 on the speed bound)."""
    vertices = [(Fraction(x), Fraction(y)) for x, y in step["vertices"]]
    velocities = [(Fraction(u), Fraction(v)) for u, v in step["vertex_velocities"]]
    bound = Fraction(max_speed) * (1 + Fraction(1, 10**9))
    for u, v in velocities:
        assert u * u + v * v <= bound * bound
    exit_edge = step["exit_edge"]
    for facet in range(3):
        (ax, ay), (bx, by) = vertices[(facet + 1) % 3], vertices[(facet + 2) % 3]
        normal = (by - ay, -(bx - ax))  # outward for a counter-clockwise triangle
        for vertex in range(3):
            if vertex == facet and facet != exit_edge:
                continue  # the vertex opposite a facet is not on it
            across = normal[0] * velocities[vertex][0] + normal[1] * velocities[vertex][1]
            if facet == exit_edge:
                assert across > 0, (step["step"], facet, vertex)
            else:
                assert across < 0, (step["step"], facet, vertex)


def check_flow(
    trace: dict[str, Any], steps: list[dict[str, Any]], size: float, max_speed: float = 1.0
) -> None:
    """Each exit step's samples lie on the exact flow from the previous crossing."""
    points = np.asarray(trace["points"])
    step_of = trace["steps"]
    start = 0
    for k in range(1, len(points) + 1):
        if k < len(points) and step_of[k] == step_of[start]:
            continue
        step = steps[step_of[start]]
        if step.get("kind") == "vertex":
            # Straight to the corner at exactly max_speed, the last sample on the corner.
            entry = points[start - 1] if start else points[0]
            corner = np.asarray(step["target"])
            heading = corner - entry[1:]
            distance = float(np.linalg.norm(heading))
            assert points[k - 1][1] == corner[0]
            assert points[k - 1][2] == corner[1]
            # The run to the corner goes through the triangle's interior, not along an edge
            # (there the plan would count a label the robot never has): exactly, in rationals.
            middle = [
                (Fraction(float(a)) + Fraction(float(b))) / 2
                for a, b in zip(entry[1:], corner, strict=True)
            ]
            assert _strictly_inside(step["vertices"], middle), step["step"]
            for t, x, y in points[start:k]:
                travelled = (t - entry[0]) * max_speed
                assert travelled <= distance * (1 + 1e-9) + 1e-12 * size
                expected = entry[1:] + heading * (travelled / distance if distance else 0.0)
                assert np.linalg.norm(expected - [x, y]) <= 1e-9 * size
        elif step["exit_edge"] is not None:
            gain, offset = np.asarray(step["K"]), np.asarray(step["g"])
            center = np.asarray(step["vertices"]).mean(axis=0)
            field = np.zeros((3, 3))
            field[:2, :2], field[:2, 2] = gain, gain @ center + offset
            entry = points[start - 1] if start else points[0]
            t0, first = entry[0], entry[1:]
            for t, x, y in points[start:k]:
                expected = (expm((t - t0) * field) @ [*(first - center), 1.0])[:2] + center
                assert np.linalg.norm(expected - [x, y]) <= 1e-6 * size
        start = k


def _strictly_inside(vertices: list[list[float]], point: list[Fraction]) -> bool:
    corners = [(Fraction(x), Fraction(y)) for x, y in vertices]
    sides = []
    for i in range(3):
        (ax, ay), (bx, by) = corners[i], corners[(i + 1) % 3]
        sides.append((bx - ax) * (point[1] - ay) - (by - ay) * (point[0] - ax))
    return all(side > 0 for side in sides) or all(side < 0 for side in sides)


def check_speed(trace: dict[str, Any], max_speed: float, size: float) -> None:
    """No two consecutive samples are farther apart than max_speed allows."""
    points = np.asarray(trace["points"])
    gaps = np.diff(points, axis=0)
    moved = np.hypot(gaps[:, 1], gaps[:, 2])
    assert np.all(moved <= max_speed * gaps[:, 0] * (1 + 1e-6) + 1e-9 * size)


def piece_word(trace: dict[str, Any]) -> tuple[Word, list[bool], int]:
    """Point/open pieces of the trajectory, labelled under the trace's convention.

    Crossings with region boundaries come from shapely; a point's closed label is every
    region within a rounding distance of it (a crossing computed in floating point lies on
    the boundary only to rounding).
    """
    regions = {n: shapely.Polygon(p) for n, p in trace["regions"].items()}
    points = np.asarray(trace["points"])[:, 1:]
    extent = float(np.ptp(np.asarray(trace["workspace"]["boundary"]), axis=0).max())
    near = 1e-9 * extent
    closed = trace.get("boundary", "right") == "closed"
    outlines = shapely.union_all([shapely.boundary(r) for r in regions.values()])
    cut: list[np.ndarray] = []
    sample_piece: list[int] = []
    for k in range(len(points)):
        sample_piece.append(len(cut))
        cut.append(points[k])
        if k + 1 == len(points):
            break
        a, b = points[k], points[k + 1]
        segment = shapely.LineString([a, b])
        hits = shapely.intersection(segment, outlines)
        found = [np.asarray(g.coords[0]) for g in shapely.get_parts(hits) if g.geom_type == "Point"]
        found += [
            np.asarray(c)
            for g in shapely.get_parts(hits)
            if g.geom_type == "LineString"
            for c in g.coords
        ]
        length = float(np.linalg.norm(b - a))
        params = sorted(
            {float(np.linalg.norm(p - a)) / length for p in found} if length > 0 else set()
        )
        cut.extend(a + s * (b - a) for s in params if 1e-12 < s < 1 - 1e-12)

    def label(point: np.ndarray, *, boundary: bool) -> frozenset[str]:
        probe = shapely.Point(point)
        if boundary:
            return frozenset(n for n, r in regions.items() if shapely.distance(r, probe) <= near)
        return frozenset(n for n, r in regions.items() if shapely.intersects(r, probe))

    word: Word = []
    is_point: list[bool] = []
    for index, point in enumerate(cut):
        word.append(label(point, boundary=closed))
        is_point.append(True)
        if index + 1 < len(cut):
            word.append(label((point + cut[index + 1]) / 2, boundary=False))
            is_point.append(False)
    if not closed:
        # A point carries the label of the piece it opens (the last one: its own, kept).
        for k in range(0, len(word) - 1, 2):
            word[k] = word[k + 1]
    loop_start = trace.get("loop_start")
    if loop_start is None:
        loop = len(word) - 1  # a stay: the last point holds forever
    else:
        loop = 2 * sample_piece[loop_start]
        word, is_point = word[:-1], is_point[:-1]  # the last sample is the loop's start again
    return word, is_point, loop


def task_holds(trace: dict[str, Any]) -> bool:
    """The trace's task at t = 0 under its convention, by the definitions."""
    formula = parse_ltl(trace["ltl"])
    word, is_point, loop = piece_word(trace)
    if trace.get("boundary", "right") == "closed":
        return closed_holds(formula, word, is_point, loop, 0)
    return holds(formula, word, loop, 0)


def check_output(artifacts: dict[str, Any], max_speed: float, size: float) -> None:
    """Every independent check on a compiled output (a dict of artifact documents)."""
    controllers = artifacts["controllers.json"]
    steps = controllers["steps"]
    for index, step in enumerate(steps):
        if step.get("kind") == "vertex":
            following = index + 1 if index + 1 < len(steps) else controllers["loop_start"]
            check_pursuit(step, steps[following], max_speed)
        else:
            check_vertex_conditions(step, max_speed)
    trace = artifacts["trace.json"]
    check_speed(trace, max_speed, size)
    check_flow(trace, steps, size, max_speed)
    assert task_holds(trace), trace["ltl"]
