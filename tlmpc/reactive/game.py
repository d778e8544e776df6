"""A reactive mission as a GR(1) game on the faces of the abstraction.

Players and variables (docs/semantics.md, "Reactive missions"):

* the **environment** owns the sensors, the robot's face ``face`` and ``moved`` (the last step
  crossed into another face): the robot's motion takes time, so *when* it arrives is the
  environment's move, and a sensor can change while the robot is on its way;
* the **robot** owns ``goal`` (the face it is heading for: its own face to stay, or a
  neighbouring one), its actions, and the memory of the task's monitors.

One step of the game is one event of the continuous run: sensors change, or the robot
crosses into the face it is heading for, or both at one instant; the robot then answers (a new
goal, actions set at once).  The motion's rules are parts of the game like the user's, so a
core can name them:

* ``face' = face | face' = goal`` — the robot moves only where it is heading;
* ``moved' <-> face' != face``;
* the robot heads for its own face or a neighbour (``goal' in adjacent(face') + face'``);
* fairness: ``G F(moved | face = goal)`` — heading for a neighbour, the robot gets there.

Each user part becomes its pieces (:mod:`tlmpc.reactive.fragment`): conditions on the first
state, conditions on every next state, goals, and deterministic monitors whose state is a
variable of the part's player, updated from the next state's letter.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

from tlmpc.automata.model import Automaton
from tlmpc.ltl.ast import And, Const, Equiv, Formula, Implies, Not, Or, Prop
from tlmpc.mission.model import Mission, TaskPart
from tlmpc.reactive.faces import Faces
from tlmpc.reactive.fragment import Owner, Piece
from tlmpc.reactive.nodes import FACE, GOAL, MOVED
from tlmpc.synth.spec import (
    Atom,
    Binary,
    Compare,
    Expr,
    GameSpec,
    Location,
    Nary,
    Part,
    PartKind,
    Variable,
)
from tlmpc.synth.spec import Const as SpecConst
from tlmpc.synth.spec import Not as SpecNot

#: The texts of the motion's parts, as a core names them.
MOTION_TEXTS = {
    "start": "the robot starts in the face of its start point",
    "destination": "the robot moves only into the face it is heading for",
    "moved": "`moved` records that the last step crossed into another face",
    "heading": "the robot heads for its own face or a neighbouring one",
    "arrival": "heading for a neighbouring face, the robot gets there",
}


@dataclass(frozen=True, slots=True)
class MissionGame:
    """The game of a reactive mission: the spec, the faces, and which parts are the user's."""

    spec: GameSpec
    faces: Faces
    #: each user part of the spec, with the mission part (task or assumption) it comes from
    sources: Mapping[int, TaskPart]


class _Letters:
    """Propositions of a mission formula as game expressions."""

    def __init__(self, faces: Faces, sensors: Sequence[str], actions: Sequence[str]) -> None:
        self.faces = faces
        self.sensors = frozenset(sensors)
        self.actions = frozenset(actions)

    def prop(self, name: str, primed: bool) -> Expr:
        if name in self.sensors or name in self.actions:
            return Atom(name, primed)
        inside = self.faces.with_region(name)
        if not inside:
            return SpecConst(False)
        return _any_face(FACE, inside, primed)

    def formula(self, formula: Formula, primed: bool) -> Expr:
        if isinstance(formula, Const):
            return SpecConst(formula.value)
        if isinstance(formula, Prop):
            return self.prop(formula.name, primed)
        if isinstance(formula, Not):
            return SpecNot(self.formula(formula.arg, primed))
        if isinstance(formula, And | Or):
            args = tuple(self.formula(arg, primed) for arg in formula.args)
            return Nary("and", args) if isinstance(formula, And) else Nary("or", args)
        if isinstance(formula, Implies | Equiv):
            op: Literal["->", "<->"] = "->" if isinstance(formula, Implies) else "<->"
            return Binary(
                op, self.formula(formula.left, primed), self.formula(formula.right, primed)
            )
        raise ValueError(f"not a propositional formula: {formula}")  # fragment decides


def _any_face(name: str, faces: Sequence[int], primed: bool) -> Expr:
    tests: tuple[Expr, ...] = tuple(Compare(name, "=", f, primed) for f in faces)
    return tests[0] if len(tests) == 1 else Nary("or", tests)


def _equal(left: str, right: str, left_primed: bool, right_primed: bool, count: int) -> Expr:
    """``left == right`` for two variables over ``0..count-1``."""
    return Nary(
        "or",
        tuple(
            Nary("and", (Compare(left, "=", v, left_primed), Compare(right, "=", v, right_primed)))
            for v in range(count)
        ),
    )


