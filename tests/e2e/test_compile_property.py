"""Property: every trace that `tlmpc compile` produces satisfies its task.

Random missions (random rectangles as regions and holes, random task phrases over them) are
compiled end to end; when a plan exists, the independent verifier must accept the trace, under
both boundary conventions; when none exists, the compiler must say why (exit 1 diagnostics),
never crash.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from hypothesis import HealthCheck, given, settings
from strategies import missions

from tlmpc.errors import NoPlanError
from tlmpc.pipeline import TRACE, compile_mission
from tlmpc.verify import verdict_to_json, verify_document


@settings(max_examples=12, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(document=missions())
def test_every_compiled_trace_verifies(document: dict[str, Any], tmp_path: Path) -> None:
    path = tmp_path / "mission.yaml"
    path.write_text(yaml.safe_dump(document))
    try:
        result = compile_mission(path, until="simulate")
    except NoPlanError as exc:
        codes = [d.code for d in exc.diagnostics]
        assert all(code.startswith("P") for code in codes), codes
        return
    trace = result.compilation.get(TRACE)
    assert trace is not None
    for boundary in ("right", "closed"):
        verdict = verdict_to_json(verify_document(dict(trace), boundary=boundary))
        if boundary == "right":
            assert verdict["satisfied"], (document["task"], verdict.get("counterexample"))
