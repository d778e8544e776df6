"""Unrealizability cores in every initial reading: unrealizable, and no proper subset is.

Random small gr1c games (parts drawn from small pools), read under each of gr1c's initial
quantifications.  The verdict is checked against Spot (:func:`game_oracle.spot_verdict`, the
quantification read from gr1c's documentation).  For an unrealizable game, the core is checked
by brute force over every subset of its guarantees, each solved by the tool, with the parts a
core keeps in every trial worked out here from the quantification's meaning: the assumptions,
and under ALL_INIT the system's initial condition too (it says which starts must be won, so
dropping it makes the game harder).  Under ONE_SIDE_INIT a dropped SYSINIT conjunct is
``SYSINIT: True`` (the system still picks the start).  A subset of the core must be realizable
and the core itself not, so the core is minimal whatever the search did; Spot confirms the
core and each single deletion.
"""

from __future__ import annotations

import itertools
import random

import pytest
from game_oracle import spot_verdict
from small_games import random_spc

from tlmpc.synth.core import Core, minimal_core
from tlmpc.synth.readers.gr1c import parse_gr1c
from tlmpc.synth.solver import Game, solve
from tlmpc.synth.spec import INIT_MODES, Const, GameSpec, InitMode, Location, Part

pytest.importorskip("spot")


def _realizable(spec: GameSpec) -> bool:
    return solve(Game.build(spec), keep_layers=False).realizable


def expected_held(spec: GameSpec) -> tuple[Part, ...]:
    """The parts whose removal can make the game harder under the spec's quantification."""
    return tuple(
        p
        for p in spec.parts
        if p.owner == "env" or (p.kind == "init" and spec.init_mode == "all_init")
    )


def with_guarantees(spec: GameSpec, held: tuple[Part, ...], chosen: tuple[Part, ...]) -> GameSpec:
    """The game with ``held`` and ``chosen``; under ONE_SIDE_INIT a SYSINIT the spec had and
    ``chosen`` drops is ``SYSINIT: True``, so the system still picks the start."""
    ids = {id(p) for p in held + chosen}
    parts = tuple(p for p in spec.parts if id(p) in ids)
    had_sys_init = bool(spec.select("sys", "init"))
    if spec.init_mode == "one_side" and had_sys_init and not any(p.kind == "init" for p in chosen):
        true = Part("sys", "init", Const(True), Location(spec.file, 1, 1), "True")
        parts = (true, *parts)
    return spec.with_parts(parts)


def check_core(spec: GameSpec) -> Core:
    """The core of an unrealizable ``spec``: every proper subset realizable, itself not."""
    core = minimal_core(spec)
    held = expected_held(spec)
    assert {id(p) for p in core.held} == {id(p) for p in held}
    assert all(p.owner == "sys" and id(p) not in {id(h) for h in held} for p in core.parts)
    assert not _realizable(with_guarantees(spec, held, core.parts)), "the core is realizable"
    assert not spot_verdict(with_guarantees(spec, held, core.parts))
    for size in range(len(core.parts)):
        for subset in itertools.combinations(core.parts, size):
            assert _realizable(with_guarantees(spec, held, subset)), (
                f"not minimal: {[p.text for p in subset]} is already unrealizable"
            )
    for dropped in core.parts:
        rest = tuple(p for p in core.parts if p is not dropped)
        assert spot_verdict(with_guarantees(spec, held, rest)), f"{dropped.text} can go"
    return core


@pytest.mark.parametrize("mode", INIT_MODES)
def test_cores_are_minimal_in_every_initial_reading(mode: InitMode) -> None:
    rng = random.Random(f"cores {mode}")
    cores_of_several = 0
    for _ in range(120):
        text = random_spc(rng, mode)
        spec = parse_gr1c(text, file="random.spc", init_mode=mode)
        realizable = _realizable(spec)
        assert realizable == spot_verdict(spec), text
        if not realizable:
            cores_of_several += len(check_core(spec).parts) > 1
    assert cores_of_several >= 20


def test_all_init_holds_sysinit_and_drops_only_guarantees() -> None:
    """SYSINIT first, then the system's safety and goal: a deletion that took SYSINIT for a
    guarantee dropped it first (the game only gets harder) and ended at ``[] !z`` alone, which
    is realizable once SYSINIT's starts are kept."""
    text = "ENV: x;\nSYS: z;\nSYSINIT: !z;\nSYSTRANS: [] !z;\nSYSGOAL: []<> z;\n"
    spec = parse_gr1c(text, file="a.spc", init_mode="all_init")
    core = minimal_core(spec)
    assert [p.text for p in core.held] == ["!z"]
    assert [p.text for p in core.parts] == ["!z", "z"]
    assert not solve(core.game()).realizable
    check_core(spec)


def test_one_side_keeps_the_system_picking_the_start() -> None:
    """Under ONE_SIDE_INIT with SYSINIT the system picks the start.  Dropping SYSINIT's last
    conjunct must not turn the reading into "every state must win" (which only gets harder, so
    a deletion would drop it): without it the system starts with z up, so it is in the core."""
    text = "ENV: x;\nSYS: z;\nSYSINIT: !z;\nSYSTRANS: [](z' <-> z);\nSYSGOAL: []<> z;\n"
    spec = parse_gr1c(text, file="o.spc", init_mode="one_side")
    core = minimal_core(spec)
    assert core.start == "some_state"
    assert [p.text for p in core.parts] == ["!z", "(z' <-> z)", "z"]
    assert not solve(core.game()).realizable
    check_core(spec)
