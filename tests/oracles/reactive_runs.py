"""An independent check of a reactive run: its trace, the strategy it followed, its word.

Shares no code with tlmpc's executor, environments or verifier:

* free space: every straight piece between consecutive samples lies in the workspace minus
  its holes (shapely, to a rounding tolerance);
* the strategy: the run's steps are replayed on ``strategy.json`` itself — at every instant
  where a sensor or the robot's face (from the sampled triangles and the strategy's
  ``face_of``) changes, the strategy must have a transition reading exactly those inputs, and
  every face change goes to a neighbouring face, the one the strategy was heading for;
* the word: the letters of the run (the regions holding each piece's midpoint, by shapely,
  with the sensors' and actions' values from the signals) are a finite prefix; Spot decides
  for each assumption and each task part whether some infinite continuation satisfies it
  (LTL3: not a bad prefix) and whether every one does (a good prefix).
"""

from __future__ import annotations

import itertools
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import shapely

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import spot

TOLERANCE = 1e-7


def free_space(trace: Mapping[str, Any]) -> shapely.Geometry:
    """The workspace minus its holes, from the trace's own copy of it."""
    workspace = trace["workspace"]
    shell = shapely.Polygon(workspace["boundary"], workspace.get("holes", []))
    return shell


def check_free_space(trace: Mapping[str, Any]) -> None:
    """Every piece of the piecewise-linear trajectory stays in free space."""
    space = free_space(trace).buffer(TOLERANCE)
    points = [(x, y) for _, x, y in trace["points"]]
    for a, b in itertools.pairwise(points):
        piece = shapely.LineString([a, b]) if a != b else shapely.Point(a)
        assert space.covers(piece), f"the piece {a} -> {b} leaves free space"


def signal_value(points: Sequence[Sequence[Any]], t: float) -> bool:
    """The right-continuous value of a signal at ``t``."""
    value = bool(points[0][1])
    for time, v in points:
        if time <= t:
            value = bool(v)
        else:
            break
    return value


def face_steps(
    trace: Mapping[str, Any], strategy: Mapping[str, Any]
) -> list[tuple[float, dict[str, bool], int]]:
    """(time, sensors, face) at every instant where a sensor or the face changes."""
    face_of = strategy["faces"]["face_of"]
    sensors = trace["sensors"]
    signals = trace["signals"]
    instants = sorted(
        {float(t) for name in sensors for t, _ in signals[name]}
        | {float(trace["points"][i][0]) for i in range(len(trace["points"]))}
    )
    times = [float(p[0]) for p in trace["points"]]
    triangles = trace["triangles"]
    steps: list[tuple[float, dict[str, bool], int]] = []
    for t in instants:
        index = int(np.searchsorted(times, t, side="right")) - 1
        face = int(face_of[triangles[index]])
        reading = {s: signal_value(signals[s], t) for s in sensors}
        if not steps or steps[-1][1] != reading or steps[-1][2] != face:
            steps.append((t, reading, face))
    return steps


def check_strategy_replay(trace: Mapping[str, Any], strategy: Mapping[str, Any]) -> int:
    """Replay the run on the strategy; returns how many visible steps it had.

    Between visible steps the strategy may have taken stutter steps (nothing the environment
    owns changed); those are followed when the visible reading is not answered directly."""
    nodes = strategy["nodes"]
    inputs = [v["name"] for v in strategy["inputs"]]
    sensors = trace["sensors"]
    actions = trace["actions"]
    adjacent = strategy["faces"]["adjacent"]
    successors: dict[int, list[int]] = {}
    for source, target in strategy["transitions"]:
        successors.setdefault(source, []).append(target)

    def matches(node: int, reading: Mapping[str, bool], face: int, moved: bool) -> bool:
        state = nodes[node]["state"]
        return (
            all(state[s] == reading[s] for s in sensors)
            and state["face"] == face
            and state["moved"] == moved
        )

    steps = face_steps(trace, strategy)
    _t0, reading0, face0 = steps[0]
    current = {n for n in strategy["initial"] if matches(n, reading0, face0, False)}
    assert current, "no initial node reads the first reading"
    previous_face = face0
    for t, reading, face in steps[1:]:
        moved = face != previous_face
        if moved:
            assert face in adjacent[previous_face], f"t={t}: face {previous_face} -> {face}"
            before = _stutter_closure(current, successors, nodes, inputs)
            heading = {nodes[n]["state"]["goal"] for n in before}
            assert face in heading, f"t={t}: entered face {face}, the strategy headed for {heading}"
        reachable = _stutter_closure(current, successors, nodes, inputs)
        current = {
            target
            for node in reachable
            for target in successors.get(node, [])
            if matches(target, reading, face, moved)
        }
        assert current, f"t={t}: no transition of the strategy reads {reading} in face {face}"
        for name in actions:  # the actions shown are the strategy's answer (or a stutter's)
            shown = signal_value(trace["signals"][name], t)
            after = _stutter_closure(current, successors, nodes, inputs)
            answers = {nodes[n]["state"][name] for n in after}
            assert shown in answers, f"t={t}: action {name}={shown}, the strategy gives {answers}"
        previous_face = face
    return len(steps)


