"""Pure eventualities (``F e == e``) and pure universalities (``G u == u``), the classes the
rewriting relies on, checked on lasso words with the definition-level evaluator: every formula
the translator puts in a class satisfies the class's equation, including the forms ``x R e``,
``e1 W e2``, ``x U u`` and ``u1 M u2``."""

from __future__ import annotations

from automata_oracles import evaluate
from hypothesis import given
from hypothesis import strategies as st
from strategies import formulas

from tlmpc.automata.nnf import Binary, Node
from tlmpc.automata.terms import _pure_universality, from_ast, is_pure_eventuality, to_formula
from tlmpc.ltl.ast import (
    Eventually,
    Formula,
    Globally,
    Prop,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
)

PROPS = ("a", "b", "c")
letters = st.frozensets(st.sampled_from(PROPS))
words = st.lists(
    st.tuples(st.lists(letters, max_size=4), st.lists(letters, min_size=1, max_size=4)),
    min_size=1,
    max_size=8,
)
small = formulas(PROPS, max_leaves=4)
#: Formulas shaped like the members of the classes: one operator over (partly) F/G operands.
operand = st.one_of(small, st.builds(Eventually, small), st.builds(Globally, small))
shaped = st.builds(
    lambda op, a, b: op(a, b),
    st.sampled_from([Until, Release, WeakUntil, StrongRelease]),
    operand,
    operand,
)


@given(st.one_of(shaped, formulas(PROPS, max_leaves=8)), words)
def test_classes_satisfy_their_equations(
    formula: Formula, samples: list[tuple[list[frozenset[str]], list[frozenset[str]]]]
) -> None:
    node: Node = from_ast(formula)
    plain = to_formula(node)
    for prefix, loop in samples:
        if is_pure_eventuality(node):
            assert evaluate(Eventually(plain), prefix, loop) == evaluate(plain, prefix, loop)
        if _pure_universality(node):
            assert evaluate(Globally(plain), prefix, loop) == evaluate(plain, prefix, loop)


def test_new_members_are_recognised() -> None:
    a, fa, fb, ga, gb = (
        from_ast(f)
        for f in (
            Prop("a"),
            Eventually(Prop("a")),
            Eventually(Prop("b")),
            Globally(Prop("a")),
            Globally(Prop("b")),
        )
    )
    assert is_pure_eventuality(Binary("R", a, fb))
    assert is_pure_eventuality(Binary("W", fa, fb))
    assert not is_pure_eventuality(Binary("W", a, fb))
    assert _pure_universality(Binary("U", a, gb))
    assert _pure_universality(Binary("M", ga, gb))
    assert not _pure_universality(Binary("M", a, gb))
