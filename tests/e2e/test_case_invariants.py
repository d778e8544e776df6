"""Every shipped mission is a test case with expectations written by hand from its task text
(never copied from tlmpc's output), plus invariants checked on every case with independent
tools (shapely, numpy, Euler's formula):

* the triangles tile the free space exactly: their areas add up to its area, and their counts
  obey Euler's relation ``T = 2V - B - 2(components - holes)`` for a triangulated region;
* the trajectory enters the regions the task names in the order the task names them;
* it never enters a region the task forbids (touching its boundary is not entering);
* a patrol's loop enters every patrolled region; a task that ends in a stay ends inside.

Example 1's formula is the one printed in the paper (Fainekos et al. 2005, Example 1).
"""

from __future__ import annotations

import io
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"


@dataclass(frozen=True)
class Expect:
    """What the task text says, read by a person."""

    #: Regions to enter, one after the other (each set in any order, after the previous set).
    order: tuple[frozenset[str], ...] = ()
    #: Regions never to enter.
    never: frozenset[str] = frozenset()
    #: Regions the loop of a patrol must enter on every round.
    loop_visits: frozenset[str] = frozenset()
    #: The region the robot ends in (a final stay).
    ends_in: str | None = None
    #: The whole task as LTL, when a source gives it.
    formula: str | None = None


def _steps(*names: str) -> tuple[frozenset[str], ...]:
    return tuple(frozenset({n}) for n in names)


CASES: dict[str, Expect] = {
    # "visit p2 then p3 then p4 then return to p1 while avoiding p2 and p3"
    "example1": Expect(
        order=_steps("p2", "p3", "p4", "p1"),
        formula="F(p2 & F(p3 & F(p4 & ((!p2 & !p3) U p1))))",
    ),
    # "visit r1, r2, r3, r4, r5 and r6": all of them, in any order
    "example6": Expect(order=(frozenset({"r1", "r2", "r3", "r4", "r5", "r6"}),)),
    # "avoid o1, o2, o3" and F(r2 & F(r1 & F r3 & F r4 & F r5))
    "example7": Expect(
        order=(frozenset({"r2"}), frozenset({"r1"}), frozenset({"r3", "r4", "r5"})),
        never=frozenset({"o1", "o2", "o3"}),
    ),
    # "visit r31_13 and r12_30"
    "example8": Expect(order=(frozenset({"r31_13", "r12_30"}),)),
    # "patrol alpha, bravo and charlie", "avoid lake"
    "patrol": Expect(
        loop_visits=frozenset({"alpha", "bravo", "charlie"}), never=frozenset({"lake"})
    ),
    # "visit dock within 45 s", "avoid hazard", "eventually stay in home" and
    # G(dock -> F[0,40] home): dock, then home, where it stays
    "deadline": Expect(order=_steps("dock", "home"), never=frozenset({"hazard"}), ends_in="home"),
    # "visit dock then return to home", "avoid hazard", "eventually stay in home"
    "reach-avoid": Expect(
        order=_steps("dock", "home"), never=frozenset({"hazard"}), ends_in="home"
    ),
}


def test_every_shipped_mission_is_a_case() -> None:
    assert {p.stem for p in SPECS.glob("*.yaml")} == set(CASES)


@pytest.fixture(scope="module")
def outputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    base = tmp_path_factory.mktemp("cases")
    found: dict[str, dict[str, Any]] = {}
    for name in CASES:
        out = base / name
        err = io.StringIO()
        code = main(
            ["compile", str(SPECS / f"{name}.yaml"), "-o", str(out), "-q"], io.StringIO(), err
        )
        assert code == 0, err.getvalue()
        found[name] = {
            artifact: json.loads((out / f"{artifact}.json").read_text())
            for artifact in ("mission", "abstraction", "trace")
        }
    return found


def _free_space(mission: dict[str, Any]) -> shapely.Geometry:
    workspace = mission["workspace"]
    outer = shapely.Polygon(workspace["boundary"])
    holes = [shapely.Polygon(h) for h in workspace["holes"]]
    return outer.difference(shapely.union_all(holes)) if holes else outer


def _region(mission: dict[str, Any], name: str) -> shapely.Geometry:
    return shapely.Polygon(mission["regions"][name])


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_triangles_tile_the_free_space(name: str, outputs: dict[str, Any]) -> None:
    mission, abstraction = outputs[name]["mission"], outputs[name]["abstraction"]
    vertices = np.asarray(abstraction["vertices"], dtype=np.float64)
    triangles = np.asarray(abstraction["triangles"], dtype=np.int64)
    a, b, c = vertices[triangles[:, 0]], vertices[triangles[:, 1]], vertices[triangles[:, 2]]
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert (np.abs(cross) > 0).all()  # no degenerate triangle
    free = _free_space(mission)
    assert float(np.abs(cross).sum() / 2) == pytest.approx(free.area, rel=1e-9)
    # Euler: V - E + T = components - holes for a triangulated planar region.
    parts = list(free.geoms) if hasattr(free, "geoms") else [free]
    characteristic = len(parts) - sum(len(p.interiors) for p in parts)
    edges: dict[tuple[int, int], int] = {}
    for tri in triangles.tolist():
        for i in range(3):
            edge = (min(tri[i], tri[(i + 1) % 3]), max(tri[i], tri[(i + 1) % 3]))
            edges[edge] = edges.get(edge, 0) + 1
    assert set(edges.values()) <= {1, 2}  # an edge borders one triangle (boundary) or two
    boundary = sum(1 for count in edges.values() if count == 1)
    used = len(np.unique(triangles))
    assert len(triangles) == 2 * used - boundary - 2 * characteristic


def _inside(region: shapely.Geometry, points: np.ndarray) -> np.ndarray:
    """Samples strictly inside ``region`` (on its boundary is not inside)."""
    return np.asarray(shapely.contains_xy(region, points[:, 0], points[:, 1]), dtype=bool)


def _touching(region: shapely.Geometry, points: np.ndarray) -> np.ndarray:
    """Samples in ``region`` or on its boundary (a crossing sample lies on it)."""
    return np.asarray(
        shapely.intersects_xy(region.buffer(1e-9), points[:, 0], points[:, 1]), dtype=bool
    )


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_trajectory_does_what_the_task_says(name: str, outputs: dict[str, Any]) -> None:
    expect = CASES[name]
    mission, trace = outputs[name]["mission"], outputs[name]["trace"]
    samples = np.asarray(trace["points"], dtype=np.float64)[:, 1:]
    # Entering a region means crossing its boundary, where the simulation puts a sample; the
    # sample after it lies inside unless the robot only grazed the boundary.
    position = 0
    for step in expect.order:
        latest = position
        for region_name in sorted(step):
            hits = np.flatnonzero(_touching(_region(mission, region_name), samples[position:]))
            assert len(hits), f"{name}: never enters {region_name} after sample {position}"
            latest = max(latest, position + int(hits[0]))
        position = latest
    for region_name in expect.never:
        assert not _inside(_region(mission, region_name), samples).any(), region_name
    if expect.loop_visits:
        assert trace["loop_start"] is not None
        loop = samples[int(trace["loop_start"]) :]
        for region_name in expect.loop_visits:
            assert _touching(_region(mission, region_name), loop).any(), region_name
    if expect.ends_in is not None:
        assert trace.get("end") == "stay"
        assert _inside(_region(mission, expect.ends_in), samples[-1:]).all()


def test_example1_means_the_papers_formula(outputs: dict[str, Any]) -> None:
    assert outputs["example1"]["mission"]["formula"] == CASES["example1"].formula