def _stutter_closure(
    current: set[int],
    successors: Mapping[int, list[int]],
    nodes: Sequence[Mapping[str, Any]],
    inputs: Sequence[str],
) -> set[int]:
    """``current`` and every node reached from it by steps that keep the sensors and the
    face and do not move (the environment's stutter)."""
    seen = set(current)
    todo = list(current)
    while todo:
        node = todo.pop()
        state = nodes[node]["state"]
        for target in successors.get(node, []):
            other = nodes[target]["state"]
            if other["moved"] or any(
                other[name] != state[name]
                for name in inputs
                if not name.startswith("assumed_monitor") and name != "moved"
            ):
                continue
            if target not in seen:
                seen.add(target)
                todo.append(target)
    return seen


def word(trace: Mapping[str, Any]) -> list[frozenset[str]]:
    """The letters of the run in order (consecutive repeats merged)."""
    regions = {n: shapely.Polygon(p) for n, p in trace["regions"].items()}
    signals = trace["signals"]
    times = [float(p[0]) for p in trace["points"]]
    points = np.asarray([(p[1], p[2]) for p in trace["points"]])
    instants = sorted(set(times) | {float(t) for s in signals.values() for t, _ in s})
    letters: list[frozenset[str]] = []
    for a, b in itertools.pairwise(instants):
        middle = 0.5 * (a + b)
        x = np.interp(middle, times, points[:, 0])
        y = np.interp(middle, times, points[:, 1])
        probe = shapely.Point(x, y)
        inside = {n for n, r in regions.items() if r.contains(probe)}
        on = {n for n, s in signals.items() if signal_value(s, a)}
        letter = frozenset(inside | on)
        if not letters or letters[-1] != letter:
            letters.append(letter)
    return letters


def three_valued(formula: str, letters: Sequence[frozenset[str]], props: Sequence[str]) -> str:
    """LTL3 verdict of ``formula`` on the finite word (Spot): satisfied, violated or
    inconclusive."""

    def literal(letter: frozenset[str]) -> str:
        return " & ".join(p if p in letter else f"!{p}" for p in props) or "1"

    text = "; ".join(literal(letter) for letter in letters) + "; cycle{1}"
    closure = spot.parse_word(text).as_automaton()
    f = spot.formula(formula)
    if not spot.translate(f).intersects(closure):
        return "violated"
    if not spot.translate(spot.formula.Not(f)).intersects(closure):
        return "satisfied"
    return "inconclusive"


def parts(formula: str) -> list[str]:
    """Top-level conjuncts of an LTL formula, as Spot prints them."""
    f = spot.formula(formula)
    children = list(f) if f.kind() == spot.op_And else [f]
    return [str(c) for c in children]


def check_run(trace: Mapping[str, Any], strategy: Mapping[str, Any]) -> dict[str, str]:
    """All the checks; returns each task part's three-valued verdict on the run."""
    check_free_space(trace)
    check_strategy_replay(trace, strategy)
    letters = word(trace)
    props = sorted({*trace["regions"], *trace["sensors"], *trace["actions"]})
    for assumption in trace["assumptions"]:
        verdict = three_valued(assumption, letters, props)
        assert verdict != "violated", f"the environment broke {assumption}"
    verdicts = {}
    for part in parts(trace["ltl"]):
        verdicts[part] = three_valued(part, letters, props)
        assert verdicts[part] != "violated", f"the robot broke {part}"
    return verdicts
