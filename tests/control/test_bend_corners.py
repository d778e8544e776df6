"""The corners a path bends round, read off its channel (tlmpc.pipeline.corners)."""

from __future__ import annotations

from test_follow import _BentCorridor

from tlmpc.control.follow import path_guides
from tlmpc.control.synthesize import plan_steps
from tlmpc.pipeline.corners import bend_corners


def test_bend_corners_name_the_inner_corner_of_a_bent_corridor() -> None:
    """Round an L-shaped corridor's bend the path turns left at the inner corner (2.5, 0.5):
    the corners read off are exactly the mesh vertices there."""
    bent = _BentCorridor()
    steps, loop_start = plan_steps(bent.abstraction, bent.witness)
    guides = path_guides(
        bent.abstraction, steps, loop_start, bent.start, passages=True, clearance=0.0
    )
    found = bend_corners(
        bent.abstraction, [(s.triangle, s.exit_edge) for s in steps], guides, loop_start
    )
    assert found
    assert {tuple(bent.abstraction.vertices[v].tolist()) for v in found} == {(2.5, 0.5)}
