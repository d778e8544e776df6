"""A reactive mission's strategy.json: the symbolic form alone (past the explicit budget) still
wins the mission's game, checked by the definition-level oracle on the machine it induces;
with the budget, both forms are written and agree."""

from __future__ import annotations

import json

import jsonschema
import yaml
from game_oracle import check_strategy, explore

from tlmpc.abstraction import build_abstraction
from tlmpc.io.schema_check import load_schema
from tlmpc.mission import load_mission_text
from tlmpc.reactive.synthesize import Synthesis, strategy_to_json, synthesize
from tlmpc.synth.strategy import machine_from_json
from tlmpc.synth.symbolic_strategy import symbolic_from_json

MISSION = {
    "version": 1,
    "name": "two-sensors",
    "workspace": {"boundary": {"rect": [0, 0, 10, 6]}, "holes": [{"rect": [4, 2, 6, 4]}]},
    "regions": {
        "home": {"rect": [0.5, 0.5, 2, 2]},
        "exit": {"rect": [8, 4, 9.5, 5.5]},
        "lab": {"rect": [4, 4.5, 6, 6]},
    },
    "sensors": {"person": None, "alarm": None},
    "actions": {"camera": None},
    "assumptions": ["G F !person", "G F !alarm"],
    "robot": {"start": [1, 1]},
    "task": [
        "if you sense person then visit exit",
        "visit home infinitely often",
        "never enter lab while alarm",
        "if you sense person then do camera",
    ],
}


def _synthesis(budget: int) -> Synthesis:
    mission = load_mission_text(yaml.safe_dump(MISSION, sort_keys=False), "two.yaml")
    return synthesize(mission, build_abstraction(mission), explicit_transitions=budget)


def test_the_symbolic_form_alone_wins() -> None:
    found = _synthesis(0)
    assert found.realizable
    assert found.strategy is None
    document = json.loads(json.dumps(strategy_to_json(found)))
    jsonschema.validate(document, load_schema("strategy"))
    assert "nodes" not in document
    spec = found.game.spec
    machine = explore(spec, symbolic_from_json(document))
    check_strategy(spec, machine)
    assert found.size is not None
    assert len(machine.states) == found.size.nodes == document["reachable"]["nodes"]


def test_both_forms_are_written_within_the_budget_and_agree() -> None:
    found = _synthesis(10**9)
    assert found.strategy is not None
    document = json.loads(json.dumps(strategy_to_json(found)))
    jsonschema.validate(document, load_schema("strategy"))
    listed = machine_from_json(document)
    stepper = symbolic_from_json(document)
    inputs = [v.name for v in listed.inputs]
    for source, target in listed.transitions:
        after = listed.states[target]
        stepped = stepper.step(
            listed.states[source], listed.node_goals[source], {k: after[k] for k in inputs}
        )
        assert stepped is not None
        assert stepped[0] == after
