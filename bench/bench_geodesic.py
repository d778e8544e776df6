"""How close the simulated trajectory comes to the shortest path, before and after the
controllers follow the channel's shortest path.

For every workload the mission is compiled twice through the whole pipeline: *before* with the
vertex program's fields alone (``synthesize(..., follow=False)``), *after* with the fields that
follow the channel (the default).  Measured on the exact closed-loop trajectory (trace.json,
each sampled piece refined by the step's own matrix exponential):

* **length ratio**: the trajectory's length until the task is met (the first entry into its
  last target) over the shortest path from the start touching the same targets in the same
  order, keeping the body's clearance and off the avoided regions (tests/oracles/
  shortest_paths.py: a visibility graph on shapely geometry, independent of tlmpc);
* **time ratio**: the time the task is met over that shortest length at ``max_speed``;
* **lap ratio** (patrols): one lap of the trajectory's cycle over the shortest closed tour
  touching the targets in the lap's cyclic order; **lap / best order**: over the shortest
  closed tour touching them in any order (the best lasso's lap);
* **robustness**: the verifier's (how far the trajectory stays from every label boundary that
  would change the verdict): a path that hugs the shortest one passes closer to them.

Targets are given per workload as ordered groups: the regions of a group are taken in the
order the trajectory first enters them (so the oracle compares the same visiting order; a
better order is the planner's business, not the controllers').  Prints one table.
Run: ``python bench/bench_geodesic.py`` (about a minute); ``--speed`` splits the time lost to
speeds below max_speed by kind of plan step (:func:`speed_rows`).
"""

from __future__ import annotations

import functools
import itertools
import math
import random
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from unittest import mock

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
for extra in (ROOT, ROOT / "tests" / "oracles"):
    if str(extra) not in sys.path:
        sys.path.insert(0, str(extra))


@dataclass(frozen=True)
class Workload:
    """A mission and what its task asks: ordered groups of targets, regions to avoid."""

    name: str
    mission: Any  # a path or a mission dict
    groups: tuple[tuple[str, ...], ...]
    avoid: tuple[str, ...] = ()
    patrol: bool = False


def shipped() -> list[Workload]:
    """The shipped specs (Example 1's 'avoiding p2 and p3' is left out of the oracle: its
    path is then a lower bound and the ratio an upper bound)."""
    specs = ROOT / "specs"
    rooms = tuple(f"r{k}" for k in range(1, 7))
    return [
        Workload("example1", specs / "example1.yaml", (("p2",), ("p3",), ("p4",), ("p1",))),
        Workload("example6", specs / "example6.yaml", (rooms,)),
        Workload(
            "example7",
            specs / "example7.yaml",
            (("r2",), ("r1",), ("r3", "r4", "r5")),
            avoid=("o1", "o2", "o3"),
        ),
        Workload("example8", specs / "example8.yaml", (("r31_13", "r12_30"),)),
        Workload("reach-avoid", specs / "reach-avoid.yaml", (("dock",), ("home",)), ("hazard",)),
        Workload(
            "patrol",
            specs / "patrol.yaml",
            (("alpha", "bravo", "charlie"),),
            avoid=("lake",),
            patrol=True,
        ),
    ]


def _rect(x: float, y: float, w: float, h: float) -> list[float]:
    return [round(x, 3), round(y, 3), round(x + w, 3), round(y + h, 3)]


def generated(seed: int, *, radius: float = 0.0, patrol: bool = False) -> Workload:
    """A random room: a 16 x 10 box with 5 to 9 rectangular pillars, 3 goal regions and an
    avoided pond, start in a corner; visit the goals in sequence, or patrol them."""
    rng = random.Random(seed)
    holes: list[list[float]] = []
    while len(holes) < rng.randint(5, 9):
        w, h = rng.uniform(0.4, 2.5), rng.uniform(0.4, 2.5)
        holes.append(_rect(rng.uniform(2.0, 14.0 - w), rng.uniform(1.0, 9.0 - h), w, h))
    regions = {
        "a": {"rect": _rect(13.5, 0.5, 2.0, 2.0)},
        "b": {"rect": _rect(13.5, 7.5, 2.0, 2.0)},
        "c": {"rect": _rect(7.0, 8.6, 2.0, 1.2)},
        "pond": {"rect": _rect(rng.uniform(3.0, 11.0), rng.uniform(0.2, 1.0), 1.5, 1.0)},
    }
    robot: dict[str, Any] = {"start": [0.8, 0.8], "max_speed": 1.0}
    if radius:
        robot["radius"] = radius
    task = ["patrol a, b and c"] if patrol else ["visit a then b then c"]
    document = {
        "version": 1,
        "name": f"room-{seed}",
        "workspace": {"boundary": {"rect": [0, 0, 16, 10]}, "holes": [{"rect": h} for h in holes]},
        "regions": regions,
        "robot": robot,
        "task": [*task, "avoid pond"],
    }
    name = f"room-{seed}" + (f" r={radius:g}" if radius else "") + (" patrol" if patrol else "")
    groups = (("a", "b", "c"),) if patrol else (("a",), ("b",), ("c",))
    return Workload(name, document, groups, avoid=("pond",), patrol=patrol)


