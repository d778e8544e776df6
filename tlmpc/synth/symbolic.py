"""The BDD encoding of a :class:`~tlmpc.synth.spec.GameSpec` (CUDD through ``dd.cudd``).

Every variable becomes ``ceil(log2(size))`` bits (one for a Boolean); each bit has a current and
a next copy, declared side by side so that the BDD order interleaves them (renaming between the
two copies is then cheap, and transition relations stay small).  Integer values are offsets
from the range's low end in binary, least significant bit first, with a domain constraint on
each copy.
"""

from __future__ import annotations

import operator
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from dd import cudd

from tlmpc.synth.spec import (
    Atom,
    Binary,
    Compare,
    Const,
    Expr,
    GameSpec,
    Linear,
    Nary,
    Not,
    Owner,
    Part,
    Variable,
)

Function = Any  # dd.cudd.Function (untyped Cython)

_COMPARE: dict[str, Callable[[int, int], bool]] = {
    "=": operator.eq,
    "!=": operator.ne,
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
}


def _carried(total: int, odd: bool) -> tuple[int, bool]:
    """A column's total written down: its low bit joins the rest, the others carry over
    (floor division, so a negative total carries correctly)."""
    return total >> 1, odd or bool(total & 1)


def bit_width(variable: Variable) -> int:
    """How many bits encode ``variable``."""
    if variable.is_bool:
        return 1
    assert variable.low is not None
    assert variable.high is not None
    return max(1, (variable.high - variable.low).bit_length())


