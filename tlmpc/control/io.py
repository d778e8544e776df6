"""``controllers.json`` (``tlmpc.controllers/1``)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from tlmpc.control.model import CellField, Controllers, StepController, VelocityJump

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
                "stay": c.is_stay,
                "vertices": c.vertices.tolist(),
                "vertex_velocities": c.velocities.tolist(),
                "K": c.gain.tolist(),
                "g": c.offset.tolist(),
                "exit_speed": c.exit_speed,
                "exit_time_bound": None if math.isinf(c.exit_time_bound) else c.exit_time_bound,
                "target": list(c.target) if c.target is not None else None,
                **({"kind": c.kind} if c.kind != "affine" else {}),
                **({"cell": _cell_to_json(c.cell)} if c.cell is not None else {}),
            }
            for c in controllers.steps
        ],
        "jumps": [
            {"step": j.step, "vertex": j.vertex, "position": list(j.position), "reason": j.reason}
            for j in controllers.jumps
        ],
        "stats": dict(controllers.stats),
    }


def _cell_to_json(field: CellField) -> dict[str, Any]:
    return {
        "cell": field.cell,
        "target_cell": field.target_cell,
        "triangles": list(field.triangles),
        "vertices": field.vertices.tolist(),
        "vertex_velocities": field.velocities.tolist(),
        "K": field.gains.tolist(),
        "g": field.offsets.tolist(),
        "across": [list(row) for row in field.neighbours],
        "direction": list(field.direction) if field.direction is not None else None,
        "plan_index": field.plan_index,
    }


def _cell_from_json(document: Mapping[str, Any]) -> CellField:
    count = len(document["triangles"])
    return CellField(
        triangles=tuple(int(t) for t in document["triangles"]),
        vertices=_array(document["vertices"], (count, 3, 2)),
        velocities=_array(document["vertex_velocities"], (count, 3, 2)),
        gains=_array(document["K"], (count, 2, 2)),
        offsets=_array(document["g"], (count, 2)),
        neighbours=tuple((int(a), int(b), int(c)) for a, b, c in document["across"]),
        direction=None if document["direction"] is None else _point(document["direction"]),
        cell=int(document["cell"]),
        target_cell=None if document["target_cell"] is None else int(document["target_cell"]),
        plan_index=int(document["plan_index"]),
    )


def _array(value: Any, shape: tuple[int, ...]) -> np.ndarray[Any, np.dtype[np.float64]]:
    array = np.asarray(value, dtype=np.float64).reshape(shape)
    array.setflags(write=False)
    return array


def _point(value: Any) -> tuple[float, float]:
    return float(value[0]), float(value[1])


def controllers_from_json(document: Mapping[str, Any]) -> Controllers:
    """Rebuild the :class:`Controllers` written by :func:`controllers_to_json`."""
    return Controllers(
        steps=tuple(
            StepController(
                step=int(s["step"]),
                triangle=int(s["triangle"]),
                exit_edge=s["exit_edge"],
                next_triangle=s["next_triangle"],
                vertices=_array(s["vertices"], (3, 2)),
                velocities=_array(s["vertex_velocities"], (3, 2)),
                gain=_array(s["K"], (2, 2)),
                offset=_array(s["g"], (2,)),
                exit_speed=float(s["exit_speed"]),
                exit_time_bound=(
                    math.inf if s["exit_time_bound"] is None else float(s["exit_time_bound"])
                ),
                target=None if s["target"] is None else _point(s["target"]),
                kind=s.get("kind", "affine"),
                cell=_cell_from_json(s["cell"]) if "cell" in s else None,
            )
            for s in document["steps"]
        ),
        loop_start=document["loop_start"],
        max_speed=float(document["max_speed"]),
        margin=float(document["margin"]),
        jumps=tuple(
            VelocityJump(
                step=int(j["step"]),
                vertex=int(j["vertex"]),
                position=_point(j["position"]),
                reason=j["reason"],
            )
            for j in document["jumps"]
        ),
        stats=dict(document.get("stats", {})),
    )
