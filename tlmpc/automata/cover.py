"""Guards from letter sets: an irredundant sum of products of a truth table.

The simulation-based pruning removes single letters from an edge (those for which a better
edge exists), which leaves a letter set, not a formula; this module writes it back as a
disjunction of cubes with the Minato–Morreale recursion (the ``isop`` of BDD packages, here on
truth tables held in Python integers: bit ``v`` is the valuation in which proposition ``i`` is
true iff bit ``i`` of ``v`` is set).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

from tlmpc.ltl.ast import FALSE, TRUE, Formula, Not, Prop, conjoin, disjoin

#: A cube as (variable index, value) pairs.
Cube = tuple[tuple[int, bool], ...]


def _full(variables: int) -> int:
    return (1 << (1 << variables)) - 1


@lru_cache(maxsize=4096)
def isop(lower: int, upper: int, variables: int) -> tuple[tuple[Cube, ...], int]:
    """Cubes whose union contains ``lower`` and lies inside ``upper`` (``lower ⊆ upper``,
    truth tables over ``variables`` variables), and the truth table of that union.

    The cover is irredundant: no cube can be dropped or widened (Minato–Morreale)."""
    if lower == 0:
        return (), 0
    if upper == _full(variables):
        return ((),), upper
    top = variables - 1
    half = 1 << top
    low_bits = (1 << half) - 1
    lower0, lower1 = lower & low_bits, lower >> half
    upper0, upper1 = upper & low_bits, upper >> half
    cubes0, cover0 = isop(lower0 & ~upper1, upper0, top)
    cubes1, cover1 = isop(lower1 & ~upper0, upper1, top)
    rest = (lower0 & ~cover0) | (lower1 & ~cover1)
    cubes_both, cover_both = isop(rest, upper0 & upper1, top)
    cubes = (
        tuple(((top, False), *c) for c in cubes0)
        + tuple(((top, True), *c) for c in cubes1)
        + cubes_both
    )
    table = cover0 | cover1 << half | cover_both | cover_both << half
    return cubes, table


def cover_formula(aps: Sequence[str], lower: int, upper: int) -> Formula:
    """A disjunction of cubes over ``aps`` true on every valuation of ``lower`` and on no
    valuation outside ``upper`` (valuations numbered as in the module docstring)."""
    cubes, _table = isop(lower, upper, len(aps))
    if not cubes:
        return FALSE
    formulas = []
    for cube in cubes:
        literals: list[Formula] = [
            Prop(aps[i]) if value else Not(Prop(aps[i])) for i, value in sorted(cube)
        ]
        formulas.append(conjoin(literals))
    if any(f == TRUE for f in formulas):
        return TRUE
    return disjoin(formulas)
