"""The LTL parser is built once and reused from the per-user cache; a bad cache is harmless.

(The lark parser itself: plain formulas are read without it, see tests/ltl/test_ltl_reader.py.)
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

_PROGRAM = (
    "from tlmpc.ltl.lark_parser import parse_ltl\n"
    "from tlmpc.ltl.printer import to_text\n"
    "print(to_text(parse_ltl('G (a -> F b) & !c U d')))\n"
)


def _parse_in_fresh_process(cache: str, **extra: str) -> str:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TLMPC_CACHE_DIR": cache, **extra}
    done = subprocess.run(
        [sys.executable, "-c", _PROGRAM], capture_output=True, text=True, env=env, check=False
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_parser_is_cached_and_reused(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first = _parse_in_fresh_process(str(cache))
    files = sorted(cache.glob("lark-*.cache"))
    assert len(files) == 1
    stamp = files[0].stat().st_mtime_ns
    assert _parse_in_fresh_process(str(cache)) == first
    # Reused, not rebuilt: the file is neither rewritten nor joined by another.
    assert sorted(cache.glob("lark-*.cache")) == files
    assert files[0].stat().st_mtime_ns == stamp


def test_a_corrupt_cache_only_costs_a_rebuild(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    expected = _parse_in_fresh_process(str(cache))
    (cached,) = cache.glob("lark-*.cache")
    cached.write_bytes(b"not a parser")
    assert _parse_in_fresh_process(str(cache)) == expected


def test_the_cache_can_be_switched_off(tmp_path: Path) -> None:
    expected = _parse_in_fresh_process(str(tmp_path / "cache"))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    output = _parse_in_fresh_process(
        "off", HOME=str(elsewhere), XDG_CACHE_HOME=str(elsewhere), TMPDIR=str(elsewhere)
    )
    assert output == expected
    assert list(elsewhere.rglob("*")) == []
