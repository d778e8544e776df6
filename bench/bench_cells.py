"""Convex cells at scale: what the cells' rung costs on large maps, and whether the result holds.

Each row compiles a mission with ``robot.disturbance`` = ratio x ``max_speed`` in a fresh
interpreter (``bench/compile_cold.py``: CPU seconds of the process, wall seconds, peak RSS),
then runs ``tlmpc simulate --model-disturbance adversarial`` on the output and reports the
verdict of its trace. Example 8 (1,156 rooms) at 0.5 is beyond every triangle (at most
sin 22.5 degrees = 0.383 on its mesh) and beyond its own mesh's cells; it compiles on the
reflex cuts' mesh. The room of 40 polygons enters its goals 0.25 deep (a quarter of their
inradius, the default goal depth before it was capped at 0.1 s at ``max_speed``): at that depth
it compiles at 0.5 on the bisector cuts' mesh; at the default depth the cells of every mesh
tried carry at most 0.4516 and it is refused (C032).

    python bench/bench_cells.py
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

#: (label, spec name (grid6: a 6 x 6 grid of rooms; obstacles40: 40 seeded polygons in a
#: 30 x 30 room), disturbance ratio, the simulation's step or None for the mesh's own)
ROWS: tuple[tuple[str, str, float, float | None], ...] = (
    ("example8", "example8", 0.5, None),
    ("example1", "example1", 0.6, None),
    ("rooms 6x6", "grid6", 0.6, None),
    ("40 obstacles", "obstacles40", 0.5, 0.002),
)


def _obstacles(count: int, seed: int) -> dict[str, Any]:
    """``count`` regular polygons (5 to 7 sides) scattered in a 30 x 30 room, apart from each
    other and from the start and goal corners."""
    import math
    import random

    draw = random.Random(seed)
    holes: list[list[list[float]]] = []
    placed: list[tuple[float, float, float]] = []
    while len(holes) < count:
        cx, cy, r = draw.uniform(2, 28), draw.uniform(2, 28), draw.uniform(0.6, 1.4)
        if any(math.hypot(cx - x, cy - y) < r + q + 0.8 for x, y, q in placed):
            continue
        if math.hypot(cx - 1.5, cy - 1.5) < 3 or math.hypot(cx - 28, cy - 28) < 3:
            continue
        sides, turn = draw.choice([5, 6, 7]), draw.uniform(0, 6.28)
        holes.append(
            [
                [
                    round(cx + r * math.cos(turn + 2 * math.pi * i / sides), 3),
                    round(cy + r * math.sin(turn + 2 * math.pi * i / sides), 3),
                ]
                for i in range(sides)
            ]
        )
        placed.append((cx, cy, r))
    return {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, 30, 30]}, "holes": holes},
        "regions": {"a": {"rect": [27, 27, 29, 29]}, "b": {"rect": [1, 27, 3, 29]}},
        "robot": {"start": [1.5, 1.5], "max_speed": 1.0},
        # The depth at which the bisector cuts carry 0.5 (see the module's docstring).
        "options": {"min_angle": None, "goal_depth": 0.25},
        "task": ["visit a and b"],
    }


def _grid(rooms: int) -> dict[str, Any]:
    regions = {
        f"r{i}_{j}": {"rect": [i + 0.25, j + 0.25, i + 0.75, j + 0.75]}
        for i in range(rooms)
        for j in range(rooms)
    }
    return {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, rooms, rooms]}},
        "regions": regions,
        "robot": {"start": [1.5, 2.5], "max_speed": 1.0},
        "options": {"min_angle": None, "max_area": None},
        "task": [f"visit r{rooms - 2}_1 and r1_{rooms - 2}"],
    }


def _document(spec: str) -> dict[str, Any]:
    import yaml

    if spec == "grid6":
        return _grid(6)
    if spec == "obstacles40":
        return _obstacles(40, 4)
    loaded: dict[str, Any] = yaml.safe_load((ROOT / "specs" / f"{spec}.yaml").read_text())
    return loaded


def _row(label: str, spec: str, ratio: float, dt: float | None, folder: Path) -> list[str]:
    import yaml

    document = _document(spec)
    document["robot"]["disturbance"] = ratio * float(document["robot"]["max_speed"])
    mission = folder / f"{label.replace(' ', '-')}.yaml"
    mission.write_text(yaml.safe_dump(document), encoding="utf-8")
    out = folder / f"{mission.stem}-out"
    started = time.perf_counter()
    command = ["compile", str(mission), "-o", str(out), "-q"]
    done = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "compile_cold.py"), *command],
        capture_output=True,
        text=True,
        cwd=ROOT,
        check=False,
    )
    wall = time.perf_counter() - started
    result = json.loads(done.stdout.strip().splitlines()[-1])
    if result["exit"] != 0:
        return [label, f"{ratio:g}", str(result["exit"]), "-", "-", "-"]
    abstraction = json.loads((out / "abstraction.json").read_text(encoding="utf-8"))
    controllers = json.loads((out / "controllers.json").read_text(encoding="utf-8"))
    adversarial = ["--model-disturbance", "adversarial", *([] if dt is None else ["--dt", str(dt)])]
    simulated = subprocess.run(
        [sys.executable, "-m", "tlmpc", "simulate", str(out), *adversarial],
        capture_output=True,
        text=True,
        cwd=ROOT,
        check=False,
    )
    verdict = simulated.stdout.split(":")[1].strip() if simulated.returncode in (0, 1) else "-"
    return [
        label,
        f"{ratio:g}",
        "0",
        f"{abstraction['stats']['triangles']} / {controllers['stats'].get('cells', '-')}",
        f"{result['cpu_seconds']:.1f} / {wall:.1f}",
        verdict,
    ]


def main() -> int:
    from bench.tables import markdown_table

    header = ["mission", "ratio", "exit", "triangles / cells", "CPU / wall s", "adversarial"]
    rows = []
    with tempfile.TemporaryDirectory(prefix="tlmpc-cells-") as tmp:
        for label, spec, ratio, dt in ROWS:
            cells = _row(label, spec, ratio, dt, Path(tmp))
            rows.append(dict(zip(header, cells, strict=True)))
    print(markdown_table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
