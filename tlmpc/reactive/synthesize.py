"""Solve a reactive mission: its GR(1) game, realizability, and a core when it is not.

The core is the smallest set of task parts (deletion-minimal) that no robot strategy can
meet under all of the mission's assumptions: every one of them is needed for the conflict.
Assumptions stay in the game while the core is sought (taking one away only makes the robot's
task harder, so none would ever be needed).
"""

from __future__ import annotations

from dataclasses import dataclass

from tlmpc.abstraction.model import Abstraction
from tlmpc.base.errors import Diagnostic, InvalidInputError, error
from tlmpc.mission.model import Mission, TaskPart
from tlmpc.reactive.faces import Faces, faces_of
from tlmpc.reactive.fragment import reading
from tlmpc.reactive.game import MissionGame, build_game
from tlmpc.reactive.parts import mission_parts
from tlmpc.synth.solver import Game, Solution, solve
from tlmpc.synth.symbolic import Encoding


def mission_game(mission: Mission, abstraction: Abstraction) -> MissionGame:
    """The game of ``mission`` on the faces of ``abstraction`` (Q102 for a part outside GR(1),
    Q103 under the closed convention)."""
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
    if problems:
        raise InvalidInputError(problems)
    faces: Faces = faces_of(abstraction)
    start_face = int(faces.face_of[abstraction.start])
    return build_game(mission, faces, start_face, pieces)


@dataclass(frozen=True)
class Synthesis:
    """The outcome: the solved game; ``core`` (task parts) when unrealizable."""

    game: MissionGame
    solution: Solution
    core: tuple[TaskPart, ...] | None

    @property
    def realizable(self) -> bool:
        """Whether a robot strategy wins from the start."""
        return self.solution.realizable


def synthesize(mission: Mission, abstraction: Abstraction) -> Synthesis:
    """Solve the mission's game; find a core when it is unrealizable."""
    game = mission_game(mission, abstraction)
    encoding = Encoding(game.spec)
    solution = solve(Game.build(game.spec, encoding))
    core = None if solution.realizable else _core(game, encoding)
    return Synthesis(game=game, solution=solution, core=core)


def unrealizable(synthesis: Synthesis, mission: Mission) -> list[Diagnostic]:
    """Q110 at the core's first part, and a note at each further part of the core."""
    core = synthesis.core or ()
    names = "; ".join(part.text for part in core) or "the robot's motion alone"
    first = core[0] if core else None
    found = [
        error(
            "Q110",
            f"no robot strategy meets the task under the assumptions: {names} cannot all hold "
            "whatever the environment does",
            hint="each of these parts is needed for the conflict: weaken one of them, or add "
            "an assumption that rules out the environment's winning moves",
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
    return found


def _core(game: MissionGame, encoding: Encoding) -> tuple[TaskPart, ...]:
    """Drop one task part at a time while the rest is still unrealizable."""
    spec = game.spec
    kept: dict[int, TaskPart] = {}
    for part in spec.parts:
        source = game.sources.get(id(part))
        if source is not None and part.owner == "sys":
            kept.setdefault(id(source), source)
    for dropped in list(kept):
        trial = {key: source for key, source in kept.items() if key != dropped}
        parts = tuple(
            p
            for p in spec.parts
            if p.owner == "env" or id(game.sources.get(id(p))) in trial or id(p) not in game.sources
        )
        if not solve(Game.build(spec.with_parts(parts), encoding), keep_layers=False).realizable:
            kept = trial
    return tuple(kept.values())
