"""Maps in: map_server conventions, exact free space, simplification bounds, masks, diagnostics."""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import example, given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from robot_data import components, image_from_free, nav2_cell, require_shared, write_map
from shapely.geometry import Point, Polygon, box

from tlmpc.base.errors import UsageError
from tlmpc.cli import main
from tlmpc.importers.maps import ImportedMap, ImportSettings, import_map
from tlmpc.importers.occupancy import cell_values, read_map
from tlmpc.mission.load import check_file, load_mission


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


# --- map_server conventions -------------------------------------------------------------------


@given(
    pixels=arrays(np.uint8, (4, 5)),
    mode=st.sampled_from(["trinary", "scale", "raw"]),
    negate=st.booleans(),
    thresholds=st.tuples(st.floats(0, 1), st.floats(0, 1)).map(sorted),
)
def test_cell_values_follow_nav2(
    pixels: np.ndarray, mode: str, negate: bool, thresholds: list[float]
) -> None:
    free, occupied = thresholds
    shade = pixels.astype(np.float64) / 255.0
    got = cell_values(
        shade, None, mode=mode, negate=negate, occupied_thresh=occupied, free_thresh=free
    )
    for (r, c), value in np.ndenumerate(shade):
        want = nav2_cell(float(value), mode=mode, negate=negate, occupied=occupied, free=free)
        assert got[r, c] == want


def test_thresholds_are_strict() -> None:
    # nav2: occupied when occ > occupied_thresh, free when occ < free_thresh; equal is neither.
    shade = np.array([[102 / 255.0, 204 / 255.0, 101 / 255.0, 205 / 255.0]])
    occupied, free = 1.0 - 102 / 255.0, 1.0 - 204 / 255.0
    got = cell_values(
        shade, None, mode="trinary", negate=False, occupied_thresh=occupied, free_thresh=free
    )
    assert got.tolist() == [[-1, -1, 100, 0]]


def test_unknown_is_not_free_and_the_image_is_flipped(tmp_path: Path) -> None:
    image = np.full((4, 6), 205, dtype=np.uint8)  # unknown everywhere
    image[0, 0:2] = 254  # free, top-left of the image: the top of the map
    image[3, 5] = 0
    path = write_map(tmp_path, "m", image, resolution=0.5, origin=(10.0, 20.0, 0.0))
    grid = read_map(path)
    assert grid.values[3, 0] == 0
    assert grid.values[3, 1] == 0
    assert grid.values[0, 5] == 100
    assert (grid.values == -1).sum() == 24 - 3
    imported = import_map(path, ImportSettings(tolerance=0.0, min_area=0.0))
    assert Polygon(imported.boundary).equals(box(10.0, 21.5, 11.0, 22.0))


def test_origin_yaw_rotates_the_grid_about_the_origin(tmp_path: Path) -> None:
    image = np.zeros((3, 3), dtype=np.uint8)
    image[2, 0:2] = 254  # bottom row, two free cells
    path = write_map(tmp_path, "m", image, resolution=1.0, origin=(5.0, 5.0, math.pi / 2))
    imported = import_map(path, ImportSettings(tolerance=0.0, min_area=0.0))
    # The bottom-left cells [0,2]x[0,1] rotated by 90 degrees about (5, 5): [4,5]x[5,7].
    assert Polygon(imported.boundary).symmetric_difference(box(4, 5, 5, 7)).area < 1e-12


def test_png_with_negate_and_alpha(tmp_path: Path) -> None:
    rgba = np.zeros((3, 3, 4), dtype=np.uint8)
    rgba[..., 3] = 255
    rgba[1, 1, :3] = 0  # black, negated: free
    rgba[0, 0, :3] = 255  # white, negated: occupied
    path = write_map(tmp_path, "m", rgba, negate=1, suffix="png", mode="scale", free=0.1)
    grid = read_map(path)
    assert grid.values[1, 1] == 0
    assert grid.values[2, 0] == 100
    rgba[1, 1, 3] = 0  # transparent in scale mode: unknown
    path = write_map(tmp_path, "m2", rgba, negate=1, suffix="png", mode="scale", free=0.1)
    assert read_map(path).values[1, 1] == -1


# --- free space: exact, and simplified within the tolerance ----------------------------------

grids = arrays(np.bool_, st.tuples(st.integers(3, 14), st.integers(3, 14)))


