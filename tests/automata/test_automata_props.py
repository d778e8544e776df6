"""Language correctness of the translator against an independent lasso-word LTL evaluator."""

from __future__ import annotations

from automata_oracles import accepts, evaluate
from hypothesis import given, settings
from hypothesis import strategies as st

from tlmpc.automata import degeneralize, translate
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

PROPS = ("a", "b", "c", "d")
BINARY = (Until, Release, WeakUntil, StrongRelease, Implies, Equiv)


def formulas(max_leaves: int = 12) -> st.SearchStrategy[Formula]:
    leaves = st.one_of(
        st.sampled_from(PROPS[:3]).map(Prop),
        st.sampled_from(PROPS).map(Prop),
        st.booleans().map(Const),
    )

    def extend(inner: st.SearchStrategy[Formula]) -> st.SearchStrategy[Formula]:
        return st.one_of(
            inner.map(Not),
            inner.map(Eventually),
            inner.map(Globally),
            st.lists(inner, min_size=2, max_size=3).map(lambda xs: And(tuple(xs))),
            st.lists(inner, min_size=2, max_size=3).map(lambda xs: Or(tuple(xs))),
            st.tuples(st.sampled_from(BINARY), inner, inner).map(lambda t: t[0](t[1], t[2])),
        )

    return st.recursive(leaves, extend, max_leaves=max_leaves)


letters_all = st.frozensets(st.sampled_from(PROPS))
words = st.tuples(st.lists(letters_all, max_size=4), st.lists(letters_all, min_size=1, max_size=4))


def depth(f: Formula) -> int:
    return 1 + max((depth(c) for c in f.children()), default=0)


@given(formulas(), st.lists(words, min_size=1, max_size=6))
def test_tgba_and_ba_agree_with_evaluator(
    formula: Formula, samples: list[tuple[list[frozenset[str]], list[frozenset[str]]]]
) -> None:
    tgba = translate(formula)
    ba = degeneralize(tgba)
    assert ba.state_based
    assert ba.num_acc == 1
    for prefix, loop in samples:
        expected = evaluate(formula, prefix, loop)
        assert accepts(tgba, prefix, loop) == expected, (str(formula), prefix, loop)
        assert accepts(ba, prefix, loop) == expected, (str(formula), prefix, loop)


@settings(max_examples=100)
@given(
    formulas(),
    st.lists(st.frozensets(st.sampled_from((*PROPS, "z"))), min_size=1, max_size=5, unique=True),
    st.data(),
)
def test_letter_restricted_translation(
    formula: Formula, letter_sets: list[frozenset[str]], data: st.DataObject
) -> None:
    letters = [tuple(sorted(s)) for s in letter_sets]
    tgba = translate(formula, letters=letters)
    ba = degeneralize(tgba)
    letter = st.sampled_from([frozenset(x) for x in letters])
    for _ in range(4):
        prefix = data.draw(st.lists(letter, max_size=4))
        loop = data.draw(st.lists(letter, min_size=1, max_size=4))
        expected = evaluate(formula, prefix, loop)
        assert accepts(tgba, prefix, loop) == expected, (str(formula), letters, prefix, loop)
        assert accepts(ba, prefix, loop) == expected, (str(formula), letters, prefix, loop)


def test_evaluator_sanity() -> None:
    a, b = Prop("a"), Prop("b")
    A, B, E = frozenset({"a"}), frozenset({"b"}), frozenset[str]()
    assert evaluate(Eventually(b), [A, A], [B])
    assert not evaluate(Eventually(b), [], [A])
    assert evaluate(Globally(Eventually(a)), [E], [E, A])
    assert not evaluate(Eventually(Globally(a)), [A], [E, A])
    assert evaluate(Until(a, b), [A, A], [B])
    assert not evaluate(Until(a, b), [A, E], [B])
    assert evaluate(WeakUntil(a, b), [], [A])
    assert not evaluate(StrongRelease(b, a), [], [A])
    assert evaluate(Release(b, a), [], [A])
