"""A specification that is not UTF-8 is refused (Q001) at the line and column of the first
byte that does not decode, the column counted in characters as the readers count them."""

from __future__ import annotations

import io
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tlmpc.cli import main

SPEC = "[INPUT]\nx\n\n[OUTPUT]\ny\n\n[SYS_LIVENESS]\ny\n\n[ENV_LIVENESS]\nx\n"


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    where=st.integers(0, len(SPEC)),
    bad=st.sampled_from([b"\xff", b"\xc3", b"\x80", b"\xed\xa0\x80"]),
    before=st.sampled_from(["", "é", "日本 "]),
)
def test_the_undecodable_byte_is_placed(
    tmp_path: Path, where: int, bad: bytes, before: str
) -> None:
    text = SPEC[:where] + before
    data = text.encode("utf-8") + bad + SPEC[where:].encode("utf-8")
    path = tmp_path / "spec.slugsin"
    path.write_bytes(data)
    err = io.StringIO()
    assert main(["synth", str(path)], out=io.StringIO(), err=err) == 2
    # by hand: lines end at "\n"; the column counts the characters before the byte
    line = text.count("\n") + 1
    col = len(text) - (text.rfind("\n") + 1) + 1
    assert err.getvalue().startswith(f"{path}:{line}:{col}: error[Q001]: "), err.getvalue()