@given(free=grids)
def test_exact_import_is_the_largest_free_component(
    tmp_path_factory: pytest.TempPathFactory, free: np.ndarray
) -> None:
    parts = components(free)
    if not parts:
        return
    sizes = sorted((len(p) for p in parts), reverse=True)
    if len(sizes) > 1 and sizes[0] == sizes[1]:
        return  # a tie: either piece is right
    directory = tmp_path_factory.mktemp("map")
    path = write_map(directory, "m", image_from_free(free), resolution=1.0)
    imported = import_map(path, ImportSettings(tolerance=0.0, min_area=0.0))
    workspace = Polygon(imported.boundary, imported.holes)
    assert workspace.is_valid
    assert workspace.area == pytest.approx(sizes[0])
    largest = max(parts, key=len)
    for r, c in largest:
        assert workspace.covers(Point(c + 0.5, r + 0.5))
    assert imported.free_cells_area == pytest.approx(int(free.sum()))


def pieces_of(imported: ImportedMap) -> list[Polygon]:
    return [Polygon(imported.boundary, imported.holes)] + [
        Polygon(outer, inner) for outer, inner in imported.components
    ]


@given(free=grids)
def test_exact_import_keeps_every_free_component(
    tmp_path_factory: pytest.TempPathFactory, free: np.ndarray
) -> None:
    parts = components(free)
    if not parts:
        return
    directory = tmp_path_factory.mktemp("map")
    path = write_map(directory, "m", image_from_free(free), resolution=1.0)
    imported = import_map(path, ImportSettings(tolerance=0.0, min_area=0.0))
    pieces = pieces_of(imported)
    assert len(pieces) == len(parts)
    assert all(p.is_valid for p in pieces)
    # one piece per 4-connected component, covering exactly its cells
    for part in parts:
        cells = shapely.union_all([box(c, r, c + 1, r + 1) for r, c in part])
        matches = [p for p in pieces if p.intersection(cells).area > 0]
        assert len(matches) == 1
        assert matches[0].symmetric_difference(cells).area == pytest.approx(0.0, abs=1e-9)
    assert imported.workspace_area == pytest.approx(int(free.sum()))
    # pieces are interior-disjoint and share no edge (they may touch at corners)
    for i, a in enumerate(pieces):
        for b in pieces[i + 1 :]:
            assert a.intersection(b).area == 0
            assert a.boundary.intersection(b.boundary).length == 0


def test_small_free_pieces_are_specks(tmp_path: Path) -> None:
    free = np.zeros((12, 20), dtype=bool)
    free[1:11, 1:10] = True  # the room: 90 cells
    free[1:5, 12:15] = True  # a 12-cell pocket
    free[8, 12:14] = True  # a 2-cell speck
    free[8, 17] = True  # a 1-cell speck
    free[10, 12:16] = True  # a 4-cell piece: exactly the threshold, so kept
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.5)
    every = import_map(path, ImportSettings(tolerance=0.0, min_area=0.0))
    assert sorted(Polygon(o).area for o, _ in every.components) == pytest.approx(
        [0.25, 0.5, 1.0, 3.0]
    )
    default = import_map(path, ImportSettings(tolerance=0.0))  # 4 cells of 0.25
    assert [Polygon(o).area for o, _ in default.components] == pytest.approx([3.0, 1.0])
    assert default.workspace_area == pytest.approx(0.25 * (90 + 12 + 4))
    large = import_map(path, ImportSettings(tolerance=0.0, min_area=3.5))
    assert large.components == ()
    # with the default tolerance (one cell) the pieces are simplified, and still kept
    simplified = import_map(path, ImportSettings())
    assert len(simplified.components) == 2


@pytest.mark.slow
@given(free=grids, tolerance=st.sampled_from([0.5, 1.0, 2.0]))
def test_simplified_boundary_stays_within_the_tolerance(
    tmp_path_factory: pytest.TempPathFactory, free: np.ndarray, tolerance: float
) -> None:
    parts = components(free)
    if not parts:
        return
    largest = max(parts, key=len)
    directory = tmp_path_factory.mktemp("map")
    start = next(iter(sorted(largest)))
    path = write_map(directory, "m", image_from_free(free), resolution=1.0)
    imported = import_map(
        path,
        ImportSettings(tolerance=tolerance, min_area=0.0, start=(start[1] + 0.5, start[0] + 0.5)),
    )
    workspace = Polygon(imported.boundary, imported.holes)
    assert workspace.is_valid
    exact = shapely.union_all([box(c, r, c + 1, r + 1) for r, c in largest])
    # Every point of the simplified boundary is within the tolerance of the exact boundary
    # and vice versa (checked on densified boundaries: the discrete Hausdorff distance).
    distance = shapely.hausdorff_distance(exact.boundary, workspace.boundary, densify=0.05)
    assert distance <= tolerance + 1e-9
    # So free points deeper than the tolerance stay free, obstacle points deeper stay out.
    rows, cols = free.shape
    for r in range(rows):
        for c in range(cols):
            centre = Point(c + 0.5, r + 0.5)
            depth = exact.boundary.distance(centre)
            if depth > tolerance + 1e-9:
                assert workspace.covers(centre) == exact.covers(centre)


