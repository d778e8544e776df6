"""Features below the snapping grid (see :mod:`tlmpc.mission.resolution`, where the check
lives so that ``tlmpc check`` runs it without the triangulation's libraries)."""

from tlmpc.mission.resolution import (
    GRID,
    grid_size,
    refuse_subgrid_features,
    subgrid_problems,
)

__all__ = ["GRID", "grid_size", "refuse_subgrid_features", "subgrid_problems"]
