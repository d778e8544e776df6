"""The loaded mission (stage 1 output): typed, validated, positions resolved.

Shapes given as ``{rect: [xmin, ymin, xmax, ymax]}`` are already expanded to point lists here,
counter-clockwise from ``(xmin, ymin)``; point lists keep the user's order and orientation.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from tlmpc.base.memo import Slot, recall
from tlmpc.io.scalar_places import ScalarPlaces
from tlmpc.ltl.ast import Formula

Point = tuple[float, float]
Polygon = tuple[Point, ...]

CostMetric = Literal["length", "hops", "time"]
BoundaryConvention = Literal["right", "closed"]
RobotModel = Literal["point", "unicycle"]

#: Defaults of ``options`` (documented in docs/mission-format.md).
DEFAULT_MIN_ANGLE = 20.0
DEFAULT_BETA = 1.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Region:
    """A named region of interest: a closed simple polygon; regions may overlap."""

    name: str
    polygon: Polygon


#: The regions' documents a compilation keeps (the last map's: its three artifacts hold it
#: anyway).
REGIONS_DOCUMENTS: Slot[dict[str, list[list[float]]]] = Slot("regions document", keep=1)


def regions_document(pairs: list[tuple[str, Polygon]]) -> dict[str, list[list[float]]]:
    """``{name: [[x, y], ...]}``: the regions as ``mission.json``, ``abstraction.json`` and
    ``trace.json`` hold them.

    Asked again in the same compilation for the same polygons (the very tuples, under the
    same names, in the same order), it returns the document it built, the same object
    (:mod:`tlmpc.base.memo`): a compile of a map with a hundred thousand regions builds this
    document once for its three artifacts, and the writer, finding the same object under the
    same key, encodes it once.  The document is shared, so it must not be changed (no stage
    does; the polygons it comes from are immutable tuples).
    """
    # the polygons by identity (held with the document: their ids stay theirs), names by value
    key = tuple((name, id(polygon)) for name, polygon in pairs)
    return recall(
        REGIONS_DOCUMENTS,
        key,
        pairs,
        lambda: {name: list(map(list, polygon)) for name, polygon in pairs},
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class Component:
    """One connected piece of free space: an outer boundary minus its holes."""

    boundary: Polygon
    holes: tuple[Polygon, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class Workspace:
    """The outer boundary and the holes (obstacles that are never traversable).

    ``components`` are further pieces of free space, disjoint from the main one and from each
    other (e.g. free pockets of a map enclosed by obstacles): the workspace is their union, and
    the robot cannot cross between pieces.

    ``map_tolerance`` is how far the boundary and holes may lie from the true obstacles (an
    occupancy map's simplification tolerance; 0 for polygons given in the mission).
    """

    boundary: Polygon
    holes: tuple[Polygon, ...] = ()
    components: tuple[Component, ...] = ()
    map_tolerance: float = 0.0

    @property
    def pieces(self) -> tuple[Component, ...]:
        """Every piece of free space, the main one (``boundary`` and ``holes``) first."""
        return (Component(boundary=self.boundary, holes=self.holes), *self.components)

    def to_json(self) -> dict[str, Any]:
        """The ``workspace`` object of ``mission.json`` and ``trace.json`` (``components``
        only when there are any)."""

        def poly(p: Polygon) -> list[list[float]]:
            return list(map(list, p))

        document: dict[str, Any] = {
            "boundary": poly(self.boundary),
            "holes": [poly(h) for h in self.holes],
        }
        if self.components:
            document["components"] = [
                {"boundary": poly(c.boundary), "holes": [poly(h) for h in c.holes]}
                for c in self.components
            ]
        if self.map_tolerance:
            document["map_tolerance"] = self.map_tolerance
        return document


@dataclass(frozen=True, slots=True, kw_only=True)
class Robot:
    """The fully actuated robot x' = u + w, |u| <= max_speed, |w| <= disturbance.

    ``disturbance`` bounds an unknown additive velocity (wind, slip, tracking error) that the
    controllers must reject: every guarantee holds for every such w.  ``radius`` and
    ``footprint`` (a polygon in the robot's frame, around its reference point) give the
    robot a body; the planner keeps the disc of :func:`tlmpc.mission.body.body_radius` off
    every obstacle.  Labels are always those of the reference point ``x``.

    ``model`` is ``"point"`` or ``"unicycle"`` (differential drive): a unicycle tracks the
    planned field with the point ``offset`` ahead of its axle, which is the point ``start``,
    the labels and the trace refer to (see docs/control.md).
    """

    start: Point
    max_speed: float = 1.0
    disturbance: float = 0.0
    model: RobotModel = "point"
    offset: float = 0.0
    radius: float = 0.0
    footprint: Polygon | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Options:
    """Compiler options.

    ``min_angle``/``max_area`` are the triangulation quality bounds (``None`` turns a bound
    off; both off gives the plain constrained Delaunay triangulation); ``cost`` is the witness
    metric; ``beta`` weighs the cycle against the prefix (cost = prefix + beta * cycle);
    ``boundary`` is the labelling convention used when verifying.
    """

    min_angle: float | None = DEFAULT_MIN_ANGLE
    max_area: float | None = None
    cost: CostMetric = "length"
    beta: float = DEFAULT_BETA
    boundary: BoundaryConvention = "right"
    #: Clearance and depth objective; ``None`` is the default of
    #: :func:`tlmpc.mission.body.requested_margin` (see docs/mission-format.md).
    margin: float | None = None
    #: Depth to reach into the regions the task visits; ``None`` is the default of
    #: :func:`tlmpc.abstraction.layout.goal_depth` (a quarter of the region's inradius).
    goal_depth: float | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class TaskPart:
    """One part of the task as the user wrote it, with where it is (for explanations).

    A task phrase is one part; raw ``ltl`` gives one part per top-level conjunct.
    """

    text: str
    formula: Formula
    line: int | None = None
    col: int | None = None


#: The variables a reactive mission's game gives the robot's motion: the face it is in, the
#: face it heads for, and whether the last step crossed into another face.  They share the
#: game's name space with the sensors and actions, so no sensor or action may take them (S013).
FACE = "face"
GOAL = "goal"
MOVED = "moved"
MOTION_NAMES = (FACE, GOAL, MOVED)


@dataclass(frozen=True, slots=True, kw_only=True)
class Sensor:
    """An environment proposition the robot reads (reactive missions).

    ``column`` (a CSV log's column) or ``topic`` and ``field`` (a bag's) say where a robot's
    log carries its value, for ``tlmpc verify``; all None when the log names it alike.
    """

    name: str
    column: str | None = None
    topic: str | None = None
    field: str | None = None

    def to_json(self) -> dict[str, str]:
        """The sensor's binding as written in ``mission.json`` (keys with a value only)."""
        bound = {"column": self.column, "topic": self.topic, "field": self.field}
        return {key: value for key, value in bound.items() if value is not None}


@dataclass(frozen=True, slots=True, kw_only=True)
class Reactive:
    """What makes a mission reactive: sensors, actions and the environment's assumptions.

    ``assumptions`` are the user's formulas, one part each, with their positions;
    ``assumption`` is their conjunction (TRUE when there are none).
    """

    sensors: tuple[Sensor, ...] = ()
    actions: tuple[str, ...] = ()
    assumptions: tuple[TaskPart, ...] = ()

    @property
    def sensor_names(self) -> tuple[str, ...]:
        """Sensor names in file order."""
        return tuple(s.name for s in self.sensors)

    def motion_clashes(self) -> tuple[str, ...]:
        """The sensors and actions named like a variable of the robot's motion
        (:data:`MOTION_NAMES`), which the game could not tell apart from it."""
        return tuple(n for n in (*self.sensor_names, *self.actions) if n in MOTION_NAMES)

    def to_json(self) -> dict[str, Any]:
        """The ``reactive`` object of ``mission.json``."""
        from tlmpc.ltl.printer import to_text

        return {
            "sensors": {s.name: s.to_json() for s in self.sensors},
            "actions": list(self.actions),
            "assumptions": [
                {"text": part.text, "formula": to_text(part.formula)} for part in self.assumptions
            ],
        }


@dataclass(frozen=True, slots=True, kw_only=True)
class Mission:
    """A validated mission.

    ``formula`` is the whole task: the conjunction of the task phrases' LTL and the raw
    ``ltl``, with group names already expanded to disjunctions of their regions.
    """

    name: str
    workspace: Workspace
    regions: tuple[Region, ...]
    robot: Robot
    formula: Formula
    groups: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    task: tuple[str, ...] = ()
    ltl: str | None = None
    options: Options = field(default_factory=Options)
    source: str | None = None
    #: (line, col) of each task phrase, then of the ``ltl`` string (see :mod:`.parts`).
    task_positions: tuple[tuple[int, int], ...] = ()
    #: ... and where each of their characters is written, when the string is quoted, a block
    #: or over several lines (None for a one-line plain string: its position and the offset)
    task_places: tuple[ScalarPlaces | None, ...] = field(default=(), compare=False, repr=False)
    #: sensors, actions and assumptions; None for a mission in a world that never changes
    reactive: Reactive | None = None

    @property
    def region_names(self) -> tuple[str, ...]:
        """Region names in file order."""
        return tuple(r.name for r in self.regions)

    def region(self, name: str) -> Region:
        """The region called ``name`` (KeyError if there is none)."""
        for region in self.regions:
            if region.name == name:
                return region
        raise KeyError(name)

    def to_json(self) -> dict[str, Any]:
        """The ``mission.json`` artifact (``tlmpc.mission/1``); ``reactive`` only when the
        mission has sensors, actions or assumptions."""
        from tlmpc.ltl.printer import to_text

        def poly(p: Polygon) -> list[list[float]]:
            return list(map(list, p))

        document: dict[str, Any] = {
            "format": "tlmpc.mission/1",
            "name": self.name,
            "source": self.source,
            "workspace": self.workspace.to_json(),
            "regions": regions_document([(r.name, r.polygon) for r in self.regions]),
            "groups": {k: list(v) for k, v in self.groups.items()},
            "robot": {
                "start": list(self.robot.start),
                "max_speed": self.robot.max_speed,
                "disturbance": self.robot.disturbance,
                "model": self.robot.model,
                "offset": self.robot.offset,
                "radius": self.robot.radius,
                "footprint": poly(self.robot.footprint) if self.robot.footprint else None,
            },
            "task": list(self.task),
            "ltl": self.ltl,
            "formula": to_text(self.formula),
            "options": {
                "min_angle": self.options.min_angle,
                "max_area": self.options.max_area,
                "cost": self.options.cost,
                "beta": self.options.beta,
                "boundary": self.options.boundary,
                "margin": self.options.margin,
                "goal_depth": self.options.goal_depth,
            },
        }
        if self.reactive is not None:
            document["reactive"] = self.reactive.to_json()
        return document