def test_the_workspace_is_the_piece_the_robot_starts_in(tmp_path: Path) -> None:
    free = np.zeros((10, 20), dtype=bool)
    free[1:9, 1:12] = True  # the big room
    free[1:9, 13:19] = True  # the small room, behind a wall
    path = write_map(tmp_path, "m", image_from_free(free), resolution=1.0)
    big = import_map(path, ImportSettings(tolerance=0.0))
    assert Polygon(big.boundary).equals(box(1, 1, 12, 9))
    small = import_map(path, ImportSettings(tolerance=0.0, start=(15.0, 5.0)))
    assert Polygon(small.boundary).equals(box(13, 1, 19, 9))


def test_specks_are_filled_by_the_area_threshold(tmp_path: Path) -> None:
    free = np.ones((20, 20), dtype=bool)
    free[0, :] = free[-1, :] = free[:, 0] = free[:, -1] = False
    free[5, 5] = False  # a one-cell speck
    free[10:13, 10:13] = False  # a 9-cell pillar
    free[15:17, 4:6] = False  # a 4-cell post: exactly the threshold below, so kept
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.5)
    kept = import_map(path, ImportSettings(tolerance=0.0, min_area=0.0))
    assert len(kept.holes) == 3
    filled = import_map(path, ImportSettings(tolerance=0.0, min_area=1.0))  # 4 cells of 0.25
    assert sorted(Polygon(h).area for h in filled.holes) == pytest.approx([4 * 0.25, 9 * 0.25])


def test_an_area_of_whole_cells_is_that_many_cells(tmp_path: Path) -> None:
    # 0.0054 m² is 6 cells of 0.03 m; divided in floats it is 6.000000000000001
    free = np.ones((20, 20), dtype=bool)
    free[0, :] = free[-1, :] = free[:, 0] = free[:, -1] = False
    free[5:7, 5:8] = False  # a 6-cell post: exactly the threshold, so kept
    free[12, 12] = False  # a one-cell speck, filled
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.03)
    imported = import_map(path, ImportSettings(tolerance=0.0, min_area=0.0054))
    assert [Polygon(h).area for h in imported.holes] == pytest.approx([6 * 0.03 * 0.03])


def test_radius_erodes_free_space(tmp_path: Path) -> None:
    free = np.zeros((30, 30), dtype=bool)
    free[2:28, 2:28] = True
    free[12:18, 12:18] = False
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.1)
    radius = 0.3
    imported = import_map(path, ImportSettings(radius=radius, tolerance=0.0, min_area=0.0))
    workspace = Polygon(imported.boundary, imported.holes)
    obstacles = box(0, 0, 3, 3).difference(box(0.2, 0.2, 2.8, 2.8)).union(box(1.2, 1.2, 1.8, 1.8))
    assert obstacles.distance(workspace) >= radius * math.cos(math.pi / 32) - 1e-9
    # ...and not more than needed: the eroded area of the square ring is known.
    outer = (2.6 - 2 * radius) ** 2
    pillar = (0.6 + 2 * radius) ** 2 - (4 - math.pi) * radius**2
    assert workspace.area == pytest.approx(outer - pillar, rel=2e-3)


def test_masks_become_regions_and_groups(tmp_path: Path) -> None:
    free = np.ones((20, 30), dtype=bool)
    free[:, 0] = free[:, -1] = free[0, :] = free[-1, :] = False
    path = write_map(tmp_path, "m", image_from_free(free), resolution=1.0)
    keep = np.full((20, 30), 254, dtype=np.uint8)
    keep[2:6, 2:6] = 0  # image rows 2..5 -> map rows 14..17
    keep[10:15, 20:25] = 0
    keep[17, 2:10] = 0  # a strip one cell high: image row 17 -> map row 2
    keepout = write_map(tmp_path, "keep", keep, resolution=1.0)
    speed_image = np.full((20, 30), 254, dtype=np.uint8)
    speed_image[:, 10:15] = 127  # scale mode: 50
    speed = write_map(
        tmp_path, "speed", speed_image, resolution=1.0, mode="scale", occupied=1.0, free=0.0
    )
    imported = import_map(
        path, ImportSettings(tolerance=0.0, min_area=0.0), keepout=keepout, speed=speed
    )
    assert set(imported.groups) == {"keepout", "speed_50"}
    keep_union = shapely.union_all(
        [Polygon(imported.regions[n]) for n in imported.groups["keepout"]]
    )
    assert keep_union.equals(box(2, 14, 6, 18).union(box(20, 5, 25, 10)).union(box(2, 2, 10, 3)))
    (band,) = imported.groups["speed_50"]
    assert Polygon(imported.regions[band]).equals(box(10, 1, 15, 19))
    # With a radius the regions are the mask cells within the eroded (curved) workspace: a
    # pixel disc, whose staircase erodes into arcs that the mask edges cross.
    rows, cols = np.mgrid[0:20, 0:30]
    disc = (rows - 9.5) ** 2 + (cols - 14.5) ** 2 < 9.3**2
    path = write_map(tmp_path, "disc", image_from_free(disc), resolution=1.0)
    eroded = import_map(
        path, ImportSettings(radius=0.35, tolerance=0.0, min_area=0.0), keepout=keepout, speed=speed
    )
    free_space = Polygon(eroded.boundary, eroded.holes)
    pieces = [Polygon(eroded.regions[n]) for n in eroded.groups["keepout"]]
    want = box(2, 14, 6, 18).union(box(20, 5, 25, 10)).union(box(2, 2, 10, 3))
    want = want.intersection(free_space)
    assert shapely.union_all(pieces).symmetric_difference(want).area < 1e-9
    (band,) = eroded.groups["speed_50"]
    want_band = box(10, 1, 15, 19).intersection(free_space)
    assert Polygon(eroded.regions[band]).symmetric_difference(want_band).area < 1e-9


