"""The verifier's evaluation agrees with independent libraries on random formulas and traces.

Piece label sequences (right-continuous convention, finite traces: the last label stays) are
checked against metric-temporal-logic (``mtl``) and rtamt's discrete-time mode, and lassos
against the definition-level evaluator of ``tests/oracles``.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from lasso_ltl import holds

from tlmpc.ltl.ast import And, Eventually, Formula, Globally, Not, Or, Prop, Until
from tlmpc.verify.evaluate import truth_atoms
from tlmpc.verify.semantics import evaluate

PROPS = ("a", "b", "c")
leaves = st.sampled_from([Prop(p) for p in PROPS])
formulas = st.recursive(
    leaves,
    lambda inner: st.one_of(
        st.builds(Not, inner),
        st.builds(Eventually, inner),
        st.builds(Globally, inner),
        st.builds(lambda x, y: And((x, y)), inner, inner),
        st.builds(lambda x, y: Or((x, y)), inner, inner),
        st.builds(Until, inner, inner),
    ),
    max_leaves=8,
)
words = st.lists(st.frozensets(st.sampled_from(PROPS)), min_size=2, max_size=8)


def _mtl_text(f: Formula) -> str:
    if isinstance(f, Prop):
        return f.name
    if isinstance(f, Not):
        return f"~({_mtl_text(f.arg)})"
    if isinstance(f, And):
        return "(" + " & ".join(_mtl_text(a) for a in f.args) + ")"
    if isinstance(f, Or):
        return "(" + " | ".join(_mtl_text(a) for a in f.args) + ")"
    if isinstance(f, Eventually):
        return f"(F({_mtl_text(f.arg)}))"
    if isinstance(f, Globally):
        return f"(G({_mtl_text(f.arg)}))"
    if isinstance(f, Until):
        return f"(({_mtl_text(f.left)}) U ({_mtl_text(f.right)}))"
    raise TypeError(f)


def _ours(formula: Formula, word: list[frozenset[str]], loop: int) -> bool:
    labels = np.array([[p in letter for p in PROPS] for letter in word], dtype=bool)
    lo, _ = evaluate(formula, truth_atoms(labels, list(PROPS)), labels.shape[0], loop)
    return bool(lo[0] > 0)


@settings(deadline=None)
@given(formulas, words)
def test_agrees_with_metric_temporal_logic(formula: Formula, word: list[frozenset[str]]) -> None:
    import mtl

    data = {p: [(t, p in letter) for t, letter in enumerate(word)] for p in PROPS}
    expected = bool(mtl.parse(_mtl_text(formula))(data, quantitative=False))
    assert _ours(formula, word, len(word) - 1) == expected


def _rtamt_text(f: Formula) -> str:
    if isinstance(f, Prop):
        return f"({f.name} > 0)"
    if isinstance(f, Not):
        return f"(not {_rtamt_text(f.arg)})"
    if isinstance(f, And):
        return "(" + " and ".join(_rtamt_text(a) for a in f.args) + ")"
    if isinstance(f, Or):
        return "(" + " or ".join(_rtamt_text(a) for a in f.args) + ")"
    if isinstance(f, Eventually):
        return f"(eventually {_rtamt_text(f.arg)})"
    if isinstance(f, Globally):
        return f"(always {_rtamt_text(f.arg)})"
    if isinstance(f, Until):
        return f"({_rtamt_text(f.left)} until {_rtamt_text(f.right)})"
    raise TypeError(f)


@settings(deadline=None, max_examples=60)
@given(formulas, words)
def test_agrees_with_rtamt_discrete_time(formula: Formula, word: list[frozenset[str]]) -> None:
    import rtamt

    spec = rtamt.StlDiscreteTimeSpecification()
    for p in PROPS:
        spec.declare_var(p, "float")
    spec.spec = _rtamt_text(formula)
    spec.parse()
    # rtamt treats the trace as finite; repeat the last letter long enough to stand for
    # "forever" (a formula of depth d cannot tell more than d repetitions apart)
    padded = [*word, *[word[-1]] * 10]
    signal: dict[str, list[float]] = {"time": [float(t) for t in range(len(padded))]}
    for p in PROPS:
        signal[p] = [1.0 if p in letter else -1.0 for letter in padded]
    robustness = spec.evaluate(signal)[0][1]
    assert _ours(formula, word, len(word) - 1) == (robustness > 0)


@given(formulas, words, st.data())
def test_lassos_agree_with_the_definition(
    formula: Formula, word: list[frozenset[str]], data: st.DataObject
) -> None:
    loop = data.draw(st.integers(0, len(word) - 1))
    assert _ours(formula, word, loop) == holds(formula, word, loop)
