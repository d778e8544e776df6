"""A definition-level oracle for reactive runs: regions, signals, three-valued verdicts, blame.

Independent of tlmpc's verifier: exact rational arithmetic, rectangles, brute force.

* The run: straight segments between samples ``(t, x, y)`` (Fractions) and signals given by
  change points ``(t, value)`` (right-continuous: a value holds from its t on).
* Its letters (right-continuous convention): every instant where something may change — a
  sample, a signal change, or a segment meeting one of the lines ``x = x0``, ``x = x1``,
  ``y = y0``, ``y = y1`` of a rectangle — starts a stretch; the stretch's letter is the
  rectangles that contain (closed) its middle point plus the signals true at its start.  The
  last sample's instant has the rectangles containing it; on an open log, a rectangle whose
  boundary it lies on is unknown there (the robot's next move decides).
* LTL3 by brute force: a finite word is *bad* for a formula when every continuation — every
  lasso of up to a few letters over all the propositions — falsifies it, *good* when every
  one satisfies it (the definition-level lasso evaluator of ``lasso_ltl``).
* A part's breaking time: the first instant whose prefix (the letters up to and including
  the one starting there) is bad.
* The strict GR(1) blame of docs/semantics.md: the robot when a guarantee part breaks strictly
  before every assumption; the environment when an assumption breaks no later; otherwise, on
  a stay, the lasso's own truth (assumptions first); on an open log, satisfied iff the
  guarantee's prefix is good, else inconclusive.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

from lasso_ltl import holds

from tlmpc.ltl.ast import Formula

Letter = frozenset[str]
Rect = tuple[Fraction, Fraction, Fraction, Fraction]


@dataclass(frozen=True)
class Run:
    """Samples, rectangles and signals (change points, the first at or before the start)."""

    samples: Sequence[tuple[Fraction, Fraction, Fraction]]
    rects: dict[str, Rect]
    signals: dict[str, Sequence[tuple[Fraction, bool]]]


def _position(run: Run, t: Fraction) -> tuple[Fraction, Fraction]:
    samples = run.samples
    for (t0, x0, y0), (t1, x1, y1) in itertools.pairwise(samples):
        if t0 <= t <= t1:
            s = (t - t0) / (t1 - t0)
            return x0 + s * (x1 - x0), y0 + s * (y1 - y0)
    return samples[-1][1], samples[-1][2]


def _inside(rect: Rect, x: Fraction, y: Fraction) -> bool:
    x0, y0, x1, y1 = rect
    return x0 <= x <= x1 and y0 <= y <= y1


def _on_boundary(rect: Rect, x: Fraction, y: Fraction) -> bool:
    x0, y0, x1, y1 = rect
    return _inside(rect, x, y) and not (x0 < x < x1 and y0 < y < y1)


def _signal(points: Sequence[tuple[Fraction, bool]], t: Fraction) -> bool:
    value = False
    for when, bit in points:
        if when <= t:
            value = bit
    return value


def instants(run: Run) -> list[Fraction]:
    """Every instant at which the letter may change, sorted."""
    found = {s[0] for s in run.samples}
    start, end = run.samples[0][0], run.samples[-1][0]
    for points in run.signals.values():
        found.update(t for t, _ in points if start < t < end)
    for (t0, x0, y0), (t1, x1, y1) in itertools.pairwise(run.samples):
        for x_a, y_a, x_b, y_b in run.rects.values():
            for line, p0, p1 in ((x_a, x0, x1), (x_b, x0, x1), (y_a, y0, y1), (y_b, y0, y1)):
                if p0 != p1:
                    s = (line - p0) / (p1 - p0)
                    if 0 < s < 1:
                        found.add(t0 + s * (t1 - t0))
    return sorted(found)


def letters(run: Run, *, open_end: bool) -> tuple[list[Letter], list[Fraction], set[str]]:
    """The letters of the run's stretches and of its last instant, their start times, and the
    rectangles unknown at the last instant (open log on a boundary)."""
    times = instants(run)
    word: list[Letter] = []
    for s, s_next in itertools.pairwise(times):
        x, y = _position(run, (s + s_next) / 2)
        regions = {name for name, rect in run.rects.items() if _inside(rect, x, y)}
        sensors = {name for name, pts in run.signals.items() if _signal(pts, s)}
        word.append(frozenset(regions | sensors))
    end = times[-1]
    x, y = _position(run, end)
    regions = {name for name, rect in run.rects.items() if _inside(rect, x, y)}
    sensors = {name for name, pts in run.signals.items() if _signal(pts, end)}
    unknown = (
        {name for name, rect in run.rects.items() if _on_boundary(rect, x, y)}
        if open_end
        else set()
    )
    word.append(frozenset(regions | sensors))
    return word, times, unknown


def _destutter(word: Sequence[Letter]) -> list[Letter]:
    return [letter for i, letter in enumerate(word) if i == 0 or word[i - 1] != letter]


def all_letters(props: Sequence[str]) -> list[Letter]:
    """Every letter over ``props``."""
    return [frozenset(c) for n in range(len(props) + 1) for c in itertools.combinations(props, n)]


def tails(props: Sequence[str], longest: int) -> list[tuple[list[Letter], int]]:
    """Every lasso continuation of 1..``longest`` letters (letters, loop start)."""
    alphabet = all_letters(props)
    return [
        (list(tail), loop)
        for n in range(1, longest + 1)
        for tail in itertools.product(alphabet, repeat=n)
        for loop in range(n)
    ]


def _choices(prefix: Sequence[Letter], unknown: set[str]) -> list[list[Letter]]:
    """The prefix with each unknown proposition of its last letter either way."""
    if not unknown:
        return [list(prefix)]
    last = prefix[-1] - unknown
    return [
        [*prefix[:-1], last | frozenset(c)]
        for n in range(len(unknown) + 1)
        for c in itertools.combinations(sorted(unknown), n)
    ]


def ltl3(
    formula: Formula,
    prefix: Sequence[Letter],
    props: Sequence[str],
    unknown: set[str] = frozenset(),  # type: ignore[assignment]
    longest: int = 2,
) -> int:
    """+1 every continuation satisfies, -1 none does, 0 otherwise (brute force)."""
    seen: set[bool] = set()
    for word in _choices(prefix, set(unknown)):
        base = _destutter(word)
        for tail, loop in tails(props, longest):
            seen.add(holds(formula, base + tail, len(base) + loop))
            if len(seen) == 2:
                return 0
    return 1 if seen == {True} else -1


def breaking_time(
    formula: Formula,
    word: Sequence[Letter],
    times: Sequence[Fraction],
    props: Sequence[str],
    unknown: set[str],
    longest: int = 2,
) -> Fraction | None:
    """The first instant whose prefix is bad for ``formula`` (None: none is)."""
    for j in range(1, len(word) + 1):
        last_unknown = unknown if j == len(word) else set()
        if ltl3(formula, word[:j], props, last_unknown, longest) == -1:
            return times[j - 1]
    return None


def stay_holds(formula: Formula, word: Sequence[Letter]) -> bool:
    """The run read as staying at its last point (and signal values) forever."""
    base = _destutter(word)
    return holds(formula, base, len(base) - 1)


@dataclass(frozen=True)
class Judgement:
    """The oracle's assume-guarantee verdict, with the earliest instants at which an
    assumption and a guarantee part broke (whoever is to blame)."""

    outcome: str
    blame: str | None
    environment: Fraction | None
    robot: Fraction | None


def judge(
    run: Run,
    assumptions: Sequence[Formula],
    guarantees: Sequence[Formula],
    props: Sequence[str],
    *,
    open_end: bool,
    longest: int = 2,
) -> Judgement:
    """The strict GR(1) verdict of ``run`` (``guarantees``: the guarantee's parts)."""
    word, times, unknown = letters(run, open_end=open_end)
    # a stay's last letter is known: it holds forever
    env_times = [breaking_time(a, word, times, props, unknown, longest) for a in assumptions]
    rob_times = [breaking_time(g, word, times, props, unknown, longest) for g in guarantees]
    env = min((t for t in env_times if t is not None), default=None)
    rob = min((t for t in rob_times if t is not None), default=None)
    if rob is not None and (env is None or rob < env):
        return Judgement("violated", "robot", env, rob)
    if env is not None:
        return Judgement("satisfied", "environment", env, rob)
    if not open_end:
        if not all(stay_holds(a, word) for a in assumptions):
            return Judgement("satisfied", "environment", None, rob)
        if not all(stay_holds(g, word) for g in guarantees):
            return Judgement("violated", "robot", None, None)
        return Judgement("satisfied", None, None, None)
    good = all(ltl3(g, word, props, unknown, longest) == 1 for g in guarantees)
    return Judgement("satisfied" if good else "inconclusive", None, None, None)


def closed_pieces(run: Run) -> tuple[list[Letter], list[bool]]:
    """The run as point and open pieces under the closed convention: an instant's letter has
    the rectangles whose closure contains its point, a stretch's those containing its middle;
    both with the signals' values at their (first) instant."""
    times = instants(run)
    word: list[Letter] = []
    is_point: list[bool] = []
    for index, s in enumerate(times):
        sensors = {name for name, pts in run.signals.items() if _signal(pts, s)}
        x, y = _position(run, s)
        regions = {name for name, rect in run.rects.items() if _inside(rect, x, y)}
        word.append(frozenset(regions | sensors))
        is_point.append(True)
        if index + 1 < len(times):
            x, y = _position(run, (s + times[index + 1]) / 2)
            regions = {name for name, rect in run.rects.items() if _inside(rect, x, y)}
            word.append(frozenset(regions | sensors))
            is_point.append(False)
    return word, is_point