@dataclass
class Encoding:
    """Bits of every variable and the translation of expressions and parts to BDDs."""

    spec: GameSpec
    bdd: Any = field(default_factory=cudd.BDD)
    bits: dict[str, list[str]] = field(default_factory=dict)
    next_bits: dict[str, list[str]] = field(default_factory=dict)
    #: keep each bit's current and next copy adjacent under CUDD's dynamic reordering (sifting,
    #: on by default); free sifting measured faster on the robot-grid benchmarks
    group_pairs: bool = False

    def __post_init__(self) -> None:
        for index, variable in enumerate(self.spec.variables):
            width = bit_width(variable)
            self.bits[variable.name] = [f"v{index}b{k}" for k in range(width)]
            self.next_bits[variable.name] = [f"v{index}b{k}n" for k in range(width)]
            for k in range(width):
                self.bdd.declare(self.bits[variable.name][k], self.next_bits[variable.name][k])
                if self.group_pairs:
                    # sifting then moves each current/next pair as one block
                    self.bdd.group({self.bits[variable.name][k]: 2})
        self.to_next = {
            b: n
            for v in self.spec.variables
            for b, n in zip(self.bits[v.name], self.next_bits[v.name], strict=True)
        }
        self.to_current = {n: b for b, n in self.to_next.items()}
        self._part_cache: dict[int, Function] = {}

    # --- variable sets ----------------------------------------------------------------------

    def names(self, owner: Owner | None, primed: bool) -> set[str]:
        """Bit names of one player's (or everyone's) variables, current or next copy."""
        table = self.next_bits if primed else self.bits
        return {b for v in self.spec.variables if owner in (None, v.owner) for b in table[v.name]}

    def domain(self, owner: Owner | None, primed: bool) -> Function:
        """The constraint that every integer variable of ``owner`` lies in its range."""
        result = self.bdd.true
        for variable in self.spec.variables:
            if owner in (None, variable.owner) and not variable.is_bool:
                assert variable.low is not None
                assert variable.high is not None
                result &= self._less_equal(variable, variable.high - variable.low, primed)
        return result

    def _less_equal(self, variable: Variable, bound: int, primed: bool) -> Function:
        """``offset(variable) <= bound`` on the bits, most significant first."""
        bits = (self.next_bits if primed else self.bits)[variable.name]
        result = self.bdd.true
        for k, name in enumerate(bits):  # from the least significant bit up
            bit = self.bdd.var(name)
            if (bound >> k) & 1:
                result = ~bit | result
            else:
                result = ~bit & result
        if bound >> len(bits):
            return self.bdd.true
        return result

    def _in_range(self, variable: Variable, primed: bool) -> Function:
        assert variable.low is not None
        assert variable.high is not None
        return self._less_equal(variable, variable.high - variable.low, primed)

    def value_cube(self, variable: Variable, value: int | bool, primed: bool) -> Function:
        """The BDD of ``variable == value``."""
        bits = (self.next_bits if primed else self.bits)[variable.name]
        if variable.is_bool:
            bit = self.bdd.var(bits[0])
            return bit if value else ~bit
        assert variable.low is not None
        offset = int(value) - variable.low
        result = self.bdd.true
        for k, name in enumerate(bits):
            bit = self.bdd.var(name)
            result &= bit if (offset >> k) & 1 else ~bit
        return result

    # --- expressions ------------------------------------------------------------------------

    def expr(self, expr: Expr) -> Function:
        """The BDD of an expression (shared subexpressions are translated once)."""
        memo: dict[int, Function] = {}
        stack: list[tuple[Expr, bool]] = [(expr, False)]
        while stack:
            node, ready = stack.pop()
            if id(node) in memo:
                continue
            children: tuple[Expr, ...] = ()
            if isinstance(node, Not):
                children = (node.arg,)
            elif isinstance(node, Nary):
                children = node.args
            elif isinstance(node, Binary):
                children = (node.left, node.right)
            if children and not ready:
                stack.append((node, True))
                stack.extend((c, False) for c in children if id(c) not in memo)
                continue
            memo[id(node)] = self._node(node, memo)
        return memo[id(expr)]

    def _node(self, node: Expr, memo: Mapping[int, Function]) -> Function:
        bdd = self.bdd
        if isinstance(node, Const):
            return bdd.true if node.value else bdd.false
        if isinstance(node, Atom):
            variable = self.spec.variable(node.name)
            return self.value_cube(variable, True, node.primed)
        if isinstance(node, Compare):
            variable = self.spec.variable(node.name)
            assert variable.low is not None
            assert variable.high is not None
            if node.op in ("=", "!="):  # one cube, not a loop over the range (faces: thousands)
                inside = variable.low <= node.value <= variable.high
                cube = self.value_cube(variable, node.value, node.primed) if inside else bdd.false
                return cube if node.op == "=" else ~cube & self._in_range(variable, node.primed)
            return self._linear(Linear(((1, node.name, node.primed),), node.op, node.value))
        if isinstance(node, Linear):
            return self._linear(node)
        if isinstance(node, Not):
            return ~memo[id(node.arg)]
        if isinstance(node, Nary):
            operands = [memo[id(a)] for a in node.args]
            if node.op == "and":
                result = bdd.true
                for u in operands:
                    result &= u
            elif node.op == "or":
                result = bdd.false
                for u in operands:
                    result |= u
            else:
                result = bdd.false
                for u in operands:
                    result = bdd.apply("xor", result, u)
            return result
        assert isinstance(node, Binary)
        left, right = memo[id(node.left)], memo[id(node.right)]
        if node.op == "->":
            return ~left | right
        return bdd.apply("equiv", left, right)

    def _linear(self, node: Linear) -> Function:
        """``sum(coef * var) op value`` (with every variable in its range), built bit by bit.

        A loop over the values would cost the size of the ranges (a million and more for a
        counter); instead the bits are added column by column, least significant first, like a
        written sum.  With ``D = sum(coef * offset) - (value - sum(coef * low))``, the state
        after column k is ``(carry, odd)`` such that ``D = 2^k * (carry + the columns still to
        add) + rest`` with ``0 <= rest < 2^k`` and ``odd`` telling whether ``rest > 0``; at the
        end the sign of D is that of the carry, or of ``rest`` when the carry is 0.  The carries
        stay within the sum of the coefficients, so the cost grows with the number of bits.
        """
        bdd = self.bdd
        target = node.value
        in_range = bdd.true
        columns: list[list[tuple[int, str]]] = []
        for coef, name, primed in node.terms:
            variable = self.spec.variable(name)
            assert variable.low is not None
            target -= coef * variable.low
            in_range &= self._in_range(variable, primed)
            bits = (self.next_bits if primed else self.bits)[name]
            columns.extend([] for _ in range(len(bits) - len(columns)))
            for k, bit in enumerate(bits):
                columns[k].append((coef, bit))
        # a bit adds its coefficient to the column's total; None carries the total over
        steps: list[tuple[int, str] | None] = []
        for column in columns:
            steps.extend(column)
            steps.append(None)
        start = (-target, False)
        layers: list[set[tuple[int, bool]]] = [{start}]
        for step in steps:
            layers.append(
                {
                    after
                    for total, odd in layers[-1]
                    for after in (
                        [_carried(total, odd)]
                        if step is None
                        else [(total, odd), (total + step[0], odd)]
                    )
                }
            )
        test = _COMPARE[node.op]
        later: dict[tuple[int, bool], Function] = {}
        for carry, odd in layers[-1]:
            sign = -1 if carry < 0 else int(carry > 0 or odd)
            later[carry, odd] = bdd.true if test(sign, 0) else bdd.false
        for step, layer in zip(reversed(steps), reversed(layers[:-1]), strict=True):
            here: dict[tuple[int, bool], Function] = {}
            for total, odd in layer:
                if step is None:
                    here[total, odd] = later[_carried(total, odd)]
                else:
                    coef, bit = step
                    high, low = later[total + coef, odd], later[total, odd]
                    here[total, odd] = bdd.ite(bdd.var(bit), high, low)
            later = here
        return later[start] & in_range

    def part(self, part: Part) -> Function:
        """The BDD of one part (cached)."""
        key = id(part)
        if key not in self._part_cache:
            self._part_cache[key] = self.expr(part.formula)
        return self._part_cache[key]

    def conjoin(self, parts: Iterable[Part]) -> Function:
        """The conjunction of parts."""
        result = self.bdd.true
        for part in parts:
            result &= self.part(part)
        return result

    def prime(self, u: Function) -> Function:
        """``u`` over the next copy (``u`` mentions current bits only).

        Renaming is a permutation, so CUDD's variable swap does it; ``dd`` exposes that only as
        the private ``_swap`` (``let`` is the general substitution), hence the fallback."""
        swap = getattr(self.bdd, "_swap", None)
        if swap is not None:
            return swap(u, self.to_next)
        return self.bdd.let(self.to_next, u)

    def unprime(self, u: Function) -> Function:
        """``u`` over the current copy (``u`` mentions next bits only)."""
        swap = getattr(self.bdd, "_swap", None)
        if swap is not None:
            return swap(u, self.to_next)
        return self.bdd.let(self.to_current, u)

    # --- decoding ---------------------------------------------------------------------------

    def decode(
        self, assignment: Mapping[str, bool], owner: Owner | None, primed: bool
    ) -> dict[str, int | bool]:
        """Variable values from a bit assignment (bits missing from it read as False)."""
        table = self.next_bits if primed else self.bits
        values: dict[str, int | bool] = {}
        for variable in self.spec.variables:
            if owner not in (None, variable.owner):
                continue
            bits = table[variable.name]
            if variable.is_bool:
                values[variable.name] = bool(assignment.get(bits[0], False))
            else:
                assert variable.low is not None
                offset = sum(1 << k for k, b in enumerate(bits) if assignment.get(b, False))
                values[variable.name] = variable.low + offset
        return values

    def state_cube(
        self, values: Mapping[str, int | bool], owner: Owner | None, primed: bool
    ) -> Function:
        """The BDD of one valuation of a player's (or every) variable."""
        result = self.bdd.true
        for variable in self.spec.variables:
            if owner in (None, variable.owner):
                result &= self.value_cube(variable, values[variable.name], primed)
        return result
