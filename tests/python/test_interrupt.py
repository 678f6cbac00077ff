# Ctrl-C during a render raises KeyboardInterrupt through the render's
# cancel token (the render stops at its next tile, not at its end), and the
# interpreter renders again afterwards.
import os
import signal
import subprocess
import sys
import time

from conftest import scene_path

CHILD = r"""
import sys, time
import rastray
scene = rastray.load(sys.argv[1])
print("loaded", flush=True)
start = time.monotonic()
try:
    # Tens of seconds on two cores: far longer than the test waits. (The
    # size stays moderate for the rasterizer: allocating and clearing its
    # per-sample buffers is not a tile loop, and polls no token.)
    size = (2048, 2048) if sys.argv[2] == "raytrace" else (1536, 1536)
    rastray.render(scene, renderer=sys.argv[2], size=size, spp=64 if sys.argv[2] == "raytrace" else 16)
    print("finished", flush=True)
except KeyboardInterrupt:
    print("interrupted after %.2f s" % (time.monotonic() - start), flush=True)
frame = rastray.render(scene, size=(16, 12))
print("rendered again", frame.color.shape, flush=True)
"""


def interrupt_child(renderer):
    child = subprocess.Popen([sys.executable, "-c", CHILD, scene_path("cornell-box.gltf"), renderer],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=os.environ)
    try:
        assert child.stdout.readline().strip() == "loaded"
        time.sleep(1.0)
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=120)
    finally:
        if child.poll() is None:
            child.kill()
    return child.returncode, out, err


def test_ctrl_c_interrupts_a_render_and_the_interpreter_goes_on():
    for renderer in ("raytrace", "hybrid"):
        status, out, err = interrupt_child(renderer)
        assert status == 0, err
        lines = out.splitlines()
        assert lines[0].startswith("interrupted after"), (renderer, out, err)
        # Stopped by the token within a few tiles, long before the render's end.
        assert float(lines[0].split()[2]) < 10.0, (renderer, out)
        assert lines[1] == "rendered again (12, 16, 4)", (renderer, out)
