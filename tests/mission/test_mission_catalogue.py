"""The catalogue of bad missions: each gives its expected error code at its expected line."""

from __future__ import annotations

from pathlib import Path

import pytest

from tlmpc.mission import check_file

BAD = sorted((Path(__file__).parent / "bad").glob("*.yaml"))


def _expectation(path: Path) -> tuple[str, int]:
    first = path.read_text(encoding="utf-8").split("\n", 1)[0]
    code, line = first.removeprefix("# expect:").split()
    return code, int(line)


def test_the_catalogue_is_large_enough() -> None:
    assert len(BAD) >= 25


@pytest.mark.parametrize("path", BAD, ids=lambda p: p.stem)
def test_bad_mission_reports_code_and_line(path: Path) -> None:
    code, line = _expectation(path)
    diagnostics = check_file(path)
    assert diagnostics, "an invalid mission must produce diagnostics"
    assert (code, line) in [(d.code, d.line) for d in diagnostics]
    for diagnostic in diagnostics:
        assert diagnostic.file == str(path)
        assert diagnostic.format().startswith(f"{path}:")
        assert diagnostic.severity == "error"
