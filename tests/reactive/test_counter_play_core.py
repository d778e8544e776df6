"""The play shown for an unrealizable mission defeats the core it is shown with.

The play is a lasso: its steps up to ``again_from``, then the rest for ever.  Read as a word
(each step's face label and sensors), Spot checks that it keeps every assumption and breaks
the conjunction of the core's parts, and the motion's fairness holds on its cycle (the robot
arrives somewhere, or stays where it heads).  In these missions another conflict (a goal the
environment starves outside the core) is there as well: the whole game's counterstrategy
played against that goal and showed a play on which the core held.
"""

from __future__ import annotations

import io
import json
import warnings
from itertools import pairwise
from pathlib import Path

import pytest

pytest.importorskip("spot")
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import spot

from tlmpc.abstraction import build_abstraction
from tlmpc.abstraction.layout import planning_layout
from tlmpc.cli import main
from tlmpc.ltl import to_text
from tlmpc.mission.body import requested_margin
from tlmpc.mission.load import load_mission_text
from tlmpc.reactive.explain import counter_play_steps
from tlmpc.reactive.synthesize import synthesize
from tlmpc.synth.counter import CounterStrategy, extract_counterstrategy
from tlmpc.synth.solver import Solution

# `avoid r2` with `visit r2 infinitely often unless s1` conflicts too (s1 never comes)
UNLESS = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 6]}
regions:
  r1: {rect: [6.3, 0.3, 7.7, 1.7]}
  r2: {rect: [4.3, 2.3, 5.7, 3.7]}
sensors:
  s0: null
  s1: null
robot: {start: [9.0, 1.0], max_speed: 1.0}
task:
  - visit r2 infinitely often unless s1
  - avoid r2
  - if you sense s0 then visit r2
"""

# with an assumption and a region the sensor keeps the robot out of
ASSUMED = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 6]}
regions:
  r0: {rect: [8.3, 2.3, 9.7, 3.7]}
  r1: {rect: [6.3, 0.3, 7.7, 1.7]}
  r2: {rect: [4.3, 2.3, 5.7, 3.7]}
sensors:
  s0: null
  s1: null
assumptions:
  - "G F !s0"
  - "G(r0 -> !s0)"
robot: {start: [9.0, 1.0], max_speed: 1.0}
task:
  - visit r2 infinitely often unless s1
  - visit r0 infinitely often unless s1
  - avoid r2
  - if you sense s0 then visit r2
"""

# several goals the environment can starve; the stay phrase conflicts with never-enter
STAY = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 6]}
regions:
  r0: {rect: [0.3, 0.3, 1.7, 1.7]}
  r1: {rect: [8.3, 4.3, 9.7, 5.7]}
  r2: {rect: [4.3, 2.3, 5.7, 3.7]}
sensors:
  s0: null
  s2: null
  s4: null
assumptions:
  - "G F !s0"
  - "!s2"
robot: {start: [3.0, 5.0], max_speed: 1.0}
task:
  - if you sense s0 then visit r1
  - never enter r2 while s2
  - when s4, go to r2 and stay there while s4
  - visit r1 infinitely often
"""


@pytest.mark.parametrize("text", [UNLESS, ASSUMED, STAY], ids=["unless", "assumed", "stay"])
def test_the_play_keeps_the_assumptions_and_breaks_the_core(text: str) -> None:
    mission = load_mission_text(text, "m.yaml")
    assert mission.reactive is not None
    layout = planning_layout(mission, requested_margin(mission))
    found = synthesize(mission, build_abstraction(mission, layout))
    assert not found.realizable
    assert found.core
    assert found.counter is not None
    play = counter_play_steps(found.counter, found.game, found.core)
    assert not play.stuck
    assert play.again_from is not None
    letters = found.game.faces.letters
    props = sorted({r.name for r in mission.regions} | set(mission.reactive.sensor_names))

    def letter(step_face: int, sensors: tuple[tuple[str, bool], ...]) -> str:
        on = set(letters[step_face]) | {name for name, value in sensors if value}
        return " & ".join(p if p in on else f"!{p}" for p in props)

    steps = play.steps
    prefix = [letter(s.face, s.sensors) for s in steps[: play.again_from]]
    cycle = [letter(s.face, s.sensors) for s in steps[play.again_from :]]
    text_word = "; ".join([*prefix, f"cycle{{{'; '.join(cycle)}}}"])
    lasso = spot.parse_word(text_word).as_automaton()
    for assumption in mission.reactive.assumptions:
        kept = spot.translate(to_text(assumption.formula)).intersects(lasso)
        assert kept, f"the play breaks the assumption {assumption.text!r}"
    core = " & ".join(f"({to_text(part.formula)})" for part in found.core)
    assert not spot.translate(core).intersects(lasso), f"the play meets the core: {core}"
    # the motion's fairness on the cycle: the robot arrives, or stays where it heads
    loop = [*steps[play.again_from :], steps[play.again_from]]
    assert any(a.face != b.face for a, b in pairwise(loop)) or any(
        s.heading == s.face for s in loop
    )


def test_a_counterstrategy_too_large_to_show_leaves_the_answer_and_the_core(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Q062 is a note: the mission is still unrealizable (exit 1, Q110 with its core), as
    `tlmpc synth` answers (docs/errors.md)."""
    import tlmpc.reactive.synthesize as reactive_synthesize

    def tiny(solution: Solution) -> CounterStrategy:
        return extract_counterstrategy(solution, max_nodes=1)

    monkeypatch.setattr(reactive_synthesize, "extract_counterstrategy", tiny)
    source = tmp_path / "unless.yaml"
    source.write_text(UNLESS)
    out, err = io.StringIO(), io.StringIO()
    code = main(["compile", str(source), "-o", str(tmp_path / "out"), "--json"], out=out, err=err)
    assert code == 1
    diagnostics = json.loads(out.getvalue())["diagnostics"]
    assert [(d["code"], d["severity"]) for d in diagnostics if d["code"] == "Q062"] == [
        ("Q062", "note")
    ]
    first = diagnostics[0]
    assert (first["code"], first["severity"], first["line"]) == ("Q110", "error", 13)
    assert (tmp_path / "out" / "abstraction.json").exists()
    assert not (tmp_path / "out" / "counterstrategy.json").exists()


# fifteen actions no part of the core names: left free, every node of the core's
# counterstrategy would have 2^15 answers (Q062); held, the play is shown
ACTIONS = (
    """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 6]}
regions:
  a: {rect: [0.5, 0.5, 2, 2]}
  b: {rect: [8, 4, 9.5, 5.5]}
sensors:
  s0: null
actions:
"""
    + "".join(f"  a{k}: null\n" for k in range(15))
    + """\
robot: {start: [5, 3], max_speed: 1.0}
task:
  - avoid a
  - if you sense s0 then visit a
"""
)


def test_robot_variables_no_core_part_reads_do_not_multiply_the_counterstrategy() -> None:
    mission = load_mission_text(ACTIONS, "actions.yaml")
    found = synthesize(mission, build_abstraction(mission))
    assert not found.realizable
    assert found.untold == ()
    assert found.counter is not None
    assert len(found.counter.states) < 100
    play = counter_play_steps(found.counter, found.game, found.core)
    assert play.steps
