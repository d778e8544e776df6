"""Reactive runs: signals cut the run, assumptions and guarantees judged with blame, against
the independent oracle of ``tests/oracles/reactive_run.py`` (exact rationals, rectangles,
brute-force LTL3) and on hand-made cases whose answers follow from the definitions."""

from __future__ import annotations

import io
import json
import re
from collections.abc import Sequence
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest
from continuous_ltl import closed_holds
from hypothesis import event, given, settings
from hypothesis import strategies as st
from reactive_run import Run, closed_pieces, instants, judge
from strategies import formulas

from tlmpc.cli import main
from tlmpc.ltl.ast import (
    And,
    Const,
    Equiv,
    Eventually,
    Formula,
    Globally,
    Implies,
    Not,
    Or,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
)
from tlmpc.ltl.parser import parse_ltl
from tlmpc.ltl.printer import to_text
from tlmpc.verify import verdict_to_json, verify_document
from tlmpc.verify.model import Verdict

ROOT = Path(__file__).resolve().parents[2]
REGIONS = ("a", "b")
SENSORS = ("s",)
PROPS = (*REGIONS, *SENSORS)
WORKSPACE = {"boundary": [[-2, -2], [9, -2], [9, 9], [-2, 9]]}


def _polygon(rect: tuple[Fraction, Fraction, Fraction, Fraction]) -> list[list[float]]:
    x0, y0, x1, y1 = (float(v) for v in rect)
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


def document(
    run: Run,
    guarantee: str,
    assumptions: Sequence[str],
    *,
    end: str = "open",
    sensors: Sequence[str] = SENSORS,
) -> dict[str, Any]:
    """The trace.json of ``run``."""
    return {
        "format": "tlmpc.trace/1",
        "ltl": guarantee,
        "regions": {name: _polygon(rect) for name, rect in run.rects.items()},
        "workspace": WORKSPACE,
        "boundary": "right",
        "points": [[float(t), float(x), float(y)] for t, x, y in run.samples],
        "loop_start": None,
        "end": end,
        "sensors": list(sensors),
        "assumptions": list(assumptions),
        "signals": {
            name: [[float(t), bit] for t, bit in points] for name, points in run.signals.items()
        },
    }


def _once(formula: Formula) -> bool:
    leaves = [n.name for n in formula.walk() if isinstance(n, Prop)]
    plain = not any(isinstance(n, Const | Equiv) for n in formula.walk())
    return len(leaves) == len(set(leaves)) and plain


def _parts(formula: Formula) -> list[Formula]:
    return list(formula.args) if isinstance(formula, And) else [formula]


coordinate = st.integers(-1, 7).map(Fraction)


@st.composite
def rects(draw: st.DrawFn) -> tuple[Fraction, Fraction, Fraction, Fraction]:
    x0, y0 = draw(st.integers(0, 4)), draw(st.integers(0, 4))
    return (
        Fraction(x0),
        Fraction(y0),
        Fraction(x0 + draw(st.integers(1, 3))),
        Fraction(y0 + draw(st.integers(1, 3))),
    )


@st.composite
def runs(draw: st.DrawFn) -> Run:
    """Random piecewise-linear motion among two rectangles and a sensor whose changes fall on
    samples, on exact crossing instants and in between."""
    count = draw(st.integers(2, 4))
    steps = draw(st.lists(st.integers(1, 3), min_size=count - 1, max_size=count - 1))
    times = [Fraction(0)]
    for step in steps:
        times.append(times[-1] + step)
    samples = [(t, draw(coordinate), draw(coordinate)) for t in times]
    base = Run(samples=samples, rects={"a": draw(rects()), "b": draw(rects())}, signals={})
    moments = instants(base)  # samples and crossings, exactly
    start, end = times[0], times[-1]
    between = st.integers(1, 4 * int(end - start) - 1).map(lambda k: start + Fraction(k, 4))
    chosen = draw(st.lists(st.one_of(st.sampled_from(moments), between), max_size=3, unique=True))
    changes = sorted({t for t in chosen if t > start})
    points = [(start, draw(st.booleans()))] + [(t, draw(st.booleans())) for t in changes]
    return Run(samples=samples, rects=base.rects, signals={"s": points})


