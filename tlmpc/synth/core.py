"""Unrealizability cores: a minimal set of system guarantees that is already unrealizable.

Deletion-based: guarantees are dropped (in chunks that halve down to single parts) while the
game stays unrealizable; the guarantees left are a core in which dropping any one makes the
game realizable.  That last pass proves it only because dropping a guarantee can never make
the game harder (monotonicity): a guarantee needed when it was tested is still needed once
others are gone.  So the parts whose removal *can* make the game harder are held in every
trial and are never in a core:

* the environment's assumptions (dropping one frees the environment);
* the system's initial condition when every state it allows must be won (``every_state``:
  gr1c's ALL_INIT, slugs' robotics semantics): there it narrows the starts the environment may
  pick, like an assumption.

Every trial also keeps the start rule of the whole specification
(:func:`~tlmpc.synth.solver.start_rule`): under gr1c's ONE_SIDE_INIT, dropping the last
SYSINIT conjunct reads it as ``SYSINIT: True`` (the system still picks the start), not as an
empty section, which would ask every state to win.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass

from tlmpc.synth.solver import Game, StartRule, solve, start_rule
from tlmpc.synth.spec import GameSpec, Part
from tlmpc.synth.symbolic import Encoding


@dataclass(frozen=True)
class Core:
    """A minimal unrealizable set of guarantees (``parts``) and the solves it took.

    ``spec`` is the core's game: the parts held in every trial (``held``) and ``parts``, in
    the specification's order, read with the whole specification's ``start`` rule."""

    parts: tuple[Part, ...]
    held: tuple[Part, ...]
    spec: GameSpec
    start: StartRule
    solves: int

    def game(self, enc: Encoding | None = None) -> Game:
        """The core's game (unrealizable), for its counterstrategy."""
        return Game.build(self.spec, enc, start=self.start)


def held_parts(spec: GameSpec, start: StartRule) -> tuple[Part, ...]:
    """The parts a core search never drops: those whose removal can make the game harder."""
    return tuple(
        p for p in spec.parts if p.owner == "env" or (p.kind == "init" and start == "every_state")
    )


def minimal_core(
    spec: GameSpec,
    enc: Encoding | None = None,
    *,
    group: Callable[[Part], Hashable | None] | None = None,
    alternatives: Sequence[GameSpec] = (),
) -> Core:
    """A minimal core of an unrealizable ``spec`` (raises ValueError if it is realizable).

    With ``group``, the guarantees that share a key are dropped together (the game parts one
    phrase of a mission became), and a guarantee whose key is None is never dropped (a rule
    of the robot's motion); the core then lists the kept groups' parts.

    ``alternatives`` are games the system may play instead of ``spec`` (the same variables
    and groups, other parts that are never dropped: a reactive mission whose robot starts on
    the boundary of faces chooses the face it enters first).  The core is then unrealizable
    in ``spec`` and in every alternative, and without any one of its parts some of them is
    realizable; its ``spec`` is ``spec``'s core game.
    """
    enc = enc or Encoding(spec)
    key = group or id
    start = start_rule(spec)
    held = held_parts(spec, start)
    held_ids = {id(p) for p in held}
    members: dict[Hashable, list[Part]] = {}
    for part in spec.parts:
        if id(part) not in held_ids and key(part) is not None:
            members.setdefault(key(part), []).append(part)
    kept = list(members)
    solves = 0

    def trial_spec(game: GameSpec, groups: list[Hashable]) -> GameSpec:
        chosen = set(groups)
        held_here = {id(p) for p in held_parts(game, start)}
        return game.with_parts(
            tuple(p for p in game.parts if id(p) in held_here or key(p) is None or key(p) in chosen)
        )

    def unrealizable(groups: list[Hashable]) -> bool:
        nonlocal solves
        for game in (spec, *alternatives):
            solves += 1
            trial = Game.build(trial_spec(game, groups), enc, start=start)
            if solve(trial, keep_layers=False).realizable:
                return False
        return True

    if not unrealizable(kept):
        raise ValueError("the specification is realizable: it has no unrealizability core")
    chunk = max(1, len(kept) // 2)
    while True:
        index = 0
        while index < len(kept):
            trial = kept[:index] + kept[index + chunk :]
            if unrealizable(trial):
                kept = trial
            else:
                index += chunk
        if chunk == 1:
            break
        chunk = max(1, chunk // 2)
    enc.spec = spec
    core_spec = trial_spec(spec, kept)
    return Core(
        parts=tuple(p for g in kept for p in members[g]),
        held=held,
        spec=core_spec,
        start=start,
        solves=solves,
    )