def held_out() -> list[Workload]:
    """Missions written for this bench alone (no shipped spec, no generator): an office
    floor with a point robot, a warehouse aisle with a body, a patrol around a courtyard."""
    office = {
        "version": 1,
        "name": "office",
        "workspace": {
            "boundary": {"rect": [0, 0, 20, 12]},
            "holes": [
                {"rect": [4, 0, 4.3, 8]},
                {"rect": [9, 4, 9.3, 12]},
                {"rect": [14, 0, 14.3, 7]},
                {"rect": [16, 9, 20, 9.3]},
            ],
        },
        "regions": {
            "desk": {"rect": [1, 9, 3, 11]},
            "printer": {"rect": [11, 0.5, 12.5, 2]},
            "kitchen": {"rect": [17, 10, 19.5, 11.7]},
            "wet": {"rect": [6, 5, 7.5, 7]},
        },
        "robot": {"start": [1.0, 1.0], "max_speed": 1.0},
        "task": ["visit desk then printer then kitchen", "avoid wet"],
    }
    warehouse = {
        "version": 1,
        "name": "warehouse",
        "workspace": {
            "boundary": {"rect": [0, 0, 24, 14]},
            "holes": [{"rect": [3 + 4 * k, 2, 4.2 + 4 * k, 11]} for k in range(5)],
        },
        "regions": {
            "pick": {"rect": [8.4, 12, 10.6, 13.6]},
            "pack": {"rect": [21.5, 1, 23.5, 3]},
            "spill": {"rect": [13.5, 5, 14.8, 7]},
        },
        "robot": {"start": [1.0, 7.0], "max_speed": 1.5, "radius": 0.3},
        "task": ["visit pick then pack", "avoid spill"],
    }
    courtyard = {
        "version": 1,
        "name": "courtyard",
        "workspace": {
            "boundary": [[0, 0], [16, 0], [16, 12], [0, 12]],
            "holes": [[[5, 4], [11, 3.5], [11.5, 8], [6, 8.5]]],
        },
        "regions": {
            "gate": {"rect": [0.5, 5, 2, 7]},
            "tower": {"rect": [13.5, 9.5, 15.5, 11.5]},
            "well": {"rect": [12.5, 1, 14, 2.5]},
        },
        "robot": {"start": [1.0, 1.0], "max_speed": 1.0, "radius": 0.15},
        "task": ["patrol gate, tower and well"],
    }
    return [
        Workload("office", office, (("desk",), ("printer",), ("kitchen",)), avoid=("wet",)),
        Workload("warehouse r=0.3", warehouse, (("pick",), ("pack",)), avoid=("spill",)),
        Workload("courtyard patrol", courtyard, (("gate", "tower", "well"),), patrol=True),
    ]


def held_out_late() -> list[Workload]:
    """Missions written after the exit insets and touch splits were tuned, to measure them on
    maps they never saw: a lab with slanted benches and a margin, a hospital ward with a body,
    a margin and an explicit goal depth, a patrol of four posts round a yard of polygons."""
    lab = {
        "version": 1,
        "name": "lab",
        "workspace": {
            "boundary": [[0, 0], [22, 0], [22, 9], [14, 14], [0, 14]],
            "holes": [
                [[3, 2], [8, 4], [7.4, 5.4], [2.4, 3.4]],
                [[10, 6], [13, 9.5], [11.8, 10.4], [8.8, 6.9]],
                [[15, 1.5], [19, 1.5], [19, 3], [15, 3]],
                [[4, 8], [6, 8], [6, 12.5], [4, 12.5]],
            ],
        },
        "regions": {
            "hood": {"rect": [1, 11, 3, 13]},
            "scale": {"rect": [17, 4.5, 19.5, 6.5]},
            "sink": [[8, 11], [10.5, 11], [10.5, 13], [8, 13]],
            "spill": {"rect": [12, 3, 13.5, 5]},
        },
        "robot": {"start": [1.0, 1.0], "max_speed": 0.8},
        "task": ["visit hood then scale then sink", "avoid spill"],
        "options": {"margin": 0.2},
    }
    ward = {
        "version": 1,
        "name": "ward",
        "workspace": {
            "boundary": {"rect": [0, 0, 30, 12]},
            "holes": [
                {"rect": [6, 0, 6.4, 4.5]},
                {"rect": [6, 6.5, 6.4, 12]},
                {"rect": [13, 3, 17, 9]},
                {"rect": [23, 0, 23.4, 7]},
            ],
        },
        "regions": {
            "bed1": {"rect": [1, 9, 4, 11.5]},
            "bed2": {"rect": [19, 0.5, 22, 2.5]},
            "nurse": {"rect": [26, 9, 29.5, 11.5]},
            "cart": {"rect": [9, 5, 11, 7]},
        },
        "robot": {"start": [2.0, 2.0], "max_speed": 1.2, "radius": 0.25},
        "task": ["visit bed1, bed2 and nurse", "avoid cart"],
        "options": {"margin": 0.1, "goal_depth": 0.3},
    }
    yard = {
        "version": 1,
        "name": "yard",
        "workspace": {
            "boundary": [[0, 0], [20, 0], [20, 16], [0, 16]],
            "holes": [
                [[6, 5], [10, 4], [12, 7], [9, 10], [6, 8.5]],
                [[14, 10], [17, 11], [15.5, 13.5]],
            ],
        },
        "regions": {
            "north": {"rect": [8, 13.5, 10.5, 15.5]},
            "east": {"rect": [18, 6, 19.6, 8.5]},
            "south": {"rect": [9, 0.4, 11.5, 2]},
            "west": {"rect": [0.4, 7, 2, 9.5]},
        },
        "robot": {"start": [1.0, 1.0], "max_speed": 1.0, "radius": 0.1},
        "task": ["patrol north, east, south and west"],
    }
    return [
        Workload("lab m=0.2", lab, (("hood",), ("scale",), ("sink",)), avoid=("spill",)),
        Workload("ward r=0.25 m=0.1", ward, (("bed1", "bed2", "nurse"),), avoid=("cart",)),
        Workload("yard r=0.1 patrol", yard, (("north", "east", "south", "west"),), patrol=True),
    ]