UNARY = st.sampled_from(["", "!", "F", "G", "GF", "FG", "!F"])
BINARY = st.sampled_from(["U", "R", "W", "M", "->", "&", "|"])


def _wrap(formula: Formula, ops: str) -> Formula:
    for op in reversed(ops):
        if op == "!":
            formula = Not(formula)
        elif op == "F":
            formula = Eventually(formula)
        else:
            formula = Globally(formula)
    return formula


def _join(op: str, left: Formula, right: Formula) -> Formula:
    if op in ("&", "|"):
        return And((left, right)) if op == "&" else Or((left, right))
    if op == "->":
        return Implies(left, right)
    if op == "U":
        return Until(left, right)
    if op == "R":
        return Release(left, right)
    if op == "W":
        return WeakUntil(left, right)
    return StrongRelease(left, right)


@st.composite
def once(draw: st.DrawFn) -> Formula:
    """A random formula using each of some propositions exactly once (where the three-valued
    verdict is exact, so the oracle's answers must be matched, not only bounded)."""
    names = draw(st.permutations(PROPS))[: draw(st.integers(1, len(PROPS)))]

    def build(leaves: Sequence[str]) -> Formula:
        if len(leaves) == 1:
            return _wrap(Prop(leaves[0]), draw(UNARY))
        split = draw(st.integers(1, len(leaves) - 1))
        left, right = build(leaves[:split]), build(leaves[split:])
        return _wrap(_join(draw(BINARY), left, right), draw(UNARY))

    formula = build(names)
    assert _once(formula)
    return formula


def _ours(run: Run, guarantee: Formula, assumptions: list[Formula], end: str) -> Verdict:
    doc = document(run, to_text(guarantee), [to_text(a) for a in assumptions], end=end)
    return verify_document(doc)


def _close(ours: float | None, exact: Fraction | None) -> bool:
    if ours is None or exact is None:
        return ours is None and exact is None
    return abs(ours - float(exact)) < 1e-9


@settings(max_examples=settings().max_examples * 2)
@given(runs(), once(), st.lists(once(), max_size=2), st.sampled_from(["open", "stay"]))
def test_blame_and_verdict_agree_with_the_oracle(
    run: Run, guarantee: Formula, assumptions: list[Formula], end: str
) -> None:
    verdict = _ours(run, guarantee, assumptions, end)
    judged = verdict.reactive
    assert judged is not None
    expected = judge(run, assumptions, _parts(guarantee), PROPS, open_end=end == "open")
    ours = (
        judged.outcome,
        judged.blame,
        judged.environment.broken if judged.environment else None,
        judged.robot.broken if judged.robot else None,
    )

    def agrees(oracle: Any) -> bool:
        return (
            ours[:2] == (oracle.outcome, oracle.blame)
            and _close(ours[2], oracle.environment)
            and _close(ours[3], oracle.robot)
        )

    if not agrees(expected):
        # continuations of two letters may be too short to show a prefix is not bad yet
        expected = judge(
            run, assumptions, _parts(guarantee), PROPS, open_end=end == "open", longest=3
        )
    assert agrees(expected), (ours, expected, to_text(guarantee), [to_text(a) for a in assumptions])
    assert verdict.outcome == judged.outcome
    event(f"{end}: {judged.outcome}, blame {judged.blame}, timed {ours[2:] != (None, None)}")


# -- hand-made runs: answers from the definitions -------------------------------------------

LAB = (Fraction(4), Fraction(0), Fraction(6), Fraction(2))
GOAL = (Fraction(8), Fraction(0), Fraction(9), Fraction(2))


def corridor(alarm: list[tuple[float, bool]]) -> Run:
    """The robot crosses the lab (x in [4, 6]) at 1 m/s from x=0 to x=9, y=1, t=0..9."""
    return Run(
        samples=[(Fraction(0), Fraction(0), Fraction(1)), (Fraction(9), Fraction(9), Fraction(1))],
        rects={"lab": LAB, "goal": GOAL},
        signals={"alarm": [(Fraction(t), bit) for t, bit in alarm]},
    )


def _verify(run: Run, ltl: str, assumptions: list[str], end: str = "open") -> Verdict:
    return verify_document(document(run, ltl, assumptions, end=end, sensors=["alarm"]))


