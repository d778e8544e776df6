"""Planning: witnesses satisfy the task, never bounce, cost metrics, explanations."""

from __future__ import annotations

import itertools
import json
from pathlib import Path
from typing import Any

import pytest
import spin_runner as spin
import yaml
from ci_oracles import oracle_required
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from lasso_ltl import holds
from starts import start_triangles
from strategies import CO_SAFE_TEMPLATES, missions_with_template

from tlmpc.abstraction import build_abstraction
from tlmpc.automata import translate
from tlmpc.base.errors import NoPlanError
from tlmpc.io.schema_check import validation_errors
from tlmpc.mission import load_mission_text
from tlmpc.mission.model import Mission, Options
from tlmpc.planning import plan, witness_from_json, witness_to_json
from tlmpc.planning.export import to_promela

BASE = """\
version: 1
workspace:
  boundary: {rect: [0, 0, 12, 8]}
  holes: [HOLES]
regions:
  a: {rect: [1, 1, 3, 3]}
  b: {rect: [9, 5, 11, 7]}
  c: {rect: [5, 2, 7, 6]}
robot: {start: [0.5, 7.5]}
TASK
"""


def mission(task: str, holes: str = "", options: str = "") -> Mission:
    text = BASE.replace("HOLES", holes).replace("TASK", task) + options
    return load_mission_text(text, "m.yaml")


def compile_plan(m: Mission) -> tuple[Any, Any, Any]:
    abstraction = build_abstraction(m)
    automaton = translate(m.formula, letters=abstraction.letters)
    witness = plan(
        abstraction, automaton, formula=m.formula, options=m.options, start_point=m.robot.start
    )
    return abstraction, automaton, witness


def check_lasso(abstraction: Any, witness: Any, start_point: Any) -> None:
    path = [*witness.prefix, *witness.cycle]
    # Any triangle holding the start point may come first (a start on an edge or vertex).
    assert path[0] in start_triangles(abstraction, start_point)
    for x, y in itertools.pairwise(path):
        assert y in abstraction.neighbors[x].tolist(), "consecutive triangles are adjacent"
    for i in range(1, len(path) - 1):
        assert path[i - 1] != path[i + 1], "no bounce"
    cycle = list(witness.cycle)
    assert len(cycle) == 1 or len(cycle) >= 3, "a 2-triangle cycle bounces"
    if len(cycle) > 1:
        assert cycle[0] in abstraction.neighbors[cycle[-1]].tolist()
        loop = [cycle[-1], *cycle, cycle[0]]
        for i in range(1, len(loop) - 1):
            assert loop[i - 1] != loop[i + 1], "no bounce across the wrap"
        before = witness.prefix[-1] if witness.prefix else cycle[-1]
        assert before != cycle[1 % len(cycle)]


TASKS = [
    "visit a",
    "visit a then b",
    "visit a, b and c",
    "patrol a, b",
    "visit b while avoiding c",
    "stay in b",
    "whenever a, visit b",
    "avoid c until b",
    "visit a then b then return to a",
]


@settings(deadline=None, max_examples=30)
@given(
    st.sampled_from(TASKS),
    st.sampled_from(["", "{rect: [4, 6.5, 8, 7.5]}"]),
    st.sampled_from(["length", "hops"]),
)
def test_witness_satisfies_the_task_and_never_bounces(task: str, hole: str, cost: str) -> None:
    m = mission(f"task: [{json.dumps(task)}]", hole, f"options: {{cost: {cost}}}\n")
    abstraction, _, witness = compile_plan(m)
    check_lasso(abstraction, witness, m.robot.start)
    word = [frozenset(abstraction.labels(t)) for t in (*witness.prefix, *witness.cycle)]
    assert holds(m.formula, word, len(witness.prefix))
    assert witness.cost == pytest.approx(witness.prefix_cost + witness.beta * witness.cycle_cost)


def test_cosafe_tasks_end_in_a_stay_and_patrols_loop() -> None:
    _, _, witness = compile_plan(mission("task: [visit a then b]"))
    assert witness.is_stay
    assert witness.cycle_cost == 0.0
    abstraction, _, witness = compile_plan(mission('task: ["patrol a, b"]'))
    assert len(witness.cycle) >= 3
    labels = {name for t in witness.cycle for name in abstraction.labels(t)}
    assert {"a", "b"} <= labels