def held_out_depth() -> list[Workload]:
    """Missions written after the default goal depth (0.1 s at max_speed) and the clearance
    at a region's own boundary were tuned, measured once: an L-shaped clinic with a body and
    a margin, a hangar of large bays crossed by a fast point robot, a patrol of three posts
    round a campus with a body."""
    clinic = {
        "version": 1,
        "name": "clinic",
        "workspace": {
            "boundary": [[0, 0], [26, 0], [26, 10], [12, 10], [12, 20], [0, 20]],
            "holes": [
                {"rect": [5, 3, 5.3, 10]},
                {"rect": [5, 12, 9, 12.3]},
                {"rect": [16, 4, 21, 6.5]},
                {"rect": [7.5, 15, 8, 20]},
            ],
        },
        "regions": {
            "reception": {"rect": [1, 1, 4, 4]},
            "pharmacy": {"rect": [22, 6.5, 25.5, 9.5]},
            "xray": {"rect": [8.5, 16, 11.5, 19.5]},
            "wet": {"rect": [9, 5, 11, 7]},
        },
        "robot": {"start": [2.5, 8.0], "max_speed": 0.8, "radius": 0.2},
        "task": ["visit reception then pharmacy then xray", "avoid wet"],
        "options": {"margin": 0.15},
    }
    hangar = {
        "version": 1,
        "name": "hangar",
        "workspace": {
            "boundary": {"rect": [0, 0, 40, 25]},
            "holes": [
                [[8, 8], [16, 9], [15, 14], [9, 15]],
                [[22, 4], [30, 4], [30, 10], [22, 10]],
                [[24, 15], [33, 15], [31, 21], [26, 21]],
            ],
        },
        "regions": {
            "bay1": {"rect": [1, 17, 9, 24]},
            "bay2": {"rect": [32, 1, 39, 9]},
            "bay3": {"rect": [34, 16, 39.5, 24.5]},
            "fuel": {"rect": [17, 16, 21, 20]},
        },
        "robot": {"start": [2.0, 2.0], "max_speed": 2.0},
        "task": ["visit bay1 then bay2 then bay3", "avoid fuel"],
    }
    campus = {
        "version": 1,
        "name": "campus",
        "workspace": {
            "boundary": [[0, 0], [24, 0], [24, 18], [0, 18]],
            "holes": [
                {"rect": [4, 4, 10, 8]},
                {"rect": [13, 3, 19, 7]},
                [[6, 11], [11, 11], [11, 15], [8, 16]],
                {"rect": [15, 10, 20, 14]},
            ],
        },
        "regions": {
            "library": {"rect": [1, 14, 4, 17]},
            "gym": {"rect": [21, 1, 23.5, 4]},
            "hall": {"rect": [20.5, 15, 23.5, 17.5]},
            "pond": {"rect": [11.5, 8, 14, 10]},
        },
        "robot": {"start": [1.0, 1.0], "max_speed": 1.5, "radius": 0.25},
        "task": ["patrol library, gym and hall", "avoid pond"],
    }
    return [
        Workload(
            "clinic r=0.2 m=0.15",
            clinic,
            (("reception",), ("pharmacy",), ("xray",)),
            avoid=("wet",),
        ),
        Workload("hangar v=2", hangar, (("bay1",), ("bay2",), ("bay3",)), avoid=("fuel",)),
        Workload(
            "campus r=0.25 patrol",
            campus,
            (("library", "gym", "hall"),),
            avoid=("pond",),
            patrol=True,
        ),
    ]


