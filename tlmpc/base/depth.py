"""Room on the Python stack for inputs nested as deep as tlmpc accepts them.

The LTL reader refuses formulas nested more than :data:`NESTING_LIMIT` levels deep (L005); the
passes over a formula (printing, rewriting, translating) and the readers of GR(1)
specifications recurse a few frames per level.  At Python's default limit of 1000 frames a
formula 340 levels deep, which the reader accepts, exhausted the stack in the printer.  The
commands therefore run with the limit raised by what :data:`NESTING_LIMIT` levels need.  That
recursion is in Python code, which CPython calls without growing the C stack; the C parsers
that share the limit (json) then accept some thousands of levels, far within the stack.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager

#: Formulas (and the specifications' expressions) are refused beyond this many levels.
NESTING_LIMIT = 400
#: Frames a pass over a formula spends per level, at most (the printer spends 2.5).
FRAMES_PER_LEVEL = 8


@contextmanager
def nesting_room() -> Iterator[None]:
    """Run the block with the recursion limit raised by what :data:`NESTING_LIMIT` levels
    need (never lowered), and put it back after."""
    before = sys.getrecursionlimit()
    sys.setrecursionlimit(max(before, 1000 + NESTING_LIMIT * FRAMES_PER_LEVEL))
    try:
        yield
    finally:
        sys.setrecursionlimit(before)