def test_hops_counts_moves() -> None:
    _, _, witness = compile_plan(mission("task: [visit b]", options="options: {cost: hops}\n"))
    assert witness.prefix_cost == pytest.approx(len(witness.prefix), abs=1e-6)


def test_length_is_shorter_in_metres_than_hops_plan() -> None:
    _, _, by_length = compile_plan(mission("task: [visit b]"))
    _, _, by_hops = compile_plan(mission("task: [visit b]", options="options: {cost: hops}\n"))
    assert len(by_hops.prefix) <= len(by_length.prefix)


def test_invariants_are_respected() -> None:
    abstraction, _, witness = compile_plan(mission("task: [visit b, avoid c]"))
    assert all("c" not in abstraction.labels(t) for t in (*witness.prefix, *witness.cycle))


@pytest.mark.parametrize(
    ("task", "holes", "code", "words"),
    [
        ("task: [visit a, avoid a]", "", "P001", "unsatisfiable"),
        ('ltl: "G !o & F a"', "", "P002", "starts in"),
        ('ltl: "c U b"', "", "P003", "fails where the robot starts"),
        ("task: [visit b]", "{rect: [4, 0, 5, 8]}", "P005", "holes separate"),
        (
            # the holes overlap c's side: no corner of c's touches the free space below it
            # (at a shared corner a route passes c through that point)
            "task: [visit b, avoid c]",
            "{rect: [4, 0, 5, 2.5]}, {rect: [4, 5.5, 5, 8]}",
            "P005",
            "forbids",
        ),
    ],
)
def test_no_plan_explanations(task: str, holes: str, code: str, words: str) -> None:
    text = BASE.replace("HOLES", holes).replace("TASK", task)
    if "o &" in task:
        text = text.replace(
            "  c: {rect: [5, 2, 7, 6]}", "  c: {rect: [5, 2, 7, 6]}\n  o: {rect: [0, 7, 1, 8]}"
        )
    if "c U b" in task:
        text = text.replace("robot: {start: [0.5, 7.5]}", "robot: {start: [0.5, 0.5]}")
    m = load_mission_text(text, "m.yaml")
    with pytest.raises(NoPlanError) as caught:
        compile_plan(m)
    diagnostic = caught.value.diagnostics[0]
    assert diagnostic.code == code
    assert words in diagnostic.message


def test_witness_artifact() -> None:
    abstraction, _, witness = compile_plan(mission('task: ["patrol a, b"]'))
    document = witness_to_json(witness, abstraction)
    assert validation_errors(document, "witness") == []
    assert witness_from_json(document) == witness


needs_spin = oracle_required(spin.available(), "spin (and gcc)")

HOPS = "options: {min_angle: null, cost: hops, beta: 1}\n"


def spin_and_ours(
    tmp_path: Path, m: Mission, *, bounce: bool = False
) -> tuple[Any, spin.SpinTrail, Any]:
    """SPIN's shortest trail on the exported model, and tlmpc's plan (None: no plan)."""
    abstraction = build_abstraction(m)
    model = tmp_path / "model.pml"
    model.write_text(to_promela(abstraction, m.formula, bounce=bounce))
    trail = spin.run_spin(model, shortest=True, max_depth=100_000)
    automaton = translate(m.formula, letters=abstraction.letters)
    try:
        witness = plan(
            abstraction, automaton, formula=m.formula, options=m.options, start_point=m.robot.start
        )
    except NoPlanError:
        witness = None
    return abstraction, trail, witness


def check_spin_trail(abstraction: Any, trail: spin.SpinTrail, *, bounce: bool) -> bool:
    """SPIN's trail is a run of the exported D; returns whether it bounces."""
    path = [abstraction.start, *trail.entered]
    for before, here in itertools.pairwise(path):
        assert here in abstraction.neighbors[before].tolist()
    bounces = any(before == after for before, after in zip(path, path[2:], strict=False))
    assert bounce or not bounces
    return bounces


