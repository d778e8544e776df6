"""Planning for minimum time (``options.cost: time``).

References: a brute-force search of our own over every simple reach plan of a small mesh
(``brute_time``: the planner's choice is not consulted, each plan is timed by the exact
simulation), first-entry times read off the trace, the independent shortest-path oracle
(``shortest_time``) for "no plan meets the deadline", and ``tlmpc verify`` on every compiled
trajectory.
"""

from __future__ import annotations

import dataclasses
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from brute_time import fastest_visit
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from shortest_time import Oracle, free_space

from tlmpc.abstraction.model import Abstraction
from tlmpc.base.errors import NoPlanError
from tlmpc.cli import main
from tlmpc.mission.load import load_mission
from tlmpc.mission.model import Mission
from tlmpc.pipeline.deadlines import DeadlineMissedError
from tlmpc.pipeline.mintime import MAX_REPLANS, measure, plan_minimum_time
from tlmpc.pipeline.shortest import plan_shortest
from tlmpc.pipeline.stages import ABSTRACTION, AUTOMATON, MISSION, WITNESS, compile_mission
from tlmpc.planning.mission import move_times, plan_mission
from tlmpc.planning.product import move_lengths, move_weight_grid
from tlmpc.planning.timing import MoveTimes, move_key

ROOT = Path(__file__).resolve().parents[2]


