# docs/PYTHON.md's worked example runs as written: its ```python blocks in
# order, in one namespace, in a scratch directory holding scenes/.
import os
import re

from conftest import SCENES

SOURCE = os.environ.get("RASTRAY_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def python_blocks(text):
    return re.findall(r"^```python\n(.*?)^```$", text, flags=re.S | re.M)


def test_worked_example_runs_and_draws_the_picture(tmp_path, monkeypatch, capsys):
    with open(os.path.join(SOURCE, "docs", "PYTHON.md"), encoding="utf-8") as f:
        blocks = python_blocks(f.read())
    assert len(blocks) >= 2
    os.symlink(os.path.abspath(SCENES), tmp_path / "scenes")
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__docs__"}
    for block in blocks:
        exec(compile(block, "docs/PYTHON.md", "exec"), namespace)
    out = capsys.readouterr().out
    assert "max |dZ| where the hits agree:" in out
    # What the page says of the result: two shared-edge ties, |dZ| below 2e-6.
    pixels = namespace["diff"].summary["visibility"]["pixels"]
    assert pixels["mismatching"] == 2 and pixels["mismatches"]["shared-edge-tie"]["count"] == 2
    assert namespace["np"].nanmax(namespace["dz"]) < 2e-6
    assert (tmp_path / "python-example.png").stat().st_size > 10000
    # The picture the page shows is committed beside it.
    assert os.path.exists(os.path.join(SOURCE, "docs", "images", "python-example.png"))


def test_readme_example_runs(tmp_path, monkeypatch):
    with open(os.path.join(SOURCE, "README.md"), encoding="utf-8") as f:
        blocks = python_blocks(f.read())
    assert len(blocks) == 1
    os.symlink(os.path.abspath(SCENES), tmp_path / "scenes")
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__readme__"}
    exec(compile(blocks[0], "README.md", "exec"), namespace)
    # What the block's comment says.
    assert namespace["frame"].color.shape == (240, 320, 4)
    assert namespace["frame"].depth.shape == (240, 320)
