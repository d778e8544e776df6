"""The play of an unrealizable mission's counterstrategy shows a robot that tries its best.

Every answer of the robot loses against the environment's counterstrategy, so the play picks
one: like a GR(1) strategy, the robot pursues the core's goals in turn, never gets stuck if it
can help it, and heads for a face nearest to where the pursued goal holds.  Checked
independently of the chooser on small missions (and on the depot of docs/examples.md):

* the play is a play of the game: it starts in the counterstrategy's first node, every step
  is a move of the counterstrategy's environment and an answer of the robot, the game's
  transition relation (its BDDs) and the motion's rules (read off the faces) allow it;
* at every step the robot's heading is as close to the goal it pursues as any answer it has
  from which it need never get stuck (which nodes those are: a path to a cycle, found by
  search), with distances found by brute force (Floyd-Warshall on the face graph, the faces
  of the goal's region and the faces outside the avoided regions read off their labels), and
  it does head for the goal.  The old choice (the first answer that keeps it moving) fails
  this: in these missions its robot wanders and never heads for the place the environment
  keeps it from.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import pytest

from tlmpc.abstraction import build_abstraction
from tlmpc.mission import load_mission_text
from tlmpc.reactive.explain import Play, counter_play, counter_play_steps
from tlmpc.reactive.synthesize import Synthesis, synthesize
from tlmpc.synth.counter import CounterStrategy
from tlmpc.synth.solver import Game
from tlmpc.synth.symbolic import Encoding

ROOT = Path(__file__).resolve().parents[2]

GUARD = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 6]}
  holes: [{rect: [4, 2, 6, 4]}]
regions:
  home: {rect: [0.5, 0.5, 2, 2]}
  exit: {rect: [8, 4, 9.5, 5.5]}
  lab: {rect: [4, 4.5, 6, 6]}
sensors:
  alarm: null
robot: {start: [1, 1], max_speed: 1.0}
task:
  - visit home infinitely often
  - visit exit infinitely often
  - never enter lab while alarm
  - visit lab infinitely often
"""

# starting in the gate, the robot may meet either goal alone; both, never (the environment
# keeps `s` on once it has left): a core of two goals
CORRIDOR = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 12, 3]}
regions:
  a: {rect: [0.5, 0.5, 2, 2.5]}
  gate: {rect: [5, 0, 7, 3]}
  b: {rect: [10, 0.5, 11.5, 2.5]}
sensors:
  s: null
robot: {start: [6, 1.5], max_speed: 1.0}
task:
  - visit a infinitely often
  - visit b infinitely often
  - never enter gate while s
"""

# the same corridor from the left of the gate: a core of one goal, the right end
LEFT = CORRIDOR.replace("start: [6, 1.5]", "start: [3, 1.5]")

# the way to the lab through the pit is the shortest, but the robot must avoid the pit
DETOUR = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 6]}
  holes: [{rect: [2, 2, 8, 4]}]
regions:
  dock: {rect: [0.2, 0.2, 1.5, 1.5]}
  lab: {rect: [8.5, 4.5, 9.8, 5.8]}
  pit: {rect: [4, 0, 6, 2]}
  hall: {rect: [3.5, 4, 5, 6]}
  porch: {rect: [5, 4, 6.5, 6]}
sensors: {s: null}
robot: {start: [0.8, 0.8], max_speed: 1.0}
task:
  - avoid pit
  - visit lab infinitely often
  - never enter lab while s
"""

# a goal of an action, which the environment forbids for ever: the robot can do it anywhere
ACTION = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 6, 4]}
regions:
  a: {rect: [0.5, 0.5, 1.5, 1.5]}
sensors: {p: null}
actions: {cam: null}
robot: {start: [3, 1], max_speed: 1.0}
ltl: 'G F cam & G(p -> !cam) & G F a'
"""

# a response: its goal is read on the step (a monitor's move), not on a state
RESPONSE = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 10, 8]}
  holes: [{rect: [3, 3, 7, 5]}]
regions:
  exit: {rect: [8, 6, 9.5, 7.5]}
  dock: {rect: [0.5, 0.5, 2, 2]}
  pit: {rect: [0, 3, 3, 5]}
sensors:
  alarm: null
robot: {start: [1, 1], max_speed: 1.0}
task:
  - avoid pit
  - if you sense alarm then visit exit
  - never enter exit while alarm
"""


NAMES = ["guard", "guard, whole task", "corridor", "response", "left", "detour", "action"]


@dataclass(frozen=True)
class Case:
    """A mission, the goals the robot pursues in turn (regions to visit, or actions to do)
    and the regions it avoids."""

    name: str
    synthesis: Synthesis
    goals: tuple[str, ...]
    avoided: tuple[str, ...] = ()
    whole_task: bool = False  # pursue every goal of the task, not the core's
    heads: bool = True  # the play shows the robot heading for a goal (not only meeting it)

    def play(self) -> Play:
        counter = self.synthesis.counter
        assert counter is not None
        core = None if self.whole_task else self.synthesis.core
        return counter_play_steps(counter, self.synthesis.game, core)


