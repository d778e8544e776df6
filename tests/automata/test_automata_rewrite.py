"""The translator's formula rewriting, WDBA equivalence check and simulation, against oracles.

* Every rewrite keeps the language: the lasso-word evaluator (independent of the translator)
  agrees on the formula before and after, on random formulas over every operator, with and
  without the semantic implication checks.
* Each rule fires on an instance built for it (the expected result is written by hand) and
  Spot confirms that instance and its result are equivalent.
* Spot confirms that every rule instance and formulas one side condition away from a rule
  keep their language through the rewriting, and that random formulas the rules were written
  for translate to no more states than Spot's.
* The WDBA equivalence check accepts a right deterministic automaton and rejects wrong ones.
"""

from __future__ import annotations

import warnings

import pytest
from automata_oracles import accepts, evaluate
from hypothesis import given
from hypothesis import strategies as st
from strategies import formulas

from tlmpc.automata import to_hoa, translate
from tlmpc.automata.emptiness import equivalent_to_deterministic
from tlmpc.automata.model import Automaton, Edge
from tlmpc.automata.rewrite import rewrite
from tlmpc.automata.simplify import sccs
from tlmpc.automata.simulation import Alphabet, merge_transient
from tlmpc.automata.terms import from_ast, to_formula
from tlmpc.automata.translate import _is_empty_term
from tlmpc.ltl import parse_ltl, to_text
from tlmpc.ltl.ast import Formula, Not

with warnings.catch_warnings():
    warnings.simplefilter("ignore", DeprecationWarning)
    spot = pytest.importorskip("spot")
    from spot_families import to_tlmpc

PROPS = ("a", "b", "c")
letters = st.frozensets(st.sampled_from(PROPS))
words = st.tuples(st.lists(letters, max_size=4), st.lists(letters, min_size=1, max_size=4))


def rewritten(formula: Formula, *, semantic: bool) -> Formula:
    oracle = _is_empty_term if semantic else None
    return to_formula(rewrite(from_ast(formula), oracle, float("inf")))


@given(formulas(PROPS, max_leaves=10), st.lists(words, min_size=1, max_size=8), st.booleans())
def test_rewriting_keeps_the_language(
    formula: Formula,
    samples: list[tuple[list[frozenset[str]], list[frozenset[str]]]],
    semantic: bool,
) -> None:
    result = rewritten(formula, semantic=semantic)
    for prefix, loop in samples:
        assert evaluate(result, prefix, loop) == evaluate(formula, prefix, loop), (
            to_text(formula),
            to_text(result),
            prefix,
            loop,
        )


#: (formula, its rewrite): one instance per rule, the result written by hand.
RULES = [
    ("F(a U b)", "F b"),
    ("F(a M b)", "F(a & b)"),
    ("G(a R b)", "G b"),
    ("G(a W b)", "G(a | b)"),
    ("F(a | F b)", "F(a | b)"),
    ("G(a & G b)", "G(a & b)"),
    ("G F(a & F b)", "G F a & G F b"),
    ("a W F b", "F b | G a"),
    ("a M G b", "G b & F a"),
    ("F(b R F c)", "b R F c"),
    ("a U (b R F c)", "b R F c"),
    ("a R (b U G c)", "b U G c"),
    ("(a & b) U a", "a"),
    ("!a U (a | b)", "F(a | b)"),
    ("a W (a | b)", "a | b"),
    ("!a W (a | b)", "true"),
    ("(a | b) R a", "a"),
    ("a R (!a & b)", "G(!a & b)"),
    ("(a | b) M a", "a"),
    ("a M (!a & b)", "false"),
    ("(a & b) U (a U c)", "a U c"),
    ("(a & b) W (a W c)", "a W c"),
    ("a R ((a & b) R c)", "(a & b) R c"),
    ("a M ((a & b) M c)", "(a & b) M c"),
    ("G a | G F a", "G F a"),
    ("F b & (a U b)", "a U b"),
    ("G a & F !a", "false"),
    ("F a | G !a", "true"),
    # Suspension (Babiak et al.), Spot's F(a W b) rule, and G over a W e.
    ("G(a | G F b)", "G a | G F b"),
    ("G(a | F G b)", "G a | F G b"),
    ("F(a W b)", "F(b | G a)"),
    ("G(G a | F b)", "G(a | F b)"),
    ("F a & G F a", "G F a"),
    ("(!a & !b) W F G !a", "F G !a"),
    ("a W G F b", "a W G F b"),  # G a does not imply G F b: the W stays
    ("G a | (a U G b)", "a W G b"),
    ("F a & (a R F b)", "a M F b"),
    # Eventualities under G F, absorbed F disjuncts and G conjuncts, until/release over G/F.
    ("G F(a R F b)", "G F b"),
    ("F(a | G F a)", "F a"),
    ("G(a & F G a)", "G a"),
    ("G F((b R c) | G F c)", "G F c"),
    ("(a & b) U G a", "G a"),
    ("(a & b) W G a", "G a"),
    ("G a U !a", "!a"),
    ("G a W !a", "!a | G a"),
    ("F b U b", "F b"),
    ("a R F(a & b)", "F(a & b)"),
    ("a M F(a & b)", "F(a & b)"),
    ("F a R !a", "!a"),
    ("F a M !a", "!a & F a"),
    ("a U (a & b)", "b M a"),
    ("a W (a & b)", "b R a"),
    ("a R (a | b)", "b W a"),
    ("a M (a | b)", "b U a"),
    ("F a W G F b", "G F a | G F b"),
    ("G F(a R (b U a))", "G F a"),
    ("F a | G(a | b)", "F a | G b"),
    ("G a & F(!a & b | c)", "G a & F c"),
    ("F(a | b) | (a U c)", "F(a | b) | c"),
]


