"""Who broke a reactive run: the environment (an assumption) or the robot (a guarantee).

A reactive run is judged by the strict GR(1) reading the synthesis game decides
(docs/semantics.md, "Reactive runs: who broke what"):

* each part's *breaking time* is the earliest instant at which the run's prefix up to it is
  bad for the part (no continuation satisfies it), read by the one evaluator on the pieces
  cut there (:class:`Prefixes`); parts that fail only in the limit (a liveness part on a loop)
  have no breaking time;
* the robot is to blame when a guarantee part breaks strictly before every assumption (at the
  same instant the environment moved first, and the game frees the robot's answer to a move
  that breaks an assumption), or, when nothing breaks at an instant, when every assumption
  holds on the whole run and the guarantee does not;
* the environment is to blame when an assumption breaks no later than every guarantee part, or
  fails in the limit while the guarantee holds up to its own limit failure: the guarantee is
  then vacuous, and the run counts as satisfied (exit 0), the broken assumption reported.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import numpy.typing as npt

from tlmpc.ltl.ast import Formula, bounded_operators
from tlmpc.ltl.printer import to_text
from tlmpc.verify.clock import Clock
from tlmpc.verify.evaluate import Value
from tlmpc.verify.model import AssumeGuarantee, Blame, Outcome, PartVerdict
from tlmpc.verify.semantics import PieceEnding, Semantics, Timing

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


def outcome_of_value(lo: float, hi: float) -> Outcome:
    """The verdict an interval value at the first instant gives."""
    if lo > 0:
        return "satisfied"
    if hi < 0:
        return "violated"
    return "inconclusive"


def _prefix_atoms(atoms: Callable[[str], Value], cut: int) -> Callable[[str], Value]:
    def prefix(name: str) -> Value:
        lo, hi = atoms(name)
        if lo is hi:
            both = lo[:cut]
            return both, both
        return lo[:cut], hi[:cut]

    return prefix


class Prefixes:
    """The open (three-valued) verdicts of the run's first ``cut`` pieces, one evaluator per
    cut: what was known of a formula at the first instant of piece ``cut - 1`` (``starts``:
    seconds from the first sample)."""

    def __init__(
        self, atoms: Callable[[str], Value], starts: FloatArray, is_point: BoolArray | None
    ) -> None:
        self.atoms = atoms
        self.starts = starts
        self.is_point = is_point
        self.cache: dict[int, Semantics] = {}

    def outcome(self, formula: Formula, cut: int, *, keep: bool = True) -> Outcome:
        """The verdict of ``formula`` on the first ``cut`` pieces, the rest unknown.

        ``keep``: remember the cut's evaluator (its sub-formulas' values), for more formulas
        asked at the same cut; a bisection visits each cut once and keeps nothing, so its
        memory stays that of one evaluation."""
        semantics = self.cache.get(cut)
        if semantics is None:
            semantics = Semantics(
                _prefix_atoms(self.atoms, cut),
                cut,
                "open",
                is_point=None if self.is_point is None else self.is_point[:cut],
                timing=Timing(self.starts[:cut], float(self.starts[cut - 1])),
            )
            if keep:
                self.cache[cut] = semantics
        return outcome_of_value(*semantics.at_start(formula))


def breaking_time(
    formula: Formula,
    full: Outcome,
    prefixes: Prefixes,
    ending: PieceEnding,
) -> float | None:
    """The earliest piece start (seconds from the first sample) at which the run's prefix is
    bad for ``formula``.

    Bad prefixes stay bad when the run goes on (the evaluator refines the unknown future),
    so the earliest is found by bisection over the cuts.  A time-bounded formula is cut only
    after point pieces (instants), where its evaluator needs the prefix to end."""
    size = len(prefixes.starts)
    if full != "violated":
        return None  # the whole run does not fail, so no prefix of it is bad
    step = 2 if bounded_operators(formula) else 1
    cuts = list(range(1, size + 1, step))

    def bad(cut: int) -> bool:
        if ending == "open" and cut == size:
            return True  # the log itself: its verdict (with its last point's unknowns)
        return prefixes.outcome(formula, cut, keep=False) == "violated"

    if not cuts or not bad(cuts[-1]):
        return None  # fails only in the limit (on the loop, or on its repetitions)
    low, high = 0, len(cuts) - 1  # bad(cuts[high]) holds
    while low < high:
        middle = (low + high) // 2
        if bad(cuts[middle]):
            high = middle
        else:
            low = middle + 1
    return float(prefixes.starts[cuts[high] - 1])


def _first(parts: Sequence[PartVerdict]) -> PartVerdict | None:
    """The part broken at the earliest instant; else the first that fails in the limit."""
    timed = [p for p in parts if p.broken is not None]
    if timed:
        return min(timed, key=lambda p: p.broken or 0.0)
    return next((p for p in parts if p.outcome == "violated"), None)


def _blame(
    environment: PartVerdict | None,
    robot: PartVerdict | None,
    assumed: Sequence[PartVerdict],
    guarantee: Outcome,
) -> tuple[Outcome, Blame | None]:
    """Who is to blame, and the run's outcome (docs/semantics.md)."""
    env_time = None if environment is None else environment.broken
    robot_time = None if robot is None else robot.broken
    if robot_time is not None and (env_time is None or robot_time < env_time):
        return "violated", "robot"  # strictly first: a tie goes to the environment
    if environment is not None:
        return "satisfied", "environment"  # at an instant no later, or in the limit
    if robot is not None and all(a.outcome == "satisfied" for a in assumed):
        return "violated", "robot"  # in the limit, every assumption kept
    return ("satisfied" if guarantee == "satisfied" else "inconclusive"), None


