"""Tests of shape_from_symmetry.complete: a development scene, the command-line tool's result on
it, and bad input of every kind."""

import json
import os
import re
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import shape_from_symmetry as sfs
from gray_png import read_gray_png

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "dev" / "ycb_025_mug_wrist_0.json"
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
TOOL = TARGET / "release" / "examples" / "complete"
TYPES = [
    "plane_reflection",
    "line_reflection",
    "point_reflection",
    "axial",
    "spherical",
    "dual_plane",
    "triple_plane",
    "axial_plane",
]


@pytest.fixture(scope="module")
def scene():
    """The scene's arguments of `complete`, as the command-line tool reads its file."""
    if not SCENE.is_file():
        pytest.skip(f"no development scene at {SCENE}")
    file = json.loads(SCENE.read_text())
    return {
        "depth": read_gray_png(SCENE.parent / file["depth"]),
        "depth_scale": file["depth_scale"],
        "intrinsics": file["intrinsics"],
        "mask": read_gray_png(SCENE.parent / file["mask"]),
        "table": file["table_plane"],
    }


@pytest.fixture(scope="module")
def mug(scene):
    return sfs.complete(**scene)


@pytest.fixture(scope="module")
def unmasked(scene):
    """The scene's arguments without its mask: the engine segments the object."""
    return {key: value for key, value in scene.items() if key != "mask"}


@pytest.fixture(scope="module")
def segmented(unmasked):
    return sfs.complete(**unmasked)


def summary(result):
    """Everything a result holds, comparable with ==."""
    def parts(s):
        return s and (s.type, s.planes, s.axis, s.centre, s.score, s.confidence, s.domain_points)

    symmetries = [parts(s) for s in result.symmetries] + [parts(result.runner_up)]
    arrays = [result.points, result.provenance, result.symmetry, result.plausibility]
    return symmetries, [a.tobytes() for a in arrays], result.points_dropped, result.work_units


def k_matrix(scene):
    """The scene's intrinsics as a matrix K (a list of rows)."""
    k = scene["intrinsics"]
    return [[k["fx"], 0, k["cx"]], [0, k["fy"], k["cy"]], [0, 0, 1]]


def f32(value):
    """A number of the tool's JSON as the float32 it printed, exactly."""
    return float(np.float32(value))


def test_finds_the_mugs_symmetry_and_completes_it(mug):
    assert mug.symmetries, "no symmetry found"
    assert all(s.type in TYPES and s.score >= 0 for s in mug.symmetries)
    n = len(mug.points)
    assert mug.points.shape == (n, 3) and mug.points.dtype == np.float32
    assert mug.provenance.shape == mug.symmetry.shape == mug.plausibility.shape == (n,)
    assert mug.provenance.dtype == mug.symmetry.dtype == np.uint8
    visible = np.count_nonzero(mug.provenance == 0)
    assert 0 < visible < n, "visible points, then generated ones"
    assert set(np.unique(mug.provenance[visible:])) == {1}
    assert np.all((mug.symmetry < len(mug.symmetries)) | (mug.symmetry == 255))
    assert mug.points_dropped == 0 and mug.work_units > 0 and mug.polls > 0
    assert re.fullmatch(r"Completion\(symmetries=\[\w+\], points=\d+\)", repr(mug))


def test_matches_the_command_line_tool(mug, tmp_path):
    if not TOOL.is_file():
        pytest.skip(f"{TOOL} not built (cargo build --release --example complete)")
    out = tmp_path / "result.json"
    subprocess.run([TOOL, SCENE, "--out", out], check=True, capture_output=True)
    expected = json.loads(out.read_text())
    assert len(mug.symmetries) == len(expected["symmetries"])
    runner_up = [mug.runner_up] if mug.runner_up else []
    listed_runner_up = [expected["runner_up"]] if "runner_up" in expected else []
    assert len(runner_up) == len(listed_runner_up)
    for found, listed in zip(mug.symmetries + runner_up, expected["symmetries"] + listed_runner_up):
        assert found.type == listed["type"]
        assert found.score == f32(listed["score"])
        assert found.confidence == f32(listed["confidence"])
        assert 0.0 <= found.confidence <= 1.0
        assert found.domain_points == listed["domain_points"]
        planes = [(tuple(map(f32, p["normal"])), f32(p["offset"])) for p in listed["planes"]]
        assert found.planes == planes
        axes = [
            (tuple(map(f32, a["direction"])), tuple(map(f32, a["point"]))) for a in listed["axes"]
        ]
        assert ([found.axis] if found.axis else []) == axes
        centre = listed["center"] and tuple(map(f32, listed["center"]))
        assert found.centre == centre
    points = expected["points"]
    assert np.count_nonzero(mug.provenance == 0) == points["visible"]
    assert np.count_nonzero(mug.provenance == 1) == points["generated"]
    assert mug.points_dropped == points["dropped"]
    work = expected["work"]
    assert (mug.polls, mug.work_units) == (work["polls"], work["work_units"])


