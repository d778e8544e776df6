"""A sequence phrase whose formula, written out, is too large is refused (T005) at once.

`visit a, b, c then a, b, c then ...` means ``⋀_{s ∈ S1} F(s & Φ2)`` with ``Φ2`` repeated
for every region of the step: written out, the formula multiplies by the step's size at each
step, so a phrase of a hundred characters would mean millions of operators, which every later
pass (printing, the contradiction check, translation) walks.
"""

from __future__ import annotations

import pytest
from ci_oracles import import_oracle

from tlmpc.base.errors import InvalidInputError
from tlmpc.ltl import to_text
from tlmpc.tasks import compile_phrase
from tlmpc.tasks.compiler import MAX_PHRASE_NODES

spot = import_oracle("spot")


def _doc_formula(steps: list[list[str]]) -> tuple[str, int]:
    """docs/task-phrases.md's reading ``Φ_k = ⋀_{s ∈ S_k} F(s & Φ_{k+1})`` as text, and its
    size as a tree (``F``, ``&`` with its operands, names)."""
    text, size = "", 0
    for step in reversed(steps):
        parts = [f"F({s} & ({text}))" if text else f"F {s}" for s in step]
        sizes = [3 + size if text else 2 for _ in step]
        text = " & ".join(f"({p})" for p in parts)
        size = sum(sizes) + (1 if len(step) > 1 else 0)
    return text, size


@pytest.mark.parametrize(
    ("regions", "count"), [(3, 6), (3, 8), (3, 9), (3, 12), (2, 14), (2, 15), (4, 7)]
)
def test_a_phrase_is_refused_exactly_when_its_formula_is_too_large(
    regions: int, count: int
) -> None:
    step = ["a", "b", "c", "d"][:regions]
    phrase = "visit " + " then ".join([", ".join(step)] * count)
    _, size = _doc_formula([step] * count)
    if size > MAX_PHRASE_NODES:
        with pytest.raises(InvalidInputError) as caught:
            compile_phrase(phrase, file="m.yaml", line=4, col=5)
        (problem,) = caught.value.diagnostics
        assert (problem.code, problem.line, problem.col) == ("T005", 4, 5)
        assert f"{size:,}" in problem.message
    else:
        compile_phrase(phrase)


@pytest.mark.parametrize(("regions", "count"), [(2, 3), (3, 3), (2, 4)])
def test_a_phrase_within_the_budget_means_the_documented_formula(regions: int, count: int) -> None:
    step = ["a", "b", "c"][:regions]
    phrase = "visit " + " then ".join([", ".join(step)] * count)
    text, _ = _doc_formula([step] * count)
    formula = compile_phrase(phrase)
    assert spot.are_equivalent(spot.formula(to_text(formula)), spot.formula(text))


def test_the_refusal_does_not_write_the_formula_out() -> None:
    # forty steps mean ~5e19 operators: only a count over the shared formula answers at once
    phrase = "visit " + " then ".join(["a, b, c"] * 40)
    with pytest.raises(InvalidInputError) as caught:
        compile_phrase(phrase)
    assert caught.value.diagnostics[0].code == "T005"
