#!/usr/bin/env python3
"""Integrity check for the real-world glTF test files (Python 3 stdlib only).

For every .gltf / .glb in this directory:
  * the JSON parses (GLB: the container header and chunks are well formed);
  * every buffer resolves (data URI, external file beside the .gltf, or the
    GLB BIN chunk) and is at least as long as its declared byteLength
    (data URIs and external files must match byteLength exactly; the GLB BIN
    chunk may carry up to 3 bytes of zero padding);
  * every bufferView and accessor lies inside its buffer;
  * every accessor that declares min/max matches the data it reads exactly
    (float32 compared after rounding the declared value to float32), and
    index accessors stay below the vertex count of the primitive;
  * every embedded PNG image has valid chunk CRCs and an inflatable IDAT.

A transcription error in a copied base64 payload almost always breaks one of
these checks.  Exit status 0 when every file passes, 1 otherwise.

Known exporter quirks (KNOWN_QUIRKS below) are part of the real-world data and
are kept as stored: for those files a min/max mismatch is accepted only on the
listed kinds of accessor, and a replacement check runs instead (NORMAL: every
vector has unit length; indices: every index is below the vertex count).

Usage: python3 verify.py [FILE...]     (default: every .gltf/.glb here)
"""
import base64
import json
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))

# file -> accessor roles whose declared min/max are known to be wrong in the
# original file (kept verbatim; see README.md)
KNOWN_QUIRKS = {
    # trimesh models/mode5.gltf: NORMAL accessors repeat the POSITION min/max;
    # index accessors declare min 0 / max = count instead of the real range.
    "mode5.gltf": {"NORMAL", "indices"},
}

COMP = {5120: ("b", 1), 5121: ("B", 1), 5122: ("h", 2), 5123: ("H", 2),
        5125: ("I", 4), 5126: ("f", 4)}
NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4,
         "MAT2": 4, "MAT3": 9, "MAT4": 16}


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def load(path):
    """Return (gltf_json, [buffer bytes or None])."""
    raw = open(path, "rb").read()
    bin_chunk = None
    if raw[:4] == b"glTF":
        magic, version, length = struct.unpack_from("<4sII", raw, 0)
        if version != 2:
            raise ValueError("GLB version %d" % version)
        if length != len(raw):
            raise ValueError("GLB length %d != file size %d" % (length, len(raw)))
        off = 12
        chunks = []
        while off < len(raw):
            clen, ctype = struct.unpack_from("<II", raw, off)
            if clen % 4:
                raise ValueError("GLB chunk length %d not a multiple of 4" % clen)
            chunks.append((ctype, raw[off + 8:off + 8 + clen]))
            off += 8 + clen
        if off != len(raw):
            raise ValueError("GLB chunks overrun the file")
        if not chunks or chunks[0][0] != 0x4E4F534A:
            raise ValueError("first GLB chunk is not JSON")
        gltf = json.loads(chunks[0][1].decode("utf-8"))
        if len(chunks) > 1:
            if chunks[1][0] != 0x004E4942:
                raise ValueError("second GLB chunk is not BIN")
            bin_chunk = chunks[1][1]
    else:
        gltf = json.loads(raw.decode("utf-8"))
    bufs = []
    for i, b in enumerate(gltf.get("buffers", [])):
        uri = b.get("uri")
        n = b["byteLength"]
        if uri is None:
            if i != 0 or bin_chunk is None:
                raise ValueError("buffer %d has no uri and no GLB BIN chunk" % i)
            data = bin_chunk
            if not (n <= len(data) <= n + 3) or any(data[n:]):
                raise ValueError("buffer %d: BIN chunk %d bytes for byteLength %d"
                                 % (i, len(data), n))
        elif uri.startswith("data:"):
            head, payload = uri.split(",", 1)
            if not head.endswith(";base64"):
                raise ValueError("buffer %d: data URI is not base64" % i)
            data = base64.b64decode(payload, validate=True)
            if len(data) != n:
                raise ValueError("buffer %d: decodes to %d bytes, byteLength %d"
                                 % (i, len(data), n))
        else:
            data = open(os.path.join(os.path.dirname(path), uri), "rb").read()
            if len(data) != n:
                raise ValueError("buffer %d: file %s has %d bytes, byteLength %d"
                                 % (i, uri, len(data), n))
        bufs.append(data)
    return gltf, bufs


