# Bad input from Python raises InputError (a ValueError) with the command
# line's one-line message, never a crash; the interpreter goes on.
import os

import pytest

import rastray
from conftest import TEST_DATA, run_cli, scene_path


def cli_message(*args):
    result = run_cli(*args, check=False)
    assert result.returncode == 2, result
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    return lines[0]


def raised(f, *args, **kwargs):
    with pytest.raises(rastray.InputError) as info:
        f(*args, **kwargs)
    assert isinstance(info.value, ValueError)
    message = str(info.value)
    assert "\n" not in message
    return message


def test_missing_file(tmp_path):
    path = str(tmp_path / "missing.gltf")
    assert raised(rastray.load, path) == cli_message("info", path)


def test_malformed_gltf_files():
    folder = os.path.join(TEST_DATA, "malformed")
    names = sorted(os.listdir(folder))
    assert len(names) > 20
    for name in names[::4]:
        path = os.path.join(folder, name)
        try:
            scene = rastray.load(path)
        except rastray.InputError as e:
            assert str(e) == cli_message("info", path), name
            continue
        # Some files load and are refused at render time only (e.g. a
        # camera the renderer cannot use): then both refuse there.
        assert raised(rastray.render, scene, size=(8, 8)) == cli_message("render", path, "-o", "/dev/null.png",
                                                                         "--size", "8", "8"), name


def test_unknown_option(cornell):
    message = raised(rastray.render, cornell, frobnicate=3)
    assert message == "command line: --frobnicate: not a render option (keyword frobnicate)"


@pytest.mark.parametrize("options,cli", [
    (dict(size=(100000, 100000)), ["--size", "100000", "100000"]),
    (dict(size=(0, 10)), ["--size", "0", "10"]),
    (dict(spp=3), ["--spp", "3"]),
    (dict(shadows="rays"), ["--shadows", "rays"]),  # the rasterizer traces no rays
    (dict(depth_format="float16"), ["--depth-format", "float16"]),
    (dict(renderer="pathtracer"), ["--renderer", "pathtracer"]),
    (dict(no_packets=True), ["--no-packets"]),  # raytrace only
])
def test_bad_value_gives_the_command_lines_message(tmp_path, cornell, options, cli):
    assert raised(rastray.render, cornell, **options) == cli_message("render", cornell.path, "-o",
                                                                     tmp_path / "x.png", *cli)


def test_absurd_size_is_refused_before_allocating(cornell):
    # Within --size's range, far beyond memory with every sample kept (about
    # 5 TiB; without deep=True the rasterizer needs only the 7 GiB image):
    # refused by the estimate, under the default limit and under a given one.
    for options in (dict(), dict(max_memory="1G")):
        message = raised(rastray.render, cornell, size=(16384, 16384), spp=256, deep=True, **options)
        assert message.startswith(cornell.path + ": rendering 16384x16384 at 256 spp (raster) needs about ")
        assert "above the memory limit" in message
    assert message.endswith("above the memory limit of 1.00 GiB (--max-memory 1G)")


def test_wrong_python_values(cornell):
    assert "needs 2 values" in raised(rastray.render, cornell, size=(10,))
    assert "a flag" in raised(rastray.render, cornell, wireframe="yes")
    assert "not a value" in raised(rastray.render, cornell, spp=True)
    with pytest.raises(TypeError):
        rastray.render(42)


def test_interpreter_goes_on_after_errors(cornell):
    for _ in range(3):
        with pytest.raises(ValueError):
            rastray.render(cornell, spp=7)
    assert rastray.render(cornell, size=(8, 6)).color.shape == (6, 8, 4)
