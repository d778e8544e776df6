"""A window that starts far out on a loop is decided on the loop's own instants: moved back
by whole periods (an exact remainder), since past about 1e16 s the floats no longer tell the
instants of a 4-s period apart (``t + 1e17`` is rounded to 16 s).

Worked out by hand: an 8-s loop from x = 0 to x = 4 and back along ``y = 0.5`` (1 m/s each
way); ``a = [3, 5]`` holds on [3, 5) of each period under the right-continuous convention,
so the longest time without ``a`` is 6 s, and 1e6, 1e17, 1e20 and 1e300 (as floats) are
multiples of the period: at t + 1e17 the robot is where it is at t.  The same loop entered
at t = 3, after 3 s coming from x = 4 (inside ``a``) to x = 0, holds ``a`` on [6, 8) of each
period: the same longest gap, and at t + 1e17 (5 s into a period, mod 8) the robot has just
left ``a`` (a window moved back to before the loop would find it in ``a`` at t = 0).
"""

from __future__ import annotations

from typing import Any

import pytest

from tlmpc.verify import verify_document

FAR = ["1e6", "1e17", "1e20", "1e300"]


def loop(ltl: str, wait: float) -> dict[str, Any]:
    """The loop, after ``wait`` seconds coming from x = 4 (0: none)."""
    lap = [[wait, 0.0, 0.5], [wait + 4.0, 4.0, 0.5], [wait + 8.0, 0.0, 0.5]]
    return {
        "format": "tlmpc.trace/1",
        "points": ([[0.0, 4.0, 0.5]] if wait else []) + lap,
        "loop_start": 1 if wait else 0,
        "end": "loop",
        "ltl": ltl,
        "regions": {"a": [[3.0, 0.0], [5.0, 0.0], [5.0, 1.0], [3.0, 1.0]]},
        "workspace": {"boundary": [[-1, -1], [6, -1], [6, 2], [-1, 2]], "holes": []},
        "boundary": "right",
        "max_speed": 10.0,
    }


@pytest.mark.parametrize("wait", [0.0, 3.0])
@pytest.mark.parametrize("start", FAR)
@pytest.mark.parametrize(
    ("task", "outcome"),
    [
        ("G[{s},inf] F[0,5.9] a", "violated"),  # 6 s without a in each 8-s period
        ("G[{s},inf] F[0,6] a", "satisfied"),
        ("F[{s},{s}] a", "violated"),  # at 0 (mod 8) the robot is at x = 0
        ("G[{s},{s}] !a", "satisfied"),
    ],
)
def test_far_windows_read_the_loop_at_their_phase(
    start: str, task: str, outcome: str, wait: float
) -> None:
    assert verify_document(loop(task.format(s=start), wait)).outcome == outcome