@pytest.mark.parametrize("pocket_marked", [False, True])
def test_mask_regions_around_a_free_pocket_label_it_only_if_the_mask_does(
    tmp_path: Path, pocket_marked: bool
) -> None:
    """A keepout ring around a rack whose free pocket (another workspace piece) is or is not
    in the keepout mask: the pocket's free space is in a keepout region exactly when marked."""
    free = np.ones((20, 20), dtype=bool)
    free[0, :] = free[-1, :] = free[:, 0] = free[:, -1] = False
    free[6:14, 6:14] = False  # the rack
    free[9:11, 9:11] = True  # a free pocket inside it
    path = write_map(tmp_path, "m", image_from_free(free), resolution=1.0)
    mask = np.zeros((20, 20), dtype=bool)
    mask[4:16, 4:16] = True  # keepout around the rack ...
    if not pocket_marked:
        mask[9:11, 9:11] = False  # ... but not its pocket
    keepout = write_map(tmp_path, "keep", image_from_free(~mask), resolution=1.0)
    imported = import_map(
        path, ImportSettings(tolerance=0.0, min_area=0.0, start=(1.5, 1.5)), keepout=keepout
    )
    assert len(imported.components) == 1
    pocket = Polygon(*imported.components[0])
    assert pocket.equals(box(9, 9, 11, 11))
    regions = [Polygon(imported.regions[n]) for n in imported.groups["keepout"]]
    assert all(r.is_valid and not r.interiors for r in regions)
    covered = shapely.union_all(regions)
    free_space = shapely.union_all([Polygon(imported.boundary, imported.holes), pocket])
    cells = shapely.union_all(
        [box(c, r, c + 1, r + 1) for r, c in zip(*np.nonzero(mask & free), strict=True)]
    )
    # the keepout regions' free part is exactly the marked free cells
    assert covered.intersection(free_space).symmetric_difference(cells).area < 1e-9
    # and the mission is valid and compiles with the pocket labelled as the mask says
    out = tmp_path / "m-mission.yaml"
    code, _, err = run(
        "import-map",
        str(path),
        "--keepout",
        str(keepout),
        "--start",
        "1.5",
        "1.5",
        "--tolerance",
        "0",
        "--min-area",
        "0",
        "-o",
        str(out),
    )
    assert code == 0, err
    assert check_file(out) == []


# --- the mission form and the command -------------------------------------------------------


def _depot_like(tmp_path: Path) -> Path:
    free = np.ones((40, 60), dtype=bool)
    free[0, :] = free[-1, :] = free[:, 0] = free[:, -1] = False
    free[10:30, 20:22] = False
    write_map(tmp_path, "floor", image_from_free(free), resolution=0.1)
    keep = np.full((40, 60), 254, dtype=np.uint8)
    keep[5:15, 40:50] = 0
    write_map(tmp_path, "floor_keepout", keep, resolution=0.1)
    return tmp_path / "floor.yaml"


def test_mission_form_loads_and_compiles(tmp_path: Path) -> None:
    _depot_like(tmp_path)
    mission = tmp_path / "mission.yaml"
    mission.write_text(
        "version: 1\n"
        "workspace: {map: floor.yaml, keepout: floor_keepout.yaml, inflate: 0.1}\n"
        "regions:\n  goal: {rect: [4.5, 0.5, 5.5, 1.5]}\n"
        "robot: {start: [0.5, 0.5]}\n"
        "task: [visit goal, avoid keepout]\n"
    )
    assert check_file(mission) == []
    loaded = load_mission(mission)
    assert loaded.groups["keepout"] == ("keepout_1",)
    assert "keepout_1" in loaded.region_names
    code, _, err = run("compile", str(mission), "-o", str(tmp_path / "out"), "--until", "verify")
    assert code == 0, err


