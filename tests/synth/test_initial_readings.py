"""The verdict and the strategies read the initial conditions the same way, in every reading.

gr1c's ONE_SIDE_INIT (doc/spc_format): "At most one of ENVINIT and SYSINIT is nonempty.  Both
being empty is equivalent to ENVINIT: True.  If ENVINIT: f, then the strategy must regard any
state that satisfies f as possible initially.  If SYSINIT: f, then the strategy need only
choose one initial state satisfying f."  The machines are checked by the explicit oracle
(:func:`game_oracle.check_strategy`), which reads the initial nodes from that text.
"""

from __future__ import annotations

import random

import pytest
from game_oracle import check_counterstrategy, check_strategy
from small_games import random_spc

from tlmpc.base.errors import UsageError
from tlmpc.synth.counter import extract_counterstrategy
from tlmpc.synth.readers.gr1c import parse_gr1c
from tlmpc.synth.solver import Game, solve
from tlmpc.synth.spec import INIT_MODES, InitMode
from tlmpc.synth.strategy import extract, to_json
from tlmpc.synth.symbolic_strategy import reachable_size

GAME = "ENV: e;\nSYS: s;\nSYSTRANS: [](e | s');\nSYSGOAL: []<>s;\n"


def test_one_side_without_initial_conditions_serves_every_state() -> None:
    """No ENVINIT and no SYSINIT is ENVINIT: True: every state must win (the verdict) and
    every state is an initial node (the machine), the same machine as with ENVINIT: True."""
    empty = solve(Game.build(parse_gr1c(GAME, file="g.spc", init_mode="one_side")))
    true = solve(
        Game.build(parse_gr1c(GAME + "ENVINIT: True;\n", file="g.spc", init_mode="one_side"))
    )
    assert empty.realizable
    assert true.realizable
    machine = extract(empty)
    assert len(machine.initial) == 4
    check_strategy(empty.game.spec, machine)
    assert to_json(machine) == to_json(extract(true))
    # a state that loses makes the verdict false: every state counts
    losing = GAME.replace("[](e | s')", "[] !s")
    assert not solve(Game.build(parse_gr1c(losing, init_mode="one_side"))).realizable


def test_one_side_refuses_both_initial_conditions() -> None:
    text = "ENV: e;\nSYS: s;\nENVINIT: e;\nSYSINIT: s | e;\n"
    with pytest.raises(UsageError) as caught:
        parse_gr1c(text, file="both.spc", init_mode="one_side")
    found = caught.value.diagnostics[0]
    assert (found.code, found.line, found.col) == ("Q016", 4, 10)
    assert found.hint
    # the other readings take both
    parse_gr1c(text, init_mode="all_init")
    parse_gr1c(text.replace("s | e", "s"), init_mode="forall_env_exists_sys")


@pytest.mark.parametrize("mode", INIT_MODES)
def test_strategies_serve_the_starts_the_verdict_counted(mode: InitMode) -> None:
    """Random games: a realizable one's machine serves the starts its reading names (the
    oracle's check), its symbolic form starts from the same states (the reachable size is the
    explicit machine's), and an unrealizable one's counterstrategy starts where it should."""
    rng = random.Random(f"starts {mode}")
    for _ in range(100):
        text = random_spc(rng, mode)
        spec = parse_gr1c(text, file="random.spc", init_mode=mode)
        solution = solve(Game.build(spec))
        if solution.realizable:
            machine = extract(solution, minimal=False)
            check_strategy(spec, machine)
            size = reachable_size(solution)
            assert (size.nodes, size.transitions) == (
                len(machine.states),
                len(machine.transitions),
            ), text
        else:
            check_counterstrategy(spec, extract_counterstrategy(solution))
