"""The control stage's guarantees re-checked on controllers and plans read back from artifacts.

``tlmpc stage`` runs a stage alone on the artifacts of an output folder, which may have been
edited by hand.  The controllers the control stage writes meet every condition of its own
re-check (C030: :func:`tlmpc.control.synthesize.violated_condition` for a triangle's field,
:func:`tlmpc.control.cells.violated` for a cell's) on the triangles of the abstraction, and
state exit speeds and exit-time bounds their fields achieve; the witness it reads starts in
a triangle holding the robot's start and passes the checks of
:func:`tlmpc.control.synthesize.plan_steps`.  An artifact that breaks one of these was not
written by tlmpc: the functions here say which condition fails, so the caller refuses the
artifact instead of simulating fields that break the guarantees they state, or failing
inside the simulator as if tlmpc had a bug.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray
from tlmpc.abstraction.starts import start_cells
from tlmpc.base.errors import TlmpcError, UsageError, error
from tlmpc.control.cells import violated as violated_cell_row
from tlmpc.control.geometry import coordinate_rounding, triangle_geometry
from tlmpc.control.model import EXIT, KEPT, Controllers, StepController
from tlmpc.control.synthesize import RECHECK_TOLERANCE, plan_steps, violated_condition
from tlmpc.mission.model import Mission, Robot
from tlmpc.planning.mission import on_cells
from tlmpc.planning.model import Witness


def refuse_edited(
    directory: Path,
    mission: Mission | None,
    abstraction: Abstraction | None,
    witness: Witness | None,
    controllers: Controllers | None,
    steps_written: Sequence[Mapping[str, Any]] | None,
) -> None:
    """Refuse (U042 at the artifact, exit 2) a ``witness.json`` or ``controllers.json`` read
    from ``directory`` that breaks what the control stage guarantees: the stage after it
    would fail on it as if tlmpc had a bug, or turn it into a trace that breaks the guarantees
    the artifact states.  ``steps_written`` are the controllers' steps as written (their
    ``stay`` flags); what is None is not checked."""
    if witness is not None and abstraction is not None and mission is not None:
        problem = witness_problem(witness, abstraction, mission.robot.start)
        if problem is not None:
            raise _contradicted(directory / "witness.json", problem)
    if controllers is None:
        return
    problem = None
    stays = [bool(step["stay"]) for step in steps_written or ()]
    flagged = [k for k, step in enumerate(controllers.steps) if stays and stays[k] != step.is_stay]
    if flagged:
        k = flagged[0]
        problem = f"step {k} says stay: {str(stays[k]).lower()}, and its field says otherwise"
    elif abstraction is not None and mission is not None:
        problem = controllers_problem(controllers, abstraction, mission.robot)
    if problem is not None:
        raise _contradicted(directory / "controllers.json", problem)


def _contradicted(path: Path, problem: str) -> UsageError:
    """U042 at ``path`` (exit 2): the artifact breaks the guarantees of the stage that writes
    it."""
    return UsageError(
        error(
            "U042",
            f"{path.name} does not hold what tlmpc writes there: {problem}",
            hint="this output was edited or damaged; compile the mission again",
            file=str(path),
        )
    )


def witness_problem(
    witness: Witness, abstraction: Abstraction, start: tuple[float, float]
) -> str | None:
    """Why the control stage cannot realise ``witness`` on ``abstraction`` for a robot at
    ``start`` (None when it can): a plan whose first triangle does not hold the start point,
    or whose steps the control stage refuses (triangles that are not adjacent, a bounce, a
    passage through a vertex they do not share)."""
    first = [*witness.prefix, *witness.cycle][0]
    problem = _start_problem(first, abstraction, start)
    if problem is not None:
        return f"the plan {problem}"
    if on_cells(witness):
        return None  # (the cell plan's own checks run with its controllers' synthesis)
    try:
        plan_steps(abstraction, witness)
    except TlmpcError as exc:
        return exc.diagnostics[0].message
    return None


def controllers_problem(
    controllers: Controllers, abstraction: Abstraction, robot: Robot
) -> str | None:
    """The first guarantee of the control stage that ``controllers`` break on ``abstraction``
    for ``robot`` (None when they keep them all): the robot's speed bound, a first step in a
    triangle holding the start, each step's triangle, exit facet and successor as the mesh has
    them, its vertex conditions (C030), its gain and offset interpolating its vertex
    velocities, and an exit speed and exit-time bound no better than its field achieves."""
    if controllers.max_speed != robot.max_speed:
        return (
            f"max_speed is {controllers.max_speed:g}, the mission's robot.max_speed "
            f"{robot.max_speed:g}"
        )
    problem = _start_problem(controllers.steps[0].triangle, abstraction, robot.start)
    if problem is not None:
        return f"the first step {problem}"
    steps = controllers.steps
    for k, controller in enumerate(steps):
        if controller.is_cell:
            problem = _cell_problem(controller, abstraction, robot, _following(controllers, k))
        elif not np.array_equal(controller.vertices, abstraction.corners(controller.triangle)):
            problem = "its vertices are not the triangle's corners"
        elif controller.is_vertex:
            problem = _pursuit_problem(controller, abstraction, robot)
        else:
            problem = _affine_problem(controller, abstraction, robot)
        if problem is not None:
            return f"step {controller.step} (triangle {controller.triangle}): {problem}"
    return None


def _following(controllers: Controllers, k: int) -> StepController | None:
    """The step after step ``k``: the next one, after the last the loop's first (None after
    a final step that does not loop)."""
    if k + 1 < len(controllers.steps):
        return controllers.steps[k + 1]
    loop = controllers.loop_start
    return None if loop is None else controllers.steps[loop]


def _start_problem(
    triangle: int, abstraction: Abstraction, start: tuple[float, float]
) -> str | None:
    """Whether the plan's first ``triangle`` holds the robot's ``start`` point (a start on an
    edge or a vertex lies in each triangle around it; the planner may begin in any)."""
    if any(cell.triangle == triangle for cell in start_cells(abstraction, start)):
        return None
    x, y = start
    return f"starts in triangle {triangle}, which does not hold robot.start ({x:g}, {y:g})"


def _affine_problem(
    controller: StepController, abstraction: Abstraction, robot: Robot
) -> str | None:
    """A triangle's exit or stay field (on the triangle's corners) against the mesh and the
    C030 conditions."""
    if controller.exit_edge is None:
        if controller.next_triangle is not None:
            return "a stay names a next triangle"
    elif int(abstraction.neighbors[controller.triangle, controller.exit_edge]) != (
        controller.next_triangle
    ):
        return f"exit facet {controller.exit_edge} does not lead to the next triangle"
    problem = violated_condition(controller, robot.max_speed, robot.disturbance)
    if problem is None:
        problem = _law_problem(
            controller.vertices,
            controller.velocities,
            controller.gain,
            controller.offset,
            robot.max_speed,
        )
    if problem is not None:
        return problem
    geometry = triangle_geometry(controller.vertices)
    across = controller.velocities @ geometry.normals.T  # (vertex, facet)
    if controller.exit_edge is None:
        # a stay's exit speed is its least inward speed on the facets away from each vertex
        inward = min(-float(across[i, j]) for i in range(3) for j in range(3) if j != i)
        return _stated_problem(controller, inward, math.inf, robot, 0.0)
    exit_speed = float(across[:, controller.exit_edge].min())
    height = float(geometry.heights[controller.exit_edge])
    rounding = coordinate_rounding(controller.vertices)
    return _stated_problem(controller, exit_speed, height, robot, rounding)


def _pursuit_problem(
    controller: StepController, abstraction: Abstraction, robot: Robot
) -> str | None:
    """A vertex passage: pursuit of a corner the step's triangle shares with the next one, at
    a speed within the bound, in the time it states (on the triangle's corners)."""
    corners = abstraction.vertices[abstraction.triangles[controller.triangle]]
    target = np.asarray(controller.target, dtype=np.float64)
    shared = controller.next_triangle is not None and any(
        np.array_equal(target, abstraction.vertices[v])
        for v in set(abstraction.triangles[controller.triangle].tolist())
        & set(abstraction.triangles[controller.next_triangle].tolist())
    )
    if not shared:
        return "the pursued corner is not shared with the next triangle"
    if _fastest(controller.velocities) > robot.max_speed * (1.0 + RECHECK_TOLERANCE):
        return f"a vertex speed exceeds max_speed {robot.max_speed:g}"
    farthest = float(np.linalg.norm(corners - target, axis=1).max())
    closing = robot.max_speed - robot.disturbance
    if not controller.exit_speed <= closing * (1.0 + RECHECK_TOLERANCE):
        return f"exit_speed {controller.exit_speed:g} is more than the pursuit closes at"
    if not controller.exit_time_bound >= farthest / closing * (1.0 - RECHECK_TOLERANCE):
        return f"exit_time_bound {controller.exit_time_bound:g} is shorter than the pursuit takes"
    return None


def _cell_problem(
    controller: StepController,
    abstraction: Abstraction,
    robot: Robot,
    following: StepController | None,
) -> str | None:
    """A cell's field: its pieces the mesh's triangles and neighbours, its exit facets exactly
    the sides it shares with the cell of the ``following`` step (none for a stay), its rows
    (C030), each piece's law, and the exit speed along xi and the time to cross the cell it
    states."""
    field = controller.cell
    if field is None:
        return "a cell step without its cell field"
    piece_of = {triangle: k for k, triangle in enumerate(field.triangles)}
    # where the field may leave to: the next step's cell (a move's interface is every side
    # the two cells share); a facet marked exit elsewhere would not be asked to push inward
    if field.direction is None or following is None:
        entered: set[int] = set()
    elif following.cell is not None:
        entered = set(following.cell.triangles)
    else:
        entered = {following.triangle}
    for piece, triangle in enumerate(field.triangles):
        if not np.array_equal(field.vertices[piece], abstraction.corners(triangle)):
            return f"the vertices of piece {piece} are not the corners of triangle {triangle}"
        for facet, across in enumerate(field.neighbours[piece]):
            there = int(abstraction.neighbors[triangle, facet])
            if across in (KEPT, EXIT) and there in piece_of:
                return f"piece {piece} leaves the cell across facet {facet} inside it"
            if across not in (KEPT, EXIT) and piece_of.get(there) != across:
                return f"piece {piece} names a wrong neighbour across facet {facet}"
            if (across == EXIT) != (there in entered):
                return (
                    f"piece {piece} marks facet {facet} "
                    + ("an exit, but it does not lead" if across == EXIT else "kept, but it leads")
                    + " into the next step's cell"
                )
    problem = violated_cell_row(controller, robot.max_speed, robot.disturbance)
    pieces = zip(field.vertices, field.velocities, field.gains, field.offsets, strict=True)
    for vertices, velocities, gain, offset in pieces:
        if problem is not None:
            return problem
        problem = _law_problem(vertices, velocities, gain, offset, robot.max_speed)
    if problem is not None or field.direction is None:
        return problem
    xi = np.asarray(field.direction, dtype=np.float64)
    exit_speed = float((field.velocities.reshape(-1, 2) @ xi).min())
    along = field.vertices.reshape(-1, 2) @ xi
    width = float(along.max() - along.min())
    rounding = coordinate_rounding(field.vertices)
    return _stated_problem(controller, exit_speed, width, robot, rounding)


def _law_problem(
    vertices: FloatArray,
    velocities: FloatArray,
    gain: FloatArray,
    offset: FloatArray,
    max_speed: float,
) -> str | None:
    """Whether u = K x + g takes the vertex velocities at the vertices (the field the
    simulator integrates is the law; the conditions are checked on the velocities), to the
    re-check's tolerance and the law's own rounding far from the origin."""
    rounding = (
        8
        * float(np.finfo(np.float64).eps)
        * (float(np.abs(gain).sum() * np.abs(vertices).max()) + float(np.abs(offset).max()))
    )
    residual = np.linalg.norm(vertices @ gain.T + offset - velocities, axis=1)
    if not float(residual.max()) <= RECHECK_TOLERANCE * max_speed + rounding:
        return "K and g do not give the vertex velocities at the vertices"
    return None


def _stated_problem(
    controller: StepController, exit_speed: float, width: float, robot: Robot, rounding: float
) -> str | None:
    """Whether the step claims more than its field achieves: an exit speed above the least
    speed across the exit (``exit_speed``), or an exit-time bound below the time to cross
    ``width`` less its ``rounding`` at that speed less the disturbance (both to the re-check's
    tolerance on speeds: the C030 conditions leave the exit speed more than that above the
    disturbance)."""
    slack = RECHECK_TOLERANCE * robot.max_speed
    if not controller.exit_speed <= exit_speed + slack:
        return f"exit_speed {controller.exit_speed:g} is more than its field's {exit_speed:g}"
    if math.isinf(width):
        return None  # a stay: it never leaves
    least_time = max(width - rounding, 0.0) / (exit_speed + slack - robot.disturbance)
    if not controller.exit_time_bound >= least_time * (1.0 - RECHECK_TOLERANCE):
        return (
            f"exit_time_bound {controller.exit_time_bound:.12g} is shorter than its field "
            f"guarantees ({least_time:.12g})"
        )
    return None


def _fastest(velocities: FloatArray) -> float:
    return float(np.linalg.norm(velocities, axis=1).max())