def assume_guarantee(
    assumptions: Sequence[Formula],
    guarantees: Sequence[Formula],
    guarantee: Outcome,
    full: Callable[[Formula], Outcome],
    prefixes: Prefixes,
    ending: PieceEnding,
) -> AssumeGuarantee:
    """The strict GR(1) verdict of a run: ``guarantee`` is the whole guarantee's verdict,
    ``full`` gives a formula's verdict on the whole run, ``guarantees`` are its parts.

    On an open log a part is violated only with a bad prefix, so whatever fails has a
    breaking time; failures in the limit exist only on loops and stays."""

    def judge(formula: Formula) -> PartVerdict:
        outcome = full(formula)
        return PartVerdict(
            part=to_text(formula),
            outcome=outcome,
            broken=breaking_time(formula, outcome, prefixes, ending),
        )

    assumed = tuple(judge(a) for a in assumptions)
    promised = tuple(judge(g) for g in guarantees)
    environment, robot = _first(assumed), _first(promised)
    outcome, blame = _blame(environment, robot, assumed, guarantee)
    return AssumeGuarantee(
        outcome=outcome,
        blame=blame,
        assumptions=assumed,
        guarantees=promised,
        environment=environment,
        robot=robot,
    )


def blame_lines(judged: AssumeGuarantee, start: float) -> list[str]:
    """The text report's lines on who broke what (indented, no newlines); ``start``: the
    stamp of the log's first sample."""
    clock = Clock(start, start)

    def when(part: PartVerdict) -> str:
        if part.broken is None:
            return "in the limit (on the repeating part, at no single instant)"
        return "at " + clock.at(part.broken)

    lines: list[str] = []
    environment, robot = judged.environment, judged.robot
    if environment is not None:
        line = f"  the environment broke an assumption {when(environment)}: `{environment.part}`"
        if judged.blame == "environment":
            line += "; the guarantee holds vacuously"
        lines.append(line)
    if robot is not None:
        line = f"  the robot broke a guarantee {when(robot)}: `{robot.part}`"
        if judged.blame == "environment":
            line += " (no earlier than the environment: not to blame)"
        lines.append(line)
    for part in judged.assumptions:
        lines.append(f"  assumption {part.part}: {part.outcome}")
    return lines
