"""Held-out logs with analytically known crossing times against time-bounded tasks.

The robot runs along y = 5 at 1 m/s, so it is at x = t: it enters ``a`` (4 <= x <= 6) at 4 s,
leaves it at 6 s, enters ``b`` (10 <= x <= 12) at 10 s.  Every expected verdict below is
worked out by hand from those times and the definitions in docs/semantics.md, under both
boundary conventions.
"""

from __future__ import annotations

import io
import itertools
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.cli import main
from tlmpc.io.schema_check import validation_errors
from tlmpc.verify import verdict_to_json, verify_document

A = [[4, 0], [6, 0], [6, 10], [4, 10]]
B = [[10, 0], [12, 0], [12, 10], [10, 10]]
RUN = [[0, 0, 5], [20, 20, 5]]  # x = t for 20 s
BACK_AND_FORTH = [[0, 0, 5], [20, 20, 5], [40, 0, 5]]  # a at [4, 6] and [34, 36] of 40 s


def document(points: Sequence[Sequence[float]], ltl: str, **extra: Any) -> dict[str, Any]:
    """A trace document over ``a`` and ``b`` in a 20 x 10 workspace."""
    base = {
        "format": "tlmpc.trace/1",
        "ltl": ltl,
        "regions": {"a": A, "b": B},
        "workspace": {"boundary": [[0, 0], [20, 0], [20, 10], [0, 10]], "holes": []},
        "boundary": "right",
        "max_speed": 1.5,
        "points": points,
        "loop_start": None,
        "end": "stay",
    }
    base.update(extra)
    return base


@pytest.mark.parametrize(
    ("ltl", "right", "closed"),
    [
        ("F[0,4] a", "satisfied", "satisfied"),  # entered exactly at the deadline
        ("F[0,3.99] a", "violated", "violated"),
        ("G[4,6] a", "violated", "satisfied"),  # left exactly at the window's end
        ("G[4.01,5.99] a", "satisfied", "satisfied"),
        ("F G[0,2] a", "violated", "satisfied"),  # a stay of exactly 2 s
        ("F G[0,1.99] a", "satisfied", "satisfied"),
        ("F G[0,2.01] a", "violated", "violated"),
        ("G(a -> F[0,2] !a)", "satisfied", "violated"),  # at most 2 s in a
        ("G(a -> F[0,2.01] !a)", "satisfied", "satisfied"),
        ("G(a -> F[0,1.99] !a)", "violated", "violated"),
        ("F[0,10] b", "satisfied", "satisfied"),
        ("F[0,9.99] b", "violated", "violated"),
        ("F[0,5] (a & F[0,6] b)", "satisfied", "satisfied"),  # from 4 s, b after 6 s
        ("F[0,4.5] (a & F[0,5.4] b)", "violated", "violated"),  # needs t >= 4.6 in a
        ("F[0,4.6] (a & F[0,5.4] b)", "satisfied", "satisfied"),  # t = 4.6 exactly
        ("!b U[0,10] b", "satisfied", "satisfied"),
        ("!a U[4,4] a", "satisfied", "satisfied"),
        ("!a U[0,3.9] a", "violated", "violated"),
        ("a U[0,inf] b", "violated", "violated"),
        ("G[0,inf] !(a & b)", "satisfied", "satisfied"),
    ],
)
def test_deadlines_on_a_run(ltl: str, right: str, closed: str) -> None:
    doc = document(RUN, ltl)
    assert verify_document(doc).outcome == right, ltl
    assert verify_document(doc, boundary="closed").outcome == closed, ltl


@pytest.mark.parametrize(
    ("ltl", "expected"),
    [
        ("F[0,10] b", "inconclusive"),  # the log ends at 8 s: the deadline is ahead
        ("F[0,7] b", "violated"),  # the deadline passed at 7 s
        ("F[0,5] a", "satisfied"),
        ("G[0,20] !b", "inconclusive"),
        ("G[0,7] !b", "satisfied"),
        ("G(a -> F[0,2.5] !a)", "inconclusive"),
        ("G(a -> F[0,1.5] !a)", "violated"),  # in a from 4 s to 6 s, within the log
    ],
)
def test_deadlines_on_an_open_log(ltl: str, expected: str) -> None:
    doc = document([[0, 0, 5], [8, 8, 5]], ltl, end="open")
    for convention in ("right", "closed"):
        assert verify_document(doc, boundary=convention).outcome == expected, ltl


def test_a_stay_decides_what_an_open_log_leaves_open() -> None:
    doc = document([[0, 0, 5], [5, 5, 5]], "F G[0,100] a", end="open")
    assert verify_document(doc).outcome == "inconclusive"
    assert verify_document(doc, assume_stay=True).outcome == "satisfied"
    assert verify_document(document(RUN, "F G[0,100] a")).outcome == "violated"