#: Formulas one side condition away from a rule (the rule must not fire, or fire correctly).
NEAR_MISSES = [
    "G F(a R b)",
    "G F(a W F b)",
    "F(a | G F b)",
    "G(a & F G b)",
    "G F((b R c) | G F a)",
    "a U G (a & b)",
    "(a | b) U G a",
    "G a U b",
    "(b | c) U b",
    "a R F b",
    "F a R b",
    "F a M b",
    "a U (b & c)",
    "a R (b | c)",
    "a W G F b",
    "G a W F b",
    "G F((a & b) R a)",
    "G F(a R (b & F a))",
    "F a | (b & a)",
    "F(a & b) | G(a | c)",
    "G(a | b) & F(!a & c)",
    "a | G(!a | b)",
]


@pytest.mark.parametrize("text", NEAR_MISSES + [text for text, _ in RULES])
@pytest.mark.parametrize("semantic", [False, True])
def test_rewrite_is_equivalent_by_spot(text: str, semantic: bool) -> None:
    result = rewritten(parse_ltl(text), semantic=semantic)
    assert spot.are_equivalent(spot.formula(text), spot.formula(to_text(result))), (
        text,
        to_text(result),
    )


#: Random formulas (Spot's ``randltl``, X-free) whose automata the rules of the module
#: docstring bring down to Spot's size (they were larger before them).
SPOT_SIZED = [
    "GF((Gp1 U p0) R F(!p0 <-> p1))",
    "F(p1 | Gp0 | GFp1)",
    "F(p1 & GF((1 U p0) W (p1 R p0)))",
    "GF(p1 R Fp0)",
    "!FG(p1 & FGp1) M 1",
    "G!((p0 -> Fp1) R (p0 U Gp0))",
    "FG(Fp2 U !(0 R (!(p2 M 1) U p2)))",
    "p0 R (!p3 & G((p1 M 1) U ((p0 R Fp0) U p0)))",
    "(p1 U (p1 & !p2)) W ((Gp1 | G(p0 -> p2)) M p2)",
    "0 R F(p1 R (p2 U p1))",
    "(p2 | p3) & (p0 | (!(p1 <-> Fp3) W Fp1))",
    "F(((p0 & F!p0) M (p2 | p4)) <-> (p4 | (!p3 -> Fp4))) W (Gp0 M 1)",
]


@pytest.mark.parametrize("text", SPOT_SIZED)
def test_rules_bring_random_formulas_to_spots_size(text: str) -> None:
    ours = translate(parse_ltl(to_tlmpc(spot.formula(text))))
    theirs = spot.translate(spot.formula(text), "TGBA", "Small", "High")
    assert ours.num_states <= theirs.num_states(), (text, ours.num_states)
    assert spot.are_equivalent(spot.automaton(to_hoa(ours)), theirs), text


@pytest.mark.parametrize(("text", "expected"), RULES)
def test_each_rule_fires(text: str, expected: str) -> None:
    formula = parse_ltl(text)
    result = rewritten(formula, semantic=False)
    assert result == to_formula(from_ast(parse_ltl(expected))), (text, to_text(result))
    assert spot.are_equivalent(spot.formula(text), spot.formula(expected))