def test_mission_form_keeps_the_free_pockets_as_components(tmp_path: Path) -> None:
    free = np.ones((30, 30), dtype=bool)
    free[0, :] = free[-1, :] = free[:, 0] = free[:, -1] = False
    free[8:22, 8:22] = False  # a rack ...
    free[12:18, 12:18] = True  # ... with a free pocket inside
    write_map(tmp_path, "rack", image_from_free(free), resolution=0.1)
    mission = tmp_path / "mission.yaml"
    mission.write_text(
        "version: 1\nworkspace: {map: rack.yaml}\n"
        "regions:\n  goal: {rect: [2.5, 2.5, 2.9, 2.9]}\n  inside: {rect: [1.3, 1.3, 1.7, 1.7]}\n"
        "robot: {start: [0.5, 0.5]}\ntask: [visit goal]\n"
    )
    assert check_file(mission) == []
    loaded = load_mission(mission)
    (pocket,) = loaded.workspace.components
    assert Polygon(pocket.boundary).symmetric_difference(box(1.2, 1.2, 1.8, 1.8)).area < 1e-12
    code, _, err = run("compile", str(mission), "-o", str(tmp_path / "out"), "--until", "verify")
    assert code == 0, err
    assert (
        "region 'inside' is not reachable from the start: it lies in workspace component 0" in err
    )


@pytest.mark.parametrize(
    ("workspace", "code"),
    [
        ("{map: missing.yaml}", "M001"),
        ("{map: floor.yaml, boundary: {rect: [0, 0, 1, 1]}}", "M014"),
        ("{map: floor.yaml, keepout: floor_keepout.yaml}\ngroups: {keepout: [goal]}", "M015"),
        ("{}", "S002"),
    ],
)
def test_mission_form_errors_point_at_the_mission(
    tmp_path: Path, workspace: str, code: str
) -> None:
    _depot_like(tmp_path)
    mission = tmp_path / "mission.yaml"
    mission.write_text(
        f"version: 1\nworkspace: {workspace}\n"
        "regions:\n  goal: {rect: [4.5, 0.5, 5.5, 1.5]}\n"
        "robot: {start: [0.5, 0.5]}\ntask: [visit goal]\n"
    )
    problems = check_file(mission)
    assert problems
    assert problems[0].code == code
    assert problems[0].file == str(mission)
    assert problems[0].line is not None


def test_import_map_writes_a_mission_that_check_accepts(tmp_path: Path) -> None:
    floor = _depot_like(tmp_path)
    out = tmp_path / "imported.yaml"
    code, _, err = run(
        "import-map",
        str(floor),
        "--keepout",
        str(tmp_path / "floor_keepout.yaml"),
        "--region",
        "goal",
        "4",
        "0",
        "6",
        "2",
        "--task",
        "visit goal",
        "--task",
        "avoid keepout",
        "--radius",
        "0.05",
        "-o",
        str(out),
    )
    assert code == 0, err
    assert check_file(out) == []
    mission = load_mission(out)
    start = Point(mission.robot.start)
    keepout = Polygon(mission.region("keepout_1").polygon)
    assert not keepout.covers(start)


@pytest.mark.parametrize(
    ("setup", "code"),
    [
        ("missing_image", "M005"),
        ("corrupt_image", "M006"),
        ("not_yaml", "M002"),
        ("no_resolution", "M003"),
        ("bad_thresholds", "M004"),
        ("all_occupied", "M010"),
        ("mask_size", "M013"),
    ],
)
def test_bad_maps_get_diagnostics_not_tracebacks(tmp_path: Path, setup: str, code: str) -> None:
    free = np.ones((8, 8), dtype=bool)
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.1)
    extra: list[str] = ["--region", "g", "0.1", "0.1", "0.3", "0.3", "--task", "visit g"]
    if setup == "missing_image":
        (tmp_path / "m.pgm").unlink()
    elif setup == "corrupt_image":
        (tmp_path / "m.pgm").write_bytes(b"P5 nonsense")
    elif setup == "not_yaml":
        path.write_text("image: [unclosed\n")
    elif setup == "no_resolution":
        path.write_text("image: m.pgm\norigin: [0, 0, 0]\noccupied_thresh: 0.6\nfree_thresh: 0.2\n")
    elif setup == "bad_thresholds":
        path.write_text(
            "image: m.pgm\nresolution: 0.1\norigin: [0, 0, 0]\noccupied_thresh: 0.1\n"
            "free_thresh: 0.5\n"
        )
    elif setup == "all_occupied":
        write_map(tmp_path, "m", np.zeros((8, 8), dtype=np.uint8), resolution=0.1)
    elif setup == "mask_size":
        mask = write_map(tmp_path, "k", np.zeros((4, 4), dtype=np.uint8), resolution=0.1)
        extra += ["--keepout", str(mask)]
    result, _, err = run("import-map", str(path), *extra)
    assert result == 2, err
    assert f"error[{code}]" in err
    assert "Traceback" not in err


