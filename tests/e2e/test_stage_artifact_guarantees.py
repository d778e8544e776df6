"""`tlmpc stage` on edited witness.json / controllers.json / trace.json: the stage refuses an
artifact that breaks what the control stage guarantees (U042 at that file, exit 2) before it
runs, and `stage verify` gives the verifier's own answer; untouched artifacts still run.

The oracles are independent of tlmpc's re-check: the speeds, exit speeds and laws of the
edited documents are recomputed here with numpy from the JSON, and the workspace from the
mission's rectangle."""

from __future__ import annotations

import io
import itertools
import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tlmpc.cli import main

ROOT = Path(__file__).resolve().parents[2]
Doc = dict[str, Any]


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out=out, err=err), out.getvalue(), err.getvalue()


def _compile(directory: Path, text: str) -> Path:
    mission = directory / "mission.yaml"
    mission.write_text(text)
    out = directory / "out"
    code, _, err = run_cli("compile", str(mission), "-o", str(out), "-q")
    assert code == 0, err
    return out


EXAMPLE1 = (ROOT / "specs" / "example1.yaml").read_text()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _compile(tmp_path_factory.mktemp("guarantees"), EXAMPLE1)


@pytest.fixture(scope="module")
def disturbed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    text = EXAMPLE1.replace("max_speed: 1.0}", "max_speed: 1.0, disturbance: 0.05}")
    assert text != EXAMPLE1
    return _compile(tmp_path_factory.mktemp("guarantees_disturbed"), text)


def _copy(source: Path, tmp_path: Path) -> Path:
    copy = tmp_path / "copy"
    shutil.copytree(source, copy)
    return copy


def _edit(path: Path, change: Callable[[Doc], None]) -> None:
    document = json.loads(path.read_text())
    change(document)
    path.write_text(json.dumps(document))


def _exit_steps(document: Doc) -> list[Doc]:
    return [s for s in document["steps"] if s["exit_edge"] is not None and not s["stay"]]


def _normal(vertices: np.ndarray, facet: int) -> np.ndarray:
    """The outward unit normal of the facet opposite vertex ``facet`` (counter-clockwise)."""
    a, b = vertices[(facet + 1) % 3], vertices[(facet + 2) % 3]
    normal = np.array([b[1] - a[1], a[0] - b[0]])
    unit: np.ndarray = normal / np.linalg.norm(normal)
    return unit


def _law(vertices: np.ndarray, velocities: np.ndarray) -> tuple[list[Any], list[Any]]:
    """K, g with K v_i + g = w_i (solved here, not with tlmpc's affine_law)."""
    system = np.hstack([vertices, np.ones((3, 1))])
    solution = np.linalg.solve(system, velocities)  # rows: K^T (2) and g (1)
    return solution[:2].T.tolist(), solution[2].tolist()


def _scaled(factor: float) -> Callable[[Doc], None]:
    def change(document: Doc) -> None:
        for step in document["steps"]:
            for key in ("vertex_velocities", "K", "g"):
                step[key] = (np.asarray(step[key]) * factor).tolist()

    return change


def _rotated(document: Doc) -> None:
    """One exit step's velocities turned by 90 degrees (speeds kept), K and g made to match."""
    step = _exit_steps(document)[1]
    w = np.asarray(step["vertex_velocities"])
    step["vertex_velocities"] = np.column_stack([-w[:, 1], w[:, 0]]).tolist()
    step["K"], step["g"] = _law(np.asarray(step["vertices"]), np.asarray(step["vertex_velocities"]))


def _reversed(document: Doc) -> None:
    step = _exit_steps(document)[1]
    for key in ("vertex_velocities", "K", "g"):
        step[key] = (-np.asarray(step[key])).tolist()


def _shifted_g(document: Doc) -> None:
    _exit_steps(document)[1]["g"][0] += 0.5


def _huge_gain(document: Doc) -> None:
    _exit_steps(document)[1]["K"] = [[1e300, 0.0], [0.0, 1e300]]


def _other_exit(document: Doc) -> None:
    step = _exit_steps(document)[0]
    step["exit_edge"] = (step["exit_edge"] + 1) % 3


def _moved_vertex(document: Doc) -> None:
    _exit_steps(document)[1]["vertices"][0] = [100.0, 100.0]


def _claimed_exit_speed(document: Doc) -> None:
    _exit_steps(document)[1]["exit_speed"] *= 2.0


def _other_triangle(document: Doc) -> None:
    """One exit step's corner moved 1% toward the centroid, its law made to match: a field
    of a triangle the mesh does not have."""
    step = _exit_steps(document)[1]
    vertices = np.asarray(step["vertices"])
    vertices[0] += 0.01 * (vertices.mean(axis=0) - vertices[0])
    step["vertices"] = vertices.tolist()
    step["K"], step["g"] = _law(vertices, np.asarray(step["vertex_velocities"]))


