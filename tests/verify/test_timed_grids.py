"""The dense-time signals stay as small as their values are varied, and loops unroll only as
far as a window reaches.

Each bounded operator evaluates its result at ``T_j - a`` and ``T_j - b`` for every instant of
its operand; kept, those instants multiplied with each level of nesting (191,421 instants at 15
levels on a 5-sample trace, 40 s for its time robustness).  The oracle here is interval
arithmetic in exact rationals, from the definitions: ``F[a,b] X`` holds at t iff the window
``[t + a, t + b]`` meets X, that is on every stretch of X moved back by the window;
``G[a,b] X`` is the complement of ``F[a,b]`` of the complement.
"""

from __future__ import annotations

import io
import itertools
import json
import re
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from tlmpc.cli import main
from tlmpc.ltl.ast import BoundedEventually, BoundedGlobally, Const, Formula, Prop
from tlmpc.ltl.parser import parse_ltl
from tlmpc.verify import from_document, verdict_to_json, verify_document
from tlmpc.verify.time_robustness import tighten
from tlmpc.verify.verdict import _truth_of

#: a stretch of time: (start, start included, end, end included); None: -inf / +inf
Stretch = tuple[Fraction | None, bool, Fraction | None, bool]

A = [[4.0, 0.0], [6.0, 0.0], [6.0, 2.0], [4.0, 2.0]]
#: t, x at y = 1: through a on [3.5, 4.5), back through it on [6 + 3/7, 6 + 5/7), into it for
#: good from 9 + 2/3 (the bug's trace)
RUN = [(0, 0), (3, 3), (6, 9), (7, 2), (11, 5)]


def _document(points: list[list[float]], ltl: str, **extra: Any) -> dict[str, Any]:
    return {
        "format": "tlmpc.trace/1",
        "ltl": ltl,
        "regions": {"a": A},
        "workspace": {"boundary": [[-1.0, -1.0], [20.0, -1.0], [20.0, 10.0], [-1.0, 10.0]]},
        "boundary": "right",
        "points": points,
        "loop_start": None,
        "end": "stay",
        **extra,
    }


def _merged(stretches: list[Stretch]) -> list[Stretch]:
    """Sorted, with overlapping or touching stretches joined."""

    def start_key(s: Stretch) -> tuple[float | Fraction, bool]:
        return (float("-inf") if s[0] is None else s[0], not s[1])

    out: list[Stretch] = []
    for start, closed_start, end, closed_end in sorted(stretches, key=start_key):
        empty = (
            start is not None
            and end is not None
            and (end < start or (end == start and not (closed_start and closed_end)))
        )
        if empty:
            continue
        if out:
            _, _, last_end, last_closed = out[-1]
            joins = (
                last_end is None
                or start is None
                or start < last_end
                or (start == last_end and (last_closed or closed_start))
            )
            if joins:
                head = out[-1]
                if last_end is None or (end is not None and end < last_end):
                    continue
                if end is not None and end == last_end:
                    out[-1] = (head[0], head[1], end, last_closed or closed_end)
                else:
                    out[-1] = (head[0], head[1], end, closed_end)
                continue
        out.append((start, closed_start, end, closed_end))
    return out


def _complement(stretches: list[Stretch]) -> list[Stretch]:
    out: list[Stretch] = []
    begin: Fraction | None = None  # from -inf
    begin_closed = False
    for start, closed_start, end, closed_end in _merged(stretches):
        if start is not None:
            out.append((begin, begin_closed, start, not closed_start))
        if end is None:
            return _merged(out)
        begin, begin_closed = end, not closed_end
    out.append((begin, begin_closed, None, False))
    return _merged(out)


def _moved_back(stretches: list[Stretch], low: Fraction, high: Fraction) -> list[Stretch]:
    """``F[low,high]``: the t whose window ``[t + low, t + high]`` meets a stretch."""
    if high < low:
        return []
    return _merged(
        [
            (None if s is None else s - high, cs, None if e is None else e - low, ce)
            for s, cs, e, ce in stretches
        ]
    )


def holds(formula: Formula, atom: list[Stretch]) -> list[Stretch]:
    """Where ``formula`` (nested F[a,b], G[a,b] over ``a``) holds."""
    match formula:
        case Prop():
            return atom
        case Const(value):  # a window tightened past its start
            return [(None, False, None, False)] if value else []
        case BoundedEventually(arg, interval):
            low, high = Fraction(interval.low), Fraction(interval.high)
            return _moved_back(holds(arg, atom), low, high)
        case BoundedGlobally(arg, interval):
            low, high = Fraction(interval.low), Fraction(interval.high)
            return _complement(_moved_back(_complement(holds(arg, atom)), low, high))
    raise AssertionError(formula)


