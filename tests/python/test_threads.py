# Renders from 4 Python threads at once give the bits of renders one at a
# time (the GIL is released while rendering; each render has its own
# settings, task arena and cancel token).
from concurrent.futures import ThreadPoolExecutor

import rastray
from conftest import scene_path

CONFIGS = [
    dict(renderer="raster", size=(96, 72), spp=4),
    dict(renderer="raytrace", size=(96, 72), spp=4, threads=1),
    dict(renderer="hybrid", size=(80, 60), spp=2, shadows="rays"),
    dict(renderer="raster", size=(64, 64), spp=8, transparency="sorted", threads=2),
]


def planes(frame):
    return [frame.color.tobytes(), frame.depth.tobytes(), frame.instance.tobytes(), frame.triangle.tobytes()]


def test_four_threads_give_the_bits_of_one_at_a_time():
    scenes = [rastray.load(scene_path(name)) for name in ("cornell-box.gltf", "transparent-layers.gltf")]
    jobs = [(scenes[i % 2], config) for i, config in enumerate(CONFIGS)] * 2  # 8 renders, 4 at a time
    alone = [planes(rastray.render(scene, **config)) for scene, config in jobs]
    with ThreadPoolExecutor(max_workers=4) as pool:
        together = list(pool.map(lambda job: planes(rastray.render(job[0], **job[1])), jobs))
    assert together == alone


def test_crossval_from_threads():
    scene = rastray.load(scene_path("cornell-box.gltf"))
    one = rastray.crossval(scene, size=(48, 36), spp=2).mismatch_map.tobytes()
    with ThreadPoolExecutor(max_workers=2) as pool:
        maps = list(pool.map(lambda _: rastray.crossval(scene, size=(48, 36), spp=2).mismatch_map.tobytes(),
                             range(2)))
    assert maps == [one, one]