def held_out_detours() -> list[Workload]:
    """A mission written after the velocity-run splits, the floor cap and the cycle detours
    were tuned, measured once: a depot patrolled by a robot with a body among racks, an
    L-shaped wall and a puddle to avoid."""
    depot = {
        "version": 1,
        "name": "depot",
        "workspace": {
            "boundary": [[0, 0], [18, 0], [18, 12], [6, 12], [0, 9]],
            "holes": [
                {"rect": [3, 2, 8, 3]},
                {"rect": [3, 5, 8, 6]},
                [[11, 3], [12, 3], [12, 8], [15, 8], [15, 9], [11, 9]],
            ],
        },
        "regions": {
            "dock": {"rect": [0.5, 0.5, 2.2, 2.2]},
            "charger": {"rect": [16, 10, 17.5, 11.5]},
            "inspection": {"rect": [13, 4, 14.5, 6]},
            "puddle": [[8.5, 9], [10, 8.5], [10.5, 10], [9, 10.6]],
        },
        "robot": {"start": [1.5, 7.0], "max_speed": 1.2, "radius": 0.2},
        "task": ["patrol dock, charger and inspection", "avoid puddle"],
    }
    return [
        Workload(
            "depot r=0.2 patrol",
            depot,
            (("dock", "charger", "inspection"),),
            avoid=("puddle",),
            patrol=True,
        )
    ]


def held_out_orders() -> list[Workload]:
    """Missions written after the visiting orders were added, measured once: a body of
    radius 0.15 at 1.2 m/s patrolling five stations round a machine hall, listed as they come
    to mind, and a slow body of radius 0.25 visiting three rooms of a flat in turn, avoiding a
    rug."""
    hall = {
        "version": 1,
        "name": "hall",
        "workspace": {
            "boundary": [[0, 0], [24, 0], [24, 14], [15, 14], [15, 18], [0, 18]],
            "holes": [
                {"rect": [4, 4, 9, 6]},
                {"rect": [12, 3, 13, 9]},
                [[16, 8], [20, 7], [21, 10], [17, 11]],
                {"rect": [5, 10, 10, 12.5]},
            ],
        },
        "regions": {
            "lathe": {"rect": [21.5, 1, 23.5, 3]},
            "press": {"rect": [1, 15.5, 3, 17.5]},
            "mill": {"rect": [20.5, 11.5, 23, 13.5]},
            "store": {"rect": [1, 1, 3, 3]},
            "desk": {"rect": [12, 15, 14.5, 17.5]},
            "oil": {"rect": [13.5, 10, 15.5, 12]},
        },
        "robot": {"start": [10.5, 1.5], "max_speed": 1.2, "radius": 0.15},
        "task": ["patrol lathe, press, mill, store and desk", "avoid oil"],
    }
    flat = {
        "version": 1,
        "name": "flat",
        "workspace": {
            "boundary": {"rect": [0, 0, 15, 11]},
            "holes": [
                {"rect": [6, 0, 6.3, 4.5]},
                {"rect": [6, 6, 6.3, 11]},
                {"rect": [6.3, 5.5, 11, 5.8]},
                {"rect": [11.8, 5.5, 15, 5.8]},
            ],
        },
        "regions": {
            "kitchen": {"rect": [1, 8, 3.5, 10.5]},
            "bedroom": {"rect": [12, 1, 14.5, 3.5]},
            "bath": {"rect": [12.5, 8, 14.5, 10.5]},
            "rug": {"rect": [2, 3, 4.5, 5.5]},
        },
        "robot": {"start": [1.0, 1.0], "max_speed": 0.5, "radius": 0.25},
        "task": ["visit kitchen then bedroom then bath", "avoid rug"],
    }
    return [
        Workload(
            "hall r=0.15 patrol",
            hall,
            (("lathe", "press", "mill", "store", "desk"),),
            avoid=("oil",),
            patrol=True,
        ),
        Workload(
            "flat r=0.25 v=0.5",
            flat,
            (("kitchen",), ("bedroom",), ("bath",)),
            avoid=("rug",),
        ),
    ]


def held_out_tours() -> list[Workload]:
    """A mission written after the tour order (the fallback past the budget) was added,
    measured once: a point robot at 1.5 m/s patrolling six rooms of a school's corridor
    loop, avoiding a stairwell (its product is small enough for every order to be planned)."""
    school = {
        "version": 1,
        "name": "school",
        "workspace": {
            "boundary": {"rect": [0, 0, 30, 16]},
            "holes": [
                {"rect": [4, 4, 13, 12]},
                {"rect": [17, 4, 26, 12]},
                {"rect": [14.5, 0, 15.5, 2.5]},
            ],
        },
        "regions": {
            "art": {"rect": [0.5, 13, 3, 15.5]},
            "gym": {"rect": [27, 0.5, 29.5, 3]},
            "music": {"rect": [14, 13.5, 16, 15.5]},
            "science": {"rect": [0.5, 0.5, 3, 3]},
            "office": {"rect": [27, 13, 29.5, 15.5]},
            "library": {"rect": [13.5, 6, 16.5, 9]},
            "stairs": {"rect": [6, 13, 8, 16]},
        },
        "robot": {"start": [10.0, 2.0], "max_speed": 1.5},
        "task": ["patrol art, gym, music, science, office and library", "avoid stairs"],
    }
    return [
        Workload(
            "school patrol",
            school,
            (("art", "gym", "music", "science", "office", "library"),),
            avoid=("stairs",),
            patrol=True,
        )
    ]


