"""Cell steps: the fields of a plan made on convex cells (:mod:`tlmpc.planning.cells`).

Consecutive plan steps inside one cell are one cell step. A move's field puts at every mesh
vertex v of the cell the velocity of norm max_speed that pushes hardest along the normals of
its rows (the kept sides' inward normals through v and the flow direction xi; see
:func:`tlmpc.planning.robust.best_direction`); each triangle of the cell runs the affine
interpolation of its three vertex velocities. A stay runs the radial law
u = kappa (c - x) on the whole cell. Every row is re-checked on the solved velocities with
the disturbance and the controllers' tolerance (C030), independently of the planner's width.
"""

from __future__ import annotations

import math

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray
from tlmpc.base.errors import InvalidInputError, SolverError, error
from tlmpc.control.geometry import affine_law
from tlmpc.control.model import EXIT, KEPT, CellField, Controllers, StepController
from tlmpc.mission.model import Robot
from tlmpc.planning.cells import CellGroup, Cells, cell_groups, group_bounces, partition
from tlmpc.planning.model import Witness
from tlmpc.planning.robust import best_direction

#: The re-check's tolerance relative to max_speed (the triangle steps' own).
RECHECK_TOLERANCE = 1e-9

Vector = tuple[float, float]


def synthesize_cells(
    abstraction: Abstraction, witness: Witness, robot: Robot, *, source: str | None = None
) -> Controllers:
    """One cell field per cell step of ``witness`` (a plan made on the convex cells of
    ``abstraction``), rejecting any disturbance up to ``robot.disturbance``."""
    cells = partition(abstraction)
    groups, loop_start = cell_groups(cells, witness.prefix, witness.cycle, witness.is_stay)
    bounced = group_bounces(groups, loop_start)
    if bounced is not None:
        raise InvalidInputError(
            error(
                "C041",
                f"cell step {bounced} leaves cell {groups[bounced].cell} for the cell it "
                "entered from: no cell field leaves a cell across the interface it came in by",
                hint="the witness does not belong to this abstraction",
                file=source,
            )
        )
    path = [*witness.prefix, *witness.cycle]

    def after(i: int) -> int:
        return path[i + 1] if i + 1 < len(path) else witness.cycle[0]

    steps = []
    for index, group in enumerate(groups):
        nxt, last = None, group.indices[-1]
        if group.target is not None:
            # the plan's triangle where the group leaves its cell (a run that wraps round the
            # cycle leaves from its first part)
            last = next(i for i in group.indices if cells.cell_of[after(i)] == group.target)
            nxt = after(last)
        steps.append(_cell_step(cells, index, group, path[group.indices[0]], nxt, last, robot))
    for controller in steps:
        problem = violated(controller, robot.max_speed, robot.disturbance)
        if problem is not None:
            raise SolverError(
                error(
                    "C030",
                    f"cell step {controller.step} (cell of triangle {controller.triangle}): the "
                    f"field fails the re-check: {problem}",
                    hint="please report this mission",
                )
            )
    return Controllers(
        steps=tuple(steps),
        loop_start=loop_start,
        max_speed=robot.max_speed,
        margin=0.0,
        stats={
            "steps": len(steps),
            "cells": len(cells.cells),
            "min_exit_speed": min(c.exit_speed for c in steps),
            "follow_status": "off",
        },
    )


