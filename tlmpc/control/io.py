"""``controllers.json`` (``tlmpc.controllers/1``)."""

from __future__ import annotations

import math
from typing import Any

from tlmpc.control.model import Controllers

FORMAT = "tlmpc.controllers/1"


def controllers_to_json(controllers: Controllers) -> dict[str, Any]:
    """The artifact document (an infinite exit-time bound, for a stay, is null)."""
    return {
        "format": FORMAT,
        "max_speed": controllers.max_speed,
        "margin": controllers.margin,
        "loop_start": controllers.loop_start,
        "steps": [
            {
                "step": c.step,
                "triangle": c.triangle,
                "exit_edge": c.exit_edge,
                "next_triangle": c.next_triangle,
                "stay": c.exit_edge is None,
                "vertices": c.vertices.tolist(),
                "vertex_velocities": c.velocities.tolist(),
                "K": c.gain.tolist(),
                "g": c.offset.tolist(),
                "exit_speed": c.exit_speed,
                "exit_time_bound": None if math.isinf(c.exit_time_bound) else c.exit_time_bound,
                "target": list(c.target) if c.target is not None else None,
            }
            for c in controllers.steps
        ],
        "jumps": [
            {"step": j.step, "vertex": j.vertex, "position": list(j.position), "reason": j.reason}
            for j in controllers.jumps
        ],
        "stats": dict(controllers.stats),
    }