def held_out_corners() -> list[Workload]:
    """Missions written after the corner-reach gain and the disturbance-free floor cap were
    tuned, measured once: a greenhouse crossed by a slow robot with a wide body and a margin
    between slanted beds, and a library's stacks for a fast point robot with a margin."""
    greenhouse = {
        "version": 1,
        "name": "greenhouse",
        "workspace": {
            "boundary": [[0, 0], [26, 0], [26, 16], [0, 16]],
            "holes": [
                [[4, 3], [9, 4.5], [8.4, 6], [3.4, 4.5]],
                [[12, 2], [14, 2], [15, 9], [13, 9]],
                [[5, 9], [10, 8], [10.4, 9.6], [5.4, 10.6]],
                [[18, 6], [23, 5], [23.5, 7], [18.5, 8]],
                [[16, 11], [20, 11], [20, 13.5], [16, 13.5]],
            ],
        },
        "regions": {
            "seedlings": {"rect": [1, 12, 3.5, 14.5]},
            "pump": {"rect": [22.5, 1, 24.5, 3]},
            "potting": {"rect": [22, 12.5, 25, 15]},
            "wet": [[10.5, 4], [11.6, 4.2], [11.4, 6.5], [10.4, 6]],
        },
        "robot": {"start": [1.2, 1.2], "max_speed": 0.6, "radius": 0.35},
        "options": {"margin": 0.1},
        "task": ["visit seedlings then pump then potting", "avoid wet"],
    }
    library = {
        "version": 1,
        "name": "library",
        "workspace": {
            "boundary": {"rect": [0, 0, 30, 18]},
            "holes": [{"rect": [4 + 5 * k, 3, 5 + 5 * k, 8 + (k % 2) * 4]} for k in range(5)]
            + [{"rect": [6, 13, 16, 14]}],
        },
        "regions": {
            "desk": {"rect": [1, 1, 3, 3]},
            "archive": {"rect": [26, 14, 29, 17]},
            "reading": {"rect": [17, 15, 21, 17.5]},
            "stairs": {"rect": [26, 6, 28, 9]},
        },
        "robot": {"start": [2.0, 16.0], "max_speed": 1.8},
        "options": {"margin": 0.25},
        "task": ["visit desk then archive then reading", "avoid stairs"],
    }
    return [
        Workload(
            "greenhouse r=0.35 m=0.1",
            greenhouse,
            (("seedlings",), ("pump",), ("potting",)),
            avoid=("wet",),
        ),
        Workload(
            "library v=1.8 m=0.25",
            library,
            (("desk",), ("archive",), ("reading",)),
            avoid=("stairs",),
        ),
    ]


def _compile(workload: Workload, follow: bool) -> tuple[Any, float]:
    """The compiled mission and the length of the path its fields follow (the channel's
    shortest path with the portal insets; nan before)."""
    import importlib

    from tlmpc.api import compile as compile_mission

    control = importlib.import_module("tlmpc.control")
    module = importlib.import_module("tlmpc.control.synthesize")
    original, guides = module.path_guides, []

    def recorded(*args: Any, **keywords: Any) -> Any:
        guides[:] = original(*args, **keywords)
        return list(guides)

    fields = functools.partial(module.synthesize, follow=follow)
    with (
        mock.patch.object(control, "synthesize", fields),
        mock.patch.object(module, "path_guides", recorded),
    ):
        mission = workload.mission
        compiled = compile_mission(str(mission) if isinstance(mission, Path) else mission)
    length = sum(math.dist(g.entry, g.exit) for g in guides if g is not None)
    return compiled, length if guides else float("nan")


def _fine_trajectory(artifacts: Any, pieces: int = 8) -> tuple[Any, Any]:
    """Times and points of the trajectory, each sampled piece subdivided exactly."""
    from scipy.linalg import expm

    trace = artifacts["trace.json"]
    controllers = artifacts["controllers.json"]["steps"]
    samples = np.asarray(trace["points"], dtype=np.float64)
    steps = trace["steps"]
    times, points = [samples[0, 0]], [samples[0, 1:]]
    for k in range(1, len(samples)):
        t0, t1 = samples[k - 1, 0], samples[k, 0]
        step = controllers[steps[k]]
        if steps[k] == steps[k - 1] and step.get("kind", "affine") == "affine" and t1 > t0:
            matrix = np.zeros((3, 3))
            matrix[:2, :2] = np.asarray(step["K"])
            matrix[:2, 2] = np.asarray(step["g"])
            start = np.append(samples[k - 1, 1:], 1.0)
            for j in range(1, pieces):
                tau = (t1 - t0) * j / pieces
                times.append(t0 + tau)
                points.append((expm(tau * matrix) @ start)[:2])
        times.append(t1)
        points.append(samples[k, 1:])
    return np.asarray(times), np.asarray(points)


def _travelled(artifacts: Any) -> float:
    """The whole trajectory's length (to the end of the trace)."""
    _, points = _fine_trajectory(artifacts)
    return float(np.hypot(*np.diff(points, axis=0).T).sum())


