# crossval, info, explain and compare from Python give the command line's
# JSON (timings aside), plus the per-pixel maps as arrays.
import math

import numpy as np
import pytest

import rastray
from conftest import cli_json, run_cli, scene_path


def without_seconds(summary):
    return {k: v for k, v in summary.items() if k != "seconds"}


@pytest.mark.parametrize("scene,kwargs,options", [
    ("cornell-box.gltf", dict(size=(80, 60), spp=4), ["--size", "80", "60", "--spp", "4"]),
    ("transparent-layers.gltf", dict(size="64x48", spp=2, transparency="sorted"),
     ["--size", "64", "48", "--spp", "2", "--transparency", "sorted"]),
])
def test_crossval_summary_equals_command_line_json(scene, kwargs, options):
    result = rastray.crossval(scene_path(scene), **kwargs)
    # Exit 1: a threshold failed (sorted transparency is wrong on purpose).
    cli = cli_json("crossval", scene_path(scene), "--json", *options, statuses=(0, 1))
    assert len(cli["scenes"]) == 1
    assert without_seconds(result.summary) == without_seconds(cli["scenes"][0])
    assert set(result.summary["seconds"]) == {"raster", "raytrace", "hybrid"}


def test_crossval_maps_and_frames(cornell):
    result = rastray.crossval(cornell, size=(80, 60), spp=4)
    m = result.mismatch_map
    assert m.shape == (60, 80) and m.dtype == np.uint8
    assert m.max() < len(rastray.PIXEL_CLASSES)
    keys = [key for key, _, _ in rastray.PIXEL_CLASSES]
    assert keys[:2] == ["both-empty", "agree"]
    # The map agrees with the summary's counts: each mismatching pixel has
    # at least one mismatching layer of its class.
    vis = result.summary["rasterVsRaytrace"]["visibility"]
    assert ((m == keys.index("both-empty")) | (m == keys.index("agree"))).sum() > 0.9 * m.size
    assert (m == keys.index("agree")).sum() > 0
    for key, count in vis["mismatches"].items():
        assert (m == keys.index(key)).sum() <= count, key
    mismatching = vis["layers"]["compared"] - vis["layers"]["agreeing"]
    assert 0 < (m >= keys.index("silhouette-edge")).sum() <= mismatching
    d = result.depth_error
    assert d.shape == (60, 80) and d.dtype == np.float32
    assert np.isnan(d[m == keys.index("both-empty")]).all()
    assert np.nanmax(d) < 1e-3
    assert vis["samples"]["compared"] == 80 * 60 * 4
    # hybrid d = 0: hybrid and the ray caster agree bit for bit where their hits agree.
    hybrid = result.summary["hybridVsRaytrace"]["color"]
    assert hybrid["maxWhereHitsAgree"] == 0 and hybrid["layersWhereHitsAgree"] > 0
    for name in ("raster", "raytrace", "hybrid"):
        frame = getattr(result, name)
        assert frame.renderer == name and frame.deep is not None and frame.color.shape == (60, 80, 4)


def test_info_equals_command_line_json(cornell):
    assert cornell.info() == cli_json("info", cornell.path, "--json")
    assert cornell.info(size=(100, 50), camera=0) == cli_json("info", cornell.path, "--json", "--size", "100",
                                                                "50", "--camera", "0")
    assert cornell.lights == cornell.info()["lightList"]
    assert cornell.cameras == cornell.info()["cameraList"]
    with pytest.raises(ValueError, match="camera options only"):
        cornell.info(spp=4)


def test_explain_equals_command_line_json(cornell):
    mine = rastray.explain(cornell, 40, 30, size=(80, 60), spp=4)
    assert mine == cli_json("explain", cornell.path, "40", "30", "--json", "--size", "80", "60", "--spp", "4")
    assert mine["schema"] == "rastray.explain"
    with pytest.raises(ValueError, match=r"pixel \(80, 0\) lies outside the image"):
        rastray.explain(cornell, 80, 0, size=(80, 60))


def test_compare_files_equals_command_line(tmp_path, cornell):
    a, b = tmp_path / "a.exr", tmp_path / "b.exr"
    common = ["--size", "80", "60", "--spp", "4"]
    run_cli("render", cornell.path, "-o", a, "--renderer", "raster", *common)
    run_cli("render", cornell.path, "-o", b, "--renderer", "raytrace", *common)
    cli = cli_json("compare", a, b, "--json", "--scene", cornell.path, "--spp", "4")
    mine = rastray.compare(a, b, scene=cornell.path, spp=4)
    assert mine.summary == cli
    assert mine.mismatch_map.shape == (60, 80)


def test_compare_frames_matches_compare_of_their_files(tmp_path, cornell):
    fa = rastray.render(cornell, renderer="raster", size=(80, 60), spp=4)
    fb = rastray.render(cornell, renderer="raytrace", size=(80, 60), spp=4)
    fa.save(tmp_path / "a.exr", float_color=True)
    fb.save(tmp_path / "b.exr", float_color=True)
    frames = rastray.compare(fa, fb).summary
    files = rastray.compare(tmp_path / "a.exr", tmp_path / "b.exr", scene=cornell.path, spp=4).summary
    for key in ("visibility", "depthError", "color", "classification", "width", "height", "spp"):
        assert frames[key] == files[key], key
    # A frame against a file (the file read by rastray's reader).
    mixed = rastray.compare(fa, tmp_path / "b.exr").summary
    assert mixed["visibility"] == files["visibility"]
    with pytest.raises(ValueError, match="spp"):
        rastray.compare(fa, rastray.render(cornell, renderer="raytrace", size=(80, 60), spp=1))


def test_compare_of_crossval_frames_is_deep_and_counts_as_crossval(cornell):
    result = rastray.crossval(cornell, size=(48, 36), spp=4)
    deep = rastray.compare(result.raster, result.raytrace).summary
    assert deep["kind"] == "deep" and deep["spp"] == 4
    mine, theirs = deep["visibility"]["layers"], result.summary["rasterVsRaytrace"]["visibility"]["layers"]
    assert (mine["compared"], mine["agreeing"]) == (theirs["compared"], theirs["agreeing"])
    assert (rastray.compare(result.raster, result.raytrace).mismatch_map == result.mismatch_map).all()