def test_map_errors_are_usage_errors() -> None:
    with pytest.raises(UsageError):
        import_map(Path("/nonexistent/map.yaml"))


# --- the real nav2 maps ---------------------------------------------------------------------

REAL_MAPS = (
    ("depot", "depot_keepout", "depot_speed"),
    ("warehouse", "warehouse_keepout", "warehouse_speed"),
    ("tb3_sandbox", None, None),
    ("smoothers_world", None, None),
)


def free_cells_oracle(map_yaml: Path) -> float:
    """The free area of a trinary map_server map, from its image with numpy alone."""
    import yaml
    from PIL import Image

    info = yaml.safe_load(map_yaml.read_text())
    assert info.get("mode", "trinary") == "trinary"
    pixels = np.asarray(Image.open(map_yaml.parent / info["image"]), dtype=np.float64)
    if pixels.ndim == 3:
        pixels = pixels[..., : 1 if pixels.shape[2] <= 2 else 3].mean(axis=2)
    shade = pixels / 255.0
    occupancy = shade if info.get("negate", 0) else 1.0 - shade
    free = occupancy < float(info["free_thresh"])
    return float(np.count_nonzero(free)) * float(info["resolution"]) ** 2


@pytest.mark.parametrize(("name", "keepout", "speed"), REAL_MAPS)
def test_real_maps_import_into_valid_missions(
    tmp_path: Path, name: str, keepout: str | None, speed: str | None
) -> None:
    maps = require_shared("maps")
    imported = import_map(
        maps / f"{name}.yaml",
        keepout=maps / f"{keepout}.yaml" if keepout else None,
        speed=maps / f"{speed}.yaml" if speed else None,
    )
    pieces = pieces_of(imported)
    assert all(p.is_valid for p in pieces)
    # Every free piece above the speck threshold, simplified within one cell and specks
    # filled: within 2% of the map's free cells, counted here from the image itself.
    free_area = free_cells_oracle(maps / f"{name}.yaml")
    assert imported.free_cells_area == pytest.approx(free_area)
    assert sum(p.area for p in pieces) == pytest.approx(free_area, rel=0.02)
    assert imported.workspace_area == pytest.approx(sum(p.area for p in pieces))
    if keepout:
        assert imported.groups["keepout"]
    out = tmp_path / f"{name}.yaml"
    args = ["import-map", str(maps / f"{name}.yaml"), "-o", str(out)]
    if keepout:
        args += ["--keepout", str(maps / f"{keepout}.yaml")]
    else:
        args += ["--region", "here", "-1000.0", "-1000.0", "1000", "1000", "--task", "visit here"]
    code, _, err = run(*args)
    assert code == 0, err
    assert check_file(out) == []


