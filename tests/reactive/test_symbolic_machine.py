"""The symbolic strategy stepped through the executor's interface makes the explicit machine's
moves: on random readings (a seeded walk of allowed readings), both machines answer alike, and
refuse the same readings."""

from __future__ import annotations

import json
import random

import yaml

from tlmpc.abstraction import build_abstraction
from tlmpc.mission import load_mission_text
from tlmpc.reactive.stepper import SymbolicMachine
from tlmpc.reactive.synthesize import strategy_to_json, synthesize
from tlmpc.runtime.strategy_machine import StrategyMachine

MISSION = {
    "version": 1,
    "name": "stepper",
    "workspace": {"boundary": {"rect": [0, 0, 10, 6]}, "holes": [{"rect": [4, 2, 6, 4]}]},
    "regions": {
        "home": {"rect": [0.5, 0.5, 2, 2]},
        "exit": {"rect": [8, 4, 9.5, 5.5]},
        "lab": {"rect": [4, 4.5, 6, 6]},
    },
    "sensors": {"person": None, "alarm": None},
    "actions": {"camera": None},
    "assumptions": ["G(person -> F !person)", "G F !alarm"],
    "robot": {"start": [1, 1]},
    "task": [
        "if you sense person then visit exit",
        "visit home infinitely often",
        "never enter lab while alarm",
        "if you sense person then do camera",
    ],
}


def test_the_symbolic_machine_answers_as_the_explicit_one() -> None:
    mission = load_mission_text(yaml.safe_dump(MISSION, sort_keys=False), "stepper.yaml")
    found = synthesize(mission, build_abstraction(mission), explicit_transitions=10**9)
    document = json.loads(json.dumps(strategy_to_json(found)))
    sensors, actions = ["person", "alarm"], ["camera"]
    explicit = StrategyMachine.of_json(document, sensors, actions, "strategy.json")
    symbolic = SymbolicMachine.of_json(document, sensors, actions, "strategy.json")
    rng = random.Random(7)
    faces = len(explicit.labels)
    start = int(found.game.faces.face_of[build_abstraction(mission).start])
    for _ in range(30):
        reading = {s: rng.random() < 0.5 for s in sensors}
        a, b = explicit.start(reading, start), symbolic.start(reading, start)
        assert (a is None) == (b is None)
        if a is None or b is None:
            continue
        for _ in range(40):
            assert explicit.behaviour(a) == symbolic.behaviour(b)
            assert explicit.counters[a] == symbolic.counters[b]
            options = []
            for face in range(faces):
                for moved in (False, True):
                    reading = {s: rng.random() < 0.5 for s in sensors}
                    x, y = (
                        explicit.answer(a, reading, face, moved),
                        symbolic.answer(b, reading, face, moved),
                    )
                    assert (x is None) == (y is None), (reading, face, moved)
                    if x is not None and y is not None:
                        options.append((x, y))
            if not options:
                break
            a, b = rng.choice(options)