def _solve(text: str, name: str) -> Synthesis:
    mission = load_mission_text(text, f"{name}.yaml")
    found = synthesize(mission, build_abstraction(mission))
    assert not found.realizable
    return found


@pytest.fixture(scope="module")
def cases() -> dict[str, Case]:
    guard = _solve(GUARD, "guard")
    corridor = _solve(CORRIDOR, "corridor")
    response = _solve(RESPONSE, "response")
    left = _solve(LEFT, "left")
    detour = _solve(DETOUR, "detour")
    action = _solve(ACTION, "action")
    assert [p.text for p in guard.core or ()] == [
        "never enter lab while alarm",
        "visit lab infinitely often",
    ]
    assert len(corridor.core or ()) == 3
    assert [p.text for p in left.core or ()] == [
        "visit b infinitely often",
        "never enter gate while s",
    ]
    assert [p.text for p in action.core or ()] == ["G F cam", "G(p -> !cam)"]
    return {
        "guard": Case("guard", guard, ("lab",)),
        "guard, whole task": Case("guard", guard, ("home", "exit", "lab"), whole_task=True),
        "corridor": Case("corridor", corridor, ("a", "b")),
        "response": Case("response", response, ("exit",), ("pit",)),
        "left": Case("left", left, ("b",)),
        "detour": Case("detour", detour, ("lab",), ("pit",)),
        "action": Case("action", action, ("cam",), heads=False),
    }


def _never_stuck(counter: CounterStrategy) -> set[int]:
    """Nodes with an infinite path: those that reach a node on a cycle (search from each)."""

    def reach(start: int) -> set[int]:
        seen: set[int] = set()
        todo = list(counter.answers[start])
        while todo:
            n = todo.pop()
            if n not in seen:
                seen.add(n)
                todo.extend(counter.answers[n])
        return seen

    reached = [reach(n) for n in range(len(counter.states))]
    on_cycle = {n for n in range(len(counter.states)) if n in reached[n]}
    return {n for n in range(len(counter.states)) if n in on_cycle or reached[n] & on_cycle}


def _distances(case: Case) -> dict[str, list[int]]:
    """Per goal region (or action, done anywhere), each face's crossings to a face of it
    through faces outside the avoided regions (Floyd-Warshall; ``far`` when there is none)."""
    faces = case.synthesis.game.faces
    count = faces.count
    far = 10 * count
    open_faces = [not set(faces.letters[f]) & set(case.avoided) for f in range(count)]
    d = [[0 if i == j else far for j in range(count)] for i in range(count)]
    for i in range(count):
        for j in faces.adjacent[i]:
            if open_faces[i] and open_faces[j]:
                d[i][j] = 1
    for k in range(count):
        for i in range(count):
            for j in range(count):
                d[i][j] = min(d[i][j], d[i][k] + d[k][j])
    counter = case.synthesis.counter
    assert counter is not None
    result = {}
    for region in case.goals:
        inside = [f for f in range(count) if region in faces.letters[f] and open_faces[f]]
        if region in counter.states[0]:  # an action: done anywhere
            inside = [f for f in range(count) if open_faces[f]]
        result[region] = [
            min((d[f][t] for t in inside), default=far) if open_faces[f] else far
            for f in range(count)
        ]
    return result


def _nodes(play: Play, counter: CounterStrategy) -> list[int]:
    """The play's nodes, and the node it goes on to after its last step."""
    nodes = [step.node for step in play.steps]
    assert play.again_from is not None, "these plays repeat"
    return [*nodes, play.steps[play.again_from].node]


@pytest.mark.parametrize("name", NAMES)
def test_the_play_is_a_play_of_the_game(cases: dict[str, Case], name: str) -> None:
    case = cases[name]
    counter = case.synthesis.counter
    assert counter is not None
    play = case.play()
    nodes = _nodes(play, counter)
    states = [counter.states[n] for n in nodes]
    for step, node in zip(play.steps, nodes, strict=False):
        state = counter.states[node]
        assert (step.face, step.heading) == (state["face"], state["goal"])
        assert all(state[sensor] == value for sensor, value in step.sensors)
    assert nodes[0] in counter.initial
    for node, answer in pairwise(nodes):
        assert answer in counter.answers[node]
        # the environment moves as the counterstrategy says
        assert all(counter.states[answer][k] == v for k, v in counter.moves[node].items())

    # the game's transition relation allows every step
    spec = case.synthesis.game.spec
    enc = Encoding(spec)
    game = Game.build(spec, enc)
    bdd = enc.bdd
    first = enc.state_cube(states[0], None, False)
    assert first & game.env_init & game.sys_init != bdd.false
    for state, after in pairwise(states):
        step = enc.state_cube(state, None, False) & enc.state_cube(after, None, True)
        assert step & game.env_safety != bdd.false
        assert step & game.sys_safety != bdd.false

    # and so do the motion's rules, read off the faces
    adjacent = case.synthesis.game.faces.adjacent
    for state, after in pairwise(states):
        assert after["face"] in (state["face"], state["goal"])
        assert after["moved"] == (after["face"] != state["face"])
        assert after["goal"] == after["face"] or after["goal"] in adjacent[after["face"]]


