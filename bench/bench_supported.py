"""The largest disturbance each mission's meshes support, and where compiling stops.

For every shipped spec (and a few missions of our own): the largest disturbance any plan
rejects on the mesh with the goal cores (the default goal depth), with cores at half and a
quarter of it, and on the mesh whose goals are entered only as deep as the margin asks
(``tlmpc.planning.bottleneck``, the widest-lasso search), over ``max_speed`` ("-": no plan
without U-turns on that mesh); then the largest ratio at which ``tlmpc compile`` (until
the control stage) succeeds, found by bisection on the compiler itself (to 2^-16), and
whether the goal depth had to yield (A040) there.

    python bench/bench_supported.py [--quick]

``--quick`` prints the same table for :data:`QUICK_MISSIONS` alone, bisecting to
2^-:data:`QUICK_STEPS`: a check in well under a minute, not the published numbers.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

SPECS = ("example1", "example6", "example7", "example8", "patrol", "reach-avoid", "deadline")
#: Bisection steps on the compiler: the largest compiling ratio to 2^-STEPS.
STEPS = 16
#: ``--quick``: one shipped spec and one of our own, and a coarser bisection.
QUICK_MISSIONS = ("example1", "rooms")
QUICK_STEPS = 6

#: Missions of our own: wide corners along some route, a needle-prone corridor, a stay.
OWN: dict[str, dict[str, Any]] = {
    "rhombus-stay": {
        "version": 1,
        "workspace": {"boundary": [[0, 0], [5, -8.660254], [10, 0], [5, 8.660254]]},
        "regions": {"b": [[0, 0], [10, 0], [5, 8.660254]]},
        "robot": {"start": [5, -3], "max_speed": 1.0},
        "options": {"min_angle": 20},
        "task": ["visit b"],
    },
    "corridor-patrol": {
        "version": 1,
        "workspace": {"boundary": {"rect": [0, 0, 12, 3]}},
        "regions": {"a": {"rect": [0, 0, 2, 3]}, "b": {"rect": [10, 0, 12, 3]}},
        "robot": {"start": [6, 1.5], "max_speed": 1.0},
        "task": ["patrol a, b"],
    },
    "rooms": {
        "version": 1,
        "workspace": {
            "boundary": {"rect": [0, 0, 10, 10]},
            "holes": [{"rect": [4, 0, 6, 4]}, {"rect": [4, 6, 6, 10]}],
        },
        "regions": {"a": {"rect": [0, 0, 3, 3]}, "b": {"rect": [7, 7, 10, 10]}},
        "robot": {"start": [1, 9], "max_speed": 1.0},
        "task": ["visit a then b"],
    },
}


def _document(name: str) -> dict[str, Any]:
    import yaml

    if name in OWN:
        return dict(OWN[name])
    loaded: dict[str, Any] = yaml.safe_load((ROOT / "specs" / f"{name}.yaml").read_text())
    return loaded


def _mesh_bounds(document: dict[str, Any]) -> list[float | None]:
    import json

    from tlmpc.ltl.bounds import untimed_skeleton
    from tlmpc.mission import load_mission_text
    from tlmpc.mission.body import requested_margin
    from tlmpc.planning.bottleneck import supported_ratio
    from tlmpc.planning.mission import SHALLOWER, abstraction_for, automaton_for

    mission = load_mission_text(json.dumps(document), "m.yaml")
    found = []
    for scale in (1.0, *SHALLOWER, 0.0):
        mesh = abstraction_for(mission, requested_margin(mission), deep=scale > 0, scale=scale)
        found.append(
            supported_ratio(
                mesh,
                automaton_for(mission, mesh),
                formula=untimed_skeleton(mission.formula),
                options=mission.options,
                start_point=mission.robot.start,
            )
        )
    return found


def _compiles(document: dict[str, Any], ratio: float) -> tuple[bool, bool]:
    import copy

    import tlmpc

    trial = copy.deepcopy(document)
    trial["robot"]["disturbance"] = ratio * float(trial["robot"].get("max_speed", 1.0))
    try:
        compiled = tlmpc.compile(trial, until="control")
    except tlmpc.TlmpcError:
        return False, False
    return True, any(w.code == "A040" for w in compiled.warnings)


def _largest_compiling(document: dict[str, Any], steps: int = STEPS) -> tuple[float, bool]:
    low, high = 0.0, 1.0  # C033 refuses a disturbance of max_speed or more
    yielded = False
    for _ in range(steps):
        middle = (low + high) / 2.0
        ok, warned = _compiles(document, middle)
        if ok:
            low, yielded = middle, warned
        else:
            high = middle
    return low, yielded


def main(argv: list[str] | None = None) -> None:
    """Print one row per mission."""
    from bench.tables import markdown_table

    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="two missions, a coarser bisection")
    args = parser.parse_args(argv)
    names = QUICK_MISSIONS if args.quick else (*SPECS, *OWN)
    steps = QUICK_STEPS if args.quick else STEPS

    def show(value: float | None) -> str:
        return "-" if value is None else f"{value:.5f}"

    rows = []
    for name in names:
        started = time.perf_counter()
        document = _document(name)
        cores, half, quarter, margin = (show(bound) for bound in _mesh_bounds(document))
        largest, yielded = _largest_compiling(document, steps)
        rows.append(
            {
                "mission": name,
                "cores": cores,
                "half": half,
                "quarter": quarter,
                "margin depth": margin,
                "compiles up to": f"{largest:.5f}",
                "A040": "yes" if yielded else "no",
                "s": f"{time.perf_counter() - started:.1f}",
            }
        )
    print(markdown_table(rows))


if __name__ == "__main__":
    main()
