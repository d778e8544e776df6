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
from hypothesis import strategies as st

from tlmpc.errors import NoPlanError
from tlmpc.pipeline import compile_mission
from tlmpc.verify import verdict_to_json, verify_document

TEMPLATES = (
    "visit {a}",
    "visit {a} then {b}",
    "visit {a}, {b} and {c}",
    "avoid {c}",
    "patrol {a}, {b}",
    "stay in {a}",
    "visit {a} then {b} while avoiding {c}",
    "whenever {a}, visit {b}",
    "avoid {c} until {a}",
)


@st.composite
def missions(draw: st.DrawFn) -> dict[str, Any]:
    """A 12 x 8 box with up to one hole and three to five disjoint-or-overlapping regions."""
    regions: dict[str, Any] = {}
    count = draw(st.integers(3, 5))
    for k in range(count):
        x0 = draw(st.integers(0, 9))
        y0 = draw(st.integers(0, 5))
        w = draw(st.integers(1, 3))
        h = draw(st.integers(1, 3))
        regions[f"r{k}"] = {
            "rect": [x0 + 0.25, y0 + 0.25, min(x0 + w, 12) - 0.25, min(y0 + h, 8) - 0.25]
        }
    holes = []
    if draw(st.booleans()):
        holes.append({"rect": [5.5, 3.5, 6.5, 4.5]})
    names = sorted(regions)
    picks = draw(st.permutations(names))
    task = draw(st.sampled_from(TEMPLATES)).format(a=picks[0], b=picks[1], c=picks[2])
    return {
        "version": 1,
        "name": "random",
        "workspace": {"boundary": {"rect": [0, 0, 12, 8]}, "holes": holes},
        "regions": regions,
        "robot": {"start": [0.1, 7.9], "max_speed": 1.0},
        "task": [task],
    }


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
    trace = result.compilation.trace_document
    assert trace is not None
    for boundary in ("right", "closed"):
        verdict = verdict_to_json(verify_document(dict(trace), boundary=boundary))
        if boundary == "right":
            assert verdict["satisfied"], (document["task"], verdict.get("counterexample"))
