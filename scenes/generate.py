#!/usr/bin/env python3
"""Generates rastray's test scenes (glTF 2.0, one self-contained .gltf each).

Run from the repository root:  python3 scenes/generate.py
It rewrites every scene in scenes/ deterministically (same bytes every run)
and then re-reads each file and checks it (buffers, accessors, indices,
winding against normals, closed meshes, scene-specific claims).

Python 3 standard library only.
"""

import base64
import json
import math
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATOR = "rastray scenes/generate.py"

FLOAT, UBYTE, USHORT, UINT = 5126, 5121, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
TRIANGLES = 4
NEAREST, LINEAR, LINEAR_MIPMAP_LINEAR, REPEAT, CLAMP_TO_EDGE = 9728, 9729, 9987, 10497, 33071
COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
COMPONENT_SIZE = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}


# --------------------------------------------------------------------------
# Small vector helpers (tuples of floats)

def add(a, b): return tuple(x + y for x, y in zip(a, b))
def sub(a, b): return tuple(x - y for x, y in zip(a, b))
def mul(a, s): return tuple(x * s for x in a)
def dot(a, b): return sum(x * y for x, y in zip(a, b))
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def norm(a):
    length = math.sqrt(dot(a, a))
    return tuple(x / length for x in a)


def f32(x):
    """x rounded to the float32 the buffer will hold."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def quat_from_basis(x, y, z):
    """Unit quaternion [x, y, z, w] of the rotation whose matrix columns are x, y, z."""
    m00, m01, m02 = x[0], y[0], z[0]
    m10, m11, m12 = x[1], y[1], z[1]
    m20, m21, m22 = x[2], y[2], z[2]
    trace = m00 + m11 + m22
    if trace > 0:
        s = 0.5 / math.sqrt(trace + 1.0)
        q = ((m21 - m12) * s, (m02 - m20) * s, (m10 - m01) * s, 0.25 / s)
    elif m00 > m11 and m00 > m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        q = (0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
    elif m11 > m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        q = ((m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        q = ((m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s)
    q = norm(q)
    if q[3] < 0:
        q = mul(q, -1.0)
    return [round(c, 12) + 0.0 for c in q]


def look_rotation(forward, up=(0.0, 1.0, 0.0)):
    """Quaternion turning a node's −Z onto `forward` with +Y as close to `up` as possible."""
    f = norm(forward)
    r = norm(cross(f, up))
    u = cross(r, f)
    return quat_from_basis(r, u, mul(f, -1.0))


def axis_angle(axis, angle):
    a = norm(axis)
    s = math.sin(angle / 2)
    return [round(a[0] * s, 12) + 0.0, round(a[1] * s, 12) + 0.0,
            round(a[2] * s, 12) + 0.0, round(math.cos(angle / 2), 12) + 0.0]


# --------------------------------------------------------------------------
# Geometry: lists of vertices (positions, optional normals / uvs) + triangles

class Geometry:
    def __init__(self):
        self.positions, self.normals, self.uvs, self.triangles = [], [], [], []

    def vertex(self, p, n=None, uv=None):
        self.positions.append(tuple(p))
        if n is not None:
            self.normals.append(tuple(n))
        if uv is not None:
            self.uvs.append(tuple(uv))
        return len(self.positions) - 1

    def quad(self, corners, normal=None):
        """corners counter-clockwise seen from the front; flat normal if given."""
        i = [self.vertex(c, normal) for c in corners]
        self.triangles += [(i[0], i[1], i[2]), (i[0], i[2], i[3])]

    def face(self, center, n, u, half_u, half_v):
        """Rectangle facing n; u is its first in-plane axis (v = n × u)."""
        n, u = norm(n), norm(u)
        v = cross(n, u)
        du, dv = mul(u, half_u), mul(v, half_v)
        corners = [sub(sub(center, du), dv), sub(add(center, du), dv),
                   add(add(center, du), dv), add(sub(center, du), dv)]
        self.quad(corners, n)


def box(size):
    """Closed axis-aligned box centred at the origin, outward faces, flat normals."""
    g = Geometry()
    h = [s / 2 for s in size]
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = [0.0, 0.0, 0.0]
            n[axis] = sign
            u = [0.0, 0.0, 0.0]
            u[(axis + 1) % 3] = 1.0
            c = [0.0, 0.0, 0.0]
            c[axis] = sign * h[axis]
            g.face(c, n, u, h[(axis + 1) % 3], h[(axis + 2) % 3])
    return g


def uv_sphere(radius, segments, rings):
    """Closed UV sphere: one vertex per pole, no duplicated seam, smooth normals.
    Vertex count 2 + (rings − 1)·segments; triangle count 2·segments·(rings − 1)."""
    g = Geometry()

    def point(theta, phi):
        n = (math.sin(theta) * math.sin(phi), math.cos(theta), math.sin(theta) * math.cos(phi))
        return mul(n, radius), n

    north = g.vertex((0.0, radius, 0.0), (0.0, 1.0, 0.0))
    ring_start = []
    for i in range(1, rings):
        ring_start.append(len(g.positions))
        for j in range(segments):
            p, n = point(math.pi * i / rings, 2 * math.pi * j / segments)
            g.vertex(p, n)
    south = g.vertex((0.0, -radius, 0.0), (0.0, -1.0, 0.0))

    def at(ring, j):
        return ring_start[ring] + j % segments

    for j in range(segments):
        g.triangles.append((north, at(0, j), at(0, j + 1)))
    for i in range(rings - 2):
        for j in range(segments):
            u0, u1, l0, l1 = at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)
            g.triangles += [(u0, l0, l1), (u0, l1, u1)]
    for j in range(segments):
        g.triangles.append((south, at(rings - 2, j + 1), at(rings - 2, j)))
    return g


