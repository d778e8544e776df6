"""The runtime form of the controllers: pose in, velocity command out, plan kept on track.

An :class:`Executor` holds the compiled plan (the witness lasso and one affine field per plan
step).  Each :meth:`Executor.command` call

1. takes the robot's reference point (the point itself, or for a unicycle the point
   ``offset`` ahead of the axle) and walks the triangulation along the straight move from the
   previous one, so every triangle passed through is seen even when poses come sparsely;
2. for each triangle entered, reads its label into the task tracker (the automaton states
   consistent with the labels actually visited) and advances the plan step when it is the
   one the step leads to;
3. otherwise recovers: it *re-enters* the plan at a step in this triangle whose automaton
   state the history can be in (the rest of the plan is then an accepting continuation), or
   else *re-plans* on the product from (this triangle, these automaton states) and solves
   the new plan's fields;
4. returns the current step's field at the reference point (for a unicycle, turned into
   forward and angular speed by feedback linearisation).

A vertex passage step runs the pursuit law toward its corner v, slowed near v so that a
command held for as long as the last sample period lands on v rather than past it; the step
ends (the robot is at v, in the next step's triangle) when the robot is within
:data:`ARRIVAL` of v relative to the triangle's size, or its last move went past v.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray
from tlmpc.automata.model import Automaton
from tlmpc.base.errors import InvalidInputError, NoPlanError, SolverError, UsageError, error
from tlmpc.control.model import Controllers, StepController
from tlmpc.mission.model import Mission
from tlmpc.planning.boundary import crossing_letter, start_point_label
from tlmpc.planning.model import Witness
from tlmpc.runtime.locate import Locator
from tlmpc.runtime.model import Phase, Progress, Recovery, RecoveryKind, Status
from tlmpc.runtime.tracker import TaskTracker, working_automaton
from tlmpc.runtime.unicycle import reference_point, unicycle_command


class CompiledOutput(Protocol):
    """What the executor needs of an in-memory compilation (``tlmpc.Compiled`` is one)."""

    @property
    def artifacts(self) -> Mapping[str, Any]: ...

    @property
    def source(self) -> str: ...


#: A vertex passage has arrived within this fraction of its triangle's diameter of the corner.
ARRIVAL = 1e-6


@dataclass(frozen=True, slots=True)
class RunPlan:
    """A lasso being executed: its step fields, the automaton state after each step's
    triangle, and the first step of a moving cycle (None when the plan ends by staying)."""

    steps: tuple[StepController, ...]
    states: tuple[int, ...]
    loop_start: int | None

    @classmethod
    def of(cls, witness: Witness, controllers: Controllers) -> RunPlan:
        """The plan of a witness and its controllers (one controller per lasso triangle)."""
        states = (*witness.prefix_states, *witness.cycle_states)
        if any(c.cell is not None for c in controllers.steps):
            # cell steps: each ends in the state of the triangle it leaves its cell from
            states = tuple(
                states[c.cell.plan_index] if c.cell is not None else states[k]
                for k, c in enumerate(controllers.steps)
            )
        if len(states) != len(controllers.steps):
            raise UsageError(
                error(
                    "R021",
                    f"the witness has {len(states)} steps but the controllers "
                    f"{len(controllers.steps)}",
                    hint="the output folder mixes two compilations: compile again",
                )
            )
        return cls(controllers.steps, states, controllers.loop_start)

    def following(self, step: int) -> int | None:
        """The step after ``step`` (the cycle wraps; None after a stay)."""
        if step + 1 < len(self.steps):
            return step + 1
        return self.loop_start

    def phase(self, step: int) -> Phase:
        """Whether ``step`` is in the prefix, the moving cycle, or the final stay."""
        if self.loop_start is None:
            return "stay" if step == len(self.steps) - 1 else "prefix"
        return "cycle" if step >= self.loop_start else "prefix"

    def distance(self, start: int, target: int) -> int:
        """Steps from ``start`` forward to ``target`` along the lasso (backward ones last)."""
        if target >= start:
            return target - start
        if self.loop_start is not None and target >= self.loop_start:
            return len(self.steps) - start + target - self.loop_start
        return 2 * len(self.steps) + start - target


#: The artifacts of an output folder the executor is built from.
EXECUTOR_ARTIFACTS = (
    "mission.json",
    "abstraction.json",
    "automaton.json",
    "witness.json",
    "controllers.json",
)


class Executor:
    """Pose → velocity for a compiled mission, with plan tracking and recovery.

    Build it with :meth:`from_output` (an output folder of ``tlmpc compile`` or a
    :class:`~tlmpc.Compiled`).  Poses are ``(x, y)`` for a point robot and ``(x, y, theta)``
    for a unicycle; :meth:`command` returns ``(vx, vy)`` or ``(v, omega)``.
    """

    def __init__(
        self,
        *,
        mission: Mission,
        abstraction: Abstraction,
        automaton: Automaton,
        witness: Witness,
        controllers: Controllers,
    ) -> None:
        self.mission = mission
        self.abstraction = abstraction
        self.automaton = automaton  # as compiled: re-planning degeneralizes it as planning did
        self.locator = Locator.of(abstraction)
        self.tracker = TaskTracker(working_automaton(automaton), abstraction.letters)
        self._closed = mission.options.boundary == "closed"
        self.plan = RunPlan.of(witness, controllers)
        self._check_plan_states()
        self._step = 0
        self._states: frozenset[int] = frozenset()
        self._triangle: int | None = None
        self._point: FloatArray | None = None
        self._status: Status = "following"
        self._time = 0.0
        self._period = 0.0  # time between the last two commands (a vertex passage lands)
        self._laps = 0
        self._replans = 0
        self._reentries = 0
        self._visits: dict[str, int] = dict.fromkeys(abstraction.regions, 0)
        self._events: list[Recovery] = []

    @classmethod
    def from_output(cls, output: CompiledOutput | str | os.PathLike[str]) -> Executor:
        """The executor of a compiled output folder (or an in-memory compilation)."""
        from tlmpc.abstraction.io import abstraction_from_json
        from tlmpc.automata.io import automaton_from_json
        from tlmpc.control.io import controllers_from_json
        from tlmpc.io.artifacts import read_artifacts
        from tlmpc.mission.io import mission_from_json
        from tlmpc.planning.io import witness_from_json

        needed = EXECUTOR_ARTIFACTS
        if isinstance(output, str | os.PathLike):
            source = str(output)
            artifacts: Mapping[str, Any] = read_artifacts(Path(output), needed)
        else:
            source, artifacts = output.source, output.artifacts
        missing = [name for name in needed if name not in artifacts]
        if missing:
            raise UsageError(
                error(
                    "R020",
                    f"{source} has no {', '.join(missing)}: the executor needs a "
                    "compilation through the control stage",
                    file=source,
                    hint="compile the mission without --until (or up to the control stage)",
                )
            )
        mission = mission_from_json(artifacts["mission.json"])
        abstraction = abstraction_from_json(artifacts["abstraction.json"])
        witness = witness_from_json(artifacts["witness.json"])
        controllers = controllers_from_json(artifacts["controllers.json"])
        if isinstance(output, str | os.PathLike):
            # a folder's artifacts may have been edited: run only what the control stage wrote
            from tlmpc.control.recheck import refuse_edited

            steps = artifacts["controllers.json"]["steps"]
            refuse_edited(Path(output), mission, abstraction, witness, controllers, steps)
        return cls(
            mission=mission,
            abstraction=abstraction,
            automaton=automaton_from_json(artifacts["automaton.json"]),
            witness=witness,
            controllers=controllers,
        )

    # --- reports -------------------------------------------------------------------------

    @property
    def progress(self) -> Progress:
        """Where the robot is in its plan and its task (see :class:`Progress`)."""
        return Progress(
            time=self._time,
            status=self._status,
            triangle=self._triangle,
            step=self._step,
            phase=self.plan.phase(self._step),
            laps=self._laps,
            repeating=self._laps > 0,
            automaton_states=tuple(sorted(self._states)),
            visits=dict(self._visits),
            replans=self._replans,
            reentries=self._reentries,
        )

    @property
    def recoveries(self) -> tuple[Recovery, ...]:
        """Every recovery made so far, in order."""
        return tuple(self._events)

    @property
    def controller(self) -> StepController:
        """The field of the current plan step."""
        return self.plan.steps[self._step]

    @property
    def is_unicycle(self) -> bool:
        """True for a differential-drive robot (poses carry a heading)."""
        return self.mission.robot.model == "unicycle"

    # --- the loop ------------------------------------------------------------------------

    def reference_point(self, pose: Sequence[float]) -> FloatArray:
        """The point the plan steers: the pose itself, or the point ahead of the axle."""
        return reference_point(pose, self.mission.robot)

    def velocity(self, point: FloatArray) -> FloatArray:
        """The current step's field at ``point``, within ``max_speed`` (zero when stopped)."""
        if self._status in ("no_plan", "violated"):
            return np.zeros(2)
        controller = self.controller
        if controller.is_vertex:
            return self._pursuit(controller, point)
        gain, offset = controller.gain, controller.offset
        if controller.cell is not None:
            # the law of the cell's triangle the robot is in (the nearest piece just outside)
            piece = controller.cell.piece_of(self._triangle) if self._triangle is not None else None
            if piece is None:
                from tlmpc.simulate.cells import nearest_piece

                piece = nearest_piece(controller.cell, point)
            gain, offset = controller.cell.gains[piece], controller.cell.offsets[piece]
        u: FloatArray = gain @ point + offset
        speed = float(np.hypot(u[0], u[1]))
        limit = self.mission.robot.max_speed
        if speed > limit:  # only just outside the triangle: the field is bounded inside
            u = u * (limit / speed)
        return u

    def command(self, pose: Sequence[float], t: float) -> tuple[float, float]:
        """The command for ``pose`` at time ``t``: ``(vx, vy)``, or ``(v, omega)`` for a
        unicycle.  Updates the plan step, the task progress and recovers when needed."""
        expected = 3 if self.is_unicycle else 2
        if not finite_numbers(pose, expected, t):
            shape = "(x, y, theta)" if self.is_unicycle else "(x, y)"
            raise UsageError(
                error(
                    "R023",
                    f"a pose of this {self.mission.robot.model} robot is {shape} of finite "
                    f"numbers with a finite time, not {repr(pose)[:60]} at t={repr(t)[:30]}",
                    hint="pass the measured pose in the mission's frame",
                )
            )
        point = self.reference_point(pose)
        self._period = max(float(t) - self._time, 0.0) if self._point is not None else 0.0
        self._time = float(t)
        self.observe(point)
        u = self.velocity(point)
        if self.is_unicycle:
            return unicycle_command(float(pose[2]), u, self.mission.robot.offset)
        return float(u[0]), float(u[1])

    def observe(self, point: FloatArray) -> None:
        """Read the move from the previous reference point to ``point``."""
        if self._point is None:
            self._start(point)
            return
        previous, self._point = self._point, point
        if self._status in ("no_plan", "violated"):
            return
        controller = self.controller
        if (
            controller.is_vertex
            and self._status == "following"
            and controller.next_triangle is not None
            and self._at_corner(controller, previous, point)
        ):
            self._enter(controller.next_triangle, point, controller.target)
            return
        entered: list[int] | None = None
        if self._triangle is not None and self._status != "outside":
            entered = self.locator.walk(self._triangle, previous, point)
        if entered is None:
            found = self.locator.locate(point)
            if found is None:
                self._status = "outside"
                return
            entered = [] if found == self._triangle else [found]
            self._status = "following"
        for triangle in entered:
            self._enter(triangle, point)
            if self._status in ("no_plan", "violated"):
                return

    # --- internals -----------------------------------------------------------------------

    def _pursuit(self, controller: StepController, point: FloatArray) -> FloatArray:
        """The pursuit law toward the corner, at max_speed or slower where one more held
        command of the last period would carry the robot past it."""
        assert controller.target is not None
        towards = np.asarray(controller.target, dtype=np.float64) - point
        distance = float(np.hypot(towards[0], towards[1]))
        if distance == 0.0:
            return np.zeros(2)
        speed = self.mission.robot.max_speed
        if self._period > 0.0:
            speed = min(speed, distance / self._period)
        u: FloatArray = towards * (speed / distance)
        return u

    @staticmethod
    def _at_corner(controller: StepController, previous: FloatArray, point: FloatArray) -> bool:
        """True when a vertex passage has reached its corner (see the module doc)."""
        assert controller.target is not None
        corner = np.asarray(controller.target, dtype=np.float64)
        size = max(
            float(np.linalg.norm(controller.vertices[i] - controller.vertices[(i + 1) % 3]))
            for i in range(3)
        )
        if float(np.linalg.norm(point - corner)) <= ARRIVAL * size:
            return True
        return float((corner - previous) @ (corner - point)) < 0.0

    def _check_plan_states(self) -> None:
        """The witness's automaton states must be a run over its own labels (else R022)."""
        steps, states = self.plan.steps, self.plan.states
        start = self.mission.robot.start
        seen = self._initial_states(steps[0].triangle, np.array(start, dtype=np.float64))
        for index, (controller, state) in enumerate(zip(steps, states, strict=True)):
            if index > 0:
                previous = steps[index - 1]
                corner = previous.target if previous.is_vertex else None
                seen = self._read_entry(seen, previous.triangle, controller.triangle, corner)
            if state not in seen:
                raise UsageError(
                    error(
                        "R022",
                        f"plan step {index}: automaton state {state} is not reachable by "
                        "reading the plan's labels",
                        hint="the witness does not belong to this automaton: compile again",
                    )
                )
            seen = frozenset({state})

    def _initial_states(self, triangle: int, point: FloatArray) -> frozenset[int]:
        """The automaton states after the start: under the closed convention the start
        point's own letter first, then the start triangle's label."""
        states = frozenset({self.tracker.automaton.initial})
        if self._closed:
            states = self.tracker.read_point(states, self._point_letter(point))
        return self.tracker.read(states, int(self.abstraction.letter_of[triangle]))

    def _point_letter(self, point: Sequence[float] | FloatArray) -> tuple[str, ...]:
        """The closed convention's letter of the robot at ``point`` (the start, or a passage
        corner): every region whose closure holds it, as the planner reads it."""
        where = (float(point[0]), float(point[1]))
        return crossing_letter(start_point_label(self.abstraction, where), ())

    def _read_entry(
        self,
        states: frozenset[int],
        before: int | None,
        triangle: int,
        corner: tuple[float, float] | None = None,
    ) -> frozenset[int]:
        """The automaton states after moving into ``triangle``: under the closed convention
        the handover instant's letter first (the crossed edge's, or the corner's for a
        vertex passage), as the planner reads it."""
        if self._closed:
            if corner is not None:
                instant = self._point_letter(corner)
            else:
                left = self.abstraction.labels(before) if before is not None else ()
                instant = crossing_letter(left, self.abstraction.labels(triangle))
            states = self.tracker.read_point(states, instant)
        return self.tracker.read(states, int(self.abstraction.letter_of[triangle]))

    def _start(self, point: FloatArray) -> None:
        self._point = point
        first = self.plan.steps[0].triangle
        # A start on an edge or a vertex lies in several triangles: the plan's comes first.
        triangle = first if self.locator.contains(first, point) else self.locator.locate(point)
        if triangle is None:
            self._status = "outside"
            return
        self._triangle = triangle
        self._states = self._initial_states(triangle, point)
        for name in self.abstraction.labels(triangle):
            self._visits[name] = self._visits.get(name, 0) + 1
        if triangle == self.plan.steps[0].triangle and self.plan.states[0] in self._states:
            self._step = 0
        else:
            self._recover(triangle, point)

    def _enter(
        self, triangle: int, point: FloatArray, corner: tuple[float, float] | None = None
    ) -> None:
        previous = self._triangle
        before = set(self.abstraction.labels(previous)) if previous is not None else set()
        self._triangle = triangle
        for name in self.abstraction.labels(triangle):
            if name not in before:
                self._visits[name] = self._visits.get(name, 0) + 1
        self._states = self._read_entry(self._states, previous, triangle, corner)
        if not self._states:
            self._stop("violated", triangle)
            return
        following = self.plan.following(self._step)
        cell = self.controller.cell
        if cell is not None and triangle in cell.triangles:
            return  # on through the step's own cell: the same label, the same field
        if (
            following is not None
            and self._leads_to(following, triangle)
            and self.plan.states[following] in self._states
        ):
            if following <= self._step:  # the cycle wraps around: one more lap done
                self._laps += 1
            self._step = following
            return
        self._recover(triangle, point)

    def _leads_to(self, following: int, triangle: int) -> bool:
        """Whether entering ``triangle`` is the move to step ``following`` (for a cell step:
        into any triangle of the next step's cell)."""
        nxt = self.plan.steps[following].cell
        if self.controller.cell is not None and nxt is not None:
            return triangle in nxt.triangles
        return self.controller.next_triangle == triangle

    def _recover(self, triangle: int, point: FloatArray) -> None:
        step = self._reentry_step(triangle)
        if step is not None:
            self._record("reentry", triangle, step)
            self._step = step
            self._reentries += 1
            return
        self._replan(triangle, point)

    def _reentry_step(self, triangle: int) -> int | None:
        """The nearest step ahead in ``triangle`` whose automaton state the history allows."""
        candidates = [
            index
            for index, controller in enumerate(self.plan.steps)
            if (
                triangle in controller.cell.triangles
                if controller.cell is not None
                else controller.triangle == triangle
            )
            and self.plan.states[index] in self._states
        ]
        if not candidates:
            return None
        return min(candidates, key=lambda index: self.plan.distance(self._step, index))

    def _replan(self, triangle: int, point: FloatArray) -> None:
        from tlmpc.base.memo import memo_scope
        from tlmpc.control import synthesize
        from tlmpc.planning.mission import plan_mission

        abstraction = dataclasses.replace(self.abstraction, start=triangle)
        if not self.locator.contains(triangle, point):
            # A triangle crossed on the way to ``point``: the plan starts in it, and the
            # planner's start triangles are those holding its start point.
            point = abstraction.corners(triangle).mean(axis=0)
        try:
            # Compile's own planning entry, resumed from the tracked automaton states: edges,
            # U-turn refinement, then vertex passages, on the mesh the run was compiled with;
            # one memo for the re-plan, as a compile has (the mesh's cells partitioned once).
            with memo_scope():
                planned = plan_mission(
                    self.mission,
                    abstraction,
                    self.automaton,
                    resume=self._states,
                    start_point=(float(point[0]), float(point[1])),
                )
                controllers = synthesize(
                    planned.abstraction,
                    planned.witness,
                    self.mission.robot,
                    relevant=self.mission.formula.props(),
                )
        except (NoPlanError, SolverError, InvalidInputError):
            self._stop("no_plan", triangle)
            return
        if planned.abstraction is not abstraction:
            # Refined for a U-turn: a split triangle keeps its number for one of its parts and
            # the others are appended with its label, so the run's history stays meaningful.
            refined = planned.abstraction
            self.abstraction = dataclasses.replace(refined, start=self.abstraction.start)
            self.locator = Locator.of(self.abstraction)
        self._record("replan", triangle, 0)
        self.plan = RunPlan.of(planned.witness, controllers)
        self._step = 0
        self._laps = 0
        self._replans += 1

    def _stop(self, status: Status, triangle: int) -> None:
        self._status = status
        kind: RecoveryKind = "violated" if status == "violated" else "no_plan"
        self._record(kind, triangle, None)

    def _record(self, kind: RecoveryKind, triangle: int, step_after: int | None) -> None:
        self._events.append(
            Recovery(
                time=self._time,
                kind=kind,
                triangle=triangle,
                step_before=self._step,
                step_after=step_after,
            )
        )


def finite_numbers(pose: Any, expected: int, t: Any) -> bool:
    """Whether ``pose`` is ``expected`` finite numbers and ``t`` a finite number (anything
    else, None or text or an integer too large for a float, is not)."""
    try:
        values = [float(v) for v in (*pose, t)]
        return len(pose) == expected and all(math.isfinite(v) for v in values)
    except (TypeError, ValueError, OverflowError):
        return False