def test_robot_breaks_first() -> None:
    # the alarm sounds at 3 while the robot is before the lab; it enters at 4
    verdict = _verify(corridor([(0, False), (3, True)]), "G(alarm -> !lab) & F goal", [])
    assert verdict.outcome == "violated"
    assert verdict.reactive is not None
    assert verdict.reactive.robot is not None
    assert verdict.reactive.blame == "robot"
    assert verdict.reactive.robot.broken == pytest.approx(4.0)
    assert verdict.reactive.robot.part == "G(alarm -> !lab)"


def test_environment_breaks_first_and_the_guarantee_is_vacuous() -> None:
    # the environment promised never to sound the alarm, and sounds it at 3 (before 4)
    verdict = _verify(corridor([(0, False), (3, True)]), "G(alarm -> !lab)", ["G !alarm"])
    judged = verdict.reactive
    assert judged is not None
    assert judged.environment is not None
    assert (verdict.outcome, judged.blame) == ("satisfied", "environment")
    assert judged.environment.broken == pytest.approx(3.0)
    # the guarantee itself still fails at 4, and says so
    assert [g.broken for g in judged.guarantees] == [pytest.approx(4.0)]
    data = verdict_to_json(verdict)["reactive"]
    assert data["vacuous"] is True
    assert data["environment"]["elapsed"] == pytest.approx(3.0)
    assert data["guarantees"][0]["broken_at"] == pytest.approx(4.0)
    # both times: the robot broke its guarantee too, after the environment
    assert data["robot"]["elapsed"] == pytest.approx(4.0)
    assert data["blame"] == "environment"


def test_a_tie_goes_to_the_environment() -> None:
    # the alarm sounds at the very instant the robot enters the lab (a crossing instant)
    verdict = _verify(corridor([(0, False), (4, True)]), "G(alarm -> !lab)", ["G !alarm"])
    assert verdict.reactive is not None
    assert (verdict.outcome, verdict.reactive.blame) == ("satisfied", "environment")
    assert verdict.reactive.environment is not None
    assert verdict.reactive.environment.broken == pytest.approx(4.0)


def test_the_robot_is_blamed_before_a_later_assumption_failure() -> None:
    verdict = _verify(corridor([(0, True), (7, False)]), "G(alarm -> !lab)", ["alarm W lab"])
    # alarm W lab: the alarm stays on until the robot is in the lab — kept; the robot broke
    # its guarantee at 4
    assert verdict.reactive is not None
    assert verdict.reactive.robot is not None
    assert verdict.outcome == "violated"
    assert verdict.reactive.robot.broken == pytest.approx(4.0)


def test_a_change_inside_a_region_splits_the_piece() -> None:
    # alarm on at 5, inside the lab (4..6): entering was fine, staying is not
    verdict = _verify(corridor([(0, False), (5, True), (5.5, False)]), "G(lab -> !alarm)", [])
    assert verdict.reactive is not None
    assert verdict.reactive.robot is not None
    assert verdict.reactive.robot.broken == pytest.approx(5.0)
    # a change at a sample instant, and one after the run, are harmless
    fine = _verify(corridor([(0, False), (9, True), (20, False)]), "G(lab -> !alarm)", [])
    assert fine.outcome == "inconclusive"


def test_liveness_on_a_stay() -> None:
    # staying at x=9 with the alarm on forever: `G F !alarm` fails in the limit
    run = corridor([(0, False), (8, True)])
    verdict = _verify(run, "F goal & G F !alarm", [], end="stay")
    assert verdict.reactive is not None
    assert verdict.reactive.robot is not None
    assert (verdict.outcome, verdict.reactive.blame) == ("violated", "robot")
    assert verdict.reactive.robot.broken is None  # no instant: it fails in the limit
    vacuous = _verify(run, "G F !alarm", ["G F !alarm"], end="stay")
    assert vacuous.reactive is not None
    assert (vacuous.outcome, vacuous.reactive.blame) == ("satisfied", "environment")


def test_a_signal_is_unknown_before_its_first_sample() -> None:
    # the alarm's first sample comes at 5: while in the lab before that it may have been on
    late = corridor([(5, False)])
    assert _verify(late, "G(alarm -> !lab)", []).outcome == "inconclusive"
    assert _verify(late, "F(alarm | goal)", []).outcome == "satisfied"
    assert _verify(late, "G !alarm", [], end="stay").outcome == "inconclusive"