def _order(points: Any, shapes: dict[str, Any], groups: Any, begin: int = 0) -> tuple[list, int]:
    """The targets in the order the trajectory meets them (group by group), and the index of
    the point where the last one is first entered (-1 when never)."""
    import shapely

    order: list[str] = []
    index = begin
    for group in groups:
        pending = set(group)
        while pending:
            if index >= len(points):
                return order, -1
            inside = [n for n in sorted(pending) if shapes[n].covers(shapely.Point(points[index]))]
            if inside:
                order.extend(inside)
                pending -= set(inside)
                if not pending:
                    break
            index += 1
    return order, index


_BEST: dict[tuple[str, tuple[str, ...], bool], float] = {}


def _best(key: tuple[str, tuple[str, ...], bool], free: Any, targets: Any, start: Any) -> float:
    """The oracle's length for one workload and visiting order (computed once per order)."""
    from shortest_paths import VisibilityOracle

    if key not in _BEST:
        oracle = VisibilityOracle(free, targets, start)
        _BEST[key] = oracle.tour_length() if key[2] else oracle.path_length()
    return _BEST[key]


def _measure(workload: Workload, compiled: Any) -> dict[str, float]:
    import shapely

    from tlmpc.mission import load_mission, load_mission_text
    from tlmpc.mission.body import body_radius
    from tlmpc.mission.cspace import workspace_free_space

    mission_source = workload.mission
    if isinstance(mission_source, Path):
        mission = load_mission(mission_source)
    else:
        import yaml

        mission = load_mission_text(yaml.safe_dump(mission_source), "generated.yaml")
    shapes = {r.name: shapely.Polygon(r.polygon) for r in mission.regions}
    free = workspace_free_space(mission)
    for name in workload.avoid:
        free = free.difference(shapes[name])
    radius = body_radius(mission.robot)
    if radius > 0:
        free = free.buffer(-radius, quad_segs=16)
    times, points = _fine_trajectory(compiled.artifacts)
    steps_travelled = np.hypot(*np.diff(points, axis=0).T)
    cumulative = np.concatenate([[0.0], np.cumsum(steps_travelled)])
    speed = mission.robot.max_speed
    row: dict[str, float] = {}
    if workload.patrol:
        trace = compiled.artifacts["trace.json"]
        loop_time = trace["points"][trace["loop_start"]][0]
        lap_start = int(np.searchsorted(times, loop_time))
        order, _ = _order(points, shapes, workload.groups, lap_start)
        lap = float(cumulative[-1] - cumulative[lap_start])
        key = (workload.name, tuple(order), True)
        best = _best(key, free, tuple(shapes[n] for n in order), tuple(points[0]))
        row["lap"] = lap / best
        row["lap time"] = float(times[-1] - times[lap_start]) / (best / speed)
        # ... and over the best tour in any order (the visiting order is the planner's choice)
        tours = [best]
        for rest in itertools.permutations(order[1:]):
            others = (order[0], *rest)
            if others == tuple(order):
                continue
            key = (workload.name, others, True)
            tours.append(_best(key, free, tuple(shapes[n] for n in others), tuple(points[0])))
        row["lap / best order"] = lap / min(tours)
        return row
    order, met = _order(points, shapes, workload.groups)
    if met < 0:
        return {"length": float("nan"), "time": float("nan")}
    key = (workload.name, tuple(order), False)
    best = _best(key, free, tuple(shapes[n] for n in order), tuple(mission.robot.start))
    row["length"] = float(cumulative[met]) / best
    row["time"] = float(times[met]) / (best / speed)
    return row


def workloads() -> list[Workload]:
    """Every workload of the table: the shipped specs, generated rooms, held-out missions."""
    return [
        *shipped(),
        *(generated(seed) for seed in (1, 2, 3)),
        *(generated(seed, radius=0.2) for seed in (1, 2, 3)),
        *(generated(seed, patrol=True) for seed in (4, 5)),
        generated(6, radius=0.2, patrol=True),
        *held_out(),
        *held_out_late(),
        *held_out_depth(),
        *held_out_detours(),
        *held_out_orders(),
        *held_out_tours(),
        *held_out_corners(),
    ]