# --------------------------------------------------------------------------
# The one glTF builder: buffer, bufferViews, accessors, meshes, nodes

class Gltf:
    def __init__(self):
        self.doc = {
            "asset": {"version": "2.0", "generator": GENERATOR},
            "scene": 0,
            "scenes": [{"nodes": []}],
            "nodes": [], "cameras": [], "meshes": [], "materials": [],
            "accessors": [], "bufferViews": [], "buffers": [],
        }
        self.data = bytearray()
        self.extensions_used = []

    def use_extension(self, name):
        if name not in self.extensions_used:
            self.extensions_used.append(name)

    def _view(self, payload, target):
        while len(self.data) % 4:
            self.data.append(0)
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(payload)}
        if target is not None:
            view["target"] = target
        self.data += payload
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, values, type_, component=FLOAT, target=ARRAY_BUFFER, bounds=False, normalized=False):
        """values: list of tuples (VECn) or ints (SCALAR). Returns the accessor index.
        Integer components are stored as given (normalized: the reader divides)."""
        n = COMPONENTS[type_]
        flat = [v for t in values for v in t] if n > 1 else list(values)
        fmt = {FLOAT: "f", UBYTE: "B", USHORT: "H", UINT: "I"}[component]
        payload = struct.pack("<%d%s" % (len(flat), fmt), *flat)
        acc = {"bufferView": self._view(payload, target), "componentType": component,
               "count": len(values), "type": type_}
        if normalized:
            acc["normalized"] = True
        if bounds:
            cols = [[f32(t[k]) for t in values] for k in range(n)]
            acc["min"] = [min(c) for c in cols]
            acc["max"] = [max(c) for c in cols]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name, color, metallic=0.0, roughness=1.0, alpha_mode=None,
                 double_sided=None, extensions=None, texture=None):
        pbr = {"baseColorFactor": [float(c) for c in color],
               "metallicFactor": float(metallic), "roughnessFactor": float(roughness)}
        if texture is not None:
            pbr["baseColorTexture"] = {"index": texture}
        m = {"name": name, "pbrMetallicRoughness": pbr}
        if alpha_mode is not None:
            m["alphaMode"] = alpha_mode
        if double_sided is not None:
            m["doubleSided"] = double_sided
        if extensions:
            m["extensions"] = extensions
            for ext in extensions:
                self.use_extension(ext)
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def primitive(self, geom, material):
        attrs = {"POSITION": self.accessor(geom.positions, "VEC3", bounds=True)}
        if geom.normals:
            assert len(geom.normals) == len(geom.positions)
            attrs["NORMAL"] = self.accessor(geom.normals, "VEC3")
        if geom.uvs:
            assert len(geom.uvs) == len(geom.positions)
            attrs["TEXCOORD_0"] = self.accessor(geom.uvs, "VEC2")
        component = USHORT if len(geom.positions) <= 65535 else UINT
        indices = self.accessor([i for t in geom.triangles for i in t], "SCALAR",
                                component, ELEMENT_ARRAY_BUFFER)
        return {"attributes": attrs, "indices": indices, "material": material, "mode": TRIANGLES}

    def mesh(self, name, primitives):
        """primitives: list of (Geometry, material index)."""
        self.doc["meshes"].append({"name": name, "primitives": [self.primitive(g, m) for g, m in primitives]})
        return len(self.doc["meshes"]) - 1

    def node(self, name, translation=None, rotation=None, **fields):
        n = {"name": name}
        if translation is not None and any(translation):
            n["translation"] = [float(t) for t in translation]
        if rotation is not None and rotation != [0.0, 0.0, 0.0, 1.0]:
            n["rotation"] = rotation
        n.update(fields)
        self.doc["nodes"].append(n)
        index = len(self.doc["nodes"]) - 1
        self.doc["scenes"][0]["nodes"].append(index)
        return index

    def mesh_node(self, name, primitives, translation=None, rotation=None):
        return self.node(name, translation, rotation, mesh=self.mesh(name, primitives))

    def perspective_camera(self, name, eye, target, yfov, znear, zfar=None):
        cam = {"yfov": yfov, "znear": znear}  # no aspectRatio: the image's own
        if zfar is not None:
            cam["zfar"] = zfar
        self.doc["cameras"].append({"name": name, "type": "perspective", "perspective": cam})
        return self.node(name, eye, look_rotation(sub(target, eye)), camera=len(self.doc["cameras"]) - 1)

    def light(self, name, light, translation=None, rotation=None):
        self.use_extension("KHR_lights_punctual")
        lights = self.doc.setdefault("extensions", {}).setdefault(
            "KHR_lights_punctual", {"lights": []})["lights"]
        lights.append(dict(name=name, **light))
        return self.node(name, translation, rotation,
                         extensions={"KHR_lights_punctual": {"light": len(lights) - 1}})

    def texture(self, png_bytes, name, sampler):
        doc = self.doc
        doc.setdefault("samplers", []).append(sampler)
        doc.setdefault("images", []).append(
            {"name": name, "uri": "data:image/png;base64," + base64.b64encode(png_bytes).decode("ascii")})
        doc.setdefault("textures", []).append(
            {"sampler": len(doc["samplers"]) - 1, "source": len(doc["images"]) - 1})
        return len(doc["textures"]) - 1

    def finish(self):
        while len(self.data) % 4:
            self.data.append(0)
        self.doc["buffers"] = [{
            "byteLength": len(self.data),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.data)).decode("ascii")}]
        if self.extensions_used:
            self.doc["extensionsUsed"] = list(self.extensions_used)
        for key in ("cameras", "meshes", "materials"):
            if not self.doc[key]:
                del self.doc[key]
        return self.doc