def _at(stretches: list[Stretch], t: Fraction) -> bool:
    return any(
        (s is None or s < t or (s == t and cs)) and (e is None or t < e or (e == t and ce))
        for s, cs, e, ce in stretches
    )


def in_a(run: list[tuple[int, int]]) -> list[Stretch]:
    """Where the robot (moving along x at y = 1, staying at its last point) is in ``a``, the
    right convention: from the instant it enters to the instant it leaves."""
    breaks: list[tuple[Fraction, Fraction]] = []
    for (t0, x0), (t1, x1) in itertools.pairwise(run):
        breaks.append((Fraction(t0), Fraction(x0)))
        for edge in (Fraction(4), Fraction(6)):
            if x0 != x1 and 0 < (edge - x0) / (x1 - x0) < 1:
                breaks.append((t0 + (edge - x0) / (x1 - x0) * (t1 - t0), edge))
    breaks.sort()
    last_t, last_x = Fraction(run[-1][0]), Fraction(run[-1][1])
    inside: list[Stretch] = []
    for (begin, x_begin), (end, x_end) in zip(breaks, [*breaks[1:], (last_t, last_x)], strict=True):
        if 4 <= (x_begin + x_end) / 2 <= 6:
            inside.append((begin, True, end, False))
    if 4 <= last_x <= 6:
        inside.append((last_t, True, None, False))
    return _merged(inside)


def nested(depth: int) -> str:
    """The bug's formulas: F and G alternating, their bounds growing outwards."""
    text = "a"
    for level in range(1, depth + 1):
        operator = "F" if level % 2 else "G"
        text = f"{operator}[0.{level},{1 + 0.37 * (level - 1):.2f}] ({text})"
    return text


@pytest.mark.parametrize("depth", [5, 15, 30])
def test_nested_bounds_keep_small_grids_and_exact_answers(depth: int) -> None:
    ltl = nested(depth)
    points = [[float(t), float(x), 1.0] for t, x in RUN]
    verdict = verdict_to_json(verify_document(_document(points, ltl)))
    formula = parse_ltl(ltl)
    atom = in_a(RUN)
    expected = "satisfied" if _at(holds(formula, atom), Fraction(0)) else "violated"
    assert verdict["verdict"] == expected
    # the time robustness: the formula tightened a little less holds, a little more fails
    slack = verdict["time_robustness"]
    assert isinstance(slack, float)
    sign = 1 if expected == "satisfied" else -1
    for step, wanted in ((-1e-6, expected == "satisfied"), (1e-6, expected != "satisfied")):
        tightened = tighten(formula, sign * (abs(slack) + sign * step))
        assert _at(holds(tightened, atom), Fraction(0)) == wanted, (step, slack)
    # every signal has the trace's own instants and few more: a, moved back by windows, has
    # at most its three stretches' ends
    found = _truth_of(from_document(_document(points, ltl)))
    found.truth.at_start(formula)
    dense = found.truth.dense()
    base = len(dense.base_times)
    assert max(len(signal.times) for signal in dense.cache.values()) <= base + 6


def test_a_deadline_on_a_goal_with_bounds_is_done_where_the_goal_begins() -> None:
    # the goal begins to hold inside an open piece of the trace, at 0.16 s, and holds at 0.5:
    # done at the bound's low end, 1.98 s before the deadline
    ltl = nested(5)
    formula = parse_ltl(ltl)
    assert isinstance(formula, BoundedEventually)
    goal = holds(formula.arg, in_a(RUN))
    low = Fraction(formula.interval.low)
    first = min(max(s, low) for s, _, e, _ in goal if s is not None and (e is None or e > low))
    deadline = formula.interval.high
    verdict = verdict_to_json(
        verify_document(_document([[float(t), float(x), 1.0] for t, x in RUN], ltl))
    )
    assert verdict["conjuncts"][0]["progress"] == (
        f"done at t={float(first):.4g} s, {deadline - float(first):.4g} s before the deadline "
        f"t={deadline:.4g} s"
    )


def test_a_loops_last_stretch_is_reported_to_the_wrap() -> None:
    # 8-s loop: out of a (x in [4, 6]) at 2/3 s, back in at 22/3 s; `F[0,0.5] !a` fails while
    # the robot is in a for the next half second: [22/3, 8) and, wrapped, [0, 1/6)
    points = [[0.0, 5.0, 1.0], [4.0, 11.0, 1.0], [8.0, 5.0, 1.0]]
    ltl = "G F[0,0.5] !a"
    atom = _merged(
        [(Fraction(22, 3) + 8 * k - 8, True, Fraction(2, 3) + 8 * k, False) for k in range(4)]
    )
    # where `F[0,0.5] !a` fails: the complement of the stretches of !a moved back by the window
    failing = _complement(_moved_back(_complement(atom), Fraction(0), Fraction(1, 2)))
    expected = [
        (max(s, Fraction(0)), min(e, Fraction(8)))
        for s, _, e, _ in failing
        if s is not None and e is not None and e > 0 and s < 8
    ]
    verdict = verdict_to_json(verify_document(_document(points, ltl, loop_start=0, end="loop")))
    assert verdict["verdict"] == "violated"
    found = [
        float(end)
        for v in verdict["violations"]
        for end in re.findall(r"from t=([0-9.]+) s to t=([0-9.]+) s", v["message"])[0]
    ]
    assert found == pytest.approx([float(end) for stretch in expected for end in stretch], 1e-3)
    assert found[-1] == 8.0


