"""The scene a view draws: plain JSON built from tlmpc's artifacts or from a log and a mission.

A scene holds the workspace, the regions, the triangulation (when there is one), the trajectory
as ``[t, x, y]`` samples and the verdict.  Where the trajectory leaves the workspace or enters a
hole, the offending sample intervals are listed, so the page can draw them in the violation
colour next to the verifier's counterexample.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tlmpc.base.errors import UsageError, error

if TYPE_CHECKING:
    from tlmpc.verify import LogOptions


def _points(value: Any) -> list[list[float]]:
    return [[float(x), float(y)] for x, y in value]


def _finite(value: Any) -> Any:
    """JSON without NaN/inf (the page's JSON.parse would reject them)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def _outside_intervals(
    samples: list[list[float]],
    boundary: list[list[float]],
    holes: list[list[list[float]]],
    components: list[dict[str, Any]] | None = None,
) -> list[list[int]]:
    """Index ranges ``[first, last]`` of the segments (sample k to k+1) that leave the
    workspace (every piece of it) or cross a hole; a lone sample outside counts as the segment
    from it."""
    from shapely import LineString, Point, Polygon, prepared, union_all

    pieces = [Polygon(boundary, holes)] + [
        Polygon(c["boundary"], c["holes"]) for c in components or []
    ]
    area = prepared.prep(pieces[0] if len(pieces) == 1 else union_all(pieces))
    ranges: list[list[int]] = []
    for index in range(max(len(samples) - 1, 1)):
        a = samples[index]
        b = samples[min(index + 1, len(samples) - 1)]
        piece = Point(a[1], a[2]) if a[1:] == b[1:] else LineString([a[1:], b[1:]])
        if area.covers(piece):
            continue
        if ranges and ranges[-1][1] == index - 1:
            ranges[-1][1] = index
        else:
            ranges.append([index, index])
    return ranges


def _scene(
    *,
    title: str,
    workspace: dict[str, Any],
    regions: dict[str, Any],
    samples: list[list[float]],
    loop_start: int | None,
    verdict: dict[str, Any] | None,
    mesh: dict[str, Any] | None,
    formula: str,
    counterstrategy: dict[str, Any] | None = None,
) -> dict[str, Any]:
    boundary = _points(workspace["boundary"])
    holes = [_points(h) for h in workspace.get("holes", [])]
    components = [
        {"boundary": _points(c["boundary"]), "holes": [_points(h) for h in c.get("holes", [])]}
        for c in workspace.get("components", [])
    ]
    from tlmpc.render.scene import named_regions

    labels = [
        {"name": name, "at": [x, y], "task": task}
        for name, (x, y), task in named_regions(regions, formula)
    ]
    scene: dict[str, Any] = _finite(
        {
            "format": "tlmpc.view/1",
            "title": title,
            "formula": formula,
            "workspace": {"boundary": boundary, "holes": holes, "components": components},
            "regions": {name: _points(poly) for name, poly in regions.items()},
            "labels": labels,
            "mesh": mesh,
            "trajectory": samples,
            "loop_start": loop_start,
            "verdict": verdict,
            "outside": _outside_intervals(samples, boundary, holes, components) if samples else [],
        }
    )
    if counterstrategy is not None:
        # the same marks and route as plot's (render.scene is the one scene model)
        from tlmpc.render.scene import play_marks

        marks, route = play_marks(counterstrategy)
        scene["title"] = f"{title}: unrealizable, how the environment wins"
        scene["play"] = {
            "marks": [{"at": list(m.position), "text": m.text} for m in marks],
            "route": [list(p) for p in route],
        }
    return scene


def scene_from_output(directory: Path) -> dict[str, Any]:
    """The scene of a ``tlmpc compile`` output directory (mesh, trajectory, verdict)."""
    from tlmpc.io.artifacts import read_artifacts

    if not (directory / "mission.json").is_file():
        raise UsageError(
            error(
                "U020",
                f"{directory} has no mission.json",
                hint="pass a directory written by `tlmpc compile MISSION -o DIR`, "
                "or a log with `--log LOG --mission MISSION`",
                file=str(directory),
            )
        )
    # each checked against its schema (finite numbers) and against the others
    documents = read_artifacts(
        directory,
        ("mission.json", "abstraction.json", "trace.json", "verdict.json", "counterstrategy.json"),
    )
    mission = documents["mission.json"]
    mesh = None
    if "abstraction.json" in documents:
        abstraction = documents["abstraction.json"]
        mesh = {
            "vertices": _points(abstraction["vertices"]),
            "triangles": [list(map(int, t)) for t in abstraction["triangles"]],
            "labels": [list(map(str, label)) for label in abstraction["labels"]],
        }
    samples: list[list[float]] = []
    loop_start = None
    if "trace.json" in documents:
        trace = documents["trace.json"]
        samples = [[float(t), float(x), float(y)] for t, x, y in trace["points"]]
        loop_start = trace.get("loop_start")
    verdict = None
    if "verdict.json" in documents:
        verdict = documents["verdict.json"]
    return _scene(
        title=str(mission.get("name") or directory.name),
        workspace=mission["workspace"],
        regions=mission["regions"],
        samples=samples,
        loop_start=loop_start,
        verdict=verdict,
        mesh=mesh,
        formula=str(mission.get("formula", "")),
        counterstrategy=documents.get("counterstrategy.json"),
    )


def scene_from_log(
    log: Path,
    mission_path: Path,
    options: LogOptions | None = None,
    *,
    convention: str | None = None,
    assume_stay: bool = False,
    loop_from: float | None = None,
) -> dict[str, Any]:
    """The scene of a robot's log (any format ``tlmpc verify`` reads) verified against a
    mission, read and ended as ``tlmpc verify`` reads it with the same flags (``options``,
    ``--boundary``, ``--assume-stay``, ``--loop-from``)."""
    from tlmpc.ltl.printer import to_text
    from tlmpc.mission.load import load_mission
    from tlmpc.verify import (
        LogOptions,
        declare_ending,
        read_trace,
        verdict_to_json,
        verify_trace,
    )

    mission = load_mission(mission_path)
    trace = read_trace(log, mission, convention, options or LogOptions())
    trace = declare_ending(trace, assume_stay=assume_stay, loop_from=loop_from)
    verdict = verdict_to_json(verify_trace(trace))
    samples = [
        [float(t), float(x), float(y)]
        for t, (x, y) in zip(trace.times.tolist(), trace.points.tolist(), strict=True)
    ]
    return _scene(
        title=f"{log.name} against {mission.name}",
        workspace=mission.workspace.to_json(),
        regions={r.name: r.polygon for r in mission.regions},
        samples=samples,
        loop_start=trace.loop_start,
        verdict=verdict,
        mesh=None,
        formula=to_text(mission.formula),
    )