def test_semantic_checks_find_what_syntax_misses() -> None:
    # F(a | G !a) is valid, but no syntactic rule sees it.
    formula = parse_ltl("F(a | G !a)")
    assert rewritten(formula, semantic=False) != parse_ltl("true")
    assert rewritten(formula, semantic=True) == parse_ltl("true")
    # Both kinds of check within one node: G(a & F !a) is empty.
    assert rewritten(parse_ltl("b U G(a & F !a)"), semantic=True) == parse_ltl("false")


def test_suspendable_conjunct_is_tracked_until_fulfilled() -> None:
    """A state holding s & F(a & s) for a prefix-independent s once dropped s, and accepted
    this word although F G !p0 never holds on it."""
    formula = parse_ltl("p2 R (F(F G !p0 & !p1) | G(F p0 & p1))")
    prefix: list[frozenset[str]] = []
    loop = [frozenset(), frozenset({"p0"}), frozenset(), frozenset()]
    assert not evaluate(formula, prefix, loop)
    for automaton in (translate(formula), translate(formula, simplify=False)):
        assert not accepts(automaton, prefix, loop)


def test_wdba_replaces_a_non_obligation_when_equivalent() -> None:
    # F(p | G !p) is not a syntactic obligation (G inside F); its language is everything.
    automaton = translate(parse_ltl("true U (p <-> F p)"))
    assert automaton.num_states == 1
    assert automaton.num_acc == 0


def test_wdba_equivalence_check() -> None:
    deadline = float("inf")
    recurrence = parse_ltl("G F a")
    tgba = translate(recurrence)  # one state, deterministic, one set
    negation = translate(Not(recurrence))
    assert equivalent_to_deterministic(tgba, tgba, negation, None, deadline)
    # Deterministic but wrong: F a accepts more, G a accepts less, true accepts everything.
    for wrong in ("F a", "G a", "true"):
        candidate = translate(parse_ltl(wrong))
        assert not equivalent_to_deterministic(tgba, candidate, negation, None, deadline), wrong


def test_simulation_on_bare_marks_drops_a_dominated_entry() -> None:
    # F(!p U G p) = F G p: Spot's automaton has two states; the edge into the state of
    # (!p U G p) is dominated by the initial self-loop once the edge's marks are bare.
    automaton = translate(parse_ltl("F(!p U G p)"))
    assert automaton.num_states == 2
    assert spot.are_equivalent(spot.automaton(to_hoa(automaton)), spot.formula("F G p"))


def test_transient_state_replaced_by_an_equivalent_one() -> None:
    # The initial state only enters the SCC of the prefix-independent rest: Spot has one state.
    text = "G(!p2 M (F G(G p3 | p1) R F p2))"
    automaton = translate(parse_ltl(text))
    assert automaton.num_states == 1
    assert spot.are_equivalent(spot.automaton(to_hoa(automaton)), spot.formula(text))


@given(formulas(PROPS, max_leaves=8))
def test_reductions_agree_with_spot(formula: Formula) -> None:
    text = to_text(formula)
    ours = spot.automaton(to_hoa(translate(formula, budget=None)))
    assert spot.are_equivalent(ours, spot.formula(text)), text


def test_transient_state_never_replaced_by_a_state_that_reaches_it() -> None:
    """q (initial) reads a, then !a into p; p reads a, then !a into the loop (a !a)^ω: both
    accept (a !a)^ω.  Sending the edge into p back to q instead would close a cycle without
    the acceptance mark and lose every word."""
    a, not_a = parse_ltl("a"), parse_ltl("!a")
    edges = (
        Edge(src=1, dst=2, guard=a),  # q
        Edge(src=2, dst=0, guard=not_a),  # s, into p
        Edge(src=0, dst=3, guard=a),  # p
        Edge(src=3, dst=4, guard=not_a),
        Edge(src=4, dst=5, guard=a),
        Edge(src=5, dst=4, guard=not_a, marks=frozenset({0})),
    )
    automaton = Automaton(aps=("a",), num_states=6, initial=1, edges=edges, num_acc=1)
    word: tuple[list[frozenset[str]], list[frozenset[str]]] = ([], [frozenset({"a"}), frozenset()])
    assert accepts(automaton, *word)
    component = sccs(automaton.num_states, automaton.edges, automaton.initial)
    merged = merge_transient(automaton, Alphabet(("a",), None), component, float("inf"))
    assert accepts(merged, *word)