def png_rgb(width, height, pixel):
    """A truecolour 8-bit PNG; pixel(x, y) -> (r, g, b), row 0 at the top."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)  # filter: none
        for x in range(width):
            raw += bytes(pixel(x, y))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(bytes(raw), 9))
            + chunk(b"IEND", b""))


# --------------------------------------------------------------------------
# The scenes

RED, YELLOW, BLUE = (1, 0, 0, 1), (1, 1, 0, 1), (0, 0, 1, 1)

# three-triangles: (x, y) per vertex, exact multiples of 1/8; z = −depth.
THREE_TRIANGLES = [
    # name,   colour, view depth, vertices (x, y), counter-clockwise.
    # Arranged like a three-set Venn diagram: every one of the 7 regions
    # (each alone, each pair, all three) is non-empty.
    ("Yellow", YELLOW, 0.5,  [(-0.625, -0.375), (0.625, -0.375), (0.0, 0.75)]),
    ("Blue",   BLUE,   0.75, [(-0.375, -0.75), (0.875, -0.5), (0.25, 0.5)]),
    ("Red",    RED,    0.25, [(-0.875, -0.5), (0.375, -0.75), (-0.25, 0.5)]),
]


def three_triangles():
    """The textbook z-buffer example: three opaque triangles at view depths
    0.25 (red), 0.5 (yellow), 0.75 (blue), submitted in the order yellow,
    blue, red, so submission order is not depth order."""
    g = Gltf()
    for name, color, depth, verts in THREE_TRIANGLES:
        geom = Geometry()
        for x, y in verts:
            geom.vertex((x, y, -depth))
        geom.triangles.append((0, 1, 2))
        g.mesh_node(name, [(geom, g.material(name, color, metallic=0.0, roughness=1.0))])
    g.doc["cameras"].append({"name": "Ortho", "type": "orthographic",
                             "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.125, "zfar": 1.0}})
    g.node("Ortho", camera=0)
    return g.finish()


def interpenetrating():
    """Two opaque triangles that pass through each other along y = 0: the
    orange one leans back (its lower half in front of the blue one, its upper
    half behind), the blue one leans forward."""
    g = Gltf()
    a = Geometry()
    for p in [(-1.0, -0.75, 0.5), (1.0, -0.75, 0.5), (0.0, 0.75, -0.5)]:
        a.vertex(p)
    a.triangles.append((0, 1, 2))
    b = Geometry()
    for p in [(1.0, 0.75, 0.5), (-1.0, 0.75, 0.5), (0.0, -0.75, -0.5)]:
        b.vertex(p)
    b.triangles.append((0, 1, 2))
    g.mesh_node("Orange", [(a, g.material("Orange", (1.0, 0.5, 0.0, 1.0)))])
    g.mesh_node("Blue", [(b, g.material("Blue", (0.1, 0.4, 1.0, 1.0)))])
    g.perspective_camera("Camera", (0.6, 0.5, 3.2), (0.0, 0.0, 0.0), yfov=0.75, znear=0.1, zfar=100.0)
    return g.finish()


# cyclic-overlap: three long thin triangles ("sticks") along the sides of an
# equilateral triangle; each rises toward the camera along its length, so
# stick k lies over stick k+1 where they cross.
CYCLIC_R = 0.6          # circumradius of the triangle the sticks run along
CYCLIC_REACH = 0.375    # how far each stick runs past the corners
CYCLIC_WIDTH = 0.4      # width of a stick's base (its apex is a point)
CYCLIC_RISE = 0.4       # |z| at either end of a stick


def cyclic_sticks():
    corners = [(CYCLIC_R * math.cos(math.pi / 2 + 2 * math.pi * k / 3),
                CYCLIC_R * math.sin(math.pi / 2 + 2 * math.pi * k / 3)) for k in range(3)]
    sticks = []
    for k in range(3):
        p, q = corners[k], corners[(k + 1) % 3]
        d = norm(sub(q, p))
        half = math.dist(p, q) / 2 + CYCLIC_REACH
        mid = mul(add(p, q), 0.5)
        side = (-d[1], d[0])
        base = sub(mid, mul(d, half))
        apex = add(mid, mul(d, half))
        b0 = add(base, mul(side, -CYCLIC_WIDTH / 2))
        b1 = add(base, mul(side, CYCLIC_WIDTH / 2))
        # base at the back (z = −rise), apex in front (z = +rise); CCW from +z
        sticks.append([(b0[0], b0[1], -CYCLIC_RISE), (apex[0], apex[1], CYCLIC_RISE),
                       (b1[0], b1[1], -CYCLIC_RISE)])
    return sticks


def cyclic_overlap():
    """Three semi-transparent (BLEND, alpha 0.6) thin triangles overlapping
    cyclically: A over B, B over C, C over A. No back-to-front order exists,
    so sorted (painter's) transparency gets at least one crossing wrong."""
    g = Gltf()
    colors = [("A_Red", (1.0, 0.1, 0.1, 0.6)), ("B_Green", (0.1, 0.9, 0.1, 0.6)),
              ("C_Blue", (0.1, 0.3, 1.0, 0.6))]
    for (name, color), verts in zip(colors, cyclic_sticks()):
        geom = Geometry()
        for p in verts:
            geom.vertex(p)
        geom.triangles.append((0, 1, 2))  # counter-clockwise seen from +z
        g.mesh_node(name, [(geom, g.material(name, color, alpha_mode="BLEND", double_sided=True))])
    g.perspective_camera("Camera", (0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8, znear=0.1, zfar=100.0)
    return g.finish()


def cornell_box():
    """Cornell box (−1..1 on every axis, open at z = +1) with a point light
    under the ceiling, a mirror block and a glass sphere."""
    g = Gltf()
    white = g.material("White", (0.73, 0.73, 0.73, 1.0), double_sided=False)
    red = g.material("Red", (0.65, 0.05, 0.05, 1.0), double_sided=False)
    green = g.material("Green", (0.12, 0.45, 0.15, 1.0), double_sided=False)
    mirror = g.material("Mirror", (0.9, 0.9, 0.9, 1.0), metallic=1.0, roughness=0.0)
    glass = g.material("Glass", (1.0, 1.0, 1.0, 1.0), metallic=0.0, roughness=0.0, extensions={
        "KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_ior": {"ior": 1.5}})

    whites = Geometry()  # faces point into the box
    whites.face((0, -1, 0), (0, 1, 0), (1, 0, 0), 1, 1)   # floor
    whites.face((0, 1, 0), (0, -1, 0), (1, 0, 0), 1, 1)   # ceiling
    whites.face((0, 0, -1), (0, 0, 1), (1, 0, 0), 1, 1)   # back wall
    left = Geometry()
    left.face((-1, 0, 0), (1, 0, 0), (0, 1, 0), 1, 1)
    right = Geometry()
    right.face((1, 0, 0), (-1, 0, 0), (0, 1, 0), 1, 1)
    g.mesh_node("Walls", [(whites, white), (left, red), (right, green)])

    g.mesh_node("MirrorBlock", [(box((0.6, 1.2, 0.6)), mirror)],
                translation=(-0.4, -0.4, -0.3), rotation=axis_angle((0, 1, 0), math.radians(20)))
    g.mesh_node("GlassSphere", [(uv_sphere(0.35, 24, 16), glass)], translation=(0.4, -0.64, 0.25))
    g.light("CeilingLight", {"type": "point", "color": [1.0, 1.0, 1.0], "intensity": 4.0},
            translation=(0.0, 0.9, 0.0))
    g.perspective_camera("Camera", (0.0, 0.0, 3.5), (0.0, 0.0, 0.0), yfov=math.radians(45),
                         znear=0.1, zfar=100.0)
    return g.finish()


def transparent_layers():
    """Five BLEND sheets (alpha 0.25–0.8) over an opaque grey back wall, lit by
    one directional light: some parallel and overlapping, two tilted ones
    cutting through others."""
    g = Gltf()
    back = Geometry()
    back.face((0, 0, -2), (0, 0, 1), (1, 0, 0), 4, 4)
    g.mesh_node("Background", [(back, g.material("Grey", (0.8, 0.8, 0.8, 1.0)))])

    def sheet(name, color, center, n, u, hu, hv):
        geom = Geometry()
        geom.face(center, n, u, hu, hv)
        g.mesh_node(name, [(geom, g.material(name, color, alpha_mode="BLEND", double_sided=True))])

    t45, t40 = math.radians(45), math.radians(40)
    # parallel sheets facing the camera; the blue one lies wholly behind the red one's area
    sheet("Blue25", (0.1, 0.2, 1.0, 0.25), (-0.1, 0.0, -1.5), (0, 0, 1), (1, 0, 0), 1.2, 1.0)
    sheet("Green35", (0.1, 0.9, 0.2, 0.35), (0.4, -0.2, -1.0), (0, 0, 1), (1, 0, 0), 0.6, 0.6)
    sheet("Red50", (1.0, 0.1, 0.1, 0.5), (-0.4, 0.2, -0.5), (0, 0, 1), (1, 0, 0), 0.5, 0.5)
    # turned 45° about y: cuts through Green35 along x = 0.3
    sheet("Yellow80", (1.0, 0.9, 0.1, 0.8), (0.3, 0.2, -1.0),
          (math.sin(t45), 0, math.cos(t45)), (math.cos(t45), 0, -math.sin(t45)), 0.6, 0.6)
    # tilted 40° about x: cuts through Red50 (and Green35)
    sheet("Cyan60", (0.1, 0.9, 0.9, 0.6), (-0.3, 0.1, -0.75),
          (0, math.sin(t40), math.cos(t40)), (1, 0, 0), 0.6, 0.6)

    g.light("Sun", {"type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 3.0},
            rotation=look_rotation((0.3, -0.4, -1.0)))
    g.perspective_camera("Camera", (0.0, 0.3, 2.5), (0.0, 0.0, -1.0), yfov=0.8, znear=0.1, zfar=100.0)
    return g.finish()


def floor_box_sphere():
    """A floor, a box and a flat-shaded sphere (no NORMAL: face normals) under
    one directional light, opaque and diffuse: shadow masks against an
    independent ray tracer (`rastray povray`, docs/SHADOWS.md)."""
    g = Gltf()
    floor = Geometry()
    floor.face((0, 0, 0), (0, 1, 0), (1, 0, 0), 2.5, 2.5)
    g.mesh_node("Floor", [(floor, g.material("Floor", (0.8, 0.8, 0.8, 1.0)))])
    g.mesh_node("Box", [(box((0.7, 0.7, 0.7)), g.material("Box", (0.7, 0.5, 0.3, 1.0)))],
                translation=(-0.6, 0.35, -0.2), rotation=axis_angle((0, 1, 0), math.radians(30)))
    sphere = uv_sphere(0.45, 16, 10)
    sphere.normals = []
    g.mesh_node("FlatSphere", [(sphere, g.material("Sphere", (0.3, 0.5, 0.7, 1.0)))],
                translation=(0.7, 0.45, 0.3))
    g.light("Sun", {"type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 3.0},
            rotation=look_rotation((0.5, -1.0, -0.35)))
    g.perspective_camera("Camera", (0.3, 2.4, 3.6), (0.0, 0.2, 0.0), yfov=0.75, znear=0.1, zfar=100.0)
    return g.finish()


CHECKER_SIZE, CHECKER_SQUARE = 256, 32   # 8×8 squares per texture tile
PLANE_HALF, PLANE_CELLS, PLANE_UV = 64.0, 16, 8.0   # 128×128 units, uv 0..8 → 64×64 squares


def checker_pixel(x, y):
    if x < CHECKER_SQUARE and y < CHECKER_SQUARE:
        return (255, 0, 0)  # marks uv (0, 0) of every tile: top-left square is red
    return (255, 255, 255) if (x // CHECKER_SQUARE + y // CHECKER_SQUARE) % 2 == 0 else (0, 0, 0)


def textured_plane():
    """A 128×128-unit ground plane with a repeating checker texture (64×64
    squares in all), seen from 1 unit above at a grazing angle."""
    g = Gltf()
    png = png_rgb(CHECKER_SIZE, CHECKER_SIZE, checker_pixel)
    tex = g.texture(png, "checker", {"magFilter": LINEAR, "minFilter": LINEAR_MIPMAP_LINEAR,
                                     "wrapS": REPEAT, "wrapT": REPEAT})
    geom = Geometry()
    n = PLANE_CELLS
    for i in range(n + 1):          # along z
        for j in range(n + 1):      # along x
            x = -PLANE_HALF + 2 * PLANE_HALF * j / n
            z = -PLANE_HALF + 2 * PLANE_HALF * i / n
            geom.vertex((x, 0.0, z), (0.0, 1.0, 0.0), (PLANE_UV * j / n, PLANE_UV * i / n))
    for i in range(n):
        for j in range(n):
            a, b = i * (n + 1) + j, i * (n + 1) + j + 1
            c, d = a + n + 1, b + n + 1      # c: (j, i+1), d: (j+1, i+1)
            geom.triangles += [(a, c, d), (a, d, b)]
    g.mesh_node("Ground", [(geom, g.material("Checker", (1.0, 1.0, 1.0, 1.0), texture=tex))])
    g.light("Sun", {"type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 3.0},
            rotation=look_rotation((0.2, -1.0, -0.3)))
    pitch = math.radians(3)
    eye = (0.0, 1.0, PLANE_HALF + 2.0)
    g.perspective_camera("Camera", eye, add(eye, (0.0, -math.sin(pitch), -math.cos(pitch))),
                         yfov=math.radians(45), znear=0.05, zfar=1000.0)
    return g.finish()


# vertex-colors: four 0.8×0.8 quads at z = −1 seen by an orthographic
# camera (xmag = ymag = 1), no lights, so a pixel shows its base colour (or
# emission) directly. (u, v) run 0..1 across each quad, left to right and
# bottom to top; every COLOR_0 is a linear function of (u, v), which
# barycentric interpolation reproduces exactly on any triangulation.
VC_QUADS = [
    # name, lower-left corner (x, y), COLOR_0 (u, v) -> RGBA, component type
    ("FloatRGB", (-0.9, 0.1), lambda u, v: (u, v, 1 - u), FLOAT),
    ("ByteRGBA", (0.1, 0.1), lambda u, v: (u, v, 1 - u, 1), UBYTE),
    ("ShortMask", (-0.9, -0.9), lambda u, v: (1, 1, 0, u), USHORT),
    ("Emissive", (0.1, -0.9), None, None),
]
VC_SIZE = 0.8
# The emissive texture: 2×2 texels, row 0 (top) red, green; row 1 blue, white.
VC_TEXELS = [[(255, 0, 0), (0, 255, 0)], [(0, 0, 255), (255, 255, 255)]]


def vertex_colors():
    """COLOR_0 in the three allowed component types (float VEC3, normalized
    unsigned byte and short VEC4, the short one driving MASK coverage by its
    alpha) and an emissive texture on a black base colour."""
    g = Gltf()
    tex = g.texture(png_rgb(2, 2, lambda x, y: VC_TEXELS[y][x]), "emissive-2x2",
                    {"magFilter": NEAREST, "minFilter": NEAREST, "wrapS": CLAMP_TO_EDGE, "wrapT": CLAMP_TO_EDGE})
    scale = {FLOAT: 1.0, UBYTE: 255, USHORT: 65535}
    for name, (x0, y0), color, component in VC_QUADS:
        geom = Geometry()
        corners = [(0, 0), (1, 0), (1, 1), (0, 1)]
        for u, v in corners:
            geom.vertex((x0 + VC_SIZE * u, y0 + VC_SIZE * v, -1.0), (0.0, 0.0, 1.0), (u, 1 - v))
        geom.triangles += [(0, 1, 2), (0, 2, 3)]
        if name == "FloatRGB":
            mat = g.material(name, (1, 1, 1, 1))
        elif name == "ByteRGBA":
            mat = g.material(name, (1, 0.5, 1, 1))
        elif name == "ShortMask":
            mat = g.material(name, (1, 1, 1, 1), alpha_mode="MASK")
            g.doc["materials"][mat]["alphaCutoff"] = 0.5
        else:
            mat = g.material(name, (0, 0, 0, 1))
            g.doc["materials"][mat].update({"emissiveFactor": [1.0, 1.0, 1.0], "emissiveTexture": {"index": tex}})
        prim = g.primitive(geom, mat)
        if color is not None:
            values = [tuple(round(c * scale[component]) if component != FLOAT else float(c) for c in color(u, v))
                      for u, v in corners]
            prim["attributes"]["COLOR_0"] = g.accessor(values, "VEC%d" % len(values[0]), component,
                                                       normalized=component != FLOAT)
        g.doc["meshes"].append({"name": name, "primitives": [prim]})
        g.node(name, mesh=len(g.doc["meshes"]) - 1)
    g.doc["cameras"].append({"name": "Ortho", "type": "orthographic",
                             "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.125, "zfar": 2.0}})
    g.node("Ortho", camera=0)
    return g.finish()


SCENES = [
    ("three-triangles.gltf", three_triangles),
    ("interpenetrating.gltf", interpenetrating),
    ("cyclic-overlap.gltf", cyclic_overlap),
    ("cornell-box.gltf", cornell_box),
    ("transparent-layers.gltf", transparent_layers),
    ("textured-plane.gltf", textured_plane),
    ("vertex-colors.gltf", vertex_colors),
    ("floor-box-sphere.gltf", floor_box_sphere),
]


# --------------------------------------------------------------------------
# Self-check: re-read every written file as a loader would

class CheckError(Exception):
    pass


def require(cond, where, msg):
    if not cond:
        raise CheckError("%s: %s" % (where, msg))


def decode_data_uri(uri, where):
    require(uri.startswith("data:") and ";base64," in uri, where, "not a base64 data URI")
    return base64.b64decode(uri.split(",", 1)[1])


def read_accessor(doc, buffers, index, name=""):
    where = "%saccessor %d" % (name + ": " if name else "", index)
    acc = doc["accessors"][index]
    view_index = acc["bufferView"]
    require(0 <= view_index < len(doc["bufferViews"]), where, "bufferView out of range")
    view = doc["bufferViews"][view_index]
    buf = buffers[view["buffer"]]
    vo, vl = view.get("byteOffset", 0), view["byteLength"]
    view_where = "%sbufferView %d" % (name + ": " if name else "", view_index)
    require(vo % 4 == 0, view_where, "byteOffset not 4-byte aligned")
    require(vo + vl <= len(buf), view_where, "runs past the end of its buffer")
    n, size = COMPONENTS[acc["type"]], COMPONENT_SIZE[acc["componentType"]]
    stride = view.get("byteStride", n * size)
    ao = acc.get("byteOffset", 0)
    require(ao % size == 0, where, "byteOffset not aligned to its component")
    need = ao + (acc["count"] - 1) * stride + n * size if acc["count"] else 0
    require(need <= vl, where, "runs past the end of bufferView %d" % view_index)
    fmt = "<%d%s" % (n, {5126: "f", 5123: "H", 5125: "I", 5121: "B"}[acc["componentType"]])
    out = [struct.unpack_from(fmt, buf, vo + ao + k * stride) for k in range(acc["count"])]
    if acc.get("normalized"):
        top = {5121: 255.0, 5123: 65535.0}[acc["componentType"]]
        out = [tuple(c / top for c in v) for v in out]
    return [v[0] for v in out] if n == 1 else out


def check_png(data, where):
    require(data[:8] == b"\x89PNG\r\n\x1a\n", where, "not a PNG")
    pos, idat, size = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack_from(">I4s", data, pos)
        body = data[pos + 8: pos + 8 + length]
        crc, = struct.unpack_from(">I", data, pos + 8 + length)
        require(zlib.crc32(kind + body) & 0xFFFFFFFF == crc, where, "bad CRC in %r" % kind)
        if kind == b"IHDR":
            size = struct.unpack(">II", body[:8])
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    w, h = size
    require(len(zlib.decompress(idat)) == h * (1 + 3 * w), where, "pixel data has the wrong size")
    return w, h


def edge_closed(positions, triangles, where):
    """Every directed edge (by position) is matched by exactly one opposite edge."""
    key = lambda i: tuple(round(c, 5) for c in positions[i])
    edges = {}
    for t in triangles:
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            e = (key(a), key(b))
            edges[e] = edges.get(e, 0) + 1
    for (a, b), count in edges.items():
        require(count == 1 and edges.get((b, a)) == 1, where, "not closed at edge %s-%s" % (a, b))


def inside2(p, tri):
    """Strictly inside a 2D CCW triangle."""
    for k in range(3):
        a, b = tri[k], tri[(k + 1) % 3]
        if (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) <= 0:
            return False
    return True


def plane_depth(tri, x, y):
    """z of the triangle's plane at (x, y)."""
    n = cross(sub(tri[1], tri[0]), sub(tri[2], tri[0]))
    return tri[0][2] - (n[0] * (x - tri[0][0]) + n[1] * (y - tri[0][1])) / n[2]


def check_three_triangles(tris):
    """Claims of three-triangles, sampled on a 256×256 grid over the view:
    all 7 Venn regions (each triangle alone, each pair, all three) are
    non-empty, so every colour is visible and every depth order shows."""
    grid = [(-1 + (2 * i + 1) / 256.0) for i in range(256)]
    regions = set()
    for x in grid:
        for y in grid:
            regions.add(tuple(k for k, t in enumerate(tris) if inside2((x, y), t)))
    want = {(0,), (1,), (2,), (0, 1), (0, 2), (1, 2), (0, 1, 2)}
    require(want <= regions, "three-triangles", "regions missing: %s" % sorted(want - regions))


def check_cyclic(tris):
    """Claims of cyclic-overlap: each pair overlaps only where one fixed triangle
    is in front, and those 'in front' relations form the cycle 0>1>2>0."""
    front = set()
    steps = 400
    for i in range(steps):
        for j in range(steps):
            x, y = -1.5 + 3.0 * (i + 0.5) / steps, -1.5 + 3.0 * (j + 0.5) / steps
            cover = [k for k in range(3) if inside2((x, y), [t[:2] for t in tris[k]])]
            for a in cover:
                for b in cover:
                    if a != b and plane_depth(tris[a], x, y) > plane_depth(tris[b], x, y):
                        front.add((a, b))
    require(front == {(0, 1), (1, 2), (2, 0)}, "cyclic-overlap",
            "front-of relation is %s, not the cycle 0>1>2>0" % sorted(front))


def check_vertex_colors(doc, buffers):
    """Every COLOR_0 equals its quad's colour function at the vertex, in
    the component type the table names; the emissive PNG holds VC_TEXELS."""
    where = "vertex-colors.gltf"
    for mesh, (name, (x0, y0), color, component) in zip(doc["meshes"], VC_QUADS):
        attrs = mesh["primitives"][0]["attributes"]
        require(("COLOR_0" in attrs) == (color is not None), where, "%s: COLOR_0 presence" % name)
        if color is None:
            continue
        acc = doc["accessors"][attrs["COLOR_0"]]
        require(acc["componentType"] == component and acc.get("normalized", False) == (component != FLOAT),
                where, "%s: COLOR_0 component type" % name)
        for p, c in zip(read_accessor(doc, buffers, attrs["POSITION"]),
                        read_accessor(doc, buffers, attrs["COLOR_0"])):
            want = color((p[0] - x0) / VC_SIZE, (p[1] - y0) / VC_SIZE)
            require(all(abs(a - b) < 1e-6 for a, b in zip(c, want)) and len(c) == len(want), where,
                    "%s: COLOR_0 %s at %s, want %s" % (name, c, p, want))
    png = decode_data_uri(doc["images"][0]["uri"], where)
    require(png == png_rgb(2, 2, lambda x, y: VC_TEXELS[y][x]), where, "emissive texture differs from VC_TEXELS")


def check_file(path):
    name = os.path.basename(path)
    size = os.path.getsize(path)
    require(size < 300 * 1024, name, "file is %d bytes (limit 300 KB)" % size)
    with open(path) as f:
        doc = json.load(f)
    require(doc["asset"]["version"] == "2.0", name, "asset.version is not 2.0")
    buffers = []
    for i, b in enumerate(doc["buffers"]):
        data = decode_data_uri(b["uri"], "%s: buffer %d" % (name, i))
        require(len(data) == b["byteLength"], "%s: buffer %d" % (name, i), "byteLength mismatch")
        buffers.append(data)
    for i, v in enumerate(doc["bufferViews"]):
        require(0 <= v["buffer"] < len(buffers), "%s: bufferView %d" % (name, i), "buffer out of range")
    for i in range(len(doc["accessors"])):
        read_accessor(doc, buffers, i, name)
    for i, img in enumerate(doc.get("images", [])):
        check_png(decode_data_uri(img["uri"], "%s: image %d" % (name, i)), "%s: image %d" % (name, i))
    require(doc["scene"] == 0 and doc["scenes"], name, "no scene 0")
    nodes = doc["nodes"]
    seen, stack = set(), list(reversed(doc["scenes"][0]["nodes"]))
    camera_nodes, lights = [], doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    counts = {"instances": 0, "triangles": 0, "vertices": 0}
    for i, node in enumerate(nodes):
        where = "%s: node %d" % (name, i)
        if "camera" in node:
            require(0 <= node["camera"] < len(doc["cameras"]), where, "camera out of range")
            camera_nodes.append(i)
        if "rotation" in node:
            require(abs(dot(node["rotation"], node["rotation"]) - 1) < 1e-9, where, "rotation not unit")
        light = node.get("extensions", {}).get("KHR_lights_punctual", {}).get("light")
        if light is not None:
            require(0 <= light < len(lights), where, "light out of range")
    while stack:
        i = stack.pop()
        require(0 <= i < len(nodes) and i not in seen, name, "bad node reference %d" % i)
        seen.add(i)
        stack += reversed(nodes[i].get("children", []))
    require(camera_nodes, name, "no camera node")
    for mi, mesh in enumerate(doc.get("meshes", [])):
        for pi, prim in enumerate(mesh["primitives"]):
            where = "%s: mesh %d '%s' primitive %d" % (name, mi, mesh["name"], pi)
            attrs = prim["attributes"]
            pos_acc = doc["accessors"][attrs["POSITION"]]
            pos = read_accessor(doc, buffers, attrs["POSITION"])
            for k in range(3):
                require(pos_acc["min"][k] == min(p[k] for p in pos) and
                        pos_acc["max"][k] == max(p[k] for p in pos), where, "POSITION min/max wrong")
            for attr in attrs:
                require(doc["accessors"][attrs[attr]]["count"] == len(pos), where, "%s count differs" % attr)
            idx = read_accessor(doc, buffers, prim["indices"])
            require(prim.get("mode", 4) == TRIANGLES and len(idx) % 3 == 0, where, "not a triangle list")
            require(all(0 <= i < len(pos) for i in idx), where, "index out of range (%d vertices)" % len(pos))
            require(0 <= prim["material"] < len(doc["materials"]), where, "material out of range")
            tris = [tuple(idx[k:k + 3]) for k in range(0, len(idx), 3)]
            normals = read_accessor(doc, buffers, attrs["NORMAL"]) if "NORMAL" in attrs else None
            for t in tris:
                fn = cross(sub(pos[t[1]], pos[t[0]]), sub(pos[t[2]], pos[t[0]]))
                require(dot(fn, fn) > 0, where, "degenerate triangle %s" % (t,))
                if normals:
                    for i in t:
                        require(abs(dot(normals[i], normals[i]) - 1) < 1e-5, where, "normal not unit")
                        require(dot(fn, normals[i]) > 0, where, "triangle %s wound against its normals" % (t,))
            if mesh["name"] in ("MirrorBlock", "GlassSphere", "Box", "FlatSphere"):
                edge_closed(pos, tris, where)
            counts["triangles"] += len(tris)
            counts["vertices"] += len(pos)
    for node in nodes:
        if "mesh" in node:
            counts["instances"] += len(doc["meshes"][node["mesh"]]["primitives"])
    if name == "three-triangles.gltf":
        check_three_triangles([tuple(v) for v in
                               [[(x, y, -d) for x, y in verts] for _, _, d, verts in THREE_TRIANGLES]])
    if name == "cyclic-overlap.gltf":
        check_cyclic(cyclic_sticks())
    if name == "vertex-colors.gltf":
        check_vertex_colors(doc, buffers)
    return size, counts


def main():
    for filename, build in SCENES:
        path = os.path.join(HERE, filename)
        text = json.dumps(build(), indent=1) + "\n"
        tmp = path + ".tmp"
        with open(tmp, "w", newline="\n") as f:
            f.write(text)
        os.replace(tmp, path)
    ok = True
    for filename, _ in SCENES:
        try:
            size, c = check_file(os.path.join(HERE, filename))
            print("%-24s %7d bytes  %d instances  %4d triangles  %4d vertices  ok"
                  % (filename, size, c["instances"], c["triangles"], c["vertices"]))
        except (CheckError, KeyError, IndexError, TypeError, ValueError, struct.error) as e:
            ok = False
            print("%s: SELF-CHECK FAILED: %s" % (filename, e), file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
