"""Dense-time evaluation of formulas with time bounds (MTL over continuous time).

Times are seconds from the trace's first instant, ``T_0 = 0`` (the log's stamps less its first
one): at an epoch of 1.7e9 s a stamp is rounded to 2.4e-7 s, and a window end ``T_j - b``
taken in stamps would land on an instant nearby.

Every sub-formula's value is a **signal**: piecewise constant between the instants of its
grid ``T_0 < T_1 < ... < T_m``, with a value at each instant (a *point* position) and one on
each open stretch after it (an *open* position): positions ``2i`` (the instant ``T_i``) and
``2i + 1`` (the stretch from ``T_i`` to ``T_{i+1}``).  The last open position runs to the loop's
wrap instant (a loop: it is followed by the loop's first instant, a point position) or to
infinity (a stay or an open log: the *tail*, constant, looping on itself).  Values are
interval values ``(lo, hi)`` as everywhere in the verifier; every operator is monotone, so
each end is computed on its own.

* Boolean operators and the untimed temporal ones are the lasso recursion of
  :class:`IntervalEvaluator` on the common refinement of their operands' grids (the recursion
  with the point rule is exact on any grid of alternating instants and open stretches).
* ``F[a,b] x`` at ``t`` is the maximum of ``x`` over the pieces that meet the window
  ``[t + a, t + b]``; ``G[a,b]`` the minimum.  As ``t`` moves, the window meets a range of
  pieces that changes only where a window end crosses an instant: at ``T_j - a`` and
  ``T_j - b``.  Those instants (and the operand's own) form the result's grid; the result is
  evaluated exactly at each of them and at the middle of each stretch between them, with the
  comparisons made in shifted time (``t <= T_j - a`` rather than ``t + a <= T_j``, so that
  a window end falling on an instant is decided the same way each time it is computed).
* Every result drops the instants where its value does not change (but the trace's own): the
  grids stay as large as the values are varied, however deeply bounds are nested.
* ``x U[a,b] y = G[0,a) x & F[a,a] (x U[0,b-a] y)`` (for ``a > 0``) and
  ``x U[0,c] y = (x U y) & F[0,c] y``: exact identities of the non-strict until (by cases on
  the witness, for every threshold of the real-valued reading).
* A loop repeats with its period ``P``: windows are evaluated on the trace unrolled far
  enough, from the copy ``a`` reaches.  A window that starts in the loop sees nothing new
  past ``a + P`` and is cut there; one that starts before the loop, at the wrap instant (so
  ``b = inf`` needs finitely many copies, and a long trace before the loop none more).  A
  window meeting more than :data:`MAX_UNROLLED` pieces of the copies is refused.  A stay or an open
  log: the tail takes part in every window that reaches past the last instant.
"""

from __future__ import annotations

import math
from collections.abc import Callable, MutableMapping
from dataclasses import dataclass
from typing import Literal, assert_never

import numpy as np
import numpy.typing as npt

