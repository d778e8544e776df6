"""Solve a reactive mission: its GR(1) game, realizability, and a core when it is not.

The core is a set of task parts that no robot strategy can meet under all of the mission's
assumptions, from which no part can be dropped (deletion-minimal: every one of them is needed
for the conflict); a smaller core of other parts may exist.
Assumptions stay in the game while the core is sought (taking one away only makes the robot's
task harder, so none would ever be needed).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from tlmpc.abstraction.model import Abstraction
from tlmpc.base.errors import Diagnostic, InvalidInputError, UsageError, error
from tlmpc.mission.body import MARGIN_PATH
from tlmpc.mission.model import Mission, TaskPart
from tlmpc.reactive.explain import counter_play, counter_play_steps, place
from tlmpc.reactive.faces import Faces, faces_of, start_faces
from tlmpc.reactive.fragment import reading
from tlmpc.reactive.game import MissionGame, build_game
from tlmpc.reactive.parts import mission_parts
from tlmpc.synth.core import Core, minimal_core
from tlmpc.synth.counter import CounterStrategy, extract_counterstrategy
from tlmpc.synth.solver import Game, Solution, solve
from tlmpc.synth.spec import Part, support
from tlmpc.synth.strategy import MealyMachine, extract, to_json
from tlmpc.synth.symbolic import Encoding
from tlmpc.synth.symbolic_strategy import (
    LoopSize,
    SymbolicStrategy,
    reachable_size,
    symbolic_document,
    symbolic_strategy,
)

#: the explicit machine is built (and listed in strategy.json beside the symbolic form) when it
#: has at most this many transitions; the symbolic form scales with the sensors, the explicit
#: one with 2^sensors transitions per node
EXPLICIT_TRANSITIONS = 10_000


def mission_game(mission: Mission, abstraction: Abstraction) -> MissionGame:
    """The game of ``mission`` on the faces of ``abstraction`` (Q102 for a part outside GR(1),
    Q103 under the closed convention), the robot starting in the face of
    ``abstraction.start``."""
    return mission_games(mission, abstraction)[0]


def mission_games(mission: Mission, abstraction: Abstraction) -> list[MissionGame]:
    """The games of ``mission``, one per face the robot may enter first: a start on the
    boundary of faces lies in a triangle of each, and under the right-continuous convention
    its label at t = 0 is the one of the face it moves into (docs/semantics.md, "Starts on a
    boundary").  The face of ``abstraction.start`` comes first, then the others by number."""
    pieces, problems = reading(mission_parts(mission), mission.source)
    if mission.options.boundary == "closed":
        problems.append(
            error(
                "Q103",
                "a reactive mission is read with the right-continuous convention",
                hint="leave options.boundary out (or set it to right): the game's steps are "
                "the run's events, each letter held for a positive time",
                file=mission.source,
            )
        )
    assert mission.reactive is not None
    # the loader refuses these names; they come from an edited mission.json
    for name in mission.reactive.motion_clashes():
        problems.append(
            error(
                "S013",
                f"the sensor or action {name!r} has the name of a variable of the robot's motion",
                hint="rename it in the mission and compile again",
                file=mission.source,
            )
        )
    if problems:
        raise InvalidInputError(problems)
    faces: Faces = faces_of(abstraction)
    firsts = start_faces(abstraction, faces.face_of, mission.robot.start, abstraction.start)
    return [build_game(mission, faces, face, pieces) for face in firsts]


@dataclass(frozen=True)
class Synthesis:
    """The outcome: the solved game; the strategy when realizable (``symbolic`` always, the
    explicit ``strategy`` when it has at most :data:`EXPLICIT_TRANSITIONS` transitions, and
    the explicit machine's ``size`` counted symbolically), else a core (task parts) and the
    environment's counterstrategy in the core's game (None, with the notes ``untold`` says,
    when it is too large to show)."""

    game: MissionGame
    solution: Solution
    strategy: MealyMachine | None = None
    symbolic: SymbolicStrategy | None = None
    size: LoopSize | None = None
    core: tuple[TaskPart, ...] | None = None
    counter: CounterStrategy | None = None
    #: why an unrealizable mission has no counterstrategy to show (Q062, notes)
    untold: tuple[Diagnostic, ...] = ()

    @property
    def realizable(self) -> bool:
        """Whether a robot strategy wins from the start."""
        return self.solution.realizable


def synthesize(
    mission: Mission, abstraction: Abstraction, *, explicit_transitions: int = EXPLICIT_TRANSITIONS
) -> Synthesis:
    """Solve the mission's game: its strategy, or a core and a counterstrategy.

    A robot that starts on the boundary of faces wins when it wins entering one of them
    first (the first such face in :func:`mission_games`' order, preferring one where the
    environment can keep its initial assumptions: elsewhere the win is vacuous and the
    strategy has no start to run); a core is then unrealizable whichever it enters, and its
    counterstrategy is the one from the first face."""
    games = mission_games(mission, abstraction)
    encoding = Encoding(games[0].spec)
    solved: list[tuple[MissionGame, Solution, bool]] = []
    for game in games:
        built = Game.build(game.spec, encoding)
        solved.append((game, solve(built), built.env_init != encoding.bdd.false))
        if solved[-1][1].realizable and solved[-1][2]:
            break
    # a start the environment can keep first, then a vacuous one
    winners = sorted((not kept, k) for k, (_, won, kept) in enumerate(solved) if won.realizable)
    if winners:
        game, solution, _ = solved[winners[0][1]]
        size = reachable_size(solution)
        machine = extract(solution) if size.transitions <= explicit_transitions else None
        return Synthesis(
            game=game,
            solution=solution,
            strategy=machine,
            symbolic=symbolic_strategy(solution),
            size=size,
        )
    game, solution, _ = solved[0]
    sources = {key: source for other in games for key, source in other.sources.items()}
    core = minimal_core(
        game.spec,
        encoding,
        group=lambda part: _source_key(sources, part),
        alternatives=[other.spec for other in games[1:]],
    )
    parts: dict[int, TaskPart] = {}
    for part in core.parts:
        source = game.sources[id(part)]
        parts.setdefault(id(source), source)
    counter: CounterStrategy | None = None
    untold: tuple[Diagnostic, ...] = ()
    try:
        counter = core_counterstrategy(core, encoding)
    except UsageError as exc:
        if exc.diagnostics[0].code != "Q062":
            raise
        # too large to show: the answer and the core still stand (a note, as in tlmpc synth)
        untold = tuple(dataclasses.replace(d, severity="note") for d in exc.diagnostics)
    return Synthesis(
        game=game,
        solution=solution,
        core=tuple(parts.values()),
        counter=counter,
        untold=untold,
    )


def synthesize_on_regions(
    mission: Mission, abstraction: Abstraction
) -> tuple[Synthesis, Abstraction, tuple[Diagnostic, ...]]:
    """Solve the mission on ``abstraction`` (the abstraction stage's mesh, which labels goal
    cores and grown avoided regions), then, while unrealizable, on meshes closer to the
    mission's regions: the goals as they are (the margin kept), then without the margin.

    Cores and grown regions are sound for a strategy (the task is monotone in a region of
    one polarity: a run that meets it with them meets it with the true regions), but not
    for "unrealizable": the robot may start inside a goal outside its core, or need the rim
    between a grown region and a wall.  So the answer comes from the first mesh that is
    realizable, else from the true regions.  Returns the synthesis, the mesh it was solved
    on, and a note (A030) or warning (R008) when that is not ``abstraction``."""
    from tlmpc.abstraction import build_abstraction
    from tlmpc.abstraction.layout import deepens_goals, planning_layout
    from tlmpc.mission.body import requested_margin

    synthesis = synthesize(mission, abstraction)
    notes: tuple[Diagnostic, ...] = ()
    margin = requested_margin(mission)
    rungs: list[tuple[float, Diagnostic]] = []
    if deepens_goals(mission) and margin > 0.0:
        rungs.append((margin, _shallow_note(mission)))
    if margin > 0.0:
        rungs.append((0.0, _marginless_note(mission, margin)))
    elif deepens_goals(mission):
        rungs.append((0.0, _shallow_note(mission)))
    for rung_margin, note in rungs:
        if synthesis.realizable:
            break
        layout = planning_layout(mission, rung_margin, deep=False)
        abstraction = build_abstraction(mission, layout)
        synthesis = synthesize(mission, abstraction)
        notes = (note,) if synthesis.realizable else ()
    return synthesis, abstraction, notes


def _shallow_note(mission: Mission) -> Diagnostic:
    return Diagnostic(
        code="A030",
        severity="note",
        message="no robot strategy meets the task entering the goals as deep as the goal "
        "depth asks; the strategy enters them only as deep as the margin asks",
        hint="set options.goal_depth to a smaller depth (0: the margin's) to synthesise with it",
        file=mission.source,
    )


def _marginless_note(mission: Mission, margin: float) -> Diagnostic:
    return Diagnostic(
        code="R008",
        severity="warning",
        message=f"no robot strategy meets the task keeping the margin {margin:g}; the "
        "strategy does without it",
        hint="lower options.margin to synthesise with a smaller one",
        file=mission.source,
        path=MARGIN_PATH,
    )


def core_counterstrategy(core: Core, encoding: Encoding) -> CounterStrategy:
    """The environment's strategy in the core's game (not the whole game's, which may starve
    a goal outside the core: its play would not defeat the core it is shown with).

    The robot's variables that no part of the core's game reads (the memory of the parts
    left out, actions no core part names) are held at their lowest values: they change
    nothing in that game, and left free every node would have an answer per value of each."""
    game = core.game(encoding)
    read = {name for part in core.spec.parts for name, _ in support(part.formula)}
    for variable in core.spec.owned("sys"):
        if variable.name not in read:
            lowest = False if variable.is_bool else variable.low
            assert lowest is not None
            game.sys_init &= encoding.value_cube(variable, lowest, primed=False)
            game.sys_safety &= encoding.value_cube(variable, lowest, primed=True)
    return extract_counterstrategy(solve(game))


def strategy_to_json(synthesis: Synthesis) -> dict[str, Any]:
    """``strategy.json`` of a reactive mission: the strategy (symbolic, and the explicit Mealy
    machine when it is small enough) and the faces it moves on."""
    assert synthesis.symbolic is not None
    faces = synthesis.game.faces
    document = symbolic_document(synthesis.symbolic, synthesis.size)
    if synthesis.strategy is not None:
        document = {**to_json(synthesis.strategy), **document}
    document["faces"] = {
        "labels": [list(letter) for letter in faces.letters],
        "adjacent": [list(a) for a in faces.adjacent],
        "face_of": faces.face_of.tolist(),
    }
    return document


def face_points(abstraction: Abstraction, faces: Faces) -> list[list[float]]:
    """A point inside each face: the centroid of its triangle nearest to the mean of its
    triangles' centroids (a mean alone may lie outside a bent face)."""
    import numpy as np

    vertices = np.asarray(abstraction.vertices, dtype=np.float64)
    triangles = np.asarray(abstraction.triangles, dtype=np.int64)
    centroids = vertices[triangles].mean(axis=1)
    face_of = np.asarray(faces.face_of, dtype=np.int64)
    counts = np.bincount(face_of, minlength=faces.count)
    mean_x = np.bincount(face_of, weights=centroids[:, 0], minlength=faces.count) / counts
    mean_y = np.bincount(face_of, weights=centroids[:, 1], minlength=faces.count) / counts
    distance = (centroids[:, 0] - mean_x[face_of]) ** 2 + (centroids[:, 1] - mean_y[face_of]) ** 2
    # by face, then distance, then triangle number: the first of each face is its point
    order = np.lexsort((np.arange(len(face_of)), distance, face_of))
    first = order[np.searchsorted(face_of[order], np.arange(faces.count))]
    return [[float(centroids[t][0]), float(centroids[t][1])] for t in first.tolist()]


def counterstrategy_to_json(synthesis: Synthesis, abstraction: Abstraction) -> dict[str, Any]:
    """``counterstrategy.json`` (schemas/counterstrategy.schema.json): the core, and one play
    of the environment's winning strategy in the mission's words and places."""
    assert synthesis.counter is not None
    game = synthesis.game
    letters = game.faces.letters
    play = counter_play_steps(synthesis.counter, game, synthesis.core)
    points = face_points(abstraction, game.faces)
    return {
        "format": "tlmpc.counterstrategy/1",
        "core": [
            {"text": part.text, "line": part.line, "col": part.col} for part in synthesis.core or ()
        ],
        "nodes": len(synthesis.counter.states),
        "play": [
            {
                "step": step.step,
                "face": step.face,
                "regions": list(letters[step.face]),
                "place": place(letters[step.face]),
                "position": points[step.face],
                "heading": step.heading,
                "heading_position": points[step.heading],
                "sensors": dict(step.sensors),
            }
            for step in play.steps
        ],
        "stuck": play.stuck,
        "again_from": play.again_from,
    }


def _source_key(sources: Mapping[int, TaskPart], part: Part) -> int | None:
    """The task part a game part comes from (None: a rule of the motion, never dropped)."""
    source = sources.get(id(part))
    return None if source is None else id(source)


def unrealizable(synthesis: Synthesis, mission: Mission) -> list[Diagnostic]:
    """Q110 at the core's first part, and a note at each further part of the core."""
    core = synthesis.core or ()
    names = "; ".join(part.text for part in core) or "the robot's motion alone"
    first = core[0] if core else None
    counter = synthesis.counter
    play = counter_play(counter, synthesis.game, synthesis.core) if counter is not None else []
    found = [
        error(
            "Q110",
            f"no robot strategy meets the task under the assumptions: {names} cannot all hold "
            "whatever the environment does",
            hint="each of these parts is needed for the conflict: weaken one of them, or add "
            "an assumption that rules out the environment's winning moves (the notes Q111 show "
            "how the environment wins)",
            file=mission.source,
            line=first.line if first else None,
            col=first.col if first else None,
        )
    ]
    found += [
        Diagnostic(
            code="Q110",
            message=f"part of the conflict: {part.text}",
            file=mission.source,
            line=part.line,
            col=part.col,
            severity="note",
        )
        for part in core[1:]
    ]
    found += [
        Diagnostic(
            code="Q111",
            message=f"the environment wins: {line}",
            file=mission.source,
            severity="note",
        )
        for line in play
    ]
    found += [dataclasses.replace(d, file=mission.source) for d in synthesis.untold]
    return found
