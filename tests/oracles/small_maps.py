"""Small random missions shared by the planner's property tests: a 6 x 5 room, three
rectangular regions ``a``, ``b``, ``c``, one task phrase, and the goal depth off.

``TASKS`` spans the task language's shapes (reach, sequence, patrol, avoid, stay, response,
until); ``RECTS`` draws a region as ``(x0, y0, width, height)`` on the unit grid, so regions
touch, overlap and share edges often.
"""

from __future__ import annotations

import json

from hypothesis import strategies as st

TASKS = (
    "visit a",
    "visit a then b",
    "patrol a, b",
    "visit b while avoiding c",
    "stay in b",
    "whenever a, visit b",
    "avoid c until b",
)

RECTS = st.tuples(st.integers(0, 4), st.integers(0, 3), st.integers(1, 3), st.integers(1, 3))


def small_mission(
    task: str,
    regions: list[tuple[int, int, int, int]],
    start: tuple[float, float],
    boundary: str = "{rect: [0, 0, 6, 5]}",
    quality: bool = False,
) -> str:
    """The mission's YAML text; ``quality``: the default quality mesh (inner points, cells of
    many triangles whose interfaces are several mesh edges) instead of the bare triangulation."""
    lines = "\n".join(
        f"  {name}: {{rect: [{x0}, {y0}, {x0 + w}, {y0 + h}]}}"
        for name, (x0, y0, w, h) in zip("abc", regions, strict=True)
    )
    options = "{goal_depth: 0}" if quality else "{min_angle: null, goal_depth: 0}"
    return (
        f"version: 1\nworkspace:\n  boundary: {boundary}\n"
        f"regions:\n{lines}\nrobot: {{start: [{start[0]}, {start[1]}]}}\n"
        f"task: [{json.dumps(task)}]\noptions: {options}\n"
    )