def _mid_stay(document: Doc) -> None:
    _exit_steps(document)[1]["stay"] = True


def _instant_exit(document: Doc) -> None:
    _exit_steps(document)[1]["exit_time_bound"] = 0.0


def _too_fast(document: Doc) -> bool:
    """The oracle of the ten-fold field: some vertex faster than the file's max_speed."""
    speeds = [np.linalg.norm(s["vertex_velocities"], axis=1).max() for s in document["steps"]]
    return bool(max(speeds) > document["max_speed"])


def _breaks_own_exit(document: Doc) -> bool:
    """Some exit step whose vertices do not all cross its exit facet faster than it states,
    whose law does not give its vertex velocities, or whose exit_time_bound is shorter than
    the facet's height over its least speed across it."""
    for step in _exit_steps(document):
        vertices, w = np.asarray(step["vertices"]), np.asarray(step["vertex_velocities"])
        across = w @ _normal(vertices, step["exit_edge"])
        law = vertices @ np.asarray(step["K"]).T + np.asarray(step["g"])
        a = vertices[(step["exit_edge"] + 1) % 3]
        height = float(_normal(vertices, step["exit_edge"]) @ (a - vertices[step["exit_edge"]]))
        if (
            across.min() < step["exit_speed"] * (1 - 1e-9)
            or not np.allclose(law, w, atol=1e-6)
            or step["exit_time_bound"] < height / across.min() * (1 - 1e-6)
        ):
            return True
    return False


CONTROLLER_EDITS = [
    ("ten_times_faster", _scaled(10.0)),
    ("hundred_times_slower", _scaled(0.01)),
    ("zero_field", _scaled(0.0)),
    ("rotated", _rotated),
    ("reversed", _reversed),
    ("shifted_g", _shifted_g),
    ("huge_gain", _huge_gain),
    ("other_exit_edge", _other_exit),
    ("moved_vertex", _moved_vertex),
    ("claimed_exit_speed", _claimed_exit_speed),
    ("other_triangle", _other_triangle),
    ("mid_plan_stay", _mid_stay),
    ("zero_exit_time_bound", _instant_exit),
]


@pytest.mark.parametrize(("name", "change"), CONTROLLER_EDITS, ids=[n for n, _ in CONTROLLER_EDITS])
def test_edited_controllers_are_refused_at_the_file(
    compiled: Path, tmp_path: Path, name: str, change: Callable[[Doc], None]
) -> None:
    copy = _copy(compiled, tmp_path)
    path = copy / "controllers.json"
    _edit(path, change)
    document = json.loads(path.read_text())
    original = json.loads((compiled / "controllers.json").read_text())
    # the edit breaks a stated guarantee by the oracle's own reckoning
    mesh = json.loads((copy / "abstraction.json").read_text())
    assert (
        _too_fast(document)
        or _breaks_own_exit(document)
        or [s["stay"] for s in document["steps"]] != [s["stay"] for s in original["steps"]]
        or any(
            s["vertices"] != [mesh["vertices"][v] for v in mesh["triangles"][s["triangle"]]]
            for s in document["steps"]
        )
    ), name
    trace = (copy / "trace.json").read_bytes()
    code, _, err = run_cli("stage", "simulate", str(copy))
    assert code == 2, err
    assert err.startswith(f"{path}: error[U042]: controllers.json"), err
    assert "please report" not in err
    assert (copy / "trace.json").read_bytes() == trace  # nothing written


@pytest.mark.parametrize(
    "name", ["ten_times_faster", "reversed", "other_exit_edge", "mid_plan_stay"]
)
def test_simulate_and_the_executor_refuse_edited_controllers_too(
    compiled: Path, tmp_path: Path, name: str
) -> None:
    # `tlmpc simulate` and `tlmpc.executor` run a folder's controllers as `stage simulate` does
    from tlmpc.api import executor
    from tlmpc.base.errors import UsageError

    change = dict(CONTROLLER_EDITS)[name]
    copy = _copy(compiled, tmp_path)
    path = copy / "controllers.json"
    _edit(path, change)
    code, _, err = run_cli("simulate", str(copy), "--seed", "1")
    assert code == 2, err
    assert err.startswith(f"{path}: error[U042]: controllers.json"), err
    with pytest.raises(UsageError) as caught:
        executor(copy)
    assert caught.value.diagnostics[0].code == "U042"
    assert executor(compiled) is not None  # the untouched folder runs


@pytest.fixture(scope="module")
def on_cells(tmp_path_factory: pytest.TempPathFactory) -> Path:
    # half max_speed pushes: Example 1 is planned on convex cells, every step a cell's field
    text = EXAMPLE1.replace("max_speed: 1.0}", "max_speed: 1.0, disturbance: 0.5}")
    assert text != EXAMPLE1
    return _compile(tmp_path_factory.mktemp("guarantees_cells"), text)


