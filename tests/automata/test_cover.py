"""Guards written back from letter sets (:mod:`tlmpc.automata.cover`), against brute force:
the cover is true on every required valuation, false outside the allowed ones, and no cube
can be dropped; over explicit letters, :class:`Alphabet` guards are enabled by exactly the
letters asked for."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from tlmpc.automata.cover import cover_formula, isop
from tlmpc.automata.guards import holds
from tlmpc.automata.simulation import Alphabet

APS = ("a", "b", "c", "d")


def _letter(valuation: int, aps: tuple[str, ...]) -> frozenset[str]:
    return frozenset(ap for i, ap in enumerate(aps) if valuation >> i & 1)


@st.composite
def bounds(draw: st.DrawFn) -> tuple[int, int, int]:
    """(variables, lower, upper) with lower ⊆ upper."""
    variables = draw(st.integers(0, len(APS)))
    size = 1 << (1 << variables)
    lower = draw(st.integers(0, size - 1))
    extra = draw(st.integers(0, size - 1))
    return variables, lower, lower | extra


@given(bounds())
def test_cover_lies_between_the_bounds(case: tuple[int, int, int]) -> None:
    variables, lower, upper = case
    aps = APS[:variables]
    guard = cover_formula(aps, lower, upper)
    for valuation in range(1 << variables):
        value = holds(guard, _letter(valuation, aps))
        if lower >> valuation & 1:
            assert value, (lower, upper, valuation)
        if not upper >> valuation & 1:
            assert not value, (lower, upper, valuation)


@given(bounds())
def test_cover_is_irredundant(case: tuple[int, int, int]) -> None:
    variables, lower, upper = case
    cubes, table = isop(lower, upper, variables)

    def cube_table(cube: tuple[tuple[int, bool], ...]) -> int:
        bits = 0
        for valuation in range(1 << variables):
            if all(bool(valuation >> i & 1) == value for i, value in cube):
                bits |= 1 << valuation
        return bits

    tables = [cube_table(c) for c in cubes]
    union = 0
    for bits in tables:
        union |= bits
    assert union == table
    assert lower & ~table == 0
    assert table & ~upper == 0
    for i in range(len(tables)):
        rest = 0
        for j, bits in enumerate(tables):
            if j != i:
                rest |= bits
        assert lower & ~rest != 0, (lower, upper, cubes[i])  # every cube is needed


@given(
    st.lists(st.frozensets(st.sampled_from(APS[:3])), min_size=1, max_size=8, unique=True),
    st.integers(0, 255),
)
def test_alphabet_guard_over_explicit_letters(letters: list[frozenset[str]], bits: int) -> None:
    alphabet = Alphabet(APS[:3], letters)
    mask = bits & alphabet.full
    guard = alphabet.guard(mask)
    assert guard is not None
    assert alphabet.mask(guard) == mask
    for i, letter in enumerate(letters):
        assert holds(guard, letter) == bool(mask >> i & 1)
