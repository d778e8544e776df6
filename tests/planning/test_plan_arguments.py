"""The one place that spells out how a plan's task is planned again (tlmpc.planning.mission.
again): a re-plan, the cells' rung and the touch candidate ask the planner with its task (the
mission's untimed skeleton when the plan has none of its own), the mission's options, the
start asked for (the robot's when none) and the moves' weights given; and a plan asked that way
is the plan asked with every argument written out."""

from __future__ import annotations

from pathlib import Path

from tlmpc.abstraction import build_abstraction
from tlmpc.automata import translate
from tlmpc.ltl.ast import Eventually, Prop
from tlmpc.ltl.bounds import untimed_skeleton
from tlmpc.mission.load import load_mission
from tlmpc.planning.mission import Planned, again
from tlmpc.planning.plan import plan
from tlmpc.planning.timing import MoveTimes

ROOT = Path(__file__).resolve().parents[2]


def test_a_plan_is_asked_again_with_its_task_options_start_and_weights() -> None:
    mission = load_mission(ROOT / "specs" / "example1.yaml")
    mesh = build_abstraction(mission)
    automaton = translate(mission.formula, letters=mesh.letters)
    first = plan(mesh, automaton, formula=mission.formula, options=mission.options)
    planned = Planned(abstraction=mesh, automaton=automaton, witness=first)
    times = MoveTimes(speed=2.0)
    arguments = again(mission, planned, times)
    assert arguments == {
        "formula": untimed_skeleton(mission.formula),
        "options": mission.options,
        "start_point": mission.robot.start,
        "times": times,
    }
    elsewhere = (0.25, 0.75)
    assert again(mission, planned, None, elsewhere)["start_point"] == elsewhere
    own = Eventually(Prop(mission.regions[0].name))
    with_task = Planned(abstraction=mesh, automaton=automaton, witness=first, formula=own)
    assert again(mission, with_task, None)["formula"] == own
    spelled = plan(
        mesh,
        automaton,
        formula=untimed_skeleton(mission.formula),
        options=mission.options,
        start_point=mission.robot.start,
        times=times,
        bounces=True,
    )
    assert plan(mesh, automaton, **arguments, bounces=True) == spelled