def _cell_step(
    cells: Cells,
    index: int,
    group: CellGroup,
    first: int,
    nxt: int | None,
    last: int,
    robot: Robot,
) -> StepController:
    cell = cells.cells[group.cell]
    points = cells.abstraction.vertices
    velocity: dict[int, FloatArray] = {}
    target = None
    direction: Vector | None = None
    if group.target is None:
        stay = cells.stay(group.cell)
        kappa = robot.max_speed * stay.rate
        centre = np.array(stay.centre)
        for v in cell.vertices:
            velocity[v] = kappa * (centre - points[v])
        target = stay.centre
        exits: set[tuple[int, int]] = set()
        polygon = points[list(cell.boundary)]
        speed = min(
            kappa * _distance_to_line(centre, polygon[k], polygon[(k + 1) % len(polygon)])
            for k in range(len(polygon))
        )
        bound = math.inf
    else:
        move = cells.move(group.cell, group.target)
        direction = move.xi
        normals = cells.vertex_normals(move)
        for v in cell.vertices:
            _, (ux, uy) = best_direction([*normals[v], move.xi])
            velocity[v] = np.array([robot.max_speed * ux, robot.max_speed * uy])
        exits = {(cell.sides[k].triangle, cell.sides[k].edge) for k in move.interface}
        xi = np.array(move.xi)
        speed = min(float(xi @ velocity[v]) for v in cell.vertices)
        along = [float(xi @ points[v]) for v in cell.vertices]
        closing = speed - robot.disturbance
        bound = (max(along) - min(along)) / closing if closing > 0 else math.inf
    triangles = cells.abstraction.triangles
    neighbours = cells.abstraction.neighbors
    piece_of = {t: k for k, t in enumerate(cell.triangles)}
    corners = np.array([points[triangles[t]] for t in cell.triangles])
    velocities = np.array([[velocity[int(v)] for v in triangles[t]] for t in cell.triangles])
    laws = [affine_law(c, w) for c, w in zip(corners, velocities, strict=True)]
    across = []
    for t in cell.triangles:
        row = []
        for edge in range(3):
            there = int(neighbours[t, edge])
            if there >= 0 and there in piece_of:
                row.append(piece_of[there])
            elif (t, edge) in exits:
                row.append(EXIT)
            else:
                row.append(KEPT)
        across.append((row[0], row[1], row[2]))
    field = CellField(
        triangles=cell.triangles,
        vertices=_frozen(corners),
        velocities=_frozen(velocities),
        gains=_frozen(np.array([gain for gain, _ in laws])),
        offsets=_frozen(np.array([offset for _, offset in laws])),
        neighbours=tuple(across),
        direction=direction,
        cell=group.cell,
        target_cell=group.target,
        plan_index=last,
    )
    entry = piece_of[first]
    return StepController(
        step=index,
        triangle=first,
        exit_edge=None,
        next_triangle=nxt,
        vertices=field.vertices[entry],
        velocities=field.velocities[entry],
        gain=field.gains[entry],
        offset=field.offsets[entry],
        exit_speed=float(speed),
        exit_time_bound=float(bound),
        target=target,
        kind="cell",
        cell=field,
    )


def _frozen(array: FloatArray) -> FloatArray:
    result = np.ascontiguousarray(array, dtype=np.float64)
    result.setflags(write=False)
    return result


def _distance_to_line(point: FloatArray, a: FloatArray, b: FloatArray) -> float:
    dx, dy = float(b[0] - a[0]), float(b[1] - a[1])
    return abs(dx * float(point[1] - a[1]) - dy * float(point[0] - a[0])) / math.hypot(dx, dy)


def violated(controller: StepController, max_speed: float, disturbance: float) -> str | None:
    """Which row the cell field breaks (None when all hold), re-derived from the pieces'
    geometry: the speed bound at every vertex, every kept facet pushed inward and (a move)
    every vertex pushed along xi, each by more than the disturbance plus the tolerance."""
    field = controller.cell
    if field is None:
        return "a cell step without its cell field"
    floor = disturbance + RECHECK_TOLERANCE * max_speed
    for piece in range(len(field.triangles)):
        corners = field.vertices[piece].tolist()
        w = field.velocities[piece].tolist()
        for i in range(3):
            wx, wy = w[i]
            if math.hypot(wx, wy) > max_speed * (1.0 + RECHECK_TOLERANCE):
                return f"a vertex speed {math.hypot(wx, wy):.6g} exceeds max_speed"
            if field.direction is not None:
                xx, xy = field.direction
                if xx * wx + xy * wy <= floor:
                    return f"vertex {corners[i]} does not move along xi by more than {floor:.3g}"
            for facet in range(3):
                if facet == i or field.neighbours[piece][facet] != KEPT:
                    continue
                (ax, ay), (bx, by) = corners[(facet + 1) % 3], corners[(facet + 2) % 3]
                length = math.hypot(bx - ax, by - ay)
                inward = (-(by - ay) * wx + (bx - ax) * wy) / length  # CCW: left is inside
                if inward <= floor:
                    return (
                        f"vertex {corners[i]} is not pushed inside a kept side "
                        f"(inward {inward:.3g})"
                    )
    return None