def test_check_of_a_map_mission_imports_no_heavy_packages(tmp_path: Path) -> None:
    import subprocess
    import sys

    _depot_like(tmp_path)
    mission = tmp_path / "mission.yaml"
    mission.write_text(
        "version: 1\nworkspace: {map: floor.yaml, keepout: floor_keepout.yaml}\n"
        "regions:\n  goal: {rect: [4.5, 0.5, 5.5, 1.5]}\n"
        "robot: {start: [0.5, 0.5]}\ntask: [visit goal, avoid keepout]\n"
    )
    script = (
        "import sys, io\n"
        "from tlmpc.cli import main\n"
        f"code = main(['check', {str(mission)!r}], io.StringIO(), io.StringIO())\n"
        "heavy = [m for m in ('scipy', 'cvxpy', 'triangle', 'matplotlib', 'clarabel', 'rosbags')"
        " if m in sys.modules]\n"
        "print(code, heavy)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert done.stdout.strip() == "0 []"


@pytest.mark.slow
def test_real_depot_mission_form_compiles_and_verifies(tmp_path: Path) -> None:
    maps = require_shared("maps")
    mission = tmp_path / "depot.yaml"
    mission.write_text(
        f"version: 1\nworkspace: {{map: {maps / 'depot.yaml'}, "
        f"keepout: {maps / 'depot_keepout.yaml'}, speed: {maps / 'depot_speed.yaml'}, "
        "inflate: 0.1}\n"
        "regions:\n  dock: {rect: [2, 2, 3, 3]}\n"
        "robot: {start: [5, 5]}\n"
        "task: [avoid keepout, visit speed_50 then dock]\n"
    )
    code, out, err = run("compile", str(mission), "-o", str(tmp_path / "out"), "--until", "verify")
    assert code == 0, err
    assert "trace verifies" in err + out


@pytest.mark.slow
@example(
    pillars=[(2, 2), (1, 3), (6, 4), (3, 5)],
    corner=(7, 3),
    radius=0.38834985812647604,
    tolerance=0.0,
)
@given(
    pillars=st.lists(st.tuples(st.integers(1, 13), st.integers(1, 13)), max_size=5),
    corner=st.tuples(st.integers(0, 10), st.integers(0, 10)),
    radius=st.floats(0.0, 0.6),
    tolerance=st.sampled_from([0.0, 0.5]),
)
def test_keepout_regions_are_the_mask_within_free_space(
    tmp_path_factory: pytest.TempPathFactory,
    pillars: list[tuple[int, int]],
    corner: tuple[int, int],
    radius: float,
    tolerance: float,
) -> None:
    free = np.ones((16, 16), dtype=bool)
    free[0, :] = free[-1, :] = free[:, 0] = free[:, -1] = False
    for r, c in pillars:
        free[r : r + 2, c : c + 3] = False
    directory = tmp_path_factory.mktemp("keep")
    path = write_map(directory, "m", image_from_free(free), resolution=1.0)
    keep = np.full((16, 16), 254, dtype=np.uint8)
    r, c = corner
    keep[r : r + 5, c : c + 6] = 0
    mask = write_map(directory, "k", keep, resolution=1.0)
    try:
        imported = import_map(
            path,
            ImportSettings(radius=radius, tolerance=tolerance, min_area=0.0),
            keepout=mask,
        )
    except UsageError:
        return  # eroded away entirely
    free_space = Polygon(imported.boundary, imported.holes)
    names = imported.groups.get("keepout", ())
    got = shapely.union_all([Polygon(imported.regions[n]) for n in names]).intersection(free_space)
    want = box(c, 16 - (r + 5), c + 6, 16 - r).intersection(free_space)
    # Exact without simplification; within the tolerance's band along the region's edges with.
    slack = 1e-9 if tolerance == 0 else tolerance * (want.length + got.length + 4 * 6)
    assert got.symmetric_difference(want).area <= slack


def test_default_start_avoids_keepout(tmp_path: Path) -> None:
    from tlmpc.importers.mission import default_start

    free = np.zeros((20, 20), dtype=bool)
    free[1:19, 1:19] = True
    path = write_map(tmp_path, "m", image_from_free(free), resolution=1.0)
    keep = np.full((20, 20), 254, dtype=np.uint8)
    keep[6:14, 6:14] = 0  # the middle of the room, where the farthest-from-walls point is
    mask = write_map(tmp_path, "k", keep, resolution=1.0)
    imported = import_map(path, ImportSettings(tolerance=0.0), keepout=mask)
    start = Point(default_start(imported))
    assert Polygon(imported.boundary).covers(start)
    assert not box(6, 6, 14, 14).covers(start)


def test_import_then_edit(tmp_path: Path) -> None:
    # no regions and no task: the mission is written with what is still to add
    free = np.ones((20, 20), dtype=bool)
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.1)
    out = tmp_path / "mission.yaml"
    code, _, err = run("import-map", str(path), "-o", str(out))
    assert code == 0, err
    assert "no regions and no task yet" in err
    text = out.read_text()
    assert "# still to add: regions and task" in text
    assert check_file(out) != []  # not a mission yet
    out.write_text(text + "regions:\n  dock: {rect: [0.5, 0.5, 1, 1]}\ntask: [visit dock]\n")
    assert check_file(out) == []
    # regions but no task (and no keepout mask to avoid): also written, the task to add
    code, _, err = run(
        "import-map", str(path), "--region", "g", "0.1", "0.1", "0.3", "0.3", "-o", str(out)
    )
    assert code == 0, err
    assert "# still to add: task" in out.read_text()


@pytest.mark.parametrize(
    ("flags", "where"),
    [
        (["--task", "visit goal", "--task", "visit dockk"], "--task 'visit dockk':1:7:"),
        (["--ltl", "F goal & G !pond"], "--ltl 'F goal & G !pond':1:"),
    ],
)
def test_a_task_naming_an_unknown_region_fails_at_the_flag(
    tmp_path: Path, flags: list[str], where: str
) -> None:
    free = np.ones((20, 20), dtype=bool)
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.1)
    out = tmp_path / "mission.yaml"
    code, _, err = run(
        "import-map", str(path), "--region", "goal", "0.1", "0.1", "0.3", "0.3",
        *flags, "-o", str(out),
    )  # fmt: skip
    assert code == 1, err
    assert err.startswith(where), err
    assert "error[L010]: unknown region" in err
    assert not out.exists()


