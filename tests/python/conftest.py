# Shared set-up of the Python module's tests (run by ctest: tests/CMakeLists.txt
# sets PYTHONPATH to build/python and names the rastray binary, the bundled
# scenes and the test data in the environment).
import json
import os
import subprocess

import pytest

BINARY = os.environ.get("RASTRAY_BINARY", "build/rastray")
SCENES = os.environ.get("RASTRAY_SCENES", "scenes")
TEST_DATA = os.environ.get("RASTRAY_TEST_DATA", "tests/data")


def scene_path(name):
    return os.path.join(SCENES, name)


def run_cli(*args, check=True):
    """Runs `rastray ARGS`; returns the CompletedProcess (text)."""
    result = subprocess.run([BINARY, *map(str, args)], capture_output=True, text=True, timeout=600)
    if check and result.returncode != 0:
        raise AssertionError(f"rastray {' '.join(map(str, args))}: exit {result.returncode}: {result.stderr}")
    return result


def cli_json(*args, statuses=(0,)):
    """The JSON `rastray ARGS` prints, exiting with one of `statuses`."""
    result = run_cli(*args, check=False)
    assert result.returncode in statuses, result
    return json.loads(result.stdout)


@pytest.fixture(scope="session")
def cornell():
    import rastray
    return rastray.load(scene_path("cornell-box.gltf"))