def test_a_cell_piece_whose_law_misses_its_vertex_velocities_is_refused(
    on_cells: Path, tmp_path: Path
) -> None:
    copy = _copy(on_cells, tmp_path)
    path = copy / "controllers.json"

    def shift_last_piece(document: Doc) -> None:
        cell = document["steps"][0]["cell"]
        assert document["steps"][0]["kind"] == "cell"
        cell["g"][-1] = [cell["g"][-1][0] + 0.05, cell["g"][-1][1]]

    _edit(path, shift_last_piece)
    code, _, err = run_cli("stage", "simulate", str(copy))
    assert code == 2, err
    assert err.startswith(f"{path}: error[U042]: controllers.json"), err
    assert "K and g do not give the vertex velocities" in err


def test_ten_times_faster_controllers_name_the_speed(compiled: Path, tmp_path: Path) -> None:
    copy = _copy(compiled, tmp_path)
    _edit(copy / "controllers.json", _scaled(10.0))
    code, _, err = run_cli("stage", "simulate", str(copy))
    assert code == 2
    assert "exceeds max_speed 1" in err


@pytest.mark.parametrize("fixture", ["compiled", "disturbed"])
def test_untouched_controllers_simulate_as_compiled(
    fixture: str, request: pytest.FixtureRequest, tmp_path: Path
) -> None:
    source: Path = request.getfixturevalue(fixture)
    copy = _copy(source, tmp_path)
    code, _, err = run_cli("stage", "simulate", str(copy))
    assert code == 0, err
    assert (copy / "trace.json").read_bytes() == (source / "trace.json").read_bytes()
    code, _, err = run_cli("stage", "control", str(copy))
    assert code == 0, err


def _drop_first_two(document: Doc) -> None:
    for key in ("prefix", "prefix_states", "word"):
        document[key] = document[key][2:]


def _not_adjacent(document: Doc) -> None:
    document["prefix"][2] = document["prefix"][6]


@pytest.mark.parametrize(
    ("change", "says"),
    [(_drop_first_two, "does not hold robot.start (1.5, 1.5)"), (_not_adjacent, "not adjacent")],
    ids=["wrong_start", "not_adjacent"],
)
def test_edited_witness_is_refused_at_the_file(
    compiled: Path, tmp_path: Path, change: Callable[[Doc], None], says: str
) -> None:
    copy = _copy(compiled, tmp_path)
    path = copy / "witness.json"
    _edit(path, change)
    controllers = (copy / "controllers.json").read_bytes()
    neighbours = json.loads((copy / "abstraction.json").read_text())["neighbors"]
    start = json.loads((copy / "mission.json").read_text())["robot"]["start"]
    plan = json.loads(path.read_text())["prefix"]
    # the oracle: the first triangle misses the start, or two steps are not neighbours
    corners = json.loads((copy / "abstraction.json").read_text())
    first = np.asarray([corners["vertices"][v] for v in corners["triangles"][plan[0]]])
    inside = all(
        float(_normal(first, k) @ (np.asarray(start) - first[(k + 1) % 3])) <= 0 for k in range(3)
    )
    adjacent = all(b in neighbours[a] for a, b in itertools.pairwise(plan))
    assert not (inside and adjacent)
    code, _, err = run_cli("stage", "control", str(copy))
    assert code == 2, err
    assert err.startswith(f"{path}: error[U042]: witness.json"), err
    assert says in err
    assert (copy / "controllers.json").read_bytes() == controllers


def test_stage_verify_gives_a_workspace_violation_in_the_verifiers_words(
    compiled: Path, tmp_path: Path
) -> None:
    copy = _copy(compiled, tmp_path)
    path = copy / "trace.json"
    _edit(path, lambda d: d["points"][10].__setitem__(1, d["points"][10][1] + 100.0))
    x = json.loads(path.read_text())["points"][10][1]
    assert not 0.0 <= x <= 10.0  # outside the workspace rectangle [0, 10]^2
    code, _, err = run_cli("stage", "verify", str(copy))
    verify_code, verify_out, _ = run_cli("verify", str(path))
    assert (code, verify_code) == (1, 1), err
    assert "None" not in err
    assert "left the workspace" in err
    assert "left the workspace" in verify_out


def test_stage_verify_calls_a_one_sample_trace_inconclusive(compiled: Path, tmp_path: Path) -> None:
    copy = _copy(compiled, tmp_path)
    path = copy / "trace.json"

    def one_sample(document: Doc) -> None:
        document.update(points=document["points"][:1], loop_start=None, end="open")

    _edit(path, one_sample)
    code, _, err = run_cli("stage", "verify", str(copy))
    verify_code, _, _ = run_cli("verify", str(path))
    assert (code, verify_code) == (4, 4), err
    assert err.startswith(f"{path}: error[U077]:"), err
    assert "inconclusive" in err
    assert "None" not in err
    assert "does not satisfy" not in err
