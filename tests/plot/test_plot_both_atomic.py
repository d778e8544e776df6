"""`tlmpc plot OUT --format both` writes its two pictures together: when one of them cannot be
written, the other is left as it was (no plan.svg of this run beside a plan.png of the last)."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("refused", ["plan.png", "plan.svg"])
def test_a_refused_picture_leaves_the_other_as_it_was(tmp_path: Path, refused: str) -> None:
    out = tmp_path / "out"
    assert main(["compile", str(ROOT / "specs" / "example1.yaml"), "-o", str(out), "-q"]) == 0
    other = ({"plan.png", "plan.svg"} - {refused}).pop()
    (out / other).write_bytes(b"the last run's picture")
    (out / refused).unlink(missing_ok=True)
    (out / refused).mkdir()  # a directory is never replaced (U034)
    err = io.StringIO()
    assert main(["plot", str(out), "--format", "both"], io.StringIO(), err) == 2
    assert "error[U034]" in err.getvalue()
    assert (out / other).read_bytes() == b"the last run's picture"
    assert (out / refused).is_dir()
