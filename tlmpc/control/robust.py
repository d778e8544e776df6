"""What a plan's triangles can reject, corner by corner, and the field that does it best.

At a corner of a step the vertex velocity w must push along every normal a_k its rows collect
(inward on the facets to keep, outward on the exit facet) by more than the disturbance d. The
best any |w| <= max_speed can do is the *corner push* max_w min_k a_k·w (its direction and
value: :func:`tlmpc.planning.robust.best_direction`, which the planner's convex cells use
too). For the corner opposite the exit edge, and for every corner of a stay, the two kept
facets meet at the triangle's angle a there and the push is max_speed * sin(a / 2); a corner
on the exit edge pushes max_speed * cos(a / 2). Every field of a step is an affine
interpolation of its three vertex velocities, and each vertex's rows involve that vertex
alone, so the step is feasible exactly when each corner push exceeds d: the plan's triangles
reject every disturbance below the smallest corner push of its steps, and none from there on
(see docs/control.md, "How much disturbance a plan rejects").

The *best-push field* puts, at every corner, the velocity of norm max_speed that attains the
corner push. It is the program's fallback on a needle, where the solver's tolerance (about
1e-8 of max_speed) swamps the few billionths a sliver corner can push: built from geometry
alone, it meets every row to rounding.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from tlmpc.planning.robust import Vector, best_direction


@dataclass(frozen=True, slots=True)
class Corner:
    """One corner of one plan step and what it can push."""

    step: int
    triangle: int
    position: Vector
    angle: float  # the triangle's angle at the corner, degrees
    push: float  # the corner push, in the units of max_speed
    kept: bool  # both facets through it kept (the corner opposite the exit, or a stay's)


def corner_angle(vertices: Sequence[Vector], local: int) -> float:
    """The triangle's interior angle at corner ``local``, in degrees."""
    px, py = vertices[local]
    ax, ay = vertices[(local + 1) % 3]
    bx, by = vertices[(local + 2) % 3]
    ux, uy, vx, vy = ax - px, ay - py, bx - px, by - py
    return math.degrees(math.atan2(abs(ux * vy - uy * vx), ux * vx + uy * vy))


def weakest(corners: Sequence[Corner]) -> Corner:
    """The corner with the smallest push (the plan's bound on the disturbance)."""
    return min(corners, key=lambda corner: corner.push)


#: What "below the bound" leaves to spare: the controllers' re-check tolerance.
TOLERANCE_NOTE = "2e-9 x max_speed to spare"

#: The largest smallest-angle bound the triangulator meets (degrees; the mission format's
#: ``options.min_angle`` allows up to 34).
MAX_MIN_ANGLE = 34.0


def disturbance_hint(
    disturbance: float,
    max_speed: float,
    bound: Corner,
    *,
    supported: float | None = None,
    on_cells: float | None = None,
    triangles: int | None = None,
) -> str:
    """C032's hint: the largest disturbance any plan on the mesh rejects (``supported``, from
    the planner's widest-lasso search, when known), the bound on convex cells or the budgets
    that kept the cells' rung from trying (the mesh's ``triangles`` named), the plan's own
    bound, what ``min_angle`` guarantees, and the stay limit.

    Every statement is a fact about triangles: a kept corner of angle a pushes at most
    max_speed * sin(a / 2); ``min_angle`` = m guarantees every angle >= m, hence a push of
    max_speed * sin(m / 2) at every kept corner; a stay keeps all three facets, and a triangle
    has a corner of at most 60 degrees, so no stay rejects 0.5 * max_speed or more.
    """
    ratio = disturbance / max_speed
    x, y = bound.position
    lines = []
    if supported is not None:
        lines.append(
            f"the largest disturbance any plan on this mesh rejects is {supported:.6g} "
            f"({supported / max_speed:.4f} x max_speed; every one below it, with "
            f"{TOLERANCE_NOTE}, has a plan): the widest route's weakest corner, over every plan "
            "the task admits"
        )
    if on_cells is not None:
        lines.append(
            "on convex cells (the plan stage's last rung: the mesh's, and meshes of the map's "
            f"sides extended or its reflex corners cut) plans reject at most "
            f"{on_cells:.6g} ({on_cells / max_speed:.4f} x max_speed): the widest route's "
            "weakest cell step"
        )
    elif supported is not None:
        from tlmpc.abstraction.lines import MAX_REFLEX_WORK, MAX_SIDES
        from tlmpc.planning.cells import MAX_TRIANGLES

        lines.append(
            "no plan on convex cells (the plan stage's last rung) was tried: the rung plans "
            f"on meshes of at most {MAX_TRIANGLES} triangles and builds its own mesh for maps "
            f"of at most {MAX_SIDES} straight sides (every side extended) or whose reflex "
            f"corners' cuts take at most {MAX_REFLEX_WORK} work units, and this mission is "
            "larger" + ("" if triangles is None else f" (its mesh has {triangles} triangles)")
        )
    lines.append(
        f"this plan's triangles reject disturbances below {bound.push:.6g} "
        f"({bound.push / max_speed:.4f} x max_speed), the push of its weakest corner "
        f"({x:.6g}, {y:.6g}) in step {bound.step}, angle {bound.angle:.6g} degrees (the "
        "planner takes a route through corners that reject the disturbance wherever this mesh "
        "has one; it has none)"
    )
    ceiling = math.sin(math.radians(MAX_MIN_ANGLE) / 2.0)
    if ratio < ceiling:
        needed = math.degrees(2.0 * math.asin(ratio))
        lines.append(
            f"options.min_angle above {needed:.3g} degrees asks the mesher for corners that "
            "all reject it but the map's own sharper corners (a corner of angle a held on both "
            "its facets rejects at most max_speed * sin(a / 2))"
        )
    else:
        lines.append(
            f"no options.min_angle guarantees it (at most {MAX_MIN_ANGLE:g} degrees, "
            f"{ceiling:.3f} x max_speed); it depends on the corners the plan crosses, each held "
            "on both its facets rejecting at most max_speed * sin(a / 2)"
        )
    if ratio >= 0.5:
        lines.append(
            "no triangle where the robot stays can reject 0.5 x max_speed or more (one of its "
            "corners is at most 60 degrees)"
        )
    lines.append("lower robot.disturbance or raise max_speed")
    return "; ".join(lines)


def best_push_velocities(
    rows: Sequence[Sequence[tuple[Vector, float]]], max_speed: float
) -> list[Vector]:
    """The best-push field's vertex velocities: at each corner, norm ``max_speed`` along the
    direction that pushes hardest along every normal of its rows (``rows[i]`` holds the
    (normal, weight) pairs of corner ``i``; the weights do not change the direction that
    maximises the least push, only how the step's speed is read from it)."""
    velocities: list[Vector] = []
    for corner in rows:
        _, (ux, uy) = best_direction([normal for normal, _ in corner])
        velocities.append((max_speed * ux, max_speed * uy))
    return velocities
