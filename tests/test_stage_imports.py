"""Planning, control, simulation and verification never import scipy (not even lazily).

Importing scipy.sparse and scipy.sparse.csgraph cost a compile about a fifth of a second:
the searches, the controller program's sparse matrix and the verifier's geometry use numpy
(and Clarabel, shapely) alone.  Checked on the source, every import statement of these
packages, so a function-local import cannot slip through either.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("planning", "control", "simulate", "verify")


def _imported(path: Path) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


@pytest.mark.parametrize("package", PACKAGES)
def test_stage_package_imports_no_scipy(package: str) -> None:
    files = sorted((ROOT / "tlmpc" / package).rglob("*.py"))
    assert files
    offenders = {
        str(path.relative_to(ROOT)): sorted(
            n for n in _imported(path) if n.split(".")[0] == "scipy"
        )
        for path in files
    }
    assert {k: v for k, v in offenders.items() if v} == {}
