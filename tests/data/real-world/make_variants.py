#!/usr/bin/env python3
"""Derive container variants of the real-world glTF files (Python 3 stdlib only).

The .gltf files in this directory are copied verbatim from public
repositories in their "glTF-Embedded" form (every buffer and image a base64
data URI).  This script derives, deterministically, the two other ways a
glTF file is commonly shipped, so the loader meets them too:

  external  NAME-external.gltf + NAME-external.bin (+ NAME-external-imgK.png)
            every data-URI buffer is written to a file beside the .gltf and
            its "uri" replaced by that file's name (buffer 0 -> NAME-external.bin,
            buffer K>0 -> NAME-external-K.bin); every data-URI image likewise
            becomes NAME-external-imgK.<ext>.

  glb       NAME.glb, a GLB 2.0 container (glTF 2.0 spec, section "Binary
            glTF Layout"):
              header  magic 'glTF' (0x46546C67), version 2, total length
              chunk 0 JSON, padded with spaces (0x20) to a 4-byte boundary
              chunk 1 BIN\\0, padded with zeros to a 4-byte boundary
            Buffer 0's bytes become the BIN chunk and its "uri" is removed.
            Data-URI images are moved into the BIN chunk as well, each in a
            new bufferView (4-byte aligned) referenced by the image together
            with its "mimeType" -- the way exporters lay out a .glb.
            buffer 0's byteLength grows to cover them.  Buffers other than 0
            keep their data URIs (legal in a GLB).

Usage:
  python3 make_variants.py            regenerate every committed variant
  python3 make_variants.py --check    exit 1 if a committed variant differs
                                      from what this script produces

The committed outputs are listed in VARIANTS below; rerunning the script
reproduces them byte for byte.
"""
import base64
import json
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

# (kind, source .gltf) -> outputs are named after the source
VARIANTS = [
    ("glb", "Box.gltf"),
    ("glb", "BoxTextured.gltf"),
    ("glb", "MeshPrimitiveModes.gltf"),
    ("external", "BoxTextured.gltf"),
]

GLB_MAGIC = 0x46546C67  # 'glTF'
CHUNK_JSON = 0x4E4F534A  # 'JSON'
CHUNK_BIN = 0x004E4942  # 'BIN\0'

MIME_EXT = {"image/png": "png", "image/jpeg": "jpg"}


def decode_data_uri(uri):
    """Return (mime type, bytes) of a base64 data URI."""
    if not uri.startswith("data:"):
        raise ValueError("not a data URI: %.40s" % uri)
    head, payload = uri[5:].split(",", 1)
    parts = head.split(";")
    if parts[-1] != "base64":
        raise ValueError("data URI is not base64")
    return parts[0], base64.b64decode(payload, validate=True)


def dump_json(doc):
    # Compact, key order as in the source file, plain ASCII: deterministic.
    return json.dumps(doc, separators=(",", ":"), ensure_ascii=True)


def pad4(data, fill):
    return data + fill * ((4 - len(data) % 4) % 4)


def make_external(src_name):
    base = os.path.splitext(src_name)[0] + "-external"
    doc = json.load(open(os.path.join(HERE, src_name), encoding="utf-8"))
    files = {}
    for i, buf in enumerate(doc.get("buffers", [])):
        uri = buf.get("uri", "")
        if not uri.startswith("data:"):
            continue
        _, data = decode_data_uri(uri)
        if len(data) != buf["byteLength"]:
            raise ValueError("%s buffer %d: %d bytes, byteLength %d"
                             % (src_name, i, len(data), buf["byteLength"]))
        name = base + (".bin" if i == 0 else "-%d.bin" % i)
        files[name] = data
        buf["uri"] = name
    for i, img in enumerate(doc.get("images", [])):
        uri = img.get("uri", "")
        if not uri.startswith("data:"):
            continue
        mime, data = decode_data_uri(uri)
        name = "%s-img%d.%s" % (base, i, MIME_EXT.get(mime, "bin"))
        files[name] = data
        img["uri"] = name
    files[base + ".gltf"] = (json.dumps(doc, indent=2, ensure_ascii=True) + "\n").encode("ascii")
    return files


def make_glb(src_name):
    out_name = os.path.splitext(src_name)[0] + ".glb"
    doc = json.load(open(os.path.join(HERE, src_name), encoding="utf-8"))
    buffers = doc.get("buffers", [])
    if not buffers:
        raise ValueError("%s has no buffer to pack" % src_name)
    _, bin_data = decode_data_uri(buffers[0]["uri"])
    if len(bin_data) != buffers[0]["byteLength"]:
        raise ValueError("%s buffer 0: %d bytes, byteLength %d"
                         % (src_name, len(bin_data), buffers[0]["byteLength"]))
    for img in doc.get("images", []):
        uri = img.get("uri", "")
        if not uri.startswith("data:"):
            continue
        mime, data = decode_data_uri(uri)
        bin_data = pad4(bin_data, b"\0")
        doc.setdefault("bufferViews", []).append(
            {"buffer": 0, "byteOffset": len(bin_data), "byteLength": len(data)})
        bin_data += data
        del img["uri"]
        img["bufferView"] = len(doc["bufferViews"]) - 1
        img["mimeType"] = mime
    del buffers[0]["uri"]
    buffers[0]["byteLength"] = len(bin_data)

    json_chunk = pad4(dump_json(doc).encode("ascii"), b" ")
    bin_chunk = pad4(bin_data, b"\0")
    total = 12 + 8 + len(json_chunk) + 8 + len(bin_chunk)
    out = struct.pack("<III", GLB_MAGIC, 2, total)
    out += struct.pack("<II", len(json_chunk), CHUNK_JSON) + json_chunk
    out += struct.pack("<II", len(bin_chunk), CHUNK_BIN) + bin_chunk
    assert len(out) == total
    return {out_name: out}


def build_all():
    outputs = {}
    for kind, src in VARIANTS:
        outputs.update(make_glb(src) if kind == "glb" else make_external(src))
    return outputs


def main(argv):
    check = "--check" in argv[1:]
    bad = 0
    for name, data in sorted(build_all().items()):
        path = os.path.join(HERE, name)
        if check:
            same = os.path.exists(path) and open(path, "rb").read() == data
            print("%s  %s" % ("ok  " if same else "DIFF", name))
            bad += not same
        else:
            with open(path, "wb") as f:
                f.write(data)
            print("wrote %s (%d bytes)" % (name, len(data)))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
