"""The executor of a reactive mission: the strategy's Mealy machine driving the robot.

The executor follows docs/semantics.md ("Reactive missions", "Executing a strategy"): the
continuous run is cut at its *events* — the sensors change, the robot crosses into the face it
heads for, or both at one instant — and at each event the machine takes one step: the
environment's input (sensors, the robot's face, ``moved``) in, the robot's answer (the face it
heads for, its actions) out, at once.  Between events the robot follows one affine field per
triangle (the control stage's vertex programs, solved on demand for each route and cached):

* heading for a neighbouring face, it runs the shortest route of triangles inside its face to
  the face's edge with the goal face and crosses it — no other face is ever entered, since
  each field keeps the triangle's other facets invariant;
* heading for its own face (a *stay*), it converges to the incenter of the triangle it is in;
* a route never starts by leaving through the edge the robot stands on (it would leave a face
  in the instant it entered it): the robot first *dwells* in the triangle, under the stay
  field, for a positive time.

When the robot stays and nothing changes, the game would go on taking steps in which the
environment changes nothing (*stutter* steps); the strategy may answer them by heading
elsewhere or switching actions.  The executor follows the stutter answers that change the
robot's behaviour, after a dwell, and rests where they only repeat it.
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from tlmpc.abstraction.model import Abstraction, FloatArray, IntArray, triangle_inradius
from tlmpc.base.errors import UsageError, error
from tlmpc.control.geometry import triangle_geometry
from tlmpc.control.model import StepController
from tlmpc.mission.model import Mission
from tlmpc.planning.model import Witness
from tlmpc.reactive.faces import faces_of, start_faces
from tlmpc.runtime.executor import CompiledOutput, finite_numbers
from tlmpc.runtime.locate import Locator
from tlmpc.runtime.strategy_machine import Stepper, strategy_stepper
from tlmpc.simulate.exact import exit_step
from tlmpc.simulate.matrix import expm_small

#: The artifacts a reactive output folder must hold for the executor.
REACTIVE_ARTIFACTS = ("mission.json", "abstraction.json", "strategy.json")
#: A point this close to an edge (relative to the triangle's height over it) is on it.
ON_EDGE = 1e-9
#: Samples of a stay or dwell stretch (besides its end).
STAY_SAMPLES = 6


@dataclass(frozen=True, slots=True)
class Leg:
    """One stretch of motion: a field in a triangle, leaving by its exit edge (``exit``), or
    converging for ever (``stay``), or until time ``until`` before the next leg
    (``dwell``)."""

    kind: str
    controller: StepController
    until: float = math.inf


@dataclass(slots=True)
class Event:
    """One step of the machine: when, why (``start``, ``sensors``, ``arrival``, ``both`` or
    ``stutter``), what the environment gave and what the robot answered."""

    time: float
    kind: str
    sensors: dict[str, bool]
    face: int
    node: int
    goal: int
    actions: dict[str, bool]


@dataclass(slots=True)
class Motion:
    """The robot's sampled trajectory so far: times, points and each sample's triangle."""

    times: list[float] = field(default_factory=list)
    points: list[tuple[float, float]] = field(default_factory=list)
    triangles: list[int] = field(default_factory=list)
    crossings: list[int] = field(default_factory=list)

    def add(self, t: float, point: FloatArray, triangle: int) -> None:
        if self.times and t <= self.times[-1]:
            if t == self.times[-1]:
                self.points[-1] = (float(point[0]), float(point[1]))
                self.triangles[-1] = triangle
            return
        self.times.append(float(t))
        self.points.append((float(point[0]), float(point[1])))
        self.triangles.append(triangle)


class ReactiveExecutor:
    """Steps a reactive mission's strategy at events and moves the robot between them.

    Use :meth:`from_output`, then :meth:`start` with the first sensor reading; then, in
    turn, :meth:`advance` the robot to the next environment event (it stops early when the
    robot arrives in its goal face) and :meth:`react` to what happened.
    """

    def __init__(self, *, mission: Mission, abstraction: Abstraction, machine: Stepper) -> None:
        assert mission.reactive is not None
        self.mission = mission
        self.abstraction = abstraction
        self.machine = machine
        self.face_of = np.asarray(machine.face_of, dtype=np.int64)
        faces = faces_of(abstraction)  # the strategy's faces must be the abstraction's
        if not np.array_equal(faces.face_of, self.face_of) or faces.letters != machine.labels:
            raise UsageError(
                error(
                    "Q123",
                    "strategy.json's faces are not those of abstraction.json",
                    hint="the output folder mixes two compilations: compile the mission again",
                )
            )
        self.sensors: dict[str, bool] = {}
        self.actions: dict[str, bool] = {}
        self.events: list[Event] = []
        self.motion = Motion()
        self.signals: dict[str, list[list[float | bool]]] = {}
        self.node = -1
        self.time = 0.0
        self.point = np.asarray(mission.robot.start, dtype=np.float64)
        self.triangle = self._entered_first(mission.robot.start, abstraction.start)
        self._came_from: int | None = None  # the triangle before the last crossing
        self.face = int(self.face_of[self.triangle])
        self.legs: list[Leg] = []
        self._cache: dict[tuple[int, int | None], StepController] = {}
        self.solves = 0
        #: ``following``, or ``off_course`` once the robot (pushed by something the strategy
        #: does not know of) entered a face it was not heading for: it then stops
        self.status = "following"
        self._locator: Locator | None = None
        self._inside_faces, self._portals = _face_graph(abstraction, self.face_of)

    def _entered_first(self, point: Sequence[float] | FloatArray, located: int) -> int:
        """The triangle the robot at ``point`` (found in ``located``) enters first: on the
        boundary of faces, one of the first face the strategy serves, in the order the game
        tried them (:func:`~tlmpc.reactive.faces.start_faces`)."""
        from tlmpc.abstraction.starts import start_cells

        where = (float(point[0]), float(point[1]))
        faces = start_faces(self.abstraction, self.face_of, where, located)
        if len(faces) == 1:
            return located
        readings = [
            dict(zip(self.machine.sensors, values, strict=True))
            for values in itertools.product((False, True), repeat=len(self.machine.sensors))
        ]
        cells = [located, *(c.triangle for c in start_cells(self.abstraction, where))]
        for face in faces:
            if any(self.machine.start(reading, face) is not None for reading in readings):
                return next(t for t in cells if int(self.face_of[t]) == face)
        return located

    @classmethod
    def from_output(cls, output: CompiledOutput | str | os.PathLike[str]) -> ReactiveExecutor:
        """The executor of a compiled reactive output folder (or an in-memory compilation)."""
        from tlmpc.abstraction.io import abstraction_from_json
        from tlmpc.io.artifacts import read_artifacts
        from tlmpc.mission.io import mission_from_json

        artifacts: Mapping[str, Any]
        if isinstance(output, str | os.PathLike):
            folder = Path(output)
            artifacts = read_artifacts(folder, REACTIVE_ARTIFACTS)
        else:
            folder, artifacts = Path(output.source), output.artifacts
        missing = [name for name in REACTIVE_ARTIFACTS if name not in artifacts]
        lost = "counterstrategy.json" in artifacts or (folder / "counterstrategy.json").is_file()
        if missing == ["strategy.json"] and lost:
            raise UsageError(
                error(
                    "Q123",
                    f"{folder} is the compilation of an unrealizable reactive mission: the "
                    "environment can defeat every robot strategy (counterstrategy.json), so "
                    "there is no strategy.json to simulate",
                    hint=f"tlmpc view {folder} (or tlmpc plot) draws how the environment wins; "
                    "weaken the task or add assumptions until tlmpc compile finds a strategy",
                    file=str(folder),
                )
            )
        if missing:
            raise UsageError(
                error(
                    "Q123",
                    f"{folder} has no {', '.join(missing)}: a reactive mission's executor "
                    "needs its strategy",
                    hint="compile the reactive mission (it must be realizable)",
                    file=str(folder),
                )
            )
        mission = mission_from_json(artifacts["mission.json"])
        if mission.reactive is None:
            raise UsageError(
                error(
                    "Q123",
                    f"{folder}: the mission has no sensors: it is not reactive",
                    hint="simulate a static mission without --sensors",
                    file=str(folder),
                )
            )
        machine = strategy_stepper(
            artifacts["strategy.json"],
            mission.reactive.sensor_names,
            mission.reactive.actions,
            str(folder / "strategy.json"),
        )
        return cls(
            mission=mission,
            abstraction=abstraction_from_json(artifacts["abstraction.json"]),
            machine=machine,
        )

    # --- the machine ---------------------------------------------------------------------

    @property
    def goal(self) -> int:
        """The face the robot heads for."""
        return self.machine.goal(self.node)

    @property
    def staying(self) -> bool:
        """Whether the robot heads for its own face."""
        return self.goal == self.face

    def face_regions(self, face: int | None = None) -> tuple[str, ...]:
        """The regions of ``face`` (the robot's own by default)."""
        return self.machine.labels[self.face if face is None else face]

    def start(self, sensors: Mapping[str, bool]) -> bool:
        """Begin at time 0 with the first reading; False when the strategy serves no such
        start (the reading breaks an initial assumption)."""
        node = self.machine.start(sensors, self.face)
        if node is None:
            return False
        self.motion.add(0.0, self.point, self.triangle)
        self._take(node, dict(sensors), "start")
        return True

    def react(self, sensors: Mapping[str, bool], *, arrived: bool) -> bool:
        """One step of the machine at the current time: the new reading, and whether the
        robot has just crossed into its goal face; False when the strategy has no answer."""
        node = self.machine.answer(self.node, sensors, self.face, arrived)
        if node is None:
            return False
        changed = dict(sensors) != self.sensors
        kind = ("both" if changed else "arrival") if arrived else "sensors"
        self._take(node, dict(sensors), kind)
        return True

    def stutter_answer(self) -> int | None:
        """Where a stutter step leads while the robot stays: the first node along the
        strategy's answers to "nothing changed" whose goal or actions differ; None when they
        only repeat the robot's behaviour (it then rests) or the robot is on its way."""
        if not self.staying:
            return None
        shown = self.machine.behaviour(self.node)
        node, seen = self.node, {self.node}
        while True:
            nxt = self.machine.answer(node, self.sensors, self.face, False)
            if nxt is None or nxt in seen:
                return None
            if self.machine.behaviour(nxt) != shown:
                return nxt
            node = nxt
            seen.add(node)

    def stutter(self, node: int) -> None:
        """Take the stutter answer ``node`` (from :meth:`stutter_answer`) now."""
        self._take(node, dict(self.sensors), "stutter")

    def dwell_time(self) -> float:
        """How long the robot dwells before a stutter step or before leaving through the edge
        it stands on: the time to cross its triangle's inscribed circle at full speed."""
        corners = self.abstraction.corners(self.triangle)
        return triangle_inradius(corners) / self.mission.robot.max_speed

    def _take(self, node: int, sensors: dict[str, bool], kind: str) -> None:
        self.node = node
        actions = self.machine.action_values(node)
        for name, value in (*sensors.items(), *actions.items()):
            points = self.signals.setdefault(name, [])
            if not points or points[-1][1] != value:
                if points and points[-1][0] == self.time:
                    points[-1][1] = value
                    if len(points) > 1 and points[-2][1] == value:
                        points.pop()
                else:
                    points.append([self.time, value])
        self.sensors, self.actions = sensors, actions
        self.events.append(
            Event(self.time, kind, dict(sensors), self.face, node, self.goal, dict(actions))
        )
        self._plan()

    # --- online use: pose in, velocity out -------------------------------------------------

    def _reading(self, sensors: Mapping[str, bool]) -> dict[str, bool]:
        """The readings of the mission's sensors, each given and none other (a misspelt name
        would otherwise be dropped silently and the sensor read as missing)."""
        known = self.machine.sensors
        hint = f"pass one value, true or false, per sensor of the mission: {', '.join(known)}"
        if not isinstance(sensors, Mapping):
            raise UsageError(
                error(
                    "Q125",
                    f"the readings are a mapping of sensor names to true or false, not "
                    f"{repr(sensors)[:60]}",
                    hint=hint,
                )
            )
        missing = [s for s in known if s not in sensors]
        unknown = sorted(str(s) for s in sensors if s not in known)
        # a reading is a truth value: "no" or None read by their truth would be guesses
        unread = [s for s in known if s in sensors and not _truth_value(sensors[s])]
        if missing or unknown or unread:
            said = [f"no reading of {', '.join(missing)}"] if missing else []
            said += [f"no sensor called {', '.join(unknown)}"] if unknown else []
            said += [f"not true or false: {', '.join(unread)}"] if unread else []
            raise UsageError(
                error(
                    "Q125",
                    f"the readings {dict(sensors)!r} do not fit the mission: {'; '.join(said)}",
                    hint=hint,
                )
            )
        return {s: bool(sensors[s]) for s in known}

    def command(
        self, point: Sequence[float] | FloatArray, t: float, sensors: Mapping[str, bool]
    ) -> tuple[float, float]:
        """The velocity for a robot at ``point`` at time ``t`` (not decreasing) reading
        ``sensors``: the events the readings and the position make are taken first (a
        sensor change, an arrival in the goal face, both, or a due stutter step).  A robot
        found in a face it was not heading for is ``off_course`` and gets zero velocity."""
        if isinstance(point, str | bytes) or not finite_numbers(point, 2, t):
            raise UsageError(
                error(
                    "Q125",
                    f"a position is (x, y) of finite numbers with a finite time, not "
                    f"{repr(point)[:60]} at t={repr(t)[:30]}",
                    hint="pass the robot's (reference) point in the mission's frame",
                )
            )
        where = np.asarray(point, dtype=np.float64)
        if self._locator is None:
            self._locator = Locator.of(self.abstraction)
        reading = self._reading(sensors)
        if self.node < 0:
            found = self._locator.locate(where)
            if found is None:
                raise UsageError(
                    error("Q125", f"the start {tuple(point)!r} is outside the free space")
                )
            found = self._entered_first(where, found)
            self.triangle, self.face = found, int(self.face_of[found])
            self.point, self.time = where, float(t)
            if not self.start(reading):
                raise UsageError(
                    error(
                        "Q125",
                        f"the strategy serves no start in face {self.face} with the "
                        f"readings {reading}",
                        hint="start the robot in the face of the mission's robot.start, with "
                        "readings that keep the initial assumptions",
                    )
                )
            return self.velocity(where)
        self.time = max(self.time, float(t))
        if self.status != "following":
            return (0.0, 0.0)
        entered = self._locator.walk(self.triangle, self.point, where)
        if entered is None:
            found = self._locator.locate(where)
            entered = [] if found is None or found == self.triangle else [found]
        self.point = where
        arrived = False
        for triangle in entered:
            face = int(self.face_of[triangle])
            if face != self.face and (arrived or face != self.goal):
                self.status = "off_course"
                return (0.0, 0.0)
            self._came_from, self.triangle = self.triangle, triangle
            if face != self.face:
                self.face, arrived = face, True
        if arrived or reading != self.sensors:
            if not self.react(reading, arrived=arrived):
                self.status = "off_course"  # the readings break an assumption
                return (0.0, 0.0)
        else:
            stutter = self.stutter_answer()
            if stutter is not None and t >= self.events[-1].time + self.dwell_time():
                self.stutter(stutter)
        if self.legs and self.legs[0].kind == "dwell" and t >= self.legs[0].until:
            self.legs.pop(0)
        while len(self.legs) > 1 and self.legs[0].controller.triangle != self.triangle:
            if self.legs[0].controller.next_triangle == self.triangle:
                self.legs.pop(0)  # crossed into the route's next triangle
            else:
                break
        if self.legs and self.legs[0].controller.triangle != self.triangle:
            self._plan_from_here()  # pushed off the route inside the face
        return self.velocity(where)

    def velocity(self, point: FloatArray) -> tuple[float, float]:
        """The current leg's field at ``point``, within ``max_speed``."""
        controller = self.legs[0].controller
        u = controller.gain @ point + controller.offset
        speed = float(np.hypot(u[0], u[1]))
        limit = self.mission.robot.max_speed
        if speed > limit:  # only just outside the triangle: the field is bounded inside
            u = u * (limit / speed)
        return float(u[0]), float(u[1])

    def _plan_from_here(self) -> None:
        self.legs = []
        self._plan()

    # --- motion --------------------------------------------------------------------------

    def _plan(self) -> None:
        """The legs toward the current goal from where the robot is."""
        if self.staying:
            if not (self.legs and self.legs[0].kind == "stay"):
                self.legs = [Leg("stay", self._controllers([self.triangle])[0])]
            return
        route = self.route(self.triangle, self.goal)
        steps = self._controllers(route)[:-1]
        legs = [Leg("exit", c) for c in steps]
        first = steps[0]
        assert first.exit_edge is not None
        geometry = triangle_geometry(first.vertices)
        gap = float(
            geometry.offsets[first.exit_edge] - geometry.normals[first.exit_edge] @ self.point
        )
        # Just arrived and heading back where it came from (online, the robot is a sample
        # period inside, not on the edge), or standing on the exit edge: dwell first.
        last = self.events[-1] if self.events else None
        arrived = last is not None and last.kind in ("arrival", "both") and last.time == self.time
        back = arrived and first.next_triangle == self._came_from
        if back or gap <= ON_EDGE * float(geometry.heights[first.exit_edge]):
            stay = self._controllers([self.triangle])[0]
            legs.insert(0, Leg("dwell", stay, self.time + self.dwell_time()))
        self.legs = legs

    def route(self, triangle: int, goal: int) -> list[int]:
        """The shortest chain of triangles (by centre distance) from ``triangle`` through its
        face to the first triangle of the neighbouring face ``goal``."""
        from scipy.sparse.csgraph import dijkstra

        face = int(self.face_of[triangle])
        portals = self._portals.get((face, goal))
        if portals is None:
            raise UsageError(
                error(
                    "Q124",
                    f"the strategy heads from face {face} for face {goal}, which does not "
                    "share an edge with it",
                    hint="strategy.json and abstraction.json do not belong together: compile again",
                )
            )
        inside, entries = portals
        distance, before = dijkstra(self._inside_faces, indices=triangle, return_predecessors=True)
        # the nearest triangle on the edge with the goal face (first in the list on a tie)
        best = int(np.argmin(distance[inside]))
        path = [int(inside[best])]
        while path[-1] != triangle:
            path.append(int(before[path[-1]]))
        return [*reversed(path), int(entries[best])]

    def _controllers(self, route: list[int]) -> list[StepController]:
        """One field per route triangle (exits, then a stay in the last), from the cache or
        solved together in one vertex program."""
        keys = [
            *[(a, self._edge(a, b)) for a, b in itertools.pairwise(route)],
            (route[-1], None),
        ]
        if any(key not in self._cache for key in keys):
            from tlmpc.control import synthesize

            witness = Witness(
                prefix=tuple(route[:-1]),
                cycle=(route[-1],),
                prefix_states=(0,) * (len(route) - 1),
                cycle_states=(0,),
                word=tuple(self.abstraction.labels(t) for t in route),
                cost=0.0,
                metric="hops",
                beta=1.0,
                prefix_cost=0.0,
                cycle_cost=0.0,
            )
            solved = synthesize(
                self.abstraction, witness, self.mission.robot, source=self.mission.source
            )
            self.solves += 1
            for key, controller in zip(keys, solved.steps, strict=True):
                self._cache.setdefault(key, controller)
        return [self._cache[key] for key in keys]

    def _edge(self, a: int, b: int) -> int:
        return int(self.abstraction.neighbors[a].tolist().index(b))

    def advance(self, horizon: float) -> bool:
        """Move the robot until ``horizon`` (a finite time); True when it crosses into its
        goal face first (the time is then the crossing's)."""
        while self.time < horizon:
            leg = self.legs[0]
            if leg.kind == "stay":
                self._converge(leg.controller, horizon)
                return False
            if leg.kind == "dwell":
                self._converge(leg.controller, min(horizon, leg.until))
                if self.time < leg.until:
                    return False
                self.legs.pop(0)
                continue
            if not self._exit(leg.controller, horizon):
                return False
            self.legs.pop(0)
            if int(self.face_of[self.triangle]) != self.face:
                self.face = int(self.face_of[self.triangle])
                return True
        return False

    def _converge(self, controller: StepController, end: float) -> None:
        """Follow the stay field (it converges to its target in the triangle) until ``end``."""
        assert controller.target is not None
        target = np.asarray(controller.target, dtype=np.float64)
        start, offset = self.time, self.point - target
        span = end - start
        if span <= 0.0:
            return
        fractions = (np.geomspace(1.0, 101.0, STAY_SAMPLES + 1) - 1.0) / 100.0
        for fraction in fractions[1:].tolist():
            tau = span * fraction
            point = target + expm_small(tau * controller.gain) @ offset
            self.motion.add(start + tau, point, self.triangle)
        self.point = self.motion_point()
        self.time = end

    def motion_point(self) -> FloatArray:
        """The last sampled point."""
        return np.asarray(self.motion.points[-1], dtype=np.float64)

    def _exit(self, controller: StepController, horizon: float) -> bool:
        """Follow an exit field; True when the crossing comes by ``horizon``."""
        assert controller.next_triangle is not None
        times, points = exit_step(controller, self.point)
        crossing = self.time + times[-1]
        if crossing <= horizon:
            for t, p in zip(times[:-1], points[:-1], strict=True):
                self.motion.add(self.time + t, p, self.triangle)
            self._came_from, self.triangle = self.triangle, controller.next_triangle
            self.point = np.asarray(points[-1], dtype=np.float64)
            self.time = crossing
            self.motion.add(crossing, self.point, self.triangle)
            self.motion.crossings.append(len(self.motion.times) - 1)
            return True
        tau = horizon - self.time
        for t, p in zip(times[:-1], points[:-1], strict=True):
            if t < tau:
                self.motion.add(self.time + t, p, self.triangle)
        matrix = np.zeros((3, 3))
        matrix[:2, :2] = controller.gain
        matrix[:2, 2] = controller.offset
        state = expm_small(tau * matrix) @ np.array([self.point[0], self.point[1], 1.0])
        self.point = state[:2].copy()
        self.time = horizon
        self.motion.add(horizon, self.point, self.triangle)
        return False


def _face_graph(
    abstraction: Abstraction, face_of: IntArray
) -> tuple[Any, dict[tuple[int, int], tuple[IntArray, IntArray]]]:
    """The graph of edges between triangles of one face (weighted by the distance of their
    centres, for routes), and for each pair of neighbouring faces (f, g) the triangles of f
    on their common edge with, for each, its neighbour in g (the lowest one)."""
    from scipy.sparse import csr_matrix

    count = abstraction.num_triangles
    centers = abstraction.vertices[abstraction.triangles].mean(axis=1)
    rows = np.repeat(np.arange(count, dtype=np.int64), 3)
    cols = abstraction.neighbors.reshape(-1).astype(np.int64)
    real = cols >= 0
    rows, cols = rows[real], cols[real]
    same = face_of[rows] == face_of[cols]
    weights = np.linalg.norm(centers[rows[same]] - centers[cols[same]], axis=1)
    graph = csr_matrix((weights, (rows[same], cols[same])), shape=(count, count))
    portals: dict[tuple[int, int], tuple[IntArray, IntArray]] = {}
    across = ~same
    crossing = sorted(
        zip(
            face_of[rows[across]].tolist(),
            face_of[cols[across]].tolist(),
            rows[across].tolist(),
            cols[across].tolist(),
            strict=True,
        )
    )
    for (face, goal), group in itertools.groupby(crossing, key=lambda c: (c[0], c[1])):
        entry: dict[int, int] = {}
        for _, _, triangle, other in group:
            entry[triangle] = min(entry.get(triangle, other), other)
        inside = np.array(sorted(entry), dtype=np.int64)
        portals[(face, goal)] = (inside, np.array([entry[t] for t in inside.tolist()]))
    return graph, portals


def executor_summary(executor: ReactiveExecutor) -> dict[str, Any]:
    """Counts of a run for reports."""
    kinds: dict[str, int] = {}
    for event in executor.events:
        kinds[event.kind] = kinds.get(event.kind, 0) + 1
    return {"events": len(executor.events), "by_kind": kinds, "solves": executor.solves}


def _truth_value(reading: Any) -> bool:
    """Whether ``reading`` is a sensor's truth value: a bool (numpy's too) or 0 or 1."""
    if isinstance(reading, bool | np.bool_):
        return True
    return isinstance(reading, int | np.integer) and reading in (0, 1)
