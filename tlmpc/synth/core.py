"""Unrealizability cores: a minimal set of system guarantees that is already unrealizable.

Deletion-based: parts are dropped (in chunks that halve down to single parts) while the game
stays unrealizable; the parts left are a core in which dropping any one part makes the game
realizable.  Every environment assumption stays: dropping an assumption only frees the
environment, so it can never turn an unrealizable game realizable, and an assumption is
therefore never needed in, nor removable from, the explanation.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from dataclasses import dataclass

from tlmpc.synth.solver import Game, solve
from tlmpc.synth.spec import GameSpec, Part
from tlmpc.synth.symbolic import Encoding


@dataclass(frozen=True)
class Core:
    """A minimal unrealizable set of guarantees (``parts``) and the solves it took."""

    parts: tuple[Part, ...]
    solves: int


def minimal_core(
    spec: GameSpec,
    enc: Encoding | None = None,
    *,
    group: Callable[[Part], Hashable | None] | None = None,
) -> Core:
    """A minimal core of an unrealizable ``spec`` (raises ValueError if it is realizable).

    With ``group``, the guarantees that share a key are dropped together (the game parts one
    phrase of a mission became), and a guarantee whose key is None is never dropped (a rule
    of the robot's motion); the core then lists the kept groups' parts.
    """
    enc = enc or Encoding(spec)
    key = group or id
    assumptions = tuple(p for p in spec.parts if p.owner == "env")
    fixed = tuple(p for p in spec.parts if p.owner == "sys" and key(p) is None)
    members: dict[Hashable, list[Part]] = {}
    for part in spec.parts:
        if part.owner == "sys" and key(part) is not None:
            members.setdefault(key(part), []).append(part)
    kept = list(members)
    solves = 0

    def unrealizable(groups: list[Hashable]) -> bool:
        nonlocal solves
        solves += 1
        guarantees = tuple(p for g in groups for p in members[g])
        trial = spec.with_parts(assumptions + fixed + guarantees)
        return not solve(Game.build(trial, enc), keep_layers=False).realizable

    if not unrealizable(kept):
        raise ValueError("the specification is realizable: it has no unrealizability core")
    chunk = max(1, len(kept) // 2)
    while True:
        start = 0
        while start < len(kept):
            trial = kept[:start] + kept[start + chunk :]
            if unrealizable(trial):
                kept = trial
            else:
                start += chunk
        if chunk == 1:
            break
        chunk = max(1, chunk // 2)
    enc.spec = spec
    return Core(parts=tuple(p for g in kept for p in members[g]), solves=solves)