def test_a_matrix_K_gives_the_mappings_result(scene, mug):
    matrix = k_matrix(scene)
    assert summary(sfs.complete(**{**scene, "intrinsics": matrix})) == summary(mug)
    assert summary(sfs.complete(**{**scene, "intrinsics": np.array(matrix)})) == summary(mug)


def test_the_result_does_not_depend_on_budget_memory_layout_or_mask_dtype(scene, mug):
    sliced = sfs.complete(**scene, budget=1000)
    assert summary(sliced) == summary(mug) and sliced.polls > mug.polls
    column_major = {key: np.asfortranarray(scene[key]) for key in ("depth", "mask")}
    assert summary(sfs.complete(**{**scene, **column_major})) == summary(mug)
    assert summary(sfs.complete(**{**scene, "mask": scene["mask"] > 0})) == summary(mug)


def test_searches_in_parallel_threads_alike(scene, mug):
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(lambda _: sfs.complete(**scene), range(2)))
    assert [summary(r) for r in results] == [summary(mug)] * 2


def test_runs_without_mask_or_table_and_with_options(scene):
    segmented = sfs.complete(scene["depth"], scene["depth_scale"], scene["intrinsics"])
    assert len(segmented.points) > 0
    restricted = sfs.complete(**scene, types=["plane_reflection", "axial"], parts=True)
    shown = r"Symmetry\(type='\w+', confidence=[\d.]+, score=[\d.e-]+, domain_points=\d+\)"
    assert all(re.fullmatch(shown, repr(found)) for found in restricted.symmetries)


def test_one_object_keeps_what_creases_would_part(unmasked, segmented):
    # Without a mask the mug's handle meets its body at a concave crease, where the default
    # parts two touching objects: told that nothing touches the mug, the engine keeps more.
    whole = sfs.complete(**unmasked, one_object=True)

    def visible(result):
        return int(np.count_nonzero(result.provenance == 0))

    assert visible(whole) > visible(segmented)


def test_reports_the_segmentation_without_a_mask(mug, segmented):
    assert mug.segmentation is None, "a mask: no segmentation"
    s = segmented.segmentation
    assert s is not None and s.candidates >= 1
    assert s.chosen is not None and 0 <= s.chosen < s.candidates
    x, y, w, h = s.object_box
    assert w > 0 and h > 0 and x + w <= 320 and y + h <= 240
    shown = r"Segmentation\(candidates=\d+, chosen=\d+, object_box=\(\d+, \d+, \d+, \d+\)\)"
    assert re.fullmatch(shown, repr(s))