def test_loop_from_repeats_the_signals(tmp_path: Path) -> None:
    # a lap of a square around the lab, twice; the alarm sounds only on the first lap
    points = [[float(t), x, y] for t, (x, y) in enumerate([(3, -1), (7, -1), (7, 3), (3, 3)] * 2)]
    points.append([8.0, 3.0, -1.0])
    doc = {
        **document(corridor([(0, False)]), "G F alarm", [], sensors=["alarm"]),
        "points": points,
        "signals": {"alarm": [[0.0, True], [4.0, False]]},
    }
    path = tmp_path / "t.json"
    path.write_text(json.dumps(doc))
    # open: inconclusive; looping from the second lap (t=4): the alarm never sounds again
    assert run_cli(str(path))[0] == 4
    assert run_cli(str(path), "--loop-from", "4")[0] == 1
    assert run_cli(str(path), "--loop-from", "0")[0] == 0


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(["verify", *argv], out=out, err=err), out.getvalue(), err.getvalue()


def test_json_output_validates_and_exit_codes(tmp_path: Path) -> None:
    import jsonschema

    schema = json.loads((ROOT / "schemas" / "verdict.schema.json").read_text())
    trace_schema = json.loads((ROOT / "schemas" / "trace.schema.json").read_text())
    cases = [
        (corridor([(0, False), (3, True)]), "G(alarm -> !lab)", ["G !alarm"], 0),
        (corridor([(0, False), (3, True)]), "G(alarm -> !lab)", [], 1),
        (corridor([(0, False)]), "G(alarm -> !lab)", [], 4),
    ]
    for index, (run, ltl, assumed, code) in enumerate(cases):
        doc = document(run, ltl, assumed, sensors=["alarm"])
        jsonschema.validate(doc, trace_schema)
        path = tmp_path / f"t{index}.json"
        path.write_text(json.dumps(doc))
        status, out, _ = run_cli(str(path), "--json")
        assert status == code
        result = json.loads(out)["result"]
        jsonschema.validate(result, schema)
        assert result["reactive"]["verdict"] == result["verdict"]


# -- hostile trace documents -----------------------------------------------------------------


@pytest.mark.parametrize(
    ("change", "code", "where"),
    [
        ({"signals": {"alarm": [[0, "maybe"]]}}, "V030", "$.signals.alarm[0][1]"),
        ({"signals": {"alarm": [[0, 2]]}}, "V030", "$.signals.alarm[0][1]"),
        ({"signals": {"alarm": [[1, True], [0, False]]}}, "V031", "$.signals.alarm[1][0]"),
        ({"signals": {"alarm": [[0, True], [0, False]]}}, "V031", "$.signals.alarm[1][0]"),
        ({"signals": {"alarm": [[float("nan"), True]]}}, "V031", "$.signals.alarm[0][0]"),
        ({"signals": {"alarm": [["0", True]]}}, "V031", "$.signals.alarm[0][0]"),
        ({"signals": {"siren": [[0, True]]}}, "V033", "$.signals.siren"),
        ({"signals": {"alarm": []}}, "V033", "$.signals.alarm"),
        ({"signals": {"alarm": [[0]]}}, "V033", "$.signals.alarm"),
        ({"signals": [1, 2]}, "V033", "$.signals"),
        ({"sensors": ["lab"]}, "V033", "$.sensors[0]"),
        ({"sensors": "alarm"}, "V033", "$.sensors"),
        ({"assumptions": ["G !siren"]}, "V034", "$.assumptions[0]"),
        ({"assumptions": [3]}, "V034", "$.assumptions[0]"),
        ({"assumptions": "G !alarm"}, "V034", "$.assumptions"),
    ],
)
def test_hostile_signals_are_located(
    tmp_path: Path, change: dict[str, Any], code: str, where: str
) -> None:
    doc = {**document(corridor([(0, False)]), "G(alarm -> !lab)", [], sensors=["alarm"]), **change}
    path = tmp_path / "t.json"
    path.write_text(json.dumps(doc, allow_nan=True))
    status, out, err = run_cli(str(path), "--json")
    assert status == 2
    assert "Traceback" not in err
    found = json.loads(out)["diagnostics"][0]
    assert found["code"] == code
    assert found.get("path") == where
    assert found["file"] == str(path)
    # placed in the file: at the value the path names (json's own reading of the text there)
    text = path.read_text()
    offset = sum(len(line) + 1 for line in text.split("\n")[: found["line"] - 1])
    offset += found["col"] - 1
    named: Any = json.loads(text)
    for key in re.findall(r"\.(\w+)|\[(\d+)\]", where[1:]):
        named = named[key[0] or int(key[1])]
    if named == "G !siren":
        assert text[offset:].startswith("siren")  # the unknown name inside the formula
    else:
        value, _ = json.JSONDecoder().raw_decode(text, offset)
        assert json.dumps(value) == json.dumps(named)


