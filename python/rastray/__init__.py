"""rastray from Python: load a glTF scene, render it with the rasterizer, the
ray caster or hybrid, and compare them, with numpy arrays in and out.

    import rastray
    scene = rastray.load("scenes/cornell-box.gltf")
    frame = rastray.render(scene, renderer="raytrace", size=(320, 240), spp=4)
    frame.color      # (240, 320, 4) float32, linear, premultiplied alpha
    frame.instance   # (240, 320) int32, -1 where nothing was hit

Every render option of the command line is a keyword argument, named as
there with ``_`` for ``-`` (``shadow_map_size=1024`` is
``--shadow-map-size 1024``) and checked by the same table
(docs/OPTIONS.md); a bad name or value raises InputError, a ValueError
with the command line's one-line message. docs/PYTHON.md has the whole API.
"""

import math as _math
import os as _os

from . import _core
from ._core import Comparison, Crossval, DeepLayers, Frame, InputError

__all__ = [
    "load", "render", "crossval", "explain", "compare", "read_exr", "options", "PIXEL_CLASSES",
    "Scene", "Frame", "DeepLayers", "Crossval", "Comparison", "InputError",
]

_TABLE = {row["name"]: row for row in _core.option_table()}

# The mismatch maps' values (uint8) in order: PIXEL_CLASSES[v] is
# (key, label, (r, g, b)) with the sRGB colour the HTML report draws it in.
PIXEL_CLASSES = [(key, label, srgb) for _, key, label, srgb in sorted(_core.pixel_classes())]


def options():
    """The render options as the command line's table has them: a list of
    dicts with name (``--spp``), keyword (``spp``), arity (0: a flag),
    default, applies_to and help."""
    return [dict(row, keyword=row["name"][2:].replace("-", "_")) for row in _core.option_table()]


def _word(name, value):
    # One value as the command line would spell it: floats in the shortest
    # form that reads back as the same double (repr), so a render from
    # Python and from the printed command line are the same bit for bit.
    if isinstance(value, bool):
        raise InputError(f"command line: {name}: {value!r} is not a value of this option")
    if isinstance(value, float):
        if _math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, (int, str)):
        return str(value)
    if hasattr(value, "item"):  # numpy scalars
        return _word(name, value.item())
    raise InputError(f"command line: {name}: {value!r} is not a number or a word")


def _args(options, renderer=None):
    """The command line's words for keyword options."""
    args = [] if renderer is None else ["--renderer", str(renderer)]
    for key, value in options.items():
        name = "--" + key.replace("_", "-")
        row = _TABLE.get(name)
        if row is None or name == "--renderer":
            raise InputError(f"command line: {name}: not a render option (keyword {key})")
        arity = row["arity"]
        if value is None:
            continue  # not given: the table's default
        if arity == 0:
            if not isinstance(value, bool):
                raise InputError(f"command line: {name}: a flag: give True or False, not {value!r}")
            if value:
                args.append(name)
            continue
        if isinstance(value, str) and arity > 1:
            words = _core.split_option_value(value, arity)
            if words is None:
                raise InputError(f"command line: {name}: needs {arity} values, as a sequence or '{'x'.join(['N'] * arity)}'")
        elif isinstance(value, (list, tuple)) or hasattr(value, "tolist"):
            seq = value.tolist() if hasattr(value, "tolist") else list(value)
            if arity == 1:  # --lights: indices, one word
                words = [",".join(_word(name, v) for v in seq)]
            else:
                words = [_word(name, v) for v in seq]
                if len(words) != arity:
                    raise InputError(f"command line: {name}: needs {arity} values, not {len(words)}")
        else:
            words = [_word(name, value)]
            if len(words) != arity:
                raise InputError(f"command line: {name}: needs {arity} values, not 1")
        args.append(name)
        args.extend(words)
    return args


class Scene:
    """A loaded glTF scene (``rastray.load``). Render it as often as you
    like: each render prepares its own copy (lights kept, render origin)."""

    def __init__(self, core):
        self._core = core

    @property
    def path(self):
        return self._core.path

    def info(self, **camera_options):
        """The facts ``rastray info --json`` prints (schema rastray.info), as
        a dict; camera options (camera, eye, target, up, yfov, znear, zfar,
        size) choose the camera it describes, time and animation the frame."""
        return self._core.info_json(_args(camera_options))

    @property
    def cameras(self):
        """The file's camera nodes in walk order, as ``camera=N`` picks them."""
        return self.info()["cameraList"]

    @property
    def lights(self):
        """The file's lights, as ``lights=[i, ...]`` keeps them."""
        return self.info()["lightList"]

    def __repr__(self):
        return repr(self._core)


def load(path):
    """Loads a .gltf or .glb file. Bad input raises InputError (a ValueError)
    with the command line's one line naming the file and the element."""
    return Scene(_core.load(_os.fspath(path)))


def _scene(scene):
    if isinstance(scene, Scene):
        return scene._core
    if isinstance(scene, (str, _os.PathLike)):
        return load(scene)._core
    raise TypeError(f"a rastray.Scene or a path, not {type(scene).__name__}")


def render(scene, renderer=None, size=None, spp=None, *, deep=False, **options):
    """Renders `scene` (a Scene or a path) with renderer "raster" (the
    default, as on the command line), "raytrace" or "hybrid" and returns a
    Frame: color (H×W×4 float32, linear, premultiplied), depth (H×W float32,
    +inf: no hit), instance and triangle (H×W int32, -1: no hit), counters,
    timings, passes_run, left_out, and with deep=True every sample and layer
    (frame.deep). The arrays are read-only views of the frame's buffers."""
    return _core.render(_scene(scene), _args(dict(size=size, spp=spp, **options), renderer or "raster"), deep)


def crossval(scene, size=None, spp=None, **options):
    """Renders with the rasterizer, the ray caster and hybrid and compares
    them, as ``rastray crossval`` does. Returns a Crossval: summary (the
    element of ``crossval --json``'s "scenes"), mismatch_map (H×W uint8,
    values as PIXEL_CLASSES, raster against the ray caster),
    hybrid_mismatch_map, depth_error (H×W float32 |ΔZ| on agreeing hits, NaN
    elsewhere) and the three frames raster, raytrace and hybrid (deep)."""
    return _core.crossval(_scene(scene), _args(dict(size=size, spp=spp, **options)))


def explain(scene, x, y, **options):
    """Every sample of pixel (x, y) as the rasterizer and the ray caster saw
    it: ``rastray explain --json``'s dict (schema rastray.explain)."""
    return _core.explain(_scene(scene), int(x), int(y), _args(options))


def compare(a, b, *, scene=None, spp=None):
    """Compares two frames, or EXR files by path, or one of each, as
    ``rastray compare`` does. With a rendered frame the classification uses
    its scene and camera; for two files give scene (a path) and spp as
    compare's --scene and --spp. Returns a Comparison: summary (``compare
    --json``'s dict), mismatch_map and depth_error."""
    def arg(x):
        return x if isinstance(x, Frame) else _os.fspath(x)
    return _core.compare(arg(a), arg(b), "" if scene is None else _os.fspath(scene), spp or 0)


def read_exr(path):
    """A SPEC §6 EXR file (flat or deep, any renderer's) as a Frame."""
    return _core.read_exr(_os.fspath(path))