def run(only: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """Rows of the tlmpc imported here: every workload's ratios (``only``: these names)."""
    rows = []
    for workload in workloads():
        if only and workload.name not in only:
            continue
        row: dict[str, Any] = {"workload": workload.name}
        try:
            compiled, guided = _compile(workload, True)
            measured = _measure(workload, compiled)
        except Exception as failure:  # a mission this generator made unsolvable
            row["note"] = f"{type(failure).__name__}: {str(failure)[:60]}"
            rows.append(row)
            continue
        for key, value in measured.items():
            row[key] = round(value, 3)
        row["robustness"] = round(compiled.summary["verdict"]["robustness"], 4)
        if not workload.patrol:  # how closely the flow keeps to its path
            row["trajectory / its path"] = round(_travelled(compiled.artifacts) / guided, 3)
        rows.append(row)
    return rows


def side_by_side(baseline: Path, only: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """Rows with the ratios of the tlmpc checked out at ``baseline`` (run in a child process
    importing it) and of this one, column by column."""
    import json
    import os
    import subprocess

    env = {**os.environ, "PYTHONPATH": str(baseline)}
    command = [sys.executable, str(Path(__file__).resolve()), "--rows", "--tree", str(baseline)]
    output = subprocess.run(
        [*command, *only], env=env, check=True, capture_output=True, text=True
    ).stdout
    before = {row["workload"]: row for row in json.loads(output)}
    merged = []
    for row in run(only):
        old = before.get(row["workload"], {})
        joined: dict[str, Any] = {"workload": row["workload"]}
        for key in ("length", "time", "lap", "lap time", "lap / best order", "robustness"):
            if key in row or key in old:
                joined[f"{key} before"] = old.get(key, "")
                joined[f"{key} after"] = row.get(key, "")
        joined["trajectory / its path"] = row.get("trajectory / its path", "")
        if "note" in row or "note" in old:
            joined["note"] = row.get("note", old.get("note", ""))
        merged.append(joined)
    return merged


def _cut_length(points: Any, shapes: dict[str, Any], groups: Any, step: float = 0.005) -> float:
    """A polyline's length until it first enters its last target (groups in order), the
    polyline sampled every ``step`` as the trajectory is."""
    dense = [points[0]]
    for a, b in itertools.pairwise(points):
        count = max(1, int(math.dist(a, b) / step))
        dense += [a + (b - a) * (j / count) for j in range(1, count + 1)]
    samples = np.asarray(dense)
    _, met = _order(samples, shapes, groups)
    return float(np.hypot(*np.diff(samples[: met + 1], axis=0).T).sum()) if met >= 0 else math.nan


def _polyline(guides: Any) -> Any:
    points: list[Any] = []
    for guide in guides:
        if guide is None:
            continue
        if not points or tuple(points[-1]) != tuple(guide.entry):
            points.append(np.asarray(guide.entry))
        points.append(np.asarray(guide.exit))
    return np.asarray(points)


def gap_rows(only: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """Where the length goes, per workload that ends (not patrols): factors whose product is
    the length ratio, each the next path's length over the one before, all measured until
    the last target is first entered:

    * **margin**: the shortest path in the planner's free space (eroded by the body and the
      margin, avoided regions grown) over the one keeping the body's clearance alone;
    * **goal depth**: ... touching the goals' cores (all but the last target) instead;
    * **channel**: the channel's shortest path without any inset over that;
    * **insets**: the path the fields follow (with the portal and label insets) over that;
    * **controller**: the trajectory over the path it follows.
    """
    import importlib

    import shapely
    import yaml
    from shortest_paths import VisibilityOracle

    from tlmpc.abstraction.layout import planning_layout
    from tlmpc.mission.body import body_radius, requested_margin
    from tlmpc.mission.cspace import workspace_free_space
    from tlmpc.pipeline.stages import MISSION, compile_mission

    module = importlib.import_module("tlmpc.control.synthesize")
    channel = importlib.import_module("tlmpc.control.channel")
    original = module.path_guides
    calls: list[tuple[Any, Any]] = []

    def recorded(*args: Any, **keywords: Any) -> Any:
        calls.append((args, keywords))
        return original(*args, **keywords)

    rows = []
    for workload in workloads():
        if workload.patrol or (only and workload.name not in only):
            continue

        source = workload.mission
        text = None if isinstance(source, Path) else yaml.safe_dump(source)
        with mock.patch.object(module, "path_guides", recorded):
            result = compile_mission(source if text is None else "bench.yaml", text=text)
        mission = result.compilation.get(MISSION)
        args, keywords = calls[-1]
        followed = original(*args, **keywords)
        with mock.patch.multiple(
            channel, PORTAL_INSET=0.0, LABEL_INSET=0.0, ENTERED_INSET=0.0, REACH_ROUNDS=0
        ):
            bare = original(*args, **keywords)
        shapes = {r.name: shapely.Polygon(r.polygon) for r in mission.regions}
        free = workspace_free_space(mission)
        for name in workload.avoid:
            free = free.difference(shapes[name])
        radius = body_radius(mission.robot)
        body_free = free.buffer(-radius, quad_segs=16) if radius > 0 else free
        _, trajectory = _fine_trajectory(result.artifacts)
        order, _ = _order(trajectory, shapes, workload.groups)
        start = tuple(mission.robot.start)
        layout = planning_layout(mission, requested_margin(mission))
        names = [r.name for r in mission.regions]
        planned = {
            name: shapes[name] if layout is None or layout.regions[i] is None else layout.regions[i]
            for i, name in enumerate(names)
        }
        planner_free = free if layout is None or layout.free is None else layout.free
        for name in workload.avoid:
            planner_free = planner_free.difference(planned[name])
        lengths = [
            VisibilityOracle(body_free, [shapes[n] for n in order], start).path_length(),
            VisibilityOracle(planner_free, [shapes[n] for n in order], start).path_length(),
            VisibilityOracle(
                planner_free, [planned[n] for n in order[:-1]] + [shapes[order[-1]]], start
            ).path_length(),
            _cut_length(_polyline(bare), shapes, workload.groups),
            _cut_length(_polyline(followed), shapes, workload.groups),
            _cut_length(trajectory, shapes, workload.groups),
        ]
        row: dict[str, Any] = {"workload": workload.name, "shortest": round(lengths[0], 3)}
        names_of = ("margin", "goal depth", "channel", "insets", "controller")
        for label, (a, b) in zip(names_of, itertools.pairwise(lengths), strict=True):
            row[label] = round(b / a, 3)
        row["length ratio"] = round(lengths[-1] / lengths[0], 3)
        rows.append(row)
    return rows


def _category(step: dict[str, Any], index: int, reasons: dict[int, set[str]]) -> str:
    if step["stay"]:
        return "stay"
    if step.get("kind") == "vertex":
        return "vertex passage"
    if index == 0:
        return "first step"
    if index in reasons:
        reason = sorted(reasons[index])[0]
        if "bends" in reason:
            return "jump: bend"
        return "jump: deflection" if "away from the path" in reason else "jump: other"
    return "shared"


def speed_rows(only: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """Where the time goes, per workload: the time to meet the task (a patrol: one lap)
    times max_speed minus the distance travelled, as a percentage of that distance, charged
    to the plan steps the trajectory was in, by kind of step: the stay, vertex passages, the
    first step, steps entered across a velocity jump (a bend of the path, a deflection split,
    another reason) and the others (all corner velocities shared with the step before)."""
    import shapely

    rows = []
    for workload in workloads():
        if only and workload.name not in only:
            continue
        compiled, _ = _compile(workload, True)
        artifacts = compiled.artifacts
        controllers = artifacts["controllers.json"]
        speed = controllers["max_speed"]
        trace = artifacts["trace.json"]
        times, points = _fine_trajectory(artifacts)
        # the plan step of each fine point: that of the next sample at or after its time
        samples = np.asarray(trace["points"], dtype=np.float64)
        at = np.searchsorted(samples[:, 0], times, side="left").clip(0, len(samples) - 1)
        steps = np.asarray(trace["steps"])[at]
        if workload.patrol:
            begin = int(np.searchsorted(times, samples[trace["loop_start"], 0]))
            end = len(times) - 1
        else:
            source = workload.mission
            from tlmpc.mission import load_mission, load_mission_text

            if isinstance(source, Path):
                mission = load_mission(source)
            else:
                import yaml

                mission = load_mission_text(yaml.safe_dump(source), "generated.yaml")
            shapes = {r.name: shapely.Polygon(r.polygon) for r in mission.regions}
            begin, (_, end) = 0, _order(points, shapes, workload.groups)
        reasons: dict[int, set[str]] = {}
        for jump in controllers["jumps"]:
            reasons.setdefault(jump["step"], set()).add(jump["reason"])
        lost: dict[str, float] = {}
        travelled = 0.0
        for k in range(begin, end):
            dt, ds = times[k + 1] - times[k], float(np.hypot(*(points[k + 1] - points[k])))
            index = int(steps[k + 1])
            kind = _category(controllers["steps"][index], index, reasons)
            lost[kind] = lost.get(kind, 0.0) + dt * speed - ds
            travelled += ds
        row: dict[str, Any] = {"workload": workload.name}
        row["time / length"] = round(1.0 + sum(lost.values()) / travelled, 3)
        for kind in ("shared", "jump: bend", "jump: deflection", "jump: other", "first step"):
            row[kind] = round(100.0 * lost.get(kind, 0.0) / travelled, 2)
        rows.append(row)
    return rows


def _table(rows: list[dict[str, Any]]) -> str:
    columns: list[str] = []
    for row in rows:
        columns += [key for key in row if key not in columns]
    lines = [
        "| " + " | ".join(columns) + " |",
        "|" + "---|" * len(columns),
    ]
    lines += ["| " + " | ".join(str(row.get(c, "")) for c in columns) + " |" for row in rows]
    return "\n".join(lines)


def _main(arguments: list[str]) -> None:
    import json

    if "--tree" in arguments:  # import tlmpc from that checkout (the baseline's child run)
        at = arguments.index("--tree")
        sys.path.insert(0, arguments[at + 1])
        del arguments[at : at + 2]
    if "--rows" in arguments:
        arguments.remove("--rows")
        print(json.dumps(run(tuple(arguments))))
        return
    if "--speed" in arguments:
        arguments.remove("--speed")
        print(_table(speed_rows(tuple(arguments))))
        return
    if "--gap" in arguments:
        arguments.remove("--gap")
        print(_table(gap_rows(tuple(arguments))))
        return
    if "--baseline" in arguments:
        at = arguments.index("--baseline")
        baseline = Path(arguments[at + 1])
        del arguments[at : at + 2]
        print(_table(side_by_side(baseline, tuple(arguments))))
        return
    print(_table(run(tuple(arguments))))


if __name__ == "__main__":
    _main(sys.argv[1:])
