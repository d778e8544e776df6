"""The symbolic strategy (decision diagrams per output bit) wins, by the explicit-state check of
the game's definition, and is the explicit machine's strategy: the same moves, the same
reachable size.

* Random small games (the generator of test_oracles): the machine explored by stepping the
  symbolic strategy on every input the environment's safety allows (decided by the oracle's
  own evaluator, not by the diagrams) is checked by ``check_strategy``.
* The published benchmark specifications: stepping the symbolic strategy along every
  transition of the explicit machine gives that transition's target, and the symbolically
  counted size equals the explicit machine's; a written strategy.json reads back to the
  same strategy and validates against its schema.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import jsonschema
import pytest
from game_oracle import check_strategy, explore
from hypothesis import HealthCheck, given, settings
from test_oracles import games, spc

from tlmpc.synth.readers import read_spec
from tlmpc.synth.readers.gr1c import parse_gr1c
from tlmpc.synth.readers.structuredslugs import parse_structuredslugs
from tlmpc.synth.solver import Game, solve
from tlmpc.synth.strategy import extract, machine_from_json, to_json
from tlmpc.synth.symbolic_strategy import (
    reachable_size,
    symbolic_document,
    symbolic_from_json,
    symbolic_strategy,
)

ROOT = Path(__file__).resolve().parents[2]
SHARED = (
    Path(os.environ.get("TLMPC_SHARED_BENCHMARKS") or ROOT.parent / "shared" / "benchmarks") / "gr1"
)
SCHEMA = json.loads((ROOT / "schemas" / "strategy.schema.json").read_text())

REALIZABLE = [
    "gr1c/tests/specs/arbiter4.spc",
    "gr1c/tests/specs/trivial_2var.spc",
    "gr1c/tests/specs/free_counter.spc",
    "gr1c/tests/specs/trivial_mustblock.spc",
    "gr1c/tests/specs/gridworld_2x20_1obs.spc",
    "slugs/examples/firefighting.slugsin",
    "slugs/examples/networks.slugsin",
    "slugs/examples/simple_safety_example.slugsin",
    "slugs/examples/fastslow/fastslow_orig.slugsin",
]


@settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(games)
def test_the_symbolic_strategy_wins_random_games(game: dict[str, list[object]]) -> None:
    text = spc(game)  # type: ignore[arg-type]
    spec = parse_gr1c(text, file="random.spc")
    solution = solve(Game.build(spec))
    if not solution.realizable:
        return
    strategy = symbolic_strategy(solution)
    machine = explore(spec, strategy)
    check_strategy(spec, machine)
    explicit = extract(solution, minimal=False)
    size = reachable_size(solution)
    assert (size.nodes, size.transitions) == (len(explicit.states), len(explicit.transitions))
    assert len(machine.states) == len(explicit.states), text


def _published(name: str) -> Path:
    path = SHARED / name
    if not path.is_file():
        found = list(SHARED.rglob(Path(name).name))
        if not found:
            pytest.skip(f"{name} is not in the shared benchmarks")
        path = found[0]
    return path


@pytest.mark.parametrize("name", REALIZABLE)
def test_the_symbolic_strategy_takes_the_explicit_machines_moves(name: str) -> None:
    spec = read_spec(str(_published(name)))
    solution = solve(Game.build(spec))
    assert solution.realizable
    explicit = extract(solution, minimal=False)
    strategy = symbolic_strategy(solution)
    size = reachable_size(solution)
    assert (size.nodes, size.transitions) == (len(explicit.states), len(explicit.transitions))
    written = json.loads(json.dumps(symbolic_document(strategy, size)))
    jsonschema.validate(written, SCHEMA)
    read = symbolic_from_json(written)
    assert read == strategy
    inputs = [v.name for v in explicit.inputs]
    if spec.init_mode == "forall_env_exists_sys":
        for node in explicit.initial:
            state = explicit.states[node]
            assert read.start({k: state[k] for k in inputs}) == state
    for source, target in explicit.transitions:
        after = explicit.states[target]
        stepped = read.step(
            explicit.states[source], explicit.node_goals[source], {k: after[k] for k in inputs}
        )
        assert stepped == (after, explicit.node_goals[target])


COUNTER = """\
[INPUT]
x
go
[OUTPUT]
y: 1...4
b
[ENV_INIT]
!x
[SYS_INIT]
y = 1
[ENV_TRANS]
x -> x'
[SYS_TRANS]
(go & y < 4) -> y' = y + 1
!go -> (y' = y | y' = 1)
b' <-> x'
[ENV_LIVENESS]
go'
[SYS_LIVENESS]
y = 4
y = 1 | b
"""


def test_the_explicit_and_symbolic_machines_read_back_and_step_alike() -> None:
    spec = parse_structuredslugs(COUNTER, file="counter.structuredslugs")
    solution = solve(Game.build(spec))
    assert solution.realizable
    strategy = symbolic_strategy(solution)
    check_strategy(spec, explore(spec, strategy))
    explicit = extract(solution, minimal=False)
    size = reachable_size(solution)
    assert (size.nodes, size.transitions) == (len(explicit.states), len(explicit.transitions))
    read = symbolic_from_json(json.loads(json.dumps(symbolic_document(strategy, size))))
    inputs = [v.name for v in explicit.inputs]
    for source, target in explicit.transitions:
        after = explicit.states[target]
        stepped = read.step(
            explicit.states[source], explicit.node_goals[source], {k: after[k] for k in inputs}
        )
        assert stepped == (after, explicit.node_goals[target])
    machine = extract(solution)
    document = json.loads(json.dumps(to_json(machine)))
    jsonschema.validate(document, SCHEMA)
    listed = machine_from_json(document)
    assert listed == machine
    for source, target in machine.transitions:
        x = {k: machine.states[target][k] for k in inputs}
        assert listed.successor(source, x) == target
    for node in machine.initial:
        assert listed.start({k: machine.states[node][k] for k in inputs}) == node


def test_a_step_that_breaks_the_assumption_is_refused() -> None:
    text = (
        "ENV: x;\nSYS: y;\nENVINIT: !x;\nSYSINIT: ;\nENVTRANS: [](x -> x');\n"
        "SYSTRANS: [](y' <-> x');\nENVGOAL: ;\nSYSGOAL: []<>(y | !x);\n"
    )
    spec = parse_gr1c(text, file="t.spc")
    strategy = symbolic_strategy(solve(Game.build(spec)))
    first = strategy.start({"x": False})
    assert first == {"x": False, "y": False}
    assert strategy.step({"x": True, "y": True}, 0, {"x": False}) is None
    assert strategy.step({"x": True, "y": True}, 0, {"x": True}) == ({"x": True, "y": True}, 0)
    with pytest.raises(ValueError, match="no value for x"):
        strategy.step({"x": True, "y": True}, 0, {})
