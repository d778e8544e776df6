"""Every diagnostic code the package can emit is explained somewhere in docs/."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CODE_LITERAL = re.compile(r"""["']([A-Z][0-9]{3})["']""")
CODE_WORD = re.compile(r"\b([A-Z][0-9]{3})\b")


def _codes_in_source() -> dict[str, Path]:
    found: dict[str, Path] = {}
    for module in sorted((ROOT / "tlmpc").rglob("*.py")):
        for code in CODE_LITERAL.findall(module.read_text(encoding="utf-8")):
            found.setdefault(code, module)
    return found


def _codes_in_docs() -> set[str]:
    return {
        code
        for page in (ROOT / "docs").rglob("*.md")
        for code in CODE_WORD.findall(page.read_text(encoding="utf-8"))
    }


def test_the_source_emits_codes() -> None:
    # a regex that matched nothing would make the next test pass vacuously
    assert len(_codes_in_source()) > 100


def test_every_code_is_documented() -> None:
    documented = _codes_in_docs()
    missing = {
        code: str(path.relative_to(ROOT))
        for code, path in _codes_in_source().items()
        if code not in documented
    }
    assert not missing, f"codes used in the source but explained nowhere in docs/: {missing}"