@pytest.mark.parametrize("region", [True, False])
@pytest.mark.parametrize(
    ("flags", "expected"),
    [
        (["--ltl", "G("], "--ltl 'G(':1:3: error[L002]: the LTL formula ends too early"),
        (["--task", "visit"], "--task 'visit':1:1: error[T001]"),
        (["--task", "visit goal", "--ltl", "F & goal"], "--ltl 'F & goal':1:3: error[L"),
    ],
)
def test_a_task_that_does_not_parse_fails_at_the_flag(
    tmp_path: Path, flags: list[str], expected: str, region: bool
) -> None:
    # located in the flag's own text, not at a line of the mission that is never written;
    # a syntax error is refused even when the mission has no regions yet
    free = np.ones((20, 20), dtype=bool)
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.1)
    out = tmp_path / "mission.yaml"
    regions = ["--region", "goal", "0.1", "0.1", "0.3", "0.3"] if region else []
    code, _, err = run("import-map", str(path), *regions, *flags, "-o", str(out))
    assert code == 1, err
    assert err.startswith(expected), err
    assert "mission.yaml" not in err
    assert not out.exists()


def test_a_max_speed_too_small_for_the_map_fails_at_the_flag(tmp_path: Path) -> None:
    # 2 m across at 1e-12 takes 2.8e12 s to cross, more than a trace holds (S010)
    free = np.ones((20, 20), dtype=bool)
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.1)
    out = tmp_path / "mission.yaml"
    code, _, err = run(
        "import-map", str(path), "--region", "goal", "0.1", "0.1", "0.3", "0.3",
        "--task", "visit goal", "--max-speed", "1e-12", "-o", str(out),
    )  # fmt: skip
    assert code == 1, err
    assert err.startswith("--max-speed 1e-12: error[S010]: $.robot.max_speed: 1e-12 is too small")
    assert "mission.yaml" not in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("regions", "expected"),
    [
        pytest.param(
            ["dock", "0.1", "0.1", "0.5", "0.5", "dock", "1", "1", "1.5", "1.5"],
            "--region dock 1 1 1.5 1.5: error[M017]: the region 'dock' is already given by "
            "`--region dock 0.1 0.1 0.5 0.5`",
            id="a name twice",
        ),
        pytest.param(
            [
                *("dock", "0.1", "0.1", "0.5", "0.5"),
                *("pier", "1", "1", "1.5", "1.5"),
                *("dock", "0.1", "0.1", "0.5", "0.5"),
            ],
            "--region dock 0.1 0.1 0.5 0.5: error[M017]: the region 'dock' is already given",
            id="the same rectangle again",
        ),
        pytest.param(
            ["dock", "0", "0", "x", "1"],
            "--region dock 0 0 x 1: error[M017]: the bounds must be numbers",
            id="bounds not numbers",
        ),
        pytest.param(
            ["my dock", "0", "0", "1", "1"],
            "--region 'my dock' 0 0 1 1: error[M017]: 'my dock' is not a usable region name",
            id="not an identifier",
        ),
        pytest.param(
            ["dock", "1", "1", "0.5", "0.5"],
            "--region dock 1 1 0.5 0.5: error[M017]: need finite bounds",
            id="corners swapped",
        ),
        pytest.param(
            ["dock", "10", "10", "11", "11"],
            "--region dock 10 10 11 11: error[M017]: the rectangle has no free space",
            id="off the map",
        ),
    ],
)
def test_a_region_flag_that_cannot_be_used_is_refused_at_the_flag(
    tmp_path: Path, regions: list[str], expected: str
) -> None:
    # a name given twice would otherwise silently keep the last rectangle only
    free = np.ones((20, 20), dtype=bool)
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.1)
    out = tmp_path / "mission.yaml"
    flags = [w for k in range(0, len(regions), 5) for w in ("--region", *regions[k : k + 5])]
    code, _, err = run("import-map", str(path), *flags, "--task", "visit dock", "-o", str(out))
    assert code == 2, err
    assert err.startswith(expected), err
    assert "\n  hint: " in err
    assert not out.exists()


def test_regions_of_distinct_names_are_all_written(tmp_path: Path) -> None:
    free = np.ones((20, 20), dtype=bool)
    path = write_map(tmp_path, "m", image_from_free(free), resolution=0.1)
    out = tmp_path / "mission.yaml"
    code, _, err = run(
        "import-map", str(path), "--region", "dock", "0.1", "0.1", "0.5", "0.5",
        "--region", "pier", "1", "1", "1.5", "1.5", "--task", "visit dock", "-o", str(out),
    )  # fmt: skip
    assert code == 0, err
    mission = load_mission(out)
    assert Polygon(mission.region("dock").polygon).equals(box(0.1, 0.1, 0.5, 0.5))
    assert Polygon(mission.region("pier").polygon).equals(box(1, 1, 1.5, 1.5))