def build_game(
    mission: Mission, faces: Faces, start_face: int, pieces: Sequence[Piece]
) -> MissionGame:
    """The GR(1) game of a reactive mission (``pieces``: the GR(1) reading of its parts)."""
    assert mission.reactive is not None
    # by name, as mission.json keeps them: the game (and the strategy's variable order, hence
    # its bytes) is then the same whether the mission comes from its file or from mission.json
    sensors = tuple(sorted(mission.reactive.sensor_names))
    actions = mission.reactive.actions
    letters = _Letters(faces, sensors, actions)
    count = max(faces.count, 1)
    source = mission.source or "<mission>"
    variables: list[Variable] = [Variable(s, "env") for s in sensors]
    variables += [Variable(FACE, "env", 0, count - 1), Variable(MOVED, "env")]
    monitors: list[tuple[str, Automaton, Piece]] = []
    # a monitor's variable must not take a sensor's or an action's name (they are identifiers
    # like it): the game keys its variables by name
    taken = {*sensors, *actions, FACE, GOAL, MOVED}
    for index, piece in enumerate(pieces):
        if piece.kind == "monitor":
            assert piece.automaton is not None
            name = f"{'assumed' if piece.owner == 'env' else 'task'}_monitor_{index}"
            while name in taken:
                name += "_"
            taken.add(name)
            monitors.append((name, piece.automaton, piece))
    variables += [
        Variable(name, "env", 0, max(a.num_states - 1, 1))
        for name, a, piece in monitors
        if piece.owner == "env"
    ]
    variables += [Variable(GOAL, "sys", 0, count - 1)]
    variables += [Variable(a, "sys") for a in actions]
    variables += [
        Variable(name, "sys", 0, max(a.num_states - 1, 1))
        for name, a, piece in monitors
        if piece.owner == "sys"
    ]
    parts: list[Part] = []
    sources: dict[int, TaskPart] = {}

    def motion(owner: Owner, kind: PartKind, key: str, formula: Expr) -> None:
        parts.append(Part(owner, kind, formula, Location(source, 1, 1), MOTION_TEXTS[key]))

    def user(piece: Piece, kind: PartKind, formula: Expr) -> None:
        where = Location(source, piece.part.line or 1, piece.part.col or 1)
        part = Part(piece.owner, kind, formula, where, piece.part.text)
        sources[id(part)] = piece.part
        parts.append(part)

    motion(
        "env", "init", "start", Nary("and", (Compare(FACE, "=", start_face), SpecNot(Atom(MOVED))))
    )
    stays = _equal(FACE, FACE, True, False, count)
    destination = Nary("or", (stays, _equal(FACE, GOAL, True, False, count)))
    motion("env", "safety", "destination", destination)
    motion("env", "safety", "moved", Binary("<->", Atom(MOVED, True), SpecNot(stays)))
    arrival = Nary("or", (Atom(MOVED), _equal(FACE, GOAL, False, False, count)))
    motion("env", "liveness", "arrival", arrival)
    motion("sys", "init", "heading", _heading(faces, count, primed=False))
    motion("sys", "safety", "heading", _heading(faces, count, primed=True))
    monitor_of = {id(piece): name for name, _, piece in monitors}
    for piece in pieces:
        if piece.kind == "init":
            user(piece, "init", letters.formula(piece.formula, primed=False))
        elif piece.kind == "invariant":
            user(piece, "init", letters.formula(piece.formula, primed=False))
            user(piece, "safety", letters.formula(piece.formula, primed=True))
        elif piece.kind == "recurrence":
            user(piece, "liveness", letters.formula(piece.formula, primed=False))
        else:
            assert piece.automaton is not None
            name = monitor_of[id(piece)]
            init, step, goals = _monitor_parts(name, piece.automaton, letters)
            user(piece, "init", init)
            user(piece, "safety", step)
            for goal in goals:
                user(piece, "liveness", goal)
    spec = GameSpec(
        variables=tuple(variables),
        parts=tuple(parts),
        init_mode="forall_env_exists_sys",
        source_format="tlmpc mission",
        file=source,
    )
    return MissionGame(
        spec=spec,
        faces=faces,
        sources=sources,
    )


def _heading(faces: Faces, count: int, *, primed: bool) -> Expr:
    """The robot heads for its own face or one sharing an edge with it."""
    options: list[Expr] = []
    for face in range(faces.count):
        goals = (face, *faces.adjacent[face])
        options.append(
            Nary("and", (Compare(FACE, "=", face, primed), _any_face(GOAL, goals, primed)))
        )
    return Nary("or", tuple(options)) if options else SpecConst(True)


def _monitor_parts(
    name: str, automaton: Automaton, letters: _Letters
) -> tuple[Expr, Expr, list[Expr]]:
    """The monitor's initial state (after reading the first letter), its step on every next
    letter, and one transition goal per acceptance set.

    The automaton is deterministic: in each state at most one edge reads a letter, and a
    letter no edge reads violates the part (the conditions then fail)."""
    first = [
        Nary("and", (letters.formula(e.guard, primed=False), Compare(name, "=", e.dst)))
        for e in automaton.edges
        if e.src == automaton.initial
    ]
    steps = [
        Nary(
            "and",
            (
                Compare(name, "=", e.src),
                letters.formula(e.guard, primed=True),
                Compare(name, "=", e.dst, True),
            ),
        )
        for e in automaton.edges
    ]
    goals: list[Expr] = [
        Nary(
            "or",
            tuple(steps[k] for k, e in enumerate(automaton.edges) if mark in e.marks)
            or (SpecConst(False),),
        )
        for mark in range(automaton.num_acc)
    ]
    init: Expr = Nary("or", tuple(first)) if first else SpecConst(False)
    step: Expr = Nary("or", tuple(steps)) if steps else SpecConst(False)
    return init, step, goals
