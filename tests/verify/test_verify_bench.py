"""The benchmark workload is a real, satisfied verification problem (small version)."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

from tlmpc.verify import verify_document

BENCH = Path(__file__).resolve().parents[2] / "bench" / "bench_verify.py"


def _bench() -> ModuleType:
    spec = importlib.util.spec_from_file_location("bench_verify", BENCH)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_verify_bench_workload_small() -> None:
    doc = _bench().workload(samples=5_000, cols=8, rows=5)
    verdict = verify_document(doc, assume_stay=True)
    assert verdict.satisfied
    # Drop the last row of the sweep: `F (r0_0 & F r7_4)` can no longer hold.
    doc["points"] = [p for p in doc["points"] if p[2] < 4.0]
    assert not verify_document(doc, assume_stay=True).satisfied