def rect(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


def small_mission(
    *,
    holes: list[list[list[float]]],
    goal: list[list[float]],
    start: tuple[float, float],
    speed: float,
    ltl: str,
    cost: str | None = None,
    max_area: float | None = None,
) -> str:
    """A 6 x 4 room on a coarse mesh (no angle bound, ``max_area`` if given), goals entered
    as they are."""
    lines = [
        "version: 1",
        "name: small",
        "workspace:",
        "  boundary: {rect: [0, 0, 6, 4]}",
    ]
    if holes:
        lines.append("  holes:")
        lines.extend(f"    - {json.dumps(h)}" for h in holes)
    lines += [
        "regions:",
        f"  goal: {json.dumps(goal)}",
        f"robot: {{start: {json.dumps(list(start))}, max_speed: {speed}}}",
        f'ltl: "{ltl}"',
        "options:",
        "  min_angle: null",
        "  goal_depth: 0",
    ]
    if cost is not None:
        lines.append(f"  cost: {cost}")
    if max_area is not None:
        lines.append(f"  max_area: {max_area}")
    return "\n".join(lines) + "\n"


@st.composite
def small_worlds(draw: st.DrawFn) -> dict[str, Any]:
    """A 6 x 4 room, maybe a pillar, a 1 x 1 goal on the right, a start on the left; every
    coordinate a multiple of a quarter metre; speeds powers of two (the first plan is then
    exactly the length metric's, see docs/planning.md)."""
    quarter = st.integers(0, 4).map(lambda k: k / 4)
    holes = []
    if draw(st.booleans()):
        x, y = 2.5 + draw(quarter), 1.0 + draw(quarter)
        holes.append(rect(x, y, x + 0.75, y + 1.25))
    gx, gy = 4.5 + draw(quarter) / 2, 0.25 + 2.5 * draw(quarter)
    start = (0.5 + draw(quarter), 0.5 + 2.5 * draw(quarter))
    speed = draw(st.sampled_from([0.5, 1.0, 2.0]))
    return {
        "holes": holes,
        "goal": rect(gx, gy, gx + 1.0, gy + 1.0),
        "start": start,
        "speed": speed,
        # about 10-16 triangles without an area bound, 25-30 with
        "max_area": draw(st.sampled_from([None, 1.5])),
    }


def compiled(tmp: Path, text: str) -> Any:
    return compile_mission(tmp / "m.yaml", text=text)


def goal_entry(abstraction: Abstraction, trace: dict[str, Any]) -> float:
    """The first sample time at which the trace is in a triangle labelled goal."""
    for t, tri in zip(trace["points"], trace["triangles"], strict=True):
        if "goal" in abstraction.labels(tri):
            return float(t[0])
    return float("inf")


# --- the weights -----------------------------------------------------------------------


def test_time_weights_are_lengths_at_top_speed_with_measured_moves_replaced(
    tmp_path: Path,
) -> None:
    text = small_mission(
        holes=[], goal=rect(4.5, 1.0, 5.5, 2.0), start=(0.5, 0.5), speed=0.5, ltl="F goal"
    )
    result = compiled(tmp_path, text)
    mesh = result.compilation.get(ABSTRACTION)
    start = (0.5, 0.5)
    lengths = move_lengths(mesh, start)
    estimate = move_weight_grid(mesh, start, "time", MoveTimes(speed=0.5))
    np.testing.assert_allclose(estimate, lengths / 0.5, rtol=1e-15)
    key = move_key(mesh, 3, 0, 1)
    measured = move_weight_grid(mesh, start, "time", MoveTimes(speed=0.5, measured={key: 7.25}))
    assert measured[3, 0, 1] == 7.25
    changed = np.argwhere(measured != estimate)
    assert changed.tolist() == [[3, 0, 1]]
    # keyed by corners, not index: a measurement of a triangle the mesh lacks changes nothing
    gone = (((10**6, 10**6 + 1, 10**6 + 2), 0, 1), 1.0)
    again = move_weight_grid(mesh, start, "time", MoveTimes(speed=0.5, measured=dict([gone])))
    np.testing.assert_array_equal(again, estimate)
    with pytest.raises(ValueError, match="time metric needs"):
        move_weight_grid(mesh, start, "time", None)


def test_time_is_the_default_for_bounded_tasks_and_an_explicit_cost_wins(tmp_path: Path) -> None:
    goal = rect(4.5, 1.0, 5.5, 2.0)
    path = tmp_path / "m.yaml"
    for ltl, cost, expected in [
        ("F goal", None, "length"),
        ("F[0,60] goal", None, "time"),
        ("F[0,60] goal", "length", "length"),
        ("F goal", "time", "time"),
        ("F[0,60] goal", "hops", "hops"),
    ]:
        path.write_text(
            small_mission(holes=[], goal=goal, start=(0.5, 0.5), speed=1.0, ltl=ltl, cost=cost)
        )
        mission = load_mission(path)
        assert mission.options.cost == expected, (ltl, cost)
        assert (move_times(mission) is not None) == (expected == "time")


# --- the plan of least exact time ------------------------------------------------------


def _with_cost(mission: Mission, cost: str) -> Mission:
    return dataclasses.replace(mission, options=dataclasses.replace(mission.options, cost=cost))  # type: ignore[arg-type]


@pytest.mark.slow
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(small_worlds())
def test_the_fastest_plan_against_brute_force(
    tmp_path_factory: pytest.TempPathFactory, world: dict[str, Any]
) -> None:
    """The kept plan is never slower than the length metric's plan, never faster than the
    fastest simple plan the brute force finds, and its recorded exact time is its trace's."""
    text = small_mission(
        holes=world["holes"],
        goal=world["goal"],
        start=world["start"],
        speed=world["speed"],
        ltl="F goal",
        cost="time",
        max_area=world["max_area"],
    )
    tmp = tmp_path_factory.mktemp("m")
    result = compiled(tmp, text)
    compilation = result.compilation
    mission = compilation.get(MISSION)
    mesh = compilation.get(ABSTRACTION)
    witness = compilation.get(WITNESS)
    planner = goal_entry(mesh, result.artifacts["trace.json"])
    assert witness.metric == "time"
    assert witness.stats["time_rounds"] <= MAX_REPLANS + 1
    assert witness.stats["exact_time"] == min(witness.stats["exact_times"])
    # the stay's triangle is entered at the recorded exact time (the first goal triangle)
    assert witness.stats["exact_time"] == pytest.approx(planner, abs=1e-9)
    # the length metric's plan on the same mesh and automaton, as that metric compiles it
    # (its channel chosen by the shortest path)
    as_length = _with_cost(mission, "length")
    length = plan_shortest(as_length, plan_mission(as_length, mesh, compilation.get(AUTOMATON)))
    length_time = measure(mission, length).exact_time
    assert planner <= length_time + 1e-9
    start = witness.prefix[0] if witness.prefix else witness.cycle[0]
    brute = fastest_visit(mission, mesh, start, "goal", budget=300)
    event(f"complete={brute.complete}")
    if brute.complete and not witness.passages:
        # every simple plan was timed: none is faster than the planner's by more than rounding
        assert brute.time <= planner + 1e-9
        ratio = planner / brute.time if brute.time > 0 else 1.0
        event(f"planner/brute <= {np.ceil(ratio * 20) / 20:.2f}")


def test_the_shipped_deadline_spec_keeps_its_fastest_round(tmp_path: Path) -> None:
    result = compiled(tmp_path, (ROOT / "specs" / "deadline.yaml").read_text())
    witness = result.compilation.get(WITNESS)
    assert witness.metric == "time"
    times = witness.stats["exact_times"]
    assert witness.stats["exact_time"] == min(times)
    # re-planned at least once with the measured times, or that re-plan found the first plan
    # again (a fixed point at once: with the fields that follow the channel's shortest path)
    assert len(times) >= 2 or witness.stats["time_fixed_point"]
    assert len(set(times)) == len(times)  # never the same plan twice
    first, *_ = times
    mission = result.compilation.get(MISSION)
    again = plan_minimum_time(mission, *_built(tmp_path, mission), plan_shortest)
    assert again.witness == witness  # deterministic: the same plan, the same numbers
    assert witness.stats["exact_time"] <= first


def test_the_time_metric_is_never_slower_than_the_length_metrics_compile(tmp_path: Path) -> None:
    # The shipped deadline map asked to reach its dock by a far deadline: the midpoint plan
    # (the time rounds' first before they started from the length metric's) entered the dock
    # 1.9 s later than the plan the length metric keeps.
    import yaml

    document = yaml.safe_load((ROOT / "specs" / "deadline.yaml").read_text())
    document.pop("task", None)
    document["ltl"] = "F[0,100000] dock & G !hazard"
    entries = {}
    for metric in ("length", "time"):
        document["options"] = {**(document.get("options") or {}), "cost": metric}
        text = yaml.safe_dump(document, sort_keys=False)
        result = compile_mission(tmp_path / f"{metric}.yaml", text=text, figures=())
        mesh = result.compilation.get(ABSTRACTION)
        trace = result.artifacts["trace.json"]
        entries[metric] = next(
            float(t[0])
            for t, tri in zip(trace["points"], trace["triangles"], strict=True)
            if "dock" in mesh.labels(tri)
        )
    assert entries["time"] <= entries["length"] + 1e-9


def _built(tmp: Path, mission: Mission) -> tuple[Any, Any]:
    result = compile_mission(
        tmp / "again.yaml", text=(ROOT / "specs" / "deadline.yaml").read_text(), until="automaton"
    )
    return result.compilation.get(ABSTRACTION), result.compilation.get(AUTOMATON)


# --- deadlines around the plan's time ------------------------------------------------


def run(*argv: str) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue() + err.getvalue()


@pytest.mark.slow
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(small_worlds(), st.floats(0.6, 1.3))
def test_deadlines_around_the_plans_time(
    tmp_path_factory: pytest.TempPathFactory, world: dict[str, Any], factor: float
) -> None:
    """Compiled: every bound met on the trajectory (``tlmpc verify`` agrees, slack >= 0);
    P050: the true shortest time exceeds the deadline and no simple plan meets it; else P051."""
    tmp = tmp_path_factory.mktemp("m")
    kwargs = {
        "holes": world["holes"],
        "goal": world["goal"],
        "start": world["start"],
        "speed": world["speed"],
        "max_area": world["max_area"],
    }
    free = compiled(tmp, small_mission(ltl="F goal", cost="time", **kwargs))
    mesh = free.compilation.get(ABSTRACTION)
    planned = goal_entry(mesh, free.artifacts["trace.json"])
    deadline = round(planned * factor * 64) / 64
    text = small_mission(ltl=f"F[0,{deadline}] goal", **kwargs)
    try:
        result = compiled(tmp, text)
    except (NoPlanError, DeadlineMissedError) as failure:
        code = failure.diagnostics[0].code
    else:
        code = "ok"
    event(code)
    if code == "P050":
        space = free_space(rect(0, 0, 6, 4), world["holes"], [])
        reach = Oracle(space, world["start"], [world["goal"]], spacing=0.02).reach(0)
        if reach.lower / world["speed"] <= deadline < reach.upper / world["speed"]:
            # the deadline falls inside the oracle's interval: sample the goal finer
            reach = Oracle(space, world["start"], [world["goal"]], spacing=0.001).reach(0)
        assert reach.lower / world["speed"] > deadline
        mission = free.compilation.get(MISSION)
        witness = free.compilation.get(WITNESS)
        start = witness.prefix[0] if witness.prefix else witness.cycle[0]
        # any plan the brute force times (complete or not) must miss the deadline
        assert fastest_visit(mission, mesh, start, "goal", budget=400).time > deadline
        return
    assert code in ("ok", "P051")
    if code == "P051":
        return
    (bound,) = result.summary()["bounds"]
    assert bound["slack"] >= 0.0
    assert bound["time"] == pytest.approx(deadline - bound["slack"], abs=1e-9)
    # the goal is a union of triangles: it is first entered at a crossing sample
    entry = goal_entry(result.compilation.get(ABSTRACTION), result.artifacts["trace.json"])
    assert bound["time"] == pytest.approx(entry, abs=1e-6)
    assert bound["lower_bound"] is not None
    assert bound["lower_bound"] <= bound["time"] + 1e-9
    path = tmp / "trace.json"
    path.write_text(json.dumps(result.artifacts["trace.json"]))
    status, shown = run("verify", str(path))
    assert status == 0, shown


# --- the exact time and the measured moves, read off the trace --------------------------


def _moves_of(mesh: Abstraction, path: list[int]) -> list[tuple[int, int, int]]:
    """(triangle, entry slot, exit edge) of each step of ``path`` that leaves its triangle
    for the next one (slot 3 for the first), from the mesh's neighbour table."""
    found = []
    for k in range(len(path) - 1):
        here, after = path[k], path[k + 1]
        sides = mesh.neighbors[here].tolist()
        slot = 3 if k == 0 else sides.index(path[k - 1])
        found.append((here, slot, sides.index(after)))
    return found


def test_a_stay_plans_measured_moves_are_its_steps_and_add_up_to_its_time(tmp_path: Path) -> None:
    text = small_mission(
        holes=[rect(2.5, 1.0, 3.25, 3.0)],
        goal=rect(4.75, 1.5, 5.75, 2.5),
        start=(0.5, 2.0),
        speed=1.0,
        ltl="F goal",
        cost="time",
    )
    result = compiled(tmp_path, text)
    compilation = result.compilation
    mission, mesh = compilation.get(MISSION), compilation.get(ABSTRACTION)
    witness = compilation.get(WITNESS)
    path = [*witness.prefix, *witness.cycle]
    found = measure(mission, plan_minimum_time(mission, mesh, compilation.get(AUTOMATON)))
    expected = {move_key(mesh, *move) for move in _moves_of(mesh, path)}
    assert set(found.moves) == expected
    assert sum(found.moves.values()) == pytest.approx(found.exact_time, rel=1e-12)
    entry = goal_entry(mesh, result.artifacts["trace.json"])
    assert found.exact_time == pytest.approx(entry, abs=1e-9)


def test_a_patrols_exact_time_is_its_prefix_and_one_lap(tmp_path: Path) -> None:
    text = (ROOT / "specs" / "patrol.yaml").read_text().replace("cost: length", "cost: time")
    result = compiled(tmp_path, text)
    witness = result.compilation.get(WITNESS)
    trace = result.artifacts["trace.json"]
    assert not witness.is_stay
    times = [p[0] for p in trace["points"]]
    triangles = trace["triangles"]
    # the first lap starts when the robot first enters the cycle's first triangle (after the
    # prefix); the second at the trace's loop start; the trace ends after the second lap
    if witness.prefix:
        first = next(j for j in range(1, len(times)) if triangles[j] == witness.cycle[0])
        prefix_time = times[first]
    else:
        prefix_time = 0.0
    lap = times[-1] - times[trace["loop_start"]]
    exact = prefix_time + witness.beta * lap
    assert witness.stats["exact_time"] == pytest.approx(exact, rel=1e-9)
    assert witness.stats["exact_time"] == min(witness.stats["exact_times"])
    # each round simulated a plan not simulated before
    rounds = witness.stats["exact_times"]
    assert len(set(rounds)) == len(rounds)
    assert witness.stats["time_rounds"] == len(rounds)


def _lasso_moves(
    mesh: Abstraction, prefix: list[int], cycle: list[int]
) -> tuple[list[Any], list[Any]]:
    """The moves of a lasso's prefix (into the cycle's first triangle) and of one lap of its
    cycle (each cycle triangle entered from the one before it, around the wrap)."""
    head = _moves_of(mesh, [*prefix, cycle[0]]) if prefix else []
    lap = []
    if len(cycle) > 1:
        for k, here in enumerate(cycle):
            sides = mesh.neighbors[here].tolist()
            before, after = cycle[k - 1], cycle[(k + 1) % len(cycle)]
            slot = sides.index(before)
            lap.append((here, slot, sides.index(after)))
    return head, lap


@pytest.mark.parametrize("spec", ["patrol", "deadline"])
def test_the_guided_search_reads_the_same_time_weights(spec: str, tmp_path: Path) -> None:
    """One weight array for both searches: with measured times in it, the product expanded
    on demand finds a lasso of the built product's cost, and each lasso's cost is the sum
    of the weights of its moves (measured where measured)."""
    from tlmpc.planning.plan import plan

    text = (ROOT / "specs" / f"{spec}.yaml").read_text().replace("cost: length", "cost: time")
    result = compiled(tmp_path, text)
    compilation = result.compilation
    mission, mesh = compilation.get(MISSION), compilation.get(ABSTRACTION)
    planned = plan_minimum_time(mission, mesh, compilation.get(AUTOMATON))
    assert planned.formula is not None
    # every measured move ten times slower: the plans must go round them where they can
    slow = {key: 10 * seconds for key, seconds in measure(mission, planned).moves.items()}
    times = MoveTimes(speed=mission.robot.max_speed, measured=slow)
    found = [
        plan(
            mesh,
            planned.automaton,
            formula=planned.formula,
            options=mission.options,
            start_point=mission.robot.start,
            guided=guided,
            times=times,
        )
        for guided in (False, True)
    ]
    built, searched = found
    assert searched.stats["search"] == "guided"
    assert searched.cost == pytest.approx(built.cost, rel=1e-9)
    grid = move_weight_grid(mesh, mission.robot.start, "time", times)
    for lasso in found:
        head, lap = _lasso_moves(mesh, list(lasso.prefix), list(lasso.cycle))
        total = sum(float(grid[m]) for m in head) + lasso.beta * sum(float(grid[m]) for m in lap)
        assert lasso.cost == pytest.approx(total, rel=1e-7)


def test_a_round_that_meets_the_bounds_is_preferred_to_a_faster_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The selection rule alone: rounds measured as (exact time, bounds met) = (10, no),
    (12, yes), (11, yes), then a repeat: the 11 s round is kept."""
    from tlmpc.pipeline import mintime

    result = compiled(tmp_path, (ROOT / "specs" / "deadline.yaml").read_text())
    compilation = result.compilation
    mission, mesh = compilation.get(MISSION), compilation.get(ABSTRACTION)
    rounds = iter([(10.0, False), (12.0, True), (11.0, True), (9.0, False)])
    marks = iter(range(1, 10))

    def fake_measure(_: Mission, planned: Any) -> mintime.Measured:
        exact, met = next(rounds)
        return mintime.Measured(exact_time=exact, moves={}, meets_bounds=met)

    def fake_replan(_: Mission, planned: Any, times: MoveTimes) -> Any:
        mark = next(marks)
        if mark == 3:  # the third re-plan repeats the second plan
            mark = 2
        first = tuple(t for t in planned.witness.prefix if t >= 0)
        # a plan of its own: the first plan's prefix and a mark in its shape
        witness = dataclasses.replace(planned.witness, prefix=(*first, -mark), stats={"mark": mark})
        return dataclasses.replace(planned, witness=witness)

    monkeypatch.setattr(mintime, "measure", fake_measure)
    monkeypatch.setattr(mintime, "replan", fake_replan)
    kept = mintime.plan_minimum_time(mission, mesh, compilation.get(AUTOMATON))
    assert kept.witness.stats["exact_times"] == [10.0, 12.0, 11.0]
    assert kept.witness.stats["bounds_met"] == [False, True, True]
    assert kept.witness.stats["exact_time"] == 11.0
    assert kept.witness.stats["mark"] == 2
    assert kept.witness.stats["time_fixed_point"] is True


def test_each_bounds_time_and_lower_bound_on_a_patrol_with_a_sequence(tmp_path: Path) -> None:
    """Per bound: the plan's time is never below the proof's lower bound, and the lower
    bounds are the independent oracle's: the shortest path around the lake into bravo, the
    straight way from bravo to charlie, twice the gap between alpha and bravo."""
    import shapely

    text = (ROOT / "specs" / "patrol.yaml").read_text()
    task = '"G F[0,200] alpha & F[0,300] (bravo & F[0,300] charlie)"'
    text = text.replace("options: {cost: length, beta: 1.0}", f"ltl: {task}")
    result = compiled(tmp_path, text)
    assert result.compilation.get(WITNESS).metric == "time"  # the default with bounds
    bounds = {b["bound"]: b for b in result.summary()["bounds"]}
    assert list(bounds) == [
        "F[0,200] alpha",
        "F[0,300] (bravo & F[0,300] charlie)",
        "F[0,300] charlie",
    ]
    for found in bounds.values():
        assert found["lower_bound"] <= found["time"]
        assert found["time"] == pytest.approx(
            float(found["bound"].split(",")[1].split("]")[0]) - found["slack"], abs=1e-6
        )
    regions = result.artifacts["trace.json"]["regions"]
    workspace = [[0, 0], [14, 0], [14, 9], [7, 11], [0, 9]]
    space = free_space(workspace, [regions["lake"]], [])
    oracle = Oracle(space, (2.0, 5.0), [regions["bravo"]], spacing=0.02)
    shortest = oracle.reach(0)
    bravo = bounds["F[0,300] (bravo & F[0,300] charlie)"]["lower_bound"]
    assert shortest.lower - 1e-6 <= bravo <= shortest.upper + 1e-6  # speed 1
    polygon = {name: shapely.Polygon(regions[name]) for name in ("alpha", "bravo", "charlie")}
    leg = shapely.distance(polygon["bravo"], polygon["charlie"])
    assert bounds["F[0,300] charlie"]["lower_bound"] == pytest.approx(leg, abs=1e-6)
    gap = shapely.distance(polygon["alpha"], polygon["bravo"])
    assert bounds["F[0,200] alpha"]["lower_bound"] == pytest.approx(2 * gap, abs=1e-6)
