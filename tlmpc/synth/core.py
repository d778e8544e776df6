"""Unrealizability cores: a minimal set of system guarantees that is already unrealizable.

Deletion-based: parts are dropped (in chunks that halve down to single parts) while the game
stays unrealizable; the parts left are a core in which dropping any one part makes the game
realizable.  Every environment assumption stays: dropping an assumption only frees the
environment, so it can never turn an unrealizable game realizable, and an assumption is
therefore never needed in, nor removable from, the explanation.
"""

from __future__ import annotations

from dataclasses import dataclass

from tlmpc.synth.solver import Game, solve
from tlmpc.synth.spec import GameSpec, Part
from tlmpc.synth.symbolic import Encoding


@dataclass(frozen=True)
class Core:
    """A minimal unrealizable set of guarantees (``parts``) and the solves it took."""

    parts: tuple[Part, ...]
    solves: int


def minimal_core(spec: GameSpec, enc: Encoding | None = None) -> Core:
    """A minimal core of an unrealizable ``spec`` (raises ValueError if it is realizable)."""
    enc = enc or Encoding(spec)
    assumptions = tuple(p for p in spec.parts if p.owner == "env")
    kept = [p for p in spec.parts if p.owner == "sys"]
    solves = 0

    def unrealizable(guarantees: list[Part]) -> bool:
        nonlocal solves
        solves += 1
        trial = spec.with_parts(assumptions + tuple(guarantees))
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
    return Core(parts=tuple(kept), solves=solves)