@pytest.mark.parametrize(
    ("ltl", "right", "closed", "slack"),
    [
        # a at [4, 6] and [34, 36] of a 40-s loop: gaps of 28 s and 8 s
        ("G F[0,28] a", "satisfied", "satisfied", 0.0),
        ("G F[0,27.9] a", "violated", "violated", -0.1),
        ("G F[0,30] a", "satisfied", "satisfied", 2.0),
        ("G(a -> F[0,2] !a)", "satisfied", "violated", 0.0),
        ("F[30,35] a", "satisfied", "satisfied", 1.0),
        ("G F[0,1] (a | b)", "violated", "violated", None),
    ],
)
def test_revisit_periods_on_a_loop(ltl: str, right: str, closed: str, slack: float | None) -> None:
    doc = document(BACK_AND_FORTH, ltl, loop_start=0, end="loop")
    verdict = verify_document(doc)
    assert verdict.outcome == right, ltl
    assert verify_document(doc, boundary="closed").outcome == closed, ltl
    if slack is not None:
        assert verdict.time_robustness is not None
        assert math.isclose(verdict.time_robustness, slack, abs_tol=1e-9), ltl


@pytest.mark.parametrize(
    ("ltl", "slack", "progress"),
    [
        ("F[0,5] a", 1.0, "done at t=4 s, 1 s before the deadline t=5 s"),
        ("F[0,3.5] a", -0.5, "deadline t=3.5 s missed by 0.5 s"),
        ("F G[0,1.5] a", 0.5, "longest stay in `a` 2 s (at least 1.5 s)"),
        ("G(a -> F[0,1.2] !a)", -0.8, "longest stay in `a` 2 s (at most 1.2 s)"),
        ("G(a -> F[0,7] b)", 1.0, "longest wait for `b` after `a` 6 s (within 7 s)"),
        ("G(a -> F[0,5] b)", -1.0, "deadline missed by 1 s at t=4 s"),
    ],
)
def test_time_robustness_and_progress(ltl: str, slack: float, progress: str) -> None:
    verdict = verify_document(document(RUN, ltl))
    assert verdict.time_robustness is not None
    assert math.isclose(verdict.time_robustness, slack, abs_tol=1e-9), ltl
    (report,) = verdict.conjuncts
    assert report.progress == progress
    assert report.time_robustness == verdict.time_robustness
    assert validation_errors(verdict_to_json(verdict), "verdict") == []


def test_untimed_tasks_have_no_time_robustness() -> None:
    verdict = verify_document(document(RUN, "F a & F b"))
    assert verdict.time_robustness is None
    assert verdict_to_json(verdict)["time_robustness"] is None


def test_space_robustness_agrees_in_sign() -> None:
    for ltl in ("F[0,5] a", "F[0,3.5] a", "G F[0,28] a", "F G[0,1.5] a"):
        verdict = verify_document(document(BACK_AND_FORTH, ltl, loop_start=0, end="loop"))
        if verdict.outcome == "satisfied":
            assert verdict.robustness >= 0
        else:
            assert verdict.robustness <= 0


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def test_cli_shows_progress_and_time_robustness(tmp_path: Path) -> None:
    path = tmp_path / "trace.json"
    path.write_text(json.dumps(document(RUN, "F[0,3.5] a & G !(a & b)")))
    code, out, _ = run("verify", str(path))
    assert code == 1
    assert "F[0,3.5] a: violated: deadline t=3.5 s missed by 0.5 s" in out
    assert "time robustness: -0.5 s" in out
    code, out, _ = run("verify", str(path), "--json")
    result = json.loads(out)["result"]
    assert result["time_robustness"] == -0.5
    assert result["conjuncts"][0]["time_robustness"] == -0.5


def test_compile_plans_time_bounds_and_automaton_refuses_them(tmp_path: Path) -> None:
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "version: 1\nname: timed\nworkspace:\n  boundary: {rect: [0, 0, 20, 10]}\n"
        "regions:\n  a: {rect: [4, 0, 6, 10]}\nrobot: {start: [1, 5], max_speed: 1.0}\n"
        'ltl: "F a & F[0,2] a"\n'
    )
    # a is 3 m away at 1 m/s: the deadline of 2 s is proven impossible, at the operator
    code, out, err = run("compile", str(mission), "-o", str(tmp_path / "out"), "-q")
    assert code == 1
    assert f"{mission}:8:13: error[P050]" in out + err
    assert "at least 3 s > 2 s" in out + err
    code, out, err = run("check", str(mission), "--explain")
    assert code == 0
    assert "F a & F[0,2] a" in out
    code, out, err = run("automaton", "G F[0,5] a")
    assert code == 1
    assert "<formula>:1:3: error[L045]" in out + err