def test_a_target_pixel_or_region_names_the_object(unmasked, segmented):
    x, y, w, h = segmented.segmentation.object_box
    by_pixel = sfs.complete(**unmasked, target=(x + w // 2, y + h // 2))
    by_region = sfs.complete(**unmasked, roi=np.array([x, y, w, h]))
    assert summary(by_pixel) == summary(segmented)
    for result in (by_pixel, by_region):
        found, expected = result.segmentation, segmented.segmentation
        assert (found.candidates, found.chosen, found.object_box) == (
            expected.candidates, expected.chosen, expected.object_box)
    # The region also takes the regions wholly within it, pieces of the object the segmentation
    # parted from it: the same object, with no fewer points seen.
    seen = lambda result: int((result.provenance == 0).sum())
    assert seen(by_region) >= seen(segmented)
    assert [s.type for s in by_region.symmetries] == [s.type for s in segmented.symmetries]


def test_a_target_on_no_object_is_a_value_error(unmasked):
    with pytest.raises(ValueError, match="^no object candidate at the target pixel"):
        sfs.complete(**unmasked, target=(0, 0))


def scene_with(**changes):
    """A function of the scene's arguments: the same with `changes`, each a value or a function
    of the scene."""
    return lambda scene: {
        **scene,
        **{key: value(scene) if callable(value) else value for key, value in changes.items()},
    }


NAN, INF = float("nan"), float("inf")
# (what is wrong, the arguments, the start of the ValueError's message): every kind refused.
BAD_INPUTS = [
    ("depth dtype", scene_with(depth=lambda s: s["depth"].astype(np.float64)),
     "depth must be a uint16 array, got dtype float64"),
    ("depth not an array", scene_with(depth=lambda s: s["depth"].tolist()),
     "depth must be a numpy array, got a value of type list"),
    ("depth ndim", scene_with(depth=lambda s: s["depth"][None]),
     "depth must be 2-D (height, width), got shape (1, 240, 320)"),
    ("depth too wide", scene_with(depth=np.zeros((1, 70000), np.uint16), mask=None),
     "depth has shape (1, 70000): at most 65535 pixels a side"),
    ("depth without reading",
     scene_with(depth=lambda s: np.zeros_like(s["depth"]), mask=None, table=None),
     "the depth image has no valid reading"),
    ("depth empty", scene_with(depth=lambda s: s["depth"][:0], mask=None, intrinsics=k_matrix),
     "image width or height is zero"),
    ("depth_scale NaN", scene_with(depth_scale=NAN), "depth_scale must be a finite number within"),
    ("depth_scale range", scene_with(depth_scale=2.0),
     "depth scale must be positive and at most 1 m per unit"),
    ("depth_scale type", scene_with(depth_scale="0.001"),
     "depth_scale must be a number, got '0.001'"),
    ("fx infinite", scene_with(intrinsics=lambda s: {**s["intrinsics"], "fx": INF}),
     "intrinsics fx must be a finite number"),
    ("fx zero", scene_with(intrinsics=lambda s: {**s["intrinsics"], "fx": 0}),
     "intrinsics must be finite with positive focal lengths"),
    ("cy missing", scene_with(intrinsics={"fx": 1, "fy": 1, "cx": 1}), "intrinsics has no cy"),
    ("width mismatch", scene_with(intrinsics=lambda s: {**s["intrinsics"], "width": 300}),
     "intrinsics width is 300, the depth image's is 320"),
    ("K 2x3", scene_with(intrinsics=lambda s: k_matrix(s)[:2]), "K must be 3x3, got shape (2, 3)"),
    ("K skewed", scene_with(intrinsics=[[1, 0.5, 1], [0, 1, 1], [0, 0, 1]]),
     "K must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], got [[1, 0.5, 1], [0, 1, 1], [0, 0, 1]]"),
    ("K flat", scene_with(intrinsics=lambda s: sum(k_matrix(s), [])),
     "intrinsics must be a mapping with fx, fy, cx, cy or a 3x3 matrix"),
    ("K text", scene_with(intrinsics="K"),
     "intrinsics must be a mapping with fx, fy, cx, cy or a 3x3 matrix"),
    ("mask shape", scene_with(mask=lambda s: s["mask"][:, 1:]),
     "mask has shape (240, 319), the depth image (240, 320)"),
    ("mask dtype", scene_with(mask=lambda s: s["mask"].astype(str)),
     "mask must be a boolean or numeric array, got dtype <U"),
    ("mask empty", scene_with(mask=lambda s: np.zeros_like(s["mask"])),
     "no object left after segmentation"),
    ("table length", scene_with(table=[0, -1, 0]),
     "table must be 4 numbers (nx, ny, nz, d), got [0, -1, 0]"),
    ("table NaN", scene_with(table=[NAN, -1, 0, 0.3]), "table nx must be a finite number"),
    ("table zero", scene_with(table=[0, 0, 0, 0.3]), "table normal (nx, ny, nz) is zero"),
    ("types unknown", scene_with(types=["axial", "cube"]),
     'unknown symmetry type "cube": expected one of plane_reflection, line_reflection'),
    ("types string", scene_with(types="axial"), "types must be a list of type names, got 'axial'"),
    ("types empty", scene_with(types=[]), "types is empty: name at least one type"),
    ("types number", scene_with(types=[3]), "each of types must be a type name, got 3"),
    ("parts", scene_with(parts="yes"), "parts must be True or False, got 'yes'"),
    ("one_object", scene_with(one_object=1.5), "one_object must be True or False, got 1.5"),
    ("budget zero", scene_with(budget=0),
     "budget must be a positive whole number of work units per poll, got 0"),
    ("budget negative", scene_with(budget=-5),
     "budget must be a positive whole number of work units per poll, got -5"),
    ("target and roi", scene_with(target=(1, 2), roi=(0, 0, 5, 5)),
     "target and roi exclude each other: name the object by a pixel (u, v) or by a region"),
    ("target arity", scene_with(target=(1, 2, 3)),
     "target must be 2 whole numbers (u, v), got (1, 2, 3)"),
    ("target string", scene_with(target="1,2"), "target must be 2 whole numbers (u, v), got '1,2'"),
    ("target float", scene_with(target=(1.5, 2)),
     "target must be 2 whole numbers (u, v), got (1.5, 2)"),
    ("target number", scene_with(target=7), "target must be 2 whole numbers (u, v), got 7"),
    ("target negative", scene_with(target=(-1, 2)),
     "target u must be a whole number from 0 to 65535, got -1"),
    ("target huge", scene_with(target=(1, 2**70)),
     "target v must be a whole number from 0 to 65535, got 1180591620717411303424"),
    ("target outside", scene_with(target=(320, 0)),
     "the target pixel or region is not inside the image"),
    ("roi arity", scene_with(roi=[0, 0, 5]), "roi must be 4 whole numbers (x, y, w, h), got [0, 0, 5]"),
    ("roi too large", scene_with(roi=(0, 0, 70000, 5)),
     "roi w must be a whole number from 0 to 65535, got 70000"),
    ("roi empty", scene_with(roi=(0, 0, 0, 5)),
     "roi is 0x5 pixels: its width and height must be positive"),
    ("roi outside", scene_with(roi=(300, 0, 21, 5)),
     "the target pixel or region is not inside the image"),
]


@pytest.mark.parametrize(
    "arguments, message", [case[1:] for case in BAD_INPUTS], ids=[case[0] for case in BAD_INPUTS]
)
def test_refuses_bad_input_with_a_value_error(scene, arguments, message):
    with pytest.raises(ValueError, match="^" + re.escape(message)):
        sfs.complete(**arguments(scene))
