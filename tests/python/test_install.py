# docs/PYTHON.md's install lines work: a virtual environment with the
# system's packages, `pip install --no-build-isolation ./python`, and the
# installed module (not the build tree's) imports and renders, finding its
# OpenImageIO part beside itself.
import os
import re
import subprocess
import sys

from conftest import scene_path

SOURCE = os.environ.get("RASTRAY_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def install_lines():
    with open(os.path.join(SOURCE, "docs", "PYTHON.md"), encoding="utf-8") as f:
        text = f.read()
    block = re.search(r"^```sh not-run: makes a virtual environment[^\n]*\n(.*?)^```$", text, flags=re.S | re.M)
    return block.group(1).strip().splitlines()


def test_pip_install_into_a_virtual_environment(tmp_path):
    lines = install_lines()
    assert lines[0].startswith("python3 -m venv") and "pip install" in lines[1]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    for line in lines:
        # python3: the interpreter the module was built for (ctest runs this one).
        line = line.replace("python3 ", os.path.realpath(sys.executable) + " ", 1).replace("./python", os.path.join(SOURCE, "python"))
        subprocess.run(line, shell=True, cwd=tmp_path, env=env, check=True, capture_output=True, timeout=900)
    venv_python = str(tmp_path / ".venv" / "bin" / "python")
    check = ("import os, rastray, sys\n"
             "assert rastray.__file__.startswith(sys.prefix), rastray.__file__\n"
             "assert os.path.exists(os.path.join(os.path.dirname(rastray.__file__), 'rastray_oiio.so'))\n"
             "f = rastray.render(sys.argv[1], size=(16, 12))\n"
             "f.save(sys.argv[2])\n"
             "print(f.color.shape, rastray.read_exr(sys.argv[2]).depth.shape)\n")
    out = subprocess.run([venv_python, "-c", check, scene_path("cornell-box.gltf"), str(tmp_path / "f.exr")],
                         cwd=tmp_path, env=env, check=True, capture_output=True, text=True, timeout=120).stdout
    assert out.strip() == "(12, 16, 4) (12, 16)"
