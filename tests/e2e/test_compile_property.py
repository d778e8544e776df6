"""Property: every trace that `tlmpc compile` produces satisfies its task.

Random missions (random rectangles as regions, sometimes a hole, a random task over them drawn
from the whole task language: reachability, sequences, safety only, until, release, patrol,
response, persistence; see ``strategies.TEMPLATES``) are compiled end to end.  When a plan
exists, the independent verifier must accept the trace under the right-continuous convention,
which is what the plan guarantees; under the strict closed convention a boundary instant lies in
every region it touches, which can only add labels, so a task whose negation normal form has
no negation and only ``& | F G`` must still hold there.  When no plan exists, the compiler must
say why (P-diagnostics), never crash; such draws are labelled (``--hypothesis-show-statistics``
shows how much of the budget they take).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from strategies import TEMPLATES, missions_with_template

from tlmpc.base.errors import NoPlanError
from tlmpc.ltl import nnf, parse_ltl
from tlmpc.ltl.ast import And, Eventually, Formula, Globally, Or, Prop
from tlmpc.pipeline.stages import TRACE, compile_mission
from tlmpc.verify import verdict_to_json, verify_document


def _positive_reachability(formula: Formula) -> bool:
    """No negation and only ``& | F G`` over propositions, in negation normal form: more
    labels can only make it truer, and no operator has a point rule."""
    return all(isinstance(n, Prop | And | Or | Eventually | Globally) for n in nnf(formula).walk())


def _compile(document: dict[str, Any], tmp_path: Path) -> dict[str, Any] | None:
    path = tmp_path / "mission.yaml"
    path.write_text(yaml.safe_dump(document))
    try:
        result = compile_mission(path, until="simulate")
    except NoPlanError as exc:
        codes = [d.code for d in exc.diagnostics]
        assert codes, document
        assert all(code.startswith("P") for code in codes), codes
        return None
    trace = result.compilation.get(TRACE)
    assert trace is not None
    return dict(trace)


@pytest.mark.parametrize("template", TEMPLATES)
@settings(max_examples=2, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_every_compiled_trace_verifies(template: str, data: st.DataObject, tmp_path: Path) -> None:
    # One property per template: a derandomized draw over all of them spends half its budget
    # on a few templates, and some kinds of task would go untested.
    document, _ = data.draw(missions_with_template(template))
    trace = _compile(document, tmp_path)
    if trace is None:
        event("no plan")
        return
    event("planned")
    right = verdict_to_json(verify_document(dict(trace), boundary="right"))
    assert right["satisfied"], (document, right.get("counterexample"))
    closed = verdict_to_json(verify_document(dict(trace), boundary="closed"))
    assert closed["verdict"] in ("satisfied", "violated")  # a lasso or a stay: two-valued
    if _positive_reachability(parse_ltl(str(trace["ltl"]))):
        assert closed["satisfied"], (document, closed.get("counterexample"))


def test_the_templates_cover_the_task_language() -> None:
    """Every kind of task the property promises is among the templates."""
    parsed = [
        parse_ltl(t.removeprefix("ltl: ").format(a="a", b="b", c="c"))
        for t in TEMPLATES
        if t.startswith("ltl: ")
    ]
    assert any("R" in str(f) for f in parsed)
    phrases = " ".join(t for t in TEMPLATES if not t.startswith("ltl: "))
    for word in ("patrol", "whenever", "until", "avoid", "stay", "then", "infinitely often"):
        assert word in phrases, word
    assert "avoid {c}" in TEMPLATES  # safety only
