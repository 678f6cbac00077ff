# A Python render is the command line's render: the same settings give the
# same colour, depth and ID bits (read back from the command line's EXR).
import numpy as np
import pytest

import rastray
from conftest import cli_json, run_cli, scene_path

RENDERERS = ["raster", "raytrace", "hybrid"]


def same_bits(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("renderer", RENDERERS)
@pytest.mark.parametrize("scene", ["cornell-box.gltf", "transparent-layers.gltf"])
def test_render_equals_command_line_exr(tmp_path, renderer, scene):
    frame = rastray.render(rastray.load(scene_path(scene)), renderer=renderer, size=(96, 72), spp=4)
    out = tmp_path / "cli.exr"
    # frame.args is the copy-ready command line of the settings (toArgs).
    run_cli("render", scene_path(scene), "-o", out, "--float", *frame.args)
    cli = rastray.read_exr(out)
    assert frame.args[:2] == ["--renderer", renderer]
    assert frame.color.shape == (72, 96, 4) and frame.color.dtype == np.float32
    assert frame.instance.dtype == np.int32 and frame.triangle.dtype == np.int32
    for plane in ("color", "depth", "instance", "triangle"):
        assert same_bits(getattr(frame, plane), getattr(cli, plane)), plane
    # Something was hit, and -1 marks the background.
    assert (frame.instance >= 0).any()
    assert ((frame.instance == -1) == np.isinf(frame.depth)).all()


@pytest.mark.parametrize("renderer", RENDERERS)
def test_deep_samples_equal_command_line_deep_exr(tmp_path, renderer):
    scene = scene_path("transparent-layers.gltf")
    frame = rastray.render(scene, renderer=renderer, size=(40, 30), spp=2, deep=True)
    out = tmp_path / "deep.exr"
    run_cli("render", scene, "-o", out, "--deep", *frame.args)
    cli = rastray.read_exr(out)
    assert frame.deep is not None and cli.deep is not None
    assert same_bits(frame.deep.offsets, cli.deep.offsets)
    mine, theirs = frame.deep.samples, cli.deep.samples
    for field in ("color", "depth", "instance", "triangle", "sample", "cut_off"):
        assert same_bits(np.ascontiguousarray(mine[field]), np.ascontiguousarray(theirs[field])), field
    # Layers: more entries than pixels×spp where the surfaces are transparent.
    assert len(mine) > 40 * 30 * 2
    layers = frame.deep.pixel(20, 15)
    assert (np.diff(layers["sample"].astype(np.int64)) >= 0).all()


def test_options_by_command_line_name(tmp_path):
    scene = scene_path("cornell-box.gltf")
    frame = rastray.render(scene, renderer="hybrid", size="64x48", spp=1, shadows="map", shadow_map_size=512,
                           shadow_bias=(1.5, 2), wireframe=True, max_depth=3, lights=[0])
    assert frame.args == ["--renderer", "hybrid", "--size", "64", "48", "--spp", "1", "--lights", "0",
                          "--shadows", "map", "--wireframe", "--shadow-map-size", "512",
                          "--shadow-bias", "1.5", "2", "--max-depth", "3"]
    out = tmp_path / "cli.exr"
    run_cli("render", scene, "-o", out, "--float", *frame.args)
    assert same_bits(frame.color, rastray.read_exr(out).color)


def test_frame_reports_work(cornell):
    frame = rastray.render(cornell, renderer="raster", size=(64, 48), shadows="none")
    assert frame.renderer == "raster" and frame.spp == 1 and (frame.width, frame.height) == (64, 48)
    assert frame.counters and all(isinstance(v, int) for v in frame.counters.values())
    assert frame.timings and all(v >= 0 for v in frame.timings.values())
    assert any("shadow" in p for p in frame.left_out)  # --shadows none leaves the shadow pass out
    assert frame.deep is None
    assert "perspective" in frame.camera or frame.camera


def test_arrays_are_read_only_views_that_outlive_the_frame(cornell):
    frame = rastray.render(cornell, size=(32, 24))
    color, depth = frame.color, frame.depth
    # No copy: numpy does not own the data, and two views share one buffer.
    assert not color.flags.owndata and not color.flags.writeable
    assert np.shares_memory(color, frame.color)
    expected = color.copy()
    del frame
    import gc
    gc.collect()
    assert (color == expected).all() and depth.shape == (24, 32)
    with pytest.raises(ValueError):
        color[0, 0, 0] = 1.0


def test_save_writes_what_read_exr_reads(tmp_path, cornell):
    frame = rastray.render(cornell, renderer="raytrace", size=(32, 24), spp=2)
    frame.save(tmp_path / "f.exr", float_color=True)
    back = rastray.read_exr(tmp_path / "f.exr")
    assert same_bits(back.color, frame.color) and same_bits(back.triangle, frame.triangle)


SKIN = "/usr/share/assimp/models/glTF2/simple_skin/simple_skin.gltf"


@pytest.mark.skipif(not __import__("os").path.exists(SKIN), reason="assimp-testmodels is not installed")
def test_time_poses_the_scene_as_the_command_line_does(tmp_path):
    # time= comes through the option table: a loaded scene is posed again
    # for another time, and the picture is the command line's at --time.
    scene = rastray.load(SKIN)
    camera = dict(eye=(0, 1, 4), target=(0, 1, 0), size=(48, 36))
    rest = rastray.render(scene, **camera)
    bent = rastray.render(scene, time=2, **camera)
    assert bent.args[bent.args.index("--time") + 1] == "2"
    assert not same_bits(rest.instance, bent.instance)
    out = tmp_path / "cli.exr"
    run_cli("render", SKIN, "-o", out, "--float", *bent.args)
    assert same_bits(bent.color, rastray.read_exr(out).color)
    assert same_bits(rastray.render(scene, time=2, **camera).color, bent.color)
    # info at a time is the command line's info --time.
    info = scene.info(time=2)
    assert info["bounds"] == cli_json("info", SKIN, "--json", "--time", "2")["bounds"]
    assert info["bounds"] != scene.info()["bounds"]
