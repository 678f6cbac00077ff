#!/usr/bin/env python3
"""Writes rastray's bad-input and edge-case glTF files (SPEC §7).

Run from anywhere:  python3 tests/data/malformed/generate.py
It rewrites every file below deterministically (same bytes every run):

  tests/data/malformed/*.gltf, *.glb, *.bin   one malformed input each:
      `rastray info FILE` must exit with status 2 and print one line that
      starts with the file name and names the offending element. The
      expected element of each file is listed in tests/app/bad_input_test.cpp.
  tests/data/malformed/valid/*.gltf           edge cases that must load; the
      flattened store they give is checked in
      tests/common/scene_loader_test.cpp.

Buffers are data URIs (a few cases need an external .bin). Python 3
standard library only.
"""

import base64
import json
import os
import struct
import zlib
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
VALID = os.path.join(HERE, "valid")

BYTE, UBYTE, SHORT, USHORT, UINT, FLOAT = 5120, 5121, 5122, 5123, 5125, 5126
COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
FORMAT = {BYTE: "b", UBYTE: "B", SHORT: "h", USHORT: "H", UINT: "I", FLOAT: "f"}
TRIANGLES, STRIP, FAN = 4, 5, 6
ASSET = {"version": "2.0", "generator": "rastray tests/data/malformed/generate.py"}


def data_uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(bytes(data)).decode("ascii")