@st.composite
def sparse_runs(draw: st.DrawFn) -> tuple[list[list[float]], list[list[float]]]:
    """Samples of a run along y = 5 at speed <= 1, and a motion through them that detours."""
    x = draw(st.floats(0.5, 3))
    samples = [[0.0, x, 5.0]]
    for step in range(1, draw(st.integers(3, 12))):
        x = min(19.5, max(0.5, x + draw(st.sampled_from([-0.75, 0.0, 0.5, 1.0]))))
        samples.append([float(step), x, 5.0])
    motion = [samples[0]]
    for before, after in itertools.pairwise(samples):
        budget = after[0] - before[0]  # at speed 1
        room = (budget - abs(after[1] - before[1])) / 2
        detour = draw(st.floats(-1, 1)) * room
        turn = (before[1] + after[1]) / 2 + detour
        first = abs(turn - before[1])
        total = first + abs(after[1] - turn)
        share = 0.5 if total == 0 else first / total
        when = before[0] + share * budget
        if before[0] < when < after[0]:  # a turn on a sample is no detour (and no new time)
            motion.append([when, turn, 5.0])
        motion.append(after)
    return samples, motion


@settings(deadline=None, max_examples=60)
@given(sparse_runs(), st.sampled_from(["F[0,4] a", "G[0,3] !a", "G F[0,4] (a | b)", "F G[0,1] a"]))
def test_certified_verdicts_hold_for_every_motion(
    runs: tuple[list[list[float]], list[list[float]]], ltl: str
) -> None:
    samples, motion = runs
    verdict = verify_document(document(samples, ltl, max_speed=1.0))
    if not verdict.certified:
        return
    for convention in ("right", "closed"):
        other = verify_document(document(motion, ltl, max_speed=1.0), boundary=convention)
        assert other.outcome == verdict.outcome, (ltl, samples, motion)


def test_dense_samples_certify_a_deadline() -> None:
    samples = [[t / 2, t / 2, 5.0] for t in range(41)]
    verdict = verify_document(document(samples, "F[0,5] a", max_speed=1.0))
    assert verdict.outcome == "satisfied"
    assert verdict.certified
    assert verdict.certificate.margin is not None
    assert math.isclose(verdict.certificate.margin, 0.75, abs_tol=1e-9)


def test_a_sample_on_the_boundary_is_not_certified() -> None:
    # the straight line touches a at t = 2 only; a motion at speed 1 through the same samples
    # runs on to x = 4.2 and back, inside a for 0.4 s
    samples = [[0.0, 3.0, 5.0], [1.0, 3.0, 5.0], [2.0, 4.0, 5.0], [3.0, 3.4, 5.0]]
    verdict = verify_document(document(samples, "G[0,3] !a", max_speed=1.0))
    assert verdict.outcome == "satisfied"
    assert not verdict.certified
    motion = [*samples[:3], [2.2, 4.2, 5.0], samples[3]]
    assert verify_document(document(motion, "G[0,3] !a", max_speed=1.0)).outcome == "violated"


def test_the_time_robustness_search_keeps_no_variant_in_the_memo(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # each step of the search tightens the bounds, a new formula for the memo: kept, a long
    # log's variants took gigabytes; what the verdict needs stays memoised
    import tlmpc.verify.verdict as verdict_module
    from tlmpc.ltl.ast import Formula
    from tlmpc.verify import from_document

    found: list[Any] = []
    original = verdict_module._truth_of

    def recorded(trace: Any) -> Any:
        found.append(original(trace))
        return found[-1]

    monkeypatch.setattr(verdict_module, "_truth_of", recorded)
    points = [[float(t), 1.0 + (t % 7), 1.0] for t in range(60)]
    document = {
        "format": "tlmpc.trace/1",
        "ltl": "G F[0,9] a & G(b -> F[0,1.5] !b)",
        "regions": {"a": [[0, 0], [2, 0], [2, 2], [0, 2]], "b": [[6, 0], [8, 0], [8, 2], [6, 2]]},
        "workspace": {"boundary": [[-1, -1], [10, -1], [10, 10], [-1, 10]]},
        "boundary": "right",
        "max_speed": 10.0,
        "points": points,
        "loop_start": None,
    }
    verdict = verify_document(document, assume_stay=True)
    assert any(c.time_robustness is not None for c in verdict.conjuncts)  # a search ran
    truth = found[-1].truth

    def subformulas(formula: Formula) -> set[Formula]:
        return {formula}.union(*(subformulas(c) for c in formula.children()))

    asked = subformulas(from_document(document).formula)
    assert set(truth.cache) <= asked
    assert set(truth.dense().cache) <= asked