def test_a_window_far_into_a_loop_unrolls_from_where_it_starts() -> None:
    # a 10-ms loop through a after 10 s: a window 1e5 s ahead meets 1e7 copies of the loop
    # counted from the start, two counted from where it begins
    points = [[0.0, 0.0, 1.0], [10.0, 3.0, 1.0], [10.005, 5.0, 1.0], [10.01, 3.0, 1.0]]
    verdict = verify_document(_document(points, "G F[100000,100001] a", loop_start=1, end="loop"))
    # every window, a second long, meets the loop's visits to a
    assert verdict.outcome == "satisfied"


def test_a_window_far_into_a_loop_reads_as_one_whole_periods_nearer() -> None:
    # on a loop from 0 with period 8, `F[100,100.5] x` at t is `F[4,4.5] x` (100 = 4 + 12 P):
    # the same stretches fail, though the first is evaluated on copies 11 to 13 of the loop
    points = [[0.0, 5.0, 1.0], [4.0, 11.0, 1.0], [8.0, 5.0, 1.0]]

    def stretches(ltl: str) -> list[str]:
        verdict = verdict_to_json(verify_document(_document(points, ltl, loop_start=0, end="loop")))
        return [v["message"].split(", while")[0].split(" fails ")[1] for v in verdict["violations"]]

    far, near = stretches("G F[100,100.5] !a"), stretches("G F[4,4.5] !a")
    assert far == near
    assert far  # (not vacuous: it fails while the robot is in a for half a second)


def test_a_window_far_past_its_instant_on_a_short_loop_is_refused(tmp_path: Path) -> None:
    # a 10-ms loop after 1e5 s: a window starting 1e4 s after its instant meets a million
    # copies of it
    points = [[0.0, 0.0, 1.0], [1e5, 3.0, 1.0], [1e5 + 0.005, 5.0, 1.0], [1e5 + 0.01, 3.0, 1.0]]
    trace = tmp_path / "trace.json"
    trace.write_text(json.dumps(_document(points, "G F[1e4,10001] a", loop_start=1, end="loop")))
    out, err = io.StringIO(), io.StringIO()
    assert main(["verify", str(trace)], out, err) == 2
    assert "error[V040]" in err.getvalue()
    assert f"{trace}:" in err.getvalue()
    # a window from its instant needs the loop laid out a period past the log, not a copy
    # for every period of the log before the loop: a is first entered at 1e5 + 0.0025 s (x =
    # 4 on the way out to 5), so `F[0,1] a` fails at 0 until loosened by that less 1 s
    verdict = verify_document(_document(points, "G F[0,1] a", loop_start=1, end="loop"))
    assert verdict.outcome == "violated"
    assert verdict.time_robustness == pytest.approx(-(1e5 + 0.0025 - 1.0), abs=1e-6)


def test_a_timed_stretch_starts_where_every_message_places_the_entry() -> None:
    # the stretch where `G[0,0] !hazard` fails begins at the crossing into hazard: at the
    # piece's own position, as the untimed `G !hazard` reports it, not one interpolated
    # between the samples at that instant (3.5, a rounding away)
    hazard = [[3.5, -1.0], [4.5, -1.0], [4.5, 3.0], [3.5, 3.0]]
    points = [
        [0.0, 0.19658657771943933, 1.67493816419292],
        [0.3, 5.0526719662194965, 0.5187080286560153],
    ]

    def first(ltl: str) -> Any:
        document = _document(points, ltl, regions={"hazard": hazard}, end="open")
        return verify_document(document).violations[0]

    untimed, timed = first("G !hazard"), first("G G[0,0] !hazard")
    assert (timed.time, timed.position) == (untimed.time, untimed.position)


def test_a_single_sample_is_certified_with_time_bounds() -> None:
    # one sample in a: the tube around it has radius 0 (no gap), its margin the robustness
    verdict = verify_document(_document([[5.0, 5.0, 1.0]], "F[0,1] a", max_speed=1.0))
    assert verdict.outcome == "satisfied"
    assert verdict.certificate.margin == verdict.robustness == 1.0
    assert verdict.certificate.certified