def read_accessor(gltf, bufs, ai):
    a = gltf["accessors"][ai]
    fmt, size = COMP[a["componentType"]]
    nc = NCOMP[a["type"]]
    count = a["count"]
    if "bufferView" not in a:
        return [[0] * nc for _ in range(count)]
    bv = gltf["bufferViews"][a["bufferView"]]
    buf = bufs[bv["buffer"]]
    bv_off = bv.get("byteOffset", 0)
    if bv_off + bv["byteLength"] > len(buf):
        raise ValueError("bufferView %d overruns buffer" % a["bufferView"])
    elem = size * nc
    stride = bv.get("byteStride") or elem
    start = bv_off + a.get("byteOffset", 0)
    if count and a.get("byteOffset", 0) + stride * (count - 1) + elem > bv["byteLength"]:
        raise ValueError("accessor %d overruns bufferView %d" % (ai, a["bufferView"]))
    out = []
    for k in range(count):
        out.append(list(struct.unpack_from("<%d%s" % (nc, fmt), buf, start + k * stride)))
    return out


def check_png(data):
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    p, idat = 8, b""
    while p < len(data):
        n, = struct.unpack(">I", data[p:p + 4])
        t = data[p + 4:p + 8]
        c = data[p + 8:p + 8 + n]
        crc, = struct.unpack(">I", data[p + 8 + n:p + 12 + n])
        if zlib.crc32(t + c) & 0xFFFFFFFF != crc:
            raise ValueError("PNG chunk %r CRC mismatch" % t)
        if t == b"IDAT":
            idat += c
        p += 12 + n
    zlib.decompress(idat)


def accessor_roles(gltf):
    roles = {}
    for m in gltf.get("meshes", []):
        for p in m["primitives"]:
            for name, ai in p["attributes"].items():
                roles.setdefault(ai, set()).add(name)
            if "indices" in p:
                roles.setdefault(p["indices"], set()).add("indices")
    return roles


def verify(path):
    gltf, bufs = load(path)
    quirks = KNOWN_QUIRKS.get(os.path.basename(path), set())
    roles = accessor_roles(gltf)
    for ai, a in enumerate(gltf.get("accessors", [])):
        vals = read_accessor(gltf, bufs, ai)
        role = roles.get(ai, set())
        if role and role <= quirks:
            if "NORMAL" in role:
                for v in vals:
                    if abs(sum(c * c for c in v) ** 0.5 - 1.0) > 1e-3:
                        raise ValueError("accessor %d: normal %r is not unit length" % (ai, v))
            continue  # declared min/max known to be wrong; indices checked below
        if "min" in a and "max" in a and vals:
            nc = len(a["min"])
            isf = a["componentType"] == 5126
            for c in range(nc):
                col = [v[c] for v in vals]
                lo, hi = min(col), max(col)
                dlo, dhi = a["min"][c], a["max"][c]
                if isf:
                    dlo, dhi = f32(dlo), f32(dhi)
                    ok = abs(lo - dlo) <= 1e-6 * max(1.0, abs(dlo)) and \
                        abs(hi - dhi) <= 1e-6 * max(1.0, abs(dhi))
                else:
                    ok = lo == dlo and hi == dhi
                if not ok:
                    raise ValueError("accessor %d component %d: data [%r, %r], "
                                     "declared [%r, %r]" % (ai, c, lo, hi,
                                                            a["min"][c], a["max"][c]))
    for mi, m in enumerate(gltf.get("meshes", [])):
        for pi, p in enumerate(m["primitives"]):
            nverts = gltf["accessors"][p["attributes"]["POSITION"]]["count"]
            for name, ai in p["attributes"].items():
                if gltf["accessors"][ai]["count"] != nverts:
                    raise ValueError("mesh %d prim %d: %s count differs" % (mi, pi, name))
            if "indices" in p:
                idx = read_accessor(gltf, bufs, p["indices"])
                if idx and max(v[0] for v in idx) >= nverts:
                    raise ValueError("mesh %d prim %d: index out of range" % (mi, pi))
    for ii, im in enumerate(gltf.get("images", [])):
        uri = im.get("uri", "")
        if uri.startswith("data:image/png;base64,"):
            check_png(base64.b64decode(uri.split(",", 1)[1], validate=True))
        elif "bufferView" in im and im.get("mimeType") == "image/png":
            bv = gltf["bufferViews"][im["bufferView"]]
            o = bv.get("byteOffset", 0)
            check_png(bufs[bv["buffer"]][o:o + bv["byteLength"]])


def main(argv):
    files = argv[1:] or sorted(
        os.path.join(HERE, f) for f in os.listdir(HERE)
        if f.endswith((".gltf", ".glb")))
    bad = 0
    for f in files:
        try:
            verify(f)
            print("ok    %s" % os.path.basename(f))
        except Exception as e:  # report every file, then fail
            bad += 1
            print("FAIL  %s: %s" % (os.path.basename(f), e))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