def test_assumption_parse_errors_are_diagnostics(tmp_path: Path) -> None:
    doc = document(corridor([(0, False)]), "G(alarm -> !lab)", ["G (!alarm"], sensors=["alarm"])
    path = tmp_path / "t.json"
    path.write_text(json.dumps(doc))
    status, _, err = run_cli(str(path))
    assert status == 2
    assert "error[L" in err
    assert "Traceback" not in err


def test_parse_round_trip_of_assumptions() -> None:
    verdict = _verify(corridor([(0, False)]), "G(alarm -> !lab)", ["G F !alarm", "G !alarm"])
    assert verdict.reactive is not None
    assert [a.part for a in verdict.reactive.assumptions] == [
        to_text(parse_ltl("G F !alarm")),
        to_text(parse_ltl("G !alarm")),
    ]


def test_violations_name_a_sensor_as_a_sensor() -> None:
    verdict = _verify(corridor([(0, False), (3, True)]), "G !alarm", [])
    assert verdict.violations[0].message.startswith("`alarm` is true at t=3 s")
    verdict = _verify(corridor([(0, True)]), "G(alarm -> !lab)", [])
    assert verdict.violations[0].message.startswith("entered lab at t=4 s")


@given(runs(), formulas(PROPS, max_leaves=5), formulas(PROPS, max_leaves=3))
def test_closed_convention_stay_verdicts_agree_with_the_definition(
    run: Run, guarantee: Formula, assumption: Formula
) -> None:
    # every operator, any formula: on a stay the verdicts are two-valued and exact
    doc = document(run, to_text(guarantee), [to_text(assumption)], end="stay")
    doc["boundary"] = "closed"
    judged = verify_document(doc).reactive
    assert judged is not None
    word, is_point = closed_pieces(run)
    last = len(word) - 1
    for part, formula in zip(
        (*judged.assumptions, *judged.guarantees), [assumption, *_parts(guarantee)], strict=True
    ):
        expected = closed_holds(formula, word, is_point, last, 0)
        assert part.outcome == ("satisfied" if expected else "violated"), to_text(formula)


TIMED = [
    "G(s -> F[0,{k}] a)",
    "F[0,{k}] (a & s)",
    "G[0,{k}] !b",
    "a U[0,{k}] s",
    "G(a -> G[0,{k}] !s)",
    "G(s -> (a U[0,{k}] b))",
    "!s U[1,{k}] a",
]


@given(runs(), st.sampled_from(TIMED), st.integers(1, 4), st.sampled_from(["open", "stay"]))
def test_bisection_finds_the_first_bad_cut_with_time_bounds(
    run: Run, template: str, bound: int, end: str
) -> None:
    """Bad prefixes stay bad (also in dense time), so the bisection's answer is the first bad
    cut a linear scan finds."""
    from tlmpc.verify import blame

    checked: list[tuple[float | None, float | None]] = []
    bisect = blame.breaking_time

    def scanning(formula: Formula, full: Any, prefixes: Any, ending: Any) -> float | None:
        found = bisect(formula, full, prefixes, ending)
        first = None
        if full == "violated":
            size = len(prefixes.starts)
            for cut in range(1, size + 1, 2):
                last = ending == "open" and cut == size
                if last or prefixes.outcome(formula, cut, keep=False) == "violated":
                    first = float(prefixes.starts[cut - 1])
                    break
        checked.append((found, first))
        return found

    ltl = template.format(k=bound)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(blame, "breaking_time", scanning)
        verify_document(document(run, ltl, [ltl.replace("a", "b")], end=end))
    assert checked
    for found, first in checked:
        assert found == first