from tlmpc.ltl.ast import (
    And,
    BoundedEventually,
    BoundedGlobally,
    BoundedUntil,
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
from tlmpc.verify.evaluate import UNKNOWN, IntervalEvaluator, Value

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: What follows the last piece: the loop's first piece, ``stay`` or ``open``.
PieceEnding = int | Literal["stay", "open"]

#: A window on a loop lays out at most this many pieces of the loop's copies (refused beyond,
#: :class:`UnrollTooLong`): a window ``[t + a, t + b]`` sliding over the whole trace meets
#: about (length of the trace + b - a) / period copies, millions when a long log ends in a
#: loop of a few milliseconds, and then that many instants in its result.
MAX_UNROLLED = 1 << 21


class UnrollTooLong(ValueError):
    """A window on a loop would lay out more than :data:`MAX_UNROLLED` pieces of its copies."""

    def __init__(self, low: float, high: float, period: float, pieces: int) -> None:
        super().__init__(
            f"a window [t + {low:g}, t + {high:g}] on a loop of period {period:g} s meets "
            f"{pieces:,} pieces of its copies, more than the {MAX_UNROLLED:,} the verifier lays "
            "out"
        )
        self.pieces = pieces


@dataclass(frozen=True, slots=True)
class Timing:
    """When each piece starts, and when the last one ends (a loop: the wrap instant), in
    seconds from the first piece's instant (0): the log's stamps less its first one.

    Pieces alternate: an instant (a point piece) at each even index, the open stretch up to
    the next instant at each odd one.
    """

    starts: FloatArray
    end: float


@dataclass(frozen=True, slots=True)
class Signal:
    """A piecewise-constant interval signal: instants ``times``, two positions per instant."""

    times: FloatArray
    lo: FloatArray
    hi: FloatArray


@dataclass(frozen=True, slots=True)
class Domain:
    """What every signal of one trace shares: its start, and how it ends."""

    start: float
    loop_time: float | None  # the loop's first instant (None: stay or open)
    end: float  # the loop's wrap instant; the last instant for a stay or an open log

    @property
    def period(self) -> float:
        """The loop's period."""
        assert self.loop_time is not None
        return self.end - self.loop_time

    def periods_back(self, low: float, high: float) -> tuple[float, float]:
        """A window ``[t + low, t + high]`` moved back by whole periods, as far as it still
        starts in the loop for every ``t`` of the domain: the same values (the loop repeats).

        Far out the floats no longer tell a period's instants apart (``t + 1e17`` is rounded
        to 16 s): the window is laid out where they do.  The remainder of ``low`` by the
        period is exact (``fmod``), so the window keeps its phase; its width is kept too (a
        window wider than a period is cut to one anyway)."""
        assert self.loop_time is not None
        period = self.period
        into_loop = self.loop_time - self.start  # t + low is in the loop for every t
        if not low >= into_loop + period:
            return low, high
        moved = math.fmod(low, period)
        moved += period * math.ceil((into_loop - moved) / period)
        while moved < into_loop:  # (the product rounded down)
            moved += period
        return moved, moved + (high - low)


def _placeholders(node: Formula) -> tuple[Formula, list[Formula]]:
    """``node`` with its operands replaced by propositions ``#0``, ``#1``, ... ."""
    children = list(node.children())
    names = tuple(Prop(f"#{i}") for i in range(len(children)))
    match node:
        case Not():
            return Not(names[0]), children
        case And():
            return And(names), children
        case Or():
            return Or(names), children
        case Eventually():
            return Eventually(names[0]), children
        case Globally():
            return Globally(names[0]), children
        case Implies() | Equiv() | Until() | Release() | WeakUntil() | StrongRelease():
            return type(node)(names[0], names[1]), children
        case Const() | Prop() | BoundedEventually() | BoundedGlobally() | BoundedUntil():
            raise ValueError(f"no placeholders for {node!r}")
        case _:
            assert_never(node)


def _range_reduce(values: FloatArray, first: IntArray, last: IntArray, use_max: bool) -> FloatArray:
    """``max`` (or ``min``) of ``values[first[q] : last[q] + 1]`` for every query (sparse
    table); an empty range gives the operation's neutral element.

    The table's levels are built one at a time and each answers its own queries before the
    next replaces it: memory stays a few copies of ``values``, not one per level (a window
    over 200,000 pieces would hold 18 of them), and no level past the longest range is built."""
    op = np.maximum if use_max else np.minimum
    neutral = -np.inf if use_max else np.inf
    length = last - first + 1
    empty = length <= 0
    safe_length = np.where(empty, 1, length)
    level = np.floor(np.log2(safe_length)).astype(np.int64)
    # log2 may round up just below a power of two: step down where the level is too long.
    level -= (1 << level) > safe_length
    result = np.full(len(first), neutral)
    safe_first = np.where(empty, 0, first)
    needed = set(np.unique(level[~empty]).tolist())
    row, width = values, 1  # row k: op over values[i : i + 2**k]
    for k in range(max(needed, default=-1) + 1):
        if k:
            row = op(row[: len(row) - width], row[width:])
            width *= 2
        if k not in needed:
            continue
        chosen = (level == k) & ~empty
        left = row[safe_first[chosen]]
        right = row[last[chosen] - (1 << k) + 1]
        result[chosen] = op(left, right)
    return result


def _sorted_union(runs: list[FloatArray]) -> FloatArray:
    """The sorted distinct values of ``runs``, each already sorted: what ``np.unique`` of
    their concatenation gives, with a stable sort that merges the runs in linear time
    instead of sorting afresh."""
    merged = np.sort(np.concatenate(runs), kind="stable")
    if len(merged) < 2:
        return merged
    distinct = np.empty(len(merged), dtype=bool)
    distinct[0] = True
    np.not_equal(merged[1:], merged[:-1], out=distinct[1:])
    return merged[distinct]


class DenseSemantics:
    """Signals of formulas (time bounds included) on the pieces of one trace, memoised."""

    def __init__(
        self,
        atoms: Callable[[str], Value],
        size: int,
        ending: PieceEnding,
        timing: Timing,
    ) -> None:
        starts = np.asarray(timing.starts, dtype=np.float64)
        if len(starts) != size:
            raise ValueError("one start time per piece")
        if starts[0] != 0.0:
            # a window end t + b is decided on exact differences of the stamps, never on a
            # stamp of 1.7e9 s, whose rounding (2e-7 s) would move it onto an instant nearby
            raise ValueError("times count from the first piece's instant, 0")
        looping = isinstance(ending, int)
        if looping != (size % 2 == 0):
            raise ValueError("pieces alternate: a loop ends on an open piece, else on an instant")
        self.atoms = atoms
        self.size = size
        self.ending = ending
        self.base_times = starts[0::2].copy()
        if isinstance(ending, int):
            if ending % 2:
                raise ValueError("a loop starts at an instant")
            self.domain = Domain(float(starts[0]), float(starts[ending]), float(timing.end))
        else:
            self.domain = Domain(float(starts[0]), None, float(starts[-1]))
        self.cache: MutableMapping[Formula, Signal] = {}

    # -- signals ------------------------------------------------------------------------------

    def _base(self, lo: FloatArray, hi: FloatArray) -> Signal:
        """A signal on the trace's own pieces (plus the tail after a stay or an open log)."""
        if self.ending == "open":
            lo, hi = np.append(lo, UNKNOWN[0]), np.append(hi, UNKNOWN[1])
        elif self.ending == "stay" and lo is hi:  # two-valued: one array for both ends
            lo = hi = np.append(lo, lo[-1])
        elif self.ending == "stay":
            lo, hi = np.append(lo, lo[-1]), np.append(hi, hi[-1])
        return Signal(self.base_times, np.asarray(lo, np.float64), np.asarray(hi, np.float64))

    def _loop_position(self, times: FloatArray) -> int:
        if self.domain.loop_time is None:
            return 2 * len(times) - 1  # the tail loops on itself
        return 2 * int(np.searchsorted(times, self.domain.loop_time))

    def _lasso(self, times: FloatArray, atoms: Callable[[str], Value]) -> IntervalEvaluator:
        size = 2 * len(times)
        is_point = np.zeros(size, dtype=bool)
        is_point[0::2] = True
        return IntervalEvaluator(atoms, size, self._loop_position(times), is_point)

    @staticmethod
    def _refine(signal: Signal, times: FloatArray) -> tuple[FloatArray, FloatArray]:
        """``signal``'s values on the finer grid ``times`` (which holds all of its instants)."""
        if len(times) == len(signal.times):
            return signal.lo, signal.hi
        old = signal.times
        index = np.searchsorted(old, times, side="left")
        exact = (index < len(old)) & (old[np.minimum(index, len(old) - 1)] == times)
        point = np.where(exact, 2 * index, 2 * (index - 1) + 1)
        stretch = 2 * (np.searchsorted(old, times, side="right") - 1) + 1
        positions = np.empty(2 * len(times), dtype=np.int64)
        positions[0::2] = point
        positions[1::2] = stretch
        if signal.lo is signal.hi:
            both = signal.lo[positions]
            return both, both
        return signal.lo[positions], signal.hi[positions]

    def _compact(self, times: FloatArray, lo: FloatArray, hi: FloatArray) -> Signal:
        """The signal of values ``lo``, ``hi`` on ``times`` without the instants where nothing
        changes: an instant whose value is that of the stretches on both sides goes, its two
        stretches becoming one (the trace's own instants stay: every signal is read there).

        A bounded operator adds ``T_j - a`` and ``T_j - b`` for every instant of its operand;
        kept, they would multiply with each level of nesting, while a window's value changes
        only where the window takes in or lets go of a piece holding its maximum: at most
        once per piece of the operand."""
        count = len(times)
        if count < 2:
            return Signal(times, lo, hi)

        def steady(values: FloatArray) -> npt.NDArray[np.bool_]:
            # instant i (from 1): the stretch before (2i - 1), the instant (2i), after (2i + 1)
            flat: npt.NDArray[np.bool_] = (values[1:-1:2] == values[2::2]) & (
                values[2::2] == values[3::2]
            )
            return flat

        keep = np.ones(count, dtype=bool)
        keep[1:] = ~(steady(lo) if lo is hi else steady(lo) & steady(hi))
        if keep.all():
            return Signal(times, lo, hi)
        keep[np.searchsorted(times, self.base_times)] = True
        if keep.all():
            return Signal(times, lo, hi)
        positions = np.repeat(keep, 2)
        kept_lo = lo[positions]
        return Signal(times[keep], kept_lo, kept_lo if lo is hi else hi[positions])

    def _common(self, signals: list[Signal]) -> tuple[FloatArray, list[Value]]:
        times = signals[0].times
        for other in signals[1:]:
            if other.times is not times and not np.array_equal(other.times, times):
                times = np.union1d(times, other.times)
        return times, [self._refine(s, times) for s in signals]

    def signal(self, formula: Formula) -> Signal:
        """The signal of ``formula``."""
        cached = self.cache.get(formula)
        if cached is None:
            cached = self._signal(formula)
            self.cache[formula] = cached
        return cached

    def _signal(self, formula: Formula) -> Signal:
        match formula:
            case Const(value):
                filled = np.full(2 * len(self.base_times), np.inf if value else -np.inf)
                return Signal(self.base_times, filled, filled)
            case Prop(name):
                lo, hi = self.atoms(name)
                return self._base(lo, hi)
            case BoundedEventually(arg, interval):
                return self.window(
                    self.signal(arg), interval.low, interval.high, right_closed=True, use_max=True
                )
            case BoundedGlobally(arg, interval):
                return self.window(
                    self.signal(arg), interval.low, interval.high, right_closed=True, use_max=False
                )
            case BoundedUntil(left, right, interval):
                return self.bounded_until(
                    self.signal(left), self.signal(right), interval.low, interval.high
                )
            case (
                Not()
                | And()
                | Or()
                | Implies()
                | Equiv()
                | Until()
                | Release()
                | WeakUntil()
                | StrongRelease()
                | Eventually()
                | Globally()
            ):
                shape, children = _placeholders(formula)
                return self._untimed(shape, [self.signal(c) for c in children])
            case _:
                assert_never(formula)

    def _untimed(self, shape: Formula, operands: list[Signal]) -> Signal:
        """An untimed operator (``shape`` over ``#0``, ``#1``, ...) on its operands' signals."""
        times, values = self._common(operands)
        evaluator = self._lasso(times, lambda name: values[int(name[1:])])
        lo, hi = evaluator(shape)
        return self._compact(times, lo, hi)

    def meet(self, first: Signal, second: Signal) -> Signal:
        """``first & second``."""
        return self._untimed(And((Prop("#0"), Prop("#1"))), [first, second])

    # -- time bounds --------------------------------------------------------------------------

    def _extended(
        self, signal: Signal, low: float, high: float
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, npt.NDArray[np.bool_]]:
        """Every piece of ``signal`` a window ``[t + low, t + high]`` may meet: starts, ends,
        lo, hi and whether it is an instant (a loop is unrolled up to ``high`` past the
        domain's end, from the copy ``low`` reaches; a tail runs to infinity)."""
        times = signal.times
        count = 2 * len(times)
        starts = np.repeat(times, 2)
        ends = np.empty(count)
        ends[0::2] = times
        ends[1:-1:2] = times[1:]
        is_point = np.zeros(count, dtype=bool)
        is_point[0::2] = True
        domain = self.domain
        if domain.loop_time is None:
            ends[-1] = np.inf
            return starts, ends, signal.lo, signal.hi, is_point
        ends[-1] = domain.end
        period = domain.period
        first = self._loop_position(times)
        last_copy = math.ceil(high / period) + 1
        # Copy k ends at ``end + k P``; one ending a period before ``low`` is met by no window
        # (all start at or after ``low``), nor is anything before it.
        first_copy = max(1, math.floor((low - domain.end) / period) - 1)
        copies = last_copy - first_copy + 1
        if copies * (count - first) > MAX_UNROLLED:
            raise UnrollTooLong(low, high, period, copies * (count - first))
        shifts = np.repeat(
            np.arange(first_copy, last_copy + 1, dtype=np.float64) * period, count - first
        )
        keep = slice(0, count) if first_copy == 1 else slice(count, count)  # the trace itself
        starts = np.concatenate([starts[keep], np.tile(starts[first:], copies) + shifts])
        ends = np.concatenate([ends[keep], np.tile(ends[first:], copies) + shifts])
        lo = np.concatenate([signal.lo[keep], np.tile(signal.lo[first:], copies)])
        if signal.lo is signal.hi:
            hi = lo
        else:
            hi = np.concatenate([signal.hi[keep], np.tile(signal.hi[first:], copies)])
        is_point = np.concatenate([is_point[keep], np.tile(is_point[first:], copies)])
        return starts, ends, lo, hi, is_point

    def window(
        self, signal: Signal, low: float, high: float, *, right_closed: bool, use_max: bool
    ) -> Signal:
        """``max`` (``F[low,high]``) or ``min`` (``G[low,high]``) of ``signal`` over the window
        ``[t + low, t + high]`` (``[t + low, t + high)`` unless ``right_closed``).

        On a loop a window sees nothing new past a full period after both its start and the
        loop's.  One that starts in the loop (``t + low`` at or after the loop's first
        instant) is cut to ``[t + low, t + low + P]``; one that starts before it, to the wrap
        instant (everything after it repeats the loop, which the window holds whole).  So the
        loop is laid out a period past ``low`` beyond the trace, however long the trace before
        the loop is."""
        domain = self.domain
        if domain.loop_time is not None:
            low, high = domain.periods_back(low, high)
        whole: tuple[float, float, bool] | None = None  # (cutoff, high, right_closed)
        if domain.loop_time is not None and high > low + domain.period:
            cutoff = domain.loop_time - low  # windows starting before it: cut at the wrap
            if cutoff > domain.start:
                whole = (cutoff, high, right_closed)
            high, right_closed = low + domain.period, True
        starts, ends, lo, hi, is_point = self._extended(signal, low, high)
        instants = starts[is_point]
        candidates = [signal.times, instants - low]
        if math.isfinite(high):
            candidates.append(instants - high)
        if whole is not None and math.isfinite(whole[1]):
            candidates.append(signal.times - whole[1])  # (the trace's own instants only)
        grid = _sorted_union(candidates)
        if domain.loop_time is None:
            grid = grid[(grid >= domain.start) & (grid <= domain.end)]
        else:
            grid = grid[(grid >= domain.start) & (grid < domain.end)]
        # A piece meets the window's left end iff t <= key (instant) / t < key (stretch):
        # with the stretch's key one float lower, both read "key >= t".
        left_key = np.where(is_point, starts - low, np.nextafter(ends - low, -np.inf))
        left_key = np.maximum.accumulate(left_key)
        queries = np.empty(2 * len(grid))
        queries[0::2] = grid
        queries[1:-1:2] = (grid[:-1] + grid[1:]) / 2.0
        if domain.loop_time is None:
            queries[-1] = grid[-1]  # replaced by the tail's own value below
        else:
            queries[-1] = (grid[-1] + domain.end) / 2.0
        first = np.searchsorted(left_key, queries, side="left").astype(np.int64)
        last = self._last_met(starts, is_point, queries, high, right_closed)
        if whole is not None:
            cutoff, whole_high, whole_closed = whole
            before = queries < cutoff
            # (what such a window meets past the wrap instant only repeats what it holds)
            last[before] = self._last_met(
                starts, is_point, queries[before], whole_high, whole_closed
            )
        out_lo = _range_reduce(lo, first, last, use_max)
        out_hi = out_lo if signal.lo is signal.hi else _range_reduce(hi, first, last, use_max)
        if domain.loop_time is None:
            # On the tail the window lies wholly in it: its constant value.
            out_lo[-1], out_hi[-1] = signal.lo[-1], signal.hi[-1]
        return self._compact(grid, out_lo, out_hi)

    @staticmethod
    def _last_met(
        starts: FloatArray,
        is_point: npt.NDArray[np.bool_],
        queries: FloatArray,
        high: float,
        right_closed: bool,
    ) -> IntArray:
        """For each query ``t``, the last piece that starts in the window's right end
        ``t + high`` (before it, unless ``right_closed``)."""
        # A piece meets the window's right end iff key <= t.
        shifted = starts - high
        if right_closed:
            right_key = np.where(is_point, shifted, np.nextafter(shifted, np.inf))
        else:
            right_key = np.nextafter(shifted, np.inf)
        right_key = np.maximum.accumulate(right_key)
        found: IntArray = (np.searchsorted(right_key, queries, side="right") - 1).astype(np.int64)
        return found

    def bounded_until(self, left: Signal, right: Signal, low: float, high: float) -> Signal:
        """``left U[low,high] right``."""
        core = self._untimed(Until(Prop("#0"), Prop("#1")), [left, right])
        if math.isfinite(high):
            reach = self.window(right, 0.0, high - low, right_closed=True, use_max=True)
            core = self.meet(core, reach)
        if low == 0.0:
            return core
        held = self.window(left, 0.0, low, right_closed=False, use_max=False)
        later = self.window(core, low, low, right_closed=True, use_max=True)
        return self.meet(held, later)

    # -- reading on the trace's pieces --------------------------------------------------------

    def on_pieces(self, formula: Formula) -> Value:
        """``formula``'s values on the trace's pieces: exact at the instants, the hull of the
        values inside each open piece."""
        signal = self.signal(formula)
        index = np.searchsorted(signal.times, self.base_times)
        firsts = np.empty(self.size, dtype=np.int64)
        firsts[0::2] = 2 * index
        firsts[1::2] = (2 * index + 1)[: self.size // 2]
        stop = 2 * len(signal.times) - (1 if self.domain.loop_time is None else 0)
        lo = np.minimum.reduceat(signal.lo[:stop], firsts)
        hi = np.maximum.reduceat(signal.hi[:stop], firsts)
        return lo, hi