@pytest.mark.slow
@needs_spin
@pytest.mark.parametrize(
    ("task", "holes", "start", "co_safe"),  # co_safe None: no plan
    [
        ("task: [visit a then b]", "", "[0.5, 7.5]", True),
        ("task: [visit b then a]", "{rect: [4, 1, 5, 7]}", "[0.5, 7.5]", True),
        ("task: [visit a, visit b, visit c]", "", "[11.5, 0.5]", True),
        ("task: [visit b, avoid c]", "{rect: [8, 0, 8.5, 6]}", "[6, 7]", False),
        ('ltl: "!c U b"', "", "[3.5, 4.5]", True),
        ("task: [visit a, avoid a]", "", "[0.5, 7.5]", None),
        ('ltl: "G !c & F c"', "", "[0.5, 7.5]", None),
        ('task: ["patrol a, b"]', "", "[0.5, 7.5]", False),
        ('task: ["patrol a, b, c", avoid d]', "", "[6, 0.5]", False),
        ('ltl: "G F a & G (a -> F c)"', "{rect: [4, 1, 5, 7]}", "[11.5, 7.5]", False),
    ],
)
def test_spin_agrees_on_plan_and_shortest_hops(
    tmp_path: Path, task: str, holes: str, start: str, co_safe: bool | None
) -> None:
    text = BASE.replace("HOLES", holes).replace("TASK", task) + HOPS
    text = text.replace("start: [0.5, 7.5]", f"start: {start}")
    if "avoid d" in task:
        text = text.replace("regions:\n", "regions:\n  d: {rect: [5, 6.5, 7, 8]}\n")
    m = load_mission_text(text, "m.yaml")
    abstraction, trail, witness = spin_and_ours(tmp_path, m)
    assert trail.found is (witness is not None)
    assert (co_safe is None) is (witness is None)
    if witness is None:
        return
    check_spin_trail(abstraction, trail, bounce=False)
    hops = round(witness.cost)
    if co_safe:
        # A finite trail: SPIN's claim ended on a safety violation, so -DREACH -i made it the
        # shortest one; a co-safe task's cheapest lasso is its shortest good prefix, then a stay.
        assert trail.cycle_from is None
        assert witness.is_stay
        assert hops == trail.moves
    else:
        # SPIN's lasso is one plan among many (-i gives no shortest acceptance cycle), so ours,
        # optimal over all lassos of the same D, costs at most as much.
        assert trail.cycle_from is not None
        assert witness.stats["optimal"]
        assert hops <= trail.moves


@needs_spin
@pytest.mark.parametrize("task", ["task: [visit a then b]", "task: [visit c then a then b]"])
def test_spin_on_the_bouncing_d_is_shorter_only_by_bouncing(tmp_path: Path, task: str) -> None:
    m = mission(task, options=HOPS)
    abstraction, trail, witness = spin_and_ours(tmp_path, m, bounce=True)
    assert trail.found
    assert witness is not None
    bounces = check_spin_trail(abstraction, trail, bounce=True)
    hops = round(witness.cost)
    assert trail.moves <= hops
    assert bounces or trail.moves == hops


def test_example8_plan_is_found(specs_dir: Path) -> None:
    text = (specs_dir / "example8.yaml").read_text()
    m = load_mission_text(text, "example8.yaml")
    abstraction, _, witness = compile_plan(m)
    check_lasso(abstraction, witness, m.robot.start)
    assert abstraction.num_triangles == 9250
    assert yaml.safe_load(text)["task"]
    assert isinstance(m.options, Options)


@pytest.mark.slow
@needs_spin
@settings(
    max_examples=max(2, settings().max_examples // 25),  # 8 in CI: a SPIN run per example
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(drawn=missions_with_template())
def test_spin_agrees_on_random_missions(
    drawn: tuple[dict[str, Any], str], tmp_path_factory: pytest.TempPathFactory
) -> None:
    """Random maps and tasks: the same verdict, and on co-safe tasks the same shortest hop
    count; otherwise tlmpc's optimal lasso is never longer than SPIN's trail."""
    document, template = drawn
    document = {**document, "options": {"min_angle": None, "cost": "hops", "beta": 1}}
    m = load_mission_text(yaml.safe_dump(document), "random.yaml")
    # The exported model starts inside one triangle; a start on a mesh edge or vertex may
    # begin in any triangle around it (compared with the brute-force oracle instead).
    cells = start_triangles(build_abstraction(m), m.robot.start)
    assume(len(cells) == 1 and not any(cells.values()))
    abstraction, trail, witness = spin_and_ours(tmp_path_factory.mktemp("spin"), m)
    assert trail.found is (witness is not None), document
    if witness is None:
        return
    check_spin_trail(abstraction, trail, bounce=False)
    assert witness.stats["optimal"]
    hops = round(witness.cost)
    assert hops <= trail.moves, document
    if template in CO_SAFE_TEMPLATES:
        assert trail.cycle_from is None
        assert hops == trail.moves, document