def _check_headings(case: Case) -> None:
    """At every step the robot takes an answer from which it need never get stuck if it has
    one; among those, one that meets an action goal it pursues if it can; among those, one
    heading as close to the goal as any; among those, one that moves if any does.  And it does
    head for its goal (unless the goal is an action, met anywhere)."""
    counter = case.synthesis.counter
    assert counter is not None
    letters = case.synthesis.game.faces.letters
    distance = _distances(case)
    safe = _never_stuck(counter)
    play = case.play()
    nodes = _nodes(play, counter)
    pursued = 0
    pursued_at: list[int] = []  # the goal pursued at each node of the play
    headed = 0

    def heading(node: int) -> int:
        return int(counter.states[node]["goal"])

    def stays(node: int) -> bool:
        return heading(node) == counter.states[node]["face"]

    # the first node is the robot's choice too (its first heading), among the first nodes
    for index, (node, chosen) in enumerate(pairwise([None, *nodes])):
        assert chosen is not None
        allowed = counter.initial if node is None else counter.answers[node]
        options = [a for a in allowed if a in safe] or list(allowed)
        assert chosen in options, f"step {index}: the robot may get stuck"
        goal = case.goals[pursued]
        after = counter.states[chosen]
        if goal in after:  # an action
            options = [a for a in options if counter.states[a][goal]] or options
            assert chosen in options, f"step {index}: the robot could do {goal}"
            reached = bool(after[goal])
        else:
            reached = goal in letters[int(after["face"])]
        if reached:  # on to the next goal
            pursued = (pursued + 1) % len(case.goals)
        pursued_at.append(pursued)
        to_goal = distance[case.goals[pursued]]
        best = min(to_goal[heading(a)] for a in options)
        assert to_goal[heading(chosen)] == best, (
            f"step {index}: heading for {letters[heading(chosen)]} ({to_goal[heading(chosen)]} "
            f"from {case.goals[pursued]}) when an answer heads {best} from it"
        )
        if best < to_goal[int(after["face"])]:
            headed += 1
        if any(not stays(a) for a in options if to_goal[heading(a)] == best):
            assert not stays(chosen), f"step {index}: the robot stays when it could move"
    assert headed or not case.heads, "the robot never heads for its goal"
    # the play goes on as from the step it repeats from: the same node, the same goal pursued
    assert play.again_from is not None
    assert pursued_at[-1] == pursued_at[play.again_from]


@pytest.mark.parametrize("name", NAMES)
def test_the_robot_heads_for_the_goal_it_pursues(cases: dict[str, Case], name: str) -> None:
    _check_headings(cases[name])


def test_the_robot_pursues_the_core_goals_in_turn(cases: dict[str, Case]) -> None:
    lines = counter_play(
        cases["corridor"].synthesis.counter,  # type: ignore[arg-type]
        cases["corridor"].synthesis.game,
        cases["corridor"].synthesis.core,
    )
    assert lines == [
        "0: in gate, sensing nothing, heading for free space",
        "1: in free space, sensing nothing, heading for a",
        "3: in a, sensing nothing, heading for free space",
        "4: in free space, sensing nothing, heading for gate",
        "6: in free space, sensing s, heading for its own place",
        "then again from step 5, forever",
    ]


def test_the_depot_play_is_the_one_the_examples_page_tells() -> None:
    source = ROOT / "specs" / "reactive" / "depot.yaml"
    mission = load_mission_text(
        source.read_text() + "  - visit loading infinitely often\n", "depot.yaml"
    )
    assert mission.source == "depot.yaml"
    found = synthesize(mission, build_abstraction(mission))
    assert found.counter is not None
    assert [p.text for p in found.core or ()] == [
        "never enter loading while person",
        "visit loading infinitely often",
    ]
    lines = counter_play(found.counter, found.game, found.core)
    assert lines == [
        "0: in dock, sensing nothing, heading for free space",
        "1: in free space, sensing nothing, heading for loading",
        "5: in free space, sensing person, heading for its own place",
        "then again from step 2, forever",
    ]
    page = (ROOT / "docs" / "examples.md").read_text()
    told = " ".join(page.split("Making the task impossible", 1)[1].split("\n\n", 1)[0].split())
    assert "leaves the dock and heads for the loading zone" in told
    assert "a person appears before it gets there" in told
    assert "waits where it is" in told
    _check_headings(Case("depot", found, ("loading",), tuple(f"keepout_{k}" for k in range(1, 10))))