class Builder:
    """One buffer (a data URI unless told otherwise), its views and accessors."""

    def __init__(self):
        self.bin = bytearray()
        self.views = []
        self.accessors = []

    def view(self, data, stride=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if stride:
            view["byteStride"] = stride
        self.bin += data
        self.views.append(view)
        return len(self.views) - 1

    def accessor(self, values, ctype, type_, **extra):
        data = struct.pack("<%d%s" % (len(values), FORMAT[ctype]), *values)
        accessor = {"bufferView": self.view(data), "componentType": ctype,
                    "count": len(values) // COMPONENTS[type_], "type": type_}
        accessor.update(extra)
        self.accessors.append(accessor)
        return len(self.accessors) - 1

    def positions(self, points):
        flat = [c for p in points for c in p]
        lo = [min(p[k] for p in points) for k in range(3)]
        hi = [max(p[k] for p in points) for k in range(3)]
        return self.accessor(flat, FLOAT, "VEC3", min=lo, max=hi)

    def vec3(self, vectors):
        return self.accessor([c for v in vectors for c in v], FLOAT, "VEC3")

    def vec2(self, vectors):
        return self.accessor([c for v in vectors for c in v], FLOAT, "VEC2")

    def indices(self, values, ctype=USHORT):
        return self.accessor(values, ctype, "SCALAR")

    def gltf(self, meshes, nodes, scenes=None, scene=None, **extra):
        doc = {"asset": dict(ASSET)}
        if scenes is not None:
            doc["scenes"] = scenes
        if scene is not None:
            doc["scene"] = scene
        doc["nodes"] = nodes
        doc["meshes"] = meshes
        doc.update(extra)
        if self.accessors:
            doc["accessors"] = self.accessors
            doc["bufferViews"] = self.views
            doc["buffers"] = [{"uri": data_uri(self.bin), "byteLength": len(self.bin)}]
        return doc


QUAD = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]


def quad_doc(**extra):
    """The base of most cases: one node, one mesh, an indexed quad.
    Accessors: 0 POSITION, 1 NORMAL, 2 indices."""
    b = Builder()
    pos = b.positions(QUAD)
    nrm = b.vec3([(0, 0, 1)] * 4)
    idx = b.indices([0, 1, 2, 0, 2, 3])
    mesh = {"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx}]}
    return b.gltf([mesh], [{"mesh": 0}], scenes=[{"nodes": [0]}], scene=0, **extra)


def cube_doc(index_values):
    """24 vertices (a cube, one quad per face). Accessors: 0 POSITION,
    1 NORMAL, 2 TEXCOORD_0, 3 indices (uint32)."""
    b = Builder()
    points, normals = [], []
    for axis in range(3):
        for sign in (-1, 1):
            n = [0, 0, 0]
            n[axis] = sign
            u, v = (axis + 1) % 3, (axis + 2) % 3
            for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0, 0, 0]
                p[axis], p[u], p[v] = sign, du, dv
                points.append(tuple(p))
                normals.append(tuple(n))
    pos = b.positions(points)
    nrm = b.vec3(normals)
    uv = b.vec2([(0, 0), (1, 0), (1, 1), (0, 1)] * 6)
    idx = b.indices(index_values, UINT)
    attributes = {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv}
    mesh = {"primitives": [{"attributes": attributes, "indices": idx}]}
    return b.gltf([mesh], [{"mesh": 0}], scenes=[{"nodes": [0]}], scene=0)


def animated_quad(times, values, interpolation="LINEAR", path="translation", type_="VEC3"):
    """quad_doc's quad with one animation channel on node 0. Accessors:
    0 POSITION, 1 NORMAL, 2 indices, 3 input times, 4 output values."""
    b = Builder()
    pos = b.positions(QUAD)
    nrm = b.vec3([(0, 0, 1)] * 4)
    idx = b.indices([0, 1, 2, 0, 2, 3])
    times_accessor = b.accessor(times, FLOAT, "SCALAR")
    values_accessor = b.accessor(values, FLOAT, type_)
    mesh = {"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx}]}
    animation = {"samplers": [{"input": times_accessor, "output": values_accessor,
                               "interpolation": interpolation}],
                 "channels": [{"sampler": 0, "target": {"node": 0, "path": path}}]}
    return b.gltf([mesh], [{"mesh": 0}], scenes=[{"nodes": [0]}], scene=0, animations=[animation])


def skinned_quad(joints):
    """The quad skinned to node 1, with the skin's joint list `joints`.
    Accessors: 0 POSITION, 1 indices, 2 JOINTS_0 (vertex 3 names joint 1),
    3 WEIGHTS_0."""
    b = Builder()
    pos = b.positions(QUAD)
    idx = b.indices([0, 1, 2, 0, 2, 3])
    jnt = b.accessor([0, 0, 0, 0] * 3 + [1, 0, 0, 0], USHORT, "VEC4")
    wgt = b.accessor([1, 0, 0, 0] * 4, FLOAT, "VEC4")
    mesh = {"primitives": [{"attributes": {"POSITION": pos, "JOINTS_0": jnt, "WEIGHTS_0": wgt},
                            "indices": idx}]}
    return b.gltf([mesh], [{"mesh": 0, "skin": 0}, {}, {}], scenes=[{"nodes": [0, 1, 2]}], scene=0,
                  skins=[{"joints": joints}])


def png_1x1():
    """A valid 1x1 RGB PNG (the flat normal (128, 128, 255))."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    header = struct.pack(">IIBBBBB", 1, 1, 8, 2, 0, 0, 0)
    pixels = zlib.compress(b"\x00\x80\x80\xff")
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", pixels) + chunk(b"IEND", b"")


def normal_mapped_quad(tangents, type_):
    """quad_doc with a normal-mapped material, TEXCOORD_0 and a TANGENT
    (accessor 3) of the given values and type; TEXCOORD_0 is accessor 4."""
    b = Builder()
    pos = b.positions(QUAD)
    nrm = b.vec3([(0, 0, 1)] * 4)
    idx = b.indices([0, 1, 2, 0, 2, 3])
    tan = b.accessor(tangents, FLOAT, type_)
    uv = b.vec2([(0, 1), (1, 1), (1, 0), (0, 0)])
    attributes = {"POSITION": pos, "NORMAL": nrm, "TANGENT": tan, "TEXCOORD_0": uv}
    mesh = {"primitives": [{"attributes": attributes, "indices": idx, "material": 0}]}
    return b.gltf([mesh], [{"mesh": 0}], scenes=[{"nodes": [0]}], scene=0,
                  materials=[{"normalTexture": {"index": 0}}], textures=[{"source": 0}],
                  images=[{"uri": "data:image/png;base64," + base64.b64encode(png_1x1()).decode()}])


def text(doc):
    return json.dumps(doc, indent=1) + "\n"


def glb(doc, bin_data, json_length=None, total_length=None):
    """A GLB container; json_length / total_length override the header fields."""
    js = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    js += b" " * (-len(js) % 4)
    binary = bytes(bin_data) + b"\0" * (-len(bin_data) % 4)
    body = struct.pack("<II", len(js) if json_length is None else json_length, 0x4E4F534A) + js
    if binary:
        body += struct.pack("<II", len(binary), 0x004E4942) + binary
    length = 12 + len(body) if total_length is None else total_length
    return struct.pack("<III", 0x46546C67, 2, length) + body


def glb_quad():
    """The quad with buffer 0 in the BIN chunk: (doc, bin bytes)."""
    doc = quad_doc()
    b = doc["buffers"][0]
    data = base64.b64decode(b["uri"].split(",", 1)[1])
    del b["uri"]
    return doc, data


# --------------------------------------------------------------------------
# Malformed inputs: name -> file content (str or bytes)

def malformed():
    files = {}

    files["invalid-json.gltf"] = '{"asset": {"version": "2.0"}, "nodes": [}\n'
    files["empty-file.gltf"] = ""
    files["top-level-array.gltf"] = '[{"asset": {"version": "2.0"}}]\n'
    # 100000 nested arrays in "extras": no parser may recurse that deep.
    files["deep-nesting.gltf"] = ('{"asset": {"version": "2.0"}, "extras": ' + "[" * 100000 +
                                  "]" * 100000 + "}\n")

    # Wrong types.
    d = quad_doc()
    d["accessors"][0]["count"] = "4"
    files["accessor-count-string.gltf"] = text(d)
    d = quad_doc()
    d["nodes"].append({"children": 3})
    files["node-children-number.gltf"] = text(d)
    d = quad_doc()
    d["nodes"][0]["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, "0", 0, 1]
    files["node-matrix-string.gltf"] = text(d)
    d = quad_doc(materials=[{"doubleSided": "yes"}])
    d["meshes"][0]["primitives"][0]["material"] = 0
    files["material-doublesided-string.gltf"] = text(d)
    d = quad_doc()
    d["scene"] = "0"
    files["scene-string.gltf"] = text(d)

    d = quad_doc(cameras=[{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}])
    d["nodes"][0]["camera"] = 0
    d["nodes"][0]["name"] = 5
    files["node-name-number.gltf"] = text(d)
    d = quad_doc(materials=[{"name": ["red"]}])
    files["material-name-array.gltf"] = text(d)
    d = quad_doc(extensionsUsed=["KHR_lights_punctual"],
                 extensions={"KHR_lights_punctual": {"lights": [{"type": "point", "name": {}}]}})
    d["nodes"][0]["extensions"] = {"KHR_lights_punctual": {"light": 0}}
    files["light-name-object.gltf"] = text(d)

    # Buffers.
    d = quad_doc()
    d["buffers"][0]["uri"] = "does-not-exist.bin"
    files["buffer-missing-file.gltf"] = text(d)
    d = quad_doc()
    d["buffers"][0]["byteLength"] += 8
    for v in d["bufferViews"]:
        v["byteOffset"] += 8
    files["buffer-short-data-uri.gltf"] = text(d)
    d = quad_doc()
    d["buffers"][0]["uri"] = d["buffers"][0]["uri"].replace("application/octet-stream", "text/html")
    files["buffer-data-uri-media-type.gltf"] = text(d)
    d = quad_doc()
    data = base64.b64decode(d["buffers"][0]["uri"].split(",", 1)[1])
    d["buffers"][0]["uri"] = "buffer-short-external.bin"
    files["buffer-short-external.gltf"] = text(d)
    files["buffer-short-external.bin"] = data[: len(data) - 10]
    d = quad_doc()
    d["buffers"][0]["uri"] = "valid"  # the directory beside this file
    files["buffer-uri-directory.gltf"] = text(d)
    d = quad_doc()
    d["buffers"][0]["uri"] = "data:application/octet-stream;base64,@@@@not base64@@@@"
    files["buffer-bad-base64.gltf"] = text(d)

    # Byte ranges.
    d = quad_doc()
    d["bufferViews"][2]["byteLength"] += 4
    files["bufferview-outside-buffer.gltf"] = text(d)
    d = quad_doc()
    d["accessors"][0]["count"] = 5
    files["accessor-count-too-large.gltf"] = text(d)
    d = quad_doc()
    d["accessors"][1]["byteOffset"] = 4
    files["accessor-offset-too-large.gltf"] = text(d)
    d = quad_doc()
    d["bufferViews"][0]["byteStride"] = 16
    files["accessor-stride-too-large.gltf"] = text(d)
    d = quad_doc()
    d["bufferViews"][0]["byteStride"] = 8
    files["accessor-stride-too-small.gltf"] = text(d)
    d = quad_doc()
    d["accessors"][0]["componentType"] = 5124
    files["accessor-component-type.gltf"] = text(d)
    d = quad_doc()
    del d["accessors"][0]["bufferView"]
    d["accessors"][0]["count"] = 1 << 32
    files["accessor-huge-count.gltf"] = text(d)

    # Data.
    cube = [4 * face + k for face in range(6) for k in (0, 1, 2, 0, 2, 3)]
    cube[31] = 70000
    files["index-out-of-range.gltf"] = text(cube_doc(cube))
    b = Builder()
    pos = b.positions([(0, 0, 0), (1, 0, 0), (0, 1, 0)])
    b.bin[b.views[0]["byteOffset"] + 12: b.views[0]["byteOffset"] + 16] = struct.pack("<I", 0x7FC00000)
    files["position-nan.gltf"] = text(b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}],
                                            [{"mesh": 0}], scenes=[{"nodes": [0]}]))
    b = Builder()
    pos = b.positions([(0, 0, 0), (1, 0, float("inf")), (0, 1, 0)])
    del b.accessors[pos]["max"]  # a JSON max cannot say inf
    files["position-inf.gltf"] = text(b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}],
                                            [{"mesh": 0}], scenes=[{"nodes": [0]}]))
    b = Builder()
    pos = b.positions([(0, 0, 0), (3e38, 0, 0), (0, 1, 0)])
    files["position-float-overflow.gltf"] = text(
        b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}],
               [{"mesh": 0, "scale": [10, 1, 1]}], scenes=[{"nodes": [0]}]))
    d = quad_doc()
    d["nodes"][0]["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 12345.5, 0, 0, 1]
    files["node-matrix-overflow.gltf"] = text(d).replace("12345.5", "1e400")
    d = quad_doc()
    d["nodes"] = [{"matrix": [1e300, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], "children": [1]},
                  {"mesh": 0, "scale": [1e300, 1, 1]}]
    files["node-world-matrix-overflow.gltf"] = text(d)
    d = quad_doc()
    d["nodes"][0]["rotation"] = [0, 0, 0, 0]
    files["node-rotation-zero.gltf"] = text(d)
    d = quad_doc()
    d["accessors"][2]["count"] = 5
    files["triangles-5-indices.gltf"] = text(d)
    d = cube_doc(list(range(7)))
    files["triangles-7-indices.gltf"] = text(d)
    b = Builder()
    pos = b.positions(QUAD)
    nrm = b.vec3([(0, 0, 1)] * 3)
    files["normal-count-mismatch.gltf"] = text(
        b.gltf([{"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm}, "mode": FAN}]}],
               [{"mesh": 0}], scenes=[{"nodes": [0]}]))
    b = Builder()
    pos = b.vec2([(0, 0), (1, 0), (0, 1)])
    files["position-vec2.gltf"] = text(
        b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}], [{"mesh": 0}],
               scenes=[{"nodes": [0]}]))
    d = quad_doc()
    d["accessors"][2]["componentType"] = FLOAT
    d["accessors"][2]["count"] = 3
    files["indices-float.gltf"] = text(d)
    b = Builder()
    pos = b.positions(QUAD[:3])
    b.accessors[pos]["sparse"] = {
        "count": 1,
        "indices": {"bufferView": b.view(struct.pack("<H", 7)), "componentType": USHORT},
        "values": {"bufferView": b.view(struct.pack("<3f", 5, 5, 5))}}
    files["sparse-index-out-of-range.gltf"] = text(
        b.gltf([{"primitives": [{"attributes": {"POSITION": pos}}]}], [{"mesh": 0}],
               scenes=[{"nodes": [0]}]))

    # Animations, skins, morph targets.
    files["animation-times-not-increasing.gltf"] = text(
        animated_quad([0, 1, 1], [0, 0, 0, 1, 0, 0, 2, 0, 0]))
    files["animation-output-too-short.gltf"] = text(animated_quad([0, 1, 2], [0, 0, 0, 1, 0, 0]))
    files["animation-keyframe-nan.gltf"] = text(animated_quad([0, 1], [0, 0, 0, float("nan"), 0, 0]))
    files["animation-interpolation-bad.gltf"] = text(
        animated_quad([0, 1], [0, 0, 0, 1, 0, 0], interpolation="SMOOTH"))
    d = animated_quad([0, 1], [0, 0, 0, 1, 0, 0])
    d["animations"][0]["channels"][0]["target"]["node"] = 5
    files["animation-channel-node-missing.gltf"] = text(d)
    files["animation-rotation-zero-key.gltf"] = text(
        animated_quad([0, 1], [0, 0, 0, 1, 0, 0, 0, 0], path="rotation", type_="VEC4"))
    files["skin-no-joints.gltf"] = text(skinned_quad([]))
    files["skin-joint-out-of-range.gltf"] = text(skinned_quad([1]))
    d = quad_doc()
    d["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": 1}]
    d["nodes"][0]["weights"] = [0.5, 0.5]
    files["morph-weights-count.gltf"] = text(d)

    # Node graph and scenes.
    d = quad_doc()
    d["nodes"] = [{"children": [1]}, {"mesh": 0, "children": [0]}]
    files["node-cycle.gltf"] = text(d)
    d = quad_doc()
    d["nodes"] = [{"mesh": 0}, {"children": [2]}, {"children": [1]}]
    files["node-cycle-unreachable.gltf"] = text(d)
    d = quad_doc()
    d["nodes"][0]["children"] = [0]
    files["node-self-child.gltf"] = text(d)
    d = quad_doc()
    d["nodes"] = [{"children": [2]}, {"children": [2]}, {"mesh": 0}]
    d["scenes"] = [{"nodes": [0, 1]}]
    files["node-two-parents.gltf"] = text(d)
    d = quad_doc()
    d["scenes"] = [{"nodes": [0, 0]}]
    files["scene-node-twice.gltf"] = text(d)
    d = quad_doc()
    d["scene"] = 5
    files["scene-index-missing.gltf"] = text(d)
    d = quad_doc()
    d["scenes"] = [{"nodes": [0, 3]}]
    files["scene-node-out-of-range.gltf"] = text(d)
    d = quad_doc()
    d["nodes"] = [{"children": [1]}, {"mesh": 0}]
    d["scenes"] = [{"nodes": [0, 1]}]
    files["scene-node-not-root.gltf"] = text(d)

    # Asset and extensions.
    files["extension-required-unsupported.gltf"] = text(quad_doc(
        extensionsUsed=["KHR_texture_basisu"], extensionsRequired=["KHR_texture_basisu"]))
    # Compressed geometry whose stream does not decode: the quad's float
    # positions read as a Draco stream, and as a meshopt vertex stream
    # (its first byte, 0, is no codec header).
    d = quad_doc(extensionsUsed=["KHR_draco_mesh_compression"],
                 extensionsRequired=["KHR_draco_mesh_compression"])
    d["meshes"][0]["primitives"][0]["extensions"] = {
        "KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}}
    files["draco-stream-corrupt.gltf"] = text(d)
    d = quad_doc(extensionsUsed=["EXT_meshopt_compression"], extensionsRequired=["EXT_meshopt_compression"])
    d["bufferViews"][0]["extensions"] = {"EXT_meshopt_compression": {
        "buffer": 0, "byteLength": 12, "byteStride": 12, "count": 4, "mode": "ATTRIBUTES"}}
    files["meshopt-stream-corrupt.gltf"] = text(d)
    # A meshopt fallback buffer (no data) under a plain bufferView.
    d = quad_doc(extensionsUsed=["EXT_meshopt_compression"])
    d["buffers"].append({"byteLength": 48, "extensions": {"EXT_meshopt_compression": {"fallback": True}}})
    d["bufferViews"][0]["buffer"] = 1
    files["meshopt-fallback-plain-view.gltf"] = text(d)
    d = quad_doc()
    d["asset"]["version"] = "1.0"
    files["asset-version-1.gltf"] = text(d)
    d = quad_doc()
    del d["asset"]
    files["asset-missing.gltf"] = text(d)

    # GLB containers.
    doc, data = glb_quad()
    good = glb(doc, data)
    files["glb-truncated-header.glb"] = good[:16]
    files["glb-wrong-length.glb"] = glb(doc, data, total_length=len(good) + 4)
    files["glb-json-chunk-past-eof.glb"] = glb(doc, data, json_length=len(good))
    doc, data = glb_quad()
    doc["buffers"][0]["byteLength"] = len(data) + 4
    files["glb-buffer-exceeds-bin.glb"] = glb(doc, data)
    doc, data = glb_quad()
    files["glb-bin-chunk-past-eof.glb"] = glb(doc, data)[:-4]
    fixed = bytearray(files["glb-bin-chunk-past-eof.glb"])
    fixed[8:12] = struct.pack("<I", len(fixed))
    files["glb-bin-chunk-past-eof.glb"] = bytes(fixed)

    js = json.dumps({"asset": ASSET}, separators=(",", ":")).encode("utf-8")
    js += b" " * (3 - len(js) % 4 if len(js) % 4 != 3 else 2)  # length 4k + 1 or 4k + 2
    assert len(js) % 4 != 0
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", 4, 0x004E4942) + b"\0" * 4
    files["glb-json-chunk-unaligned.glb"] = struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body
    doc, data = glb_quad()
    wrong = bytearray(glb(doc, data))
    at = 20 + struct.unpack("<I", wrong[12:16])[0]
    wrong[at + 4: at + 8] = b"XYZ\0"
    files["glb-bin-chunk-wrong-type.glb"] = bytes(wrong)
    trailing = glb({"asset": ASSET}, b"") + b"\0\0\0\0"
    files["glb-trailing-bytes.glb"] = trailing[:8] + struct.pack("<I", len(trailing)) + trailing[12:]
    doc, data = glb_quad()
    old_version = bytearray(glb(doc, data))
    old_version[4:8] = struct.pack("<I", 1)
    files["glb-version-1.glb"] = bytes(old_version)

    # Images.
    d = quad_doc(images=[{"uri": "data:image/png;base64," +
                          base64.b64encode(b"\x89PNG\r\n\x1a\n garbage, not a PNG").decode()}],
                 textures=[{"source": 0}],
                 materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])
    d["meshes"][0]["primitives"][0]["material"] = 0
    files["image-garbage-png.gltf"] = text(d)
    d = quad_doc(images=[{"uri": "does-not-exist.png"}], textures=[{"source": 0}],
                 materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])
    d["meshes"][0]["primitives"][0]["material"] = 0
    files["image-missing-file.gltf"] = text(d)

    d = quad_doc(images=[{"uri": "not-an-image.png"}], textures=[{"source": 0}])
    files["image-undecodable-file.gltf"] = text(d)
    files["not-an-image.png"] = "this is text, not a PNG\n"
    d = quad_doc(images=[{"uri": "valid"}], textures=[{"source": 0}])
    files["image-uri-directory.gltf"] = text(d)
    d = quad_doc(textures=[{"source": 3}])
    files["texture-source-missing.gltf"] = text(d)
    d = quad_doc(materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}}])
    files["material-texture-missing.gltf"] = text(d)

    # Cameras and lights.
    cam = {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.0, "zfar": 100.0}}
    files["camera-znear-zero.gltf"] = text(quad_doc(cameras=[cam]))
    cam = {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 1.0, "zfar": 0.5}}
    files["camera-zfar-below-znear.gltf"] = text(quad_doc(cameras=[cam]))
    d = quad_doc(cameras=[{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}])
    d["nodes"].append({"camera": 0, "scale": [0, 0, 0]})
    d["scenes"][0]["nodes"].append(1)
    files["camera-node-singular.gltf"] = text(d)
    # A string from the file that would break the message into two lines.
    cam = {"type": "perspective\nsecond line", "perspective": {"yfov": 0.8, "znear": 0.1}}
    files["camera-type-newline.gltf"] = text(quad_doc(cameras=[cam]))
    # Finite in JSON (a double) but beyond float range, where the scene
    # stores it: would silently become infinity.
    files["light-intensity-overflow.gltf"] = text(quad_doc(
        extensionsUsed=["KHR_lights_punctual"],
        extensions={"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1e300}]}}))
    d = quad_doc(materials=[{"alphaMode": "MASK", "alphaCutoff": 1e39}])
    d["meshes"][0]["primitives"][0]["material"] = 0
    files["material-alphacutoff-overflow.gltf"] = text(d)
    d = quad_doc(materials=[{"extensions": {"KHR_materials_ior": {"ior": 3.5e38}}}],
                 extensionsUsed=["KHR_materials_ior"])
    d["meshes"][0]["primitives"][0]["material"] = 0
    files["material-ior-overflow.gltf"] = text(d)
    files["light-negative-intensity.gltf"] = text(quad_doc(
        extensionsUsed=["KHR_lights_punctual"],
        extensions={"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": -1.0}]}}))

    # Normal maps: the TANGENT a normal-mapped primitive is read with.
    for name, values, type_, count in (
            ("tangent-nan.gltf", [1, 0, 0, 1] * 2 + [1, float("nan"), 0, 1] + [1, 0, 0, 1], "VEC4", None),
            ("tangent-vec3.gltf", [1, 0, 0] * 4, "VEC3", None),
            ("tangent-count.gltf", [1, 0, 0, 1] * 4, "VEC4", 3)):
        d = normal_mapped_quad(values, type_)
        if count is not None:
            d["accessors"][3]["count"] = count
        files[name] = text(d)
    d = quad_doc(materials=[{"normalTexture": {"index": 2}}], textures=[{"source": 0}],
                 images=[{"uri": "data:image/png;base64," + base64.b64encode(png_1x1()).decode()}])
    d["meshes"][0]["primitives"][0]["material"] = 0
    files["normal-texture-missing.gltf"] = text(d)

    # References to elements that do not exist.
    d = quad_doc()
    d["nodes"][0]["mesh"] = 5
    files["mesh-index-missing.gltf"] = text(d)
    d = quad_doc()
    d["meshes"][0]["primitives"][0]["material"] = 2
    files["material-index-missing.gltf"] = text(d)
    d = quad_doc()
    d["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 9
    files["accessor-index-missing.gltf"] = text(d)
    d = quad_doc()
    d["nodes"][0]["extensions"] = {"KHR_lights_punctual": {"light": 0}}
    files["light-index-missing.gltf"] = text(d)
    return files


# --------------------------------------------------------------------------
# Valid edge cases: name -> JSON text

def triangle_mesh(b, points, indices=None, mode=TRIANGLES, normals=None):
    attributes = {"POSITION": b.positions(points)}
    if normals:
        attributes["NORMAL"] = b.vec3(normals)
    prim = {"attributes": attributes}
    if indices is not None:
        prim["indices"] = b.indices(indices)
    if mode != TRIANGLES:
        prim["mode"] = mode
    return {"primitives": [prim]}


def valid():
    files = {}
    tri = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]

    # No meshes: background only.
    files["no-meshes.gltf"] = text({"asset": dict(ASSET), "scenes": [{"nodes": [0]}], "scene": 0,
                                    "nodes": [{"name": "empty", "children": [1]}, {}]})

    # No scenes: roots in index order (1, then 2 with its child 0).
    b = Builder()
    mesh = triangle_mesh(b, tri)
    files["no-scenes.gltf"] = text(b.gltf([mesh], [
        {"mesh": 0, "translation": [0, 0, 30]},
        {"mesh": 0, "translation": [0, 0, 10]},
        {"mesh": 0, "translation": [0, 0, 20], "children": [0]}]))

    # A primitive without POSITION keeps its instance number and draws nothing.
    b = Builder()
    mesh = triangle_mesh(b, tri)
    mesh["primitives"].insert(0, {"attributes": {}})
    files["no-position.gltf"] = text(b.gltf([mesh], [{"mesh": 0}], scenes=[{"nodes": [0]}]))

    # Sparse: accessor 0 has a bufferView and replaces vertex 2; accessor 1
    # has none (zeros) and sets vertices 1 and 2.
    b = Builder()
    base = b.positions([(0, 0, 0), (1, 0, 0), (9, 9, 9)])
    b.accessors[base]["max"] = [1, 1, 0]
    b.accessors[base]["sparse"] = {
        "count": 1,
        "indices": {"bufferView": b.view(struct.pack("<B", 2)), "componentType": UBYTE},
        "values": {"bufferView": b.view(struct.pack("<3f", 0, 1, 0))}}
    b.accessors.append({"componentType": FLOAT, "count": 3, "type": "VEC3", "min": [0, 0, 0],
                        "max": [2, 2, 0], "sparse": {
                            "count": 2,
                            "indices": {"bufferView": b.view(struct.pack("<2I", 1, 2)),
                                        "componentType": UINT},
                            "values": {"bufferView": b.view(struct.pack("<6f", 2, 0, 0, 0, 2, 0))}}})
    meshes = [{"primitives": [{"attributes": {"POSITION": base}}]},
              {"primitives": [{"attributes": {"POSITION": 1}}]}]
    files["sparse-positions.gltf"] = text(b.gltf(meshes, [{"mesh": 0}, {"mesh": 1}],
                                                 scenes=[{"nodes": [0, 1]}]))

    # KHR_mesh_quantization: normalized SHORT positions, BYTE normals.
    b = Builder()
    # Vertex attributes keep 4-byte aligned elements: a padding component each.
    shorts = struct.pack("<12h", 0, 0, 0, 0, 32767, 0, 0, 0, 0, -32768, 16384, 0)
    b.accessors.append({"bufferView": b.view(shorts, stride=8), "componentType": SHORT,
                        "normalized": True, "count": 3, "type": "VEC3",
                        "min": [0, -32768, 0], "max": [32767, 0, 16384]})
    b.accessors.append({"bufferView": b.view(struct.pack("<12b", *[0, 0, 127, 0] * 3), stride=4),
                        "componentType": BYTE, "normalized": True, "count": 3, "type": "VEC3"})
    pos, nrm = 0, 1
    files["quantized-positions.gltf"] = text(b.gltf(
        [{"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm}}]}],
        [{"mesh": 0, "scale": [2, 2, 2]}], scenes=[{"nodes": [0]}],
        extensionsUsed=["KHR_mesh_quantization"], extensionsRequired=["KHR_mesh_quantization"]))

    # 10000 nodes in one chain, each one unit further along +x.
    b = Builder()
    mesh = triangle_mesh(b, tri)
    count = 10000
    nodes = [{"translation": [1, 0, 0], "children": [i + 1]} for i in range(count - 1)]
    nodes.append({"translation": [1, 0, 0], "mesh": 0})
    files["deep-chain.gltf"] = json.dumps(b.gltf([mesh], nodes, scenes=[{"nodes": [0]}]),
                                          separators=(",", ":")) + "\n"

    # The same triangle plain (node 0) and mirrored by scale x = -1 (node 1).
    b = Builder()
    mesh = triangle_mesh(b, tri, normals=[(0, 0, 1)] * 3)
    files["mirrored.gltf"] = text(b.gltf([mesh], [{"mesh": 0}, {"mesh": 0, "scale": [-1, 1, 1]}],
                                         scenes=[{"nodes": [0, 1]}]))

    # Strip (6 vertices, non-indexed) and fan (indexed, 5 indices).
    b = Builder()
    strip = triangle_mesh(b, [(i // 2, i % 2, 0) for i in range(6)], mode=STRIP)
    fan = triangle_mesh(b, [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (-1, 1, 0)],
                        indices=[0, 1, 2, 3, 4], mode=FAN)
    files["strip-fan.gltf"] = text(b.gltf([strip, fan], [{"mesh": 0}, {"mesh": 1}],
                                          scenes=[{"nodes": [0, 1]}]))

    # T·R·S (node 0) and the same transform as a matrix (node 1). The
    # rotation is 120° about (1, 1, 1): x → y → z → x, exact in binary.
    b = Builder()
    mesh = triangle_mesh(b, [(1, 0, 0), (0, 1, 0), (0, 0, 1)], normals=[(0.6, 0.8, 0)] * 3)
    t, s = (1, 2, 3), (2, 3, 4)
    # Columns: R·S e_x = 2 e_y, R·S e_y = 3 e_z, R·S e_z = 4 e_x.
    matrix = [0, 2, 0, 0, 0, 0, 3, 0, 4, 0, 0, 0, t[0], t[1], t[2], 1]
    files["trs-vs-matrix.gltf"] = text(b.gltf(
        [mesh], [{"mesh": 0, "translation": list(t), "rotation": [0.5, 0.5, 0.5, 0.5], "scale": list(s)},
                 {"mesh": 0, "matrix": matrix}], scenes=[{"nodes": [0, 1]}]))

    # Every kind of animation data in one file (a fuzz seed; loaded at
    # several times by tests/common/animation_test.cpp): a quad skinned
    # to two joints (node 1, its child node 2), with one morph target;
    # STEP translation of joint 0, LINEAR rotation of joint 1, CUBICSPLINE
    # weights of the mesh node.
    b = Builder()
    pos = b.positions(QUAD)
    nrm = b.vec3([(0, 0, 1)] * 4)
    idx = b.indices([0, 1, 2, 0, 2, 3])
    jnt = b.accessor([0, 1, 0, 0] * 4, USHORT, "VEC4")
    wgt = b.accessor([1, 0, 0, 0, 1, 0, 0, 0, 0.5, 0.5, 0, 0, 0, 1, 0, 0], FLOAT, "VEC4")
    lift = b.vec3([(0, 0, 1)] * 4)
    ibm = b.accessor([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                      1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1], FLOAT, "MAT4")
    times = b.accessor([0, 1, 2], FLOAT, "SCALAR")
    steps = b.vec3([(0, 0, 0), (0.5, 0, 0), (0, 0.5, 0)])
    turns = b.accessor([0, 0, 0, 1, 0, 0, 0.70710678, 0.70710678, 0, 0, 1, 0], FLOAT, "VEC4")
    weights = b.accessor([0, 0, 0, 0, 1, 0, 0, 0.5, 0], FLOAT, "SCALAR")  # (in, value, out) per key
    mesh = {"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "JOINTS_0": jnt, "WEIGHTS_0": wgt},
                            "indices": idx, "targets": [{"POSITION": lift}]}], "weights": [0]}
    animations = [{"name": "all three", "samplers": [
        {"input": times, "output": steps, "interpolation": "STEP"},
        {"input": times, "output": turns},
        {"input": times, "output": weights, "interpolation": "CUBICSPLINE"}], "channels": [
        {"sampler": 0, "target": {"node": 1, "path": "translation"}},
        {"sampler": 1, "target": {"node": 2, "path": "rotation"}},
        {"sampler": 2, "target": {"node": 0, "path": "weights"}}]}]
    files["animated.gltf"] = text(b.gltf(
        [mesh], [{"mesh": 0, "skin": 0}, {"children": [2]}, {"translation": [0, 1, 0]}],
        scenes=[{"nodes": [0, 1]}], skins=[{"joints": [1, 2], "inverseBindMatrices": ibm}],
        animations=animations))

    # Three triangles: proper, collinear, repeated vertex.
    b = Builder()
    mesh = triangle_mesh(b, [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 1), (2, 2, 2)],
                         indices=[0, 1, 2, 0, 3, 4, 1, 1, 2])
    files["degenerate.gltf"] = text(b.gltf([mesh], [{"mesh": 0}], scenes=[{"nodes": [0]}]))

    # Material maps: a quad with file tangents, and one without (generated)
    # whose normal, occlusion and metallic-roughness maps are transformed.
    files["normal-mapped.gltf"] = text(normal_mapped_quad([1, 0, 0, 1] * 4, "VEC4"))
    d = normal_mapped_quad([1, 0, 0, 1] * 4, "VEC4")
    del d["meshes"][0]["primitives"][0]["attributes"]["TANGENT"]
    transform = {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 0.5, "scale": [2, 2]}}
    d["materials"] = [{"normalTexture": {"index": 0, "scale": 0.5, "extensions": transform},
                       "occlusionTexture": {"index": 0, "strength": 0.5, "extensions": transform},
                       "pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 0, "extensions": transform}}}]
    d["extensionsUsed"] = ["KHR_texture_transform"]
    files["material-maps-generated-tangents.gltf"] = text(d)
    # Tangents through a morph target and a skin: TANGENT (1, 0, 0, 1), a
    # target's TANGENT delta (-1, 1, 0) at weight 1 makes it (0, 1, 0), and
    # the one joint, turned 90 degrees about z, makes that (-1, 0, 0).
    b = Builder()
    pos = b.positions(QUAD)
    nrm = b.vec3([(0, 0, 1)] * 4)
    idx = b.indices([0, 1, 2, 0, 2, 3])
    tan = b.accessor([1, 0, 0, 1] * 4, FLOAT, "VEC4")
    uv = b.vec2([(0, 1), (1, 1), (1, 0), (0, 0)])
    jnt = b.accessor([0, 0, 0, 0] * 4, USHORT, "VEC4")
    wgt = b.accessor([1, 0, 0, 0] * 4, FLOAT, "VEC4")
    delta = b.vec3([(-1, 1, 0)] * 4)
    attributes = {"POSITION": pos, "NORMAL": nrm, "TANGENT": tan, "TEXCOORD_0": uv,
                  "JOINTS_0": jnt, "WEIGHTS_0": wgt}
    mesh = {"primitives": [{"attributes": attributes, "indices": idx, "material": 0,
                            "targets": [{"TANGENT": delta}]}], "weights": [1]}
    s45 = 0.7071067811865476
    files["normal-mapped-skinned-morphed.gltf"] = text(b.gltf(
        [mesh], [{"mesh": 0, "skin": 0}, {"rotation": [0, 0, s45, s45]}], scenes=[{"nodes": [0, 1]}], scene=0,
        skins=[{"joints": [1]}], materials=[{"normalTexture": {"index": 0}}], textures=[{"source": 0}],
        images=[{"uri": "data:image/png;base64," + base64.b64encode(png_1x1()).decode()}]))
    return files


def write(path, content):
    data = content.encode("utf-8") if isinstance(content, str) else bytes(content)
    with open(path, "wb") as f:
        f.write(data)


def main():
    os.makedirs(VALID, exist_ok=True)
    bad, good = malformed(), valid()
    for name, content in sorted(bad.items()):
        write(os.path.join(HERE, name), content)
    for name, content in sorted(good.items()):
        write(os.path.join(VALID, name), content)
    print("wrote %d malformed and %d valid files" % (len(bad), len(good)), file=sys.stderr)


if __name__ == "__main__":
    main()
