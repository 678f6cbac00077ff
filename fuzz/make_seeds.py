#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets (fuzz/corpus/<target>/).

gltf_loader_fuzzer: the small self-contained glTF files of scenes/ and
tests/data (valid, real-world and malformed: the malformed ones start the
fuzzer next to every refusal the loader has), and GLB versions of the
single-buffer data-URI files (the BIN chunk instead of base64), so both
containers are seeded, and Draco and meshopt twins of two of them (the
draco and gltfpack packages' encoders). A fuzzer input is one file:
external buffers are never found, so files that need them are left out.

exr_reader_fuzzer: tiny renders by `rastray render` (flat half and float
colour, deep) and oiiotool variants of them that other renderers write:
other compressions, tiles, a cropped data window, Z and IDs only, IDs as
normalized float (refused), a partial colour set.

Usage: fuzz/make_seeds.py RASTRAY_BINARY   (run from anywhere; rewrites
both folders). Needs oiiotool (openimageio-tools).
"""
import base64
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.path.join(ROOT, "fuzz", "corpus")
# Seeds above this size slow every mutation down and are left out.
MAX_GLTF_SEED = 30 * 1024
# scenes/stiff holds series of one scene at several scales or ratios; these
# cover its kinds once each.
STIFF = {"clip-near-w0.gltf", "degenerate.gltf", "far-node-1e7.gltf", "glass-trapped-tir.gltf",
         "grazing-textured-89.9.gltf", "layers-alpha-1e-6.gltf"}


def self_contained(doc):
    for key in ("buffers", "images"):
        for entry in doc.get(key, []) if isinstance(doc, dict) and isinstance(doc.get(key), list) else []:
            uri = entry.get("uri") if isinstance(entry, dict) else None
            if isinstance(uri, str) and not uri.startswith("data:"):
                return False
    return True


def to_glb(doc):
    """The GLB of a document whose one buffer is a base64 data URI, or None."""
    buffers = doc.get("buffers")
    if not isinstance(buffers, list) or len(buffers) != 1:
        return None
    uri = buffers[0].get("uri", "")
    if not uri.startswith("data:") or ";base64," not in uri:
        return None
    data = base64.b64decode(uri.split(";base64,", 1)[1])
    doc = json.loads(json.dumps(doc))
    del doc["buffers"][0]["uri"]
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    data += b"\0" * (-len(data) % 4)
    length = 12 + 8 + len(text) + 8 + len(data)
    return (struct.pack("<III", 0x46546C67, 2, length) + struct.pack("<II", len(text), 0x4E4F534A) + text +
            struct.pack("<II", len(data), 0x004E4942) + data)


def gltf_seeds():
    out = os.path.join(CORPUS, "gltf_loader_fuzzer")
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    sources = [("scenes", ""), (os.path.join("scenes", "stiff"), "stiff-"),
               (os.path.join("tests", "data", "real-world"), "real-"),
               (os.path.join("tests", "data", "malformed"), "malformed-"),
               (os.path.join("tests", "data", "malformed", "valid"), "valid-")]
    for folder, prefix in sources:
        for name in sorted(os.listdir(os.path.join(ROOT, folder))):
            path = os.path.join(ROOT, folder, name)
            if not name.endswith((".gltf", ".glb")) or os.path.getsize(path) > MAX_GLTF_SEED:
                continue
            raw = open(path, "rb").read()
            doc = None
            if name.endswith(".gltf"):
                try:
                    doc = json.loads(raw)
                except ValueError:
                    pass  # malformed on purpose: a seed as it is
                if isinstance(doc, dict) and not self_contained(doc):
                    continue
            if prefix == "stiff-" and name not in STIFF:
                continue
            shutil.copyfile(path, os.path.join(out, prefix + name))
            # GLB twins of the bundled scenes and the real-world models.
            glb = to_glb(doc) if isinstance(doc, dict) and prefix in ("", "real-") else None
            if glb:
                with open(os.path.join(out, prefix + name[:-5] + ".glb"), "wb") as f:
                    f.write(glb)
    compressed_seeds(out)


def compressed_seeds(out):
    """Compressed twins of two small GLBs: KHR_draco_mesh_compression
    (draco_transcoder), EXT_meshopt_compression over KHR_mesh_quantization
    (gltfpack -c) and with the OCTAHEDRAL filter (gltfpack -cc), so the
    fuzzer starts inside both decoders. Needs the draco and gltfpack
    packages (scripts/setup.sh)."""
    inputs = [os.path.join(ROOT, "tests", "data", "real-world", "Box.glb"), os.path.join(out, "cornell-box.glb")]
    with tempfile.TemporaryDirectory() as tmp:
        for path in inputs:
            stem = os.path.basename(path)[:-4]
            for prefix, command in (("draco-", ["draco_transcoder"]), ("meshopt-", ["gltfpack", "-c"]),
                                    ("meshopt-cc-", ["gltfpack", "-cc"])):
                target = os.path.join(tmp, prefix + stem + ".glb")
                subprocess.run(command + ["-i", path, "-o", target], check=True, stdout=subprocess.DEVNULL)
                if os.path.getsize(target) <= MAX_GLTF_SEED:
                    shutil.copyfile(target, os.path.join(out, prefix + stem + ".glb"))


def exr_seeds(rastray):
    out = os.path.join(CORPUS, "exr_reader_fuzzer")
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    run = lambda *args: subprocess.run(args, check=True, capture_output=True)
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(ROOT, "scenes", "transparent-layers.gltf")
        renders = {
            "flat-half.exr": [],
            "flat-float.exr": ["--float"],
            "deep.exr": ["--deep"],
            "deep-spp4.exr": ["--deep", "--spp", "4", "--renderer", "raytrace"],
        }
        for name, extra in renders.items():
            run(rastray, "render", scene, "--size", "6", "4", "--threads", "1", "-o", os.path.join(out, name),
                *extra)
        textured = os.path.join(out, "textured.exr")
        run(rastray, "render", os.path.join(ROOT, "scenes", "textured-plane.gltf"), "--size", "5", "3",
            "--threads", "1", "-o", textured)
        flat = os.path.join(out, "flat-half.exr")
        # oiiotool reads every channel as float and would write the uint
        # IDs as normalized floats: keep rastray's formats unless told.
        formats = ["-d", "half", "-d", "Z=float", "-d", "id.instance=uint32", "-d", "id.triangle=uint32"]
        oiio = lambda name, *args: run("oiiotool", "--nosoftwareattrib", *args, *(formats if "-d" not in args and "deep" not in name else []),
                                       "-o", os.path.join(out, name))
        for compression in ("none", "rle", "piz", "pxr24", "b44", "dwaa"):
            oiio("compression-" + compression + ".exr", flat, "--compression", compression)
        oiio("tiled.exr", flat, "--tile", "4", "4")
        oiio("data-window-cropped.exr", flat, "--crop", "4x2+1+1")
        oiio("z-and-ids-only.exr", flat, "--ch", "Z,id.instance,id.triangle")
        # OIIO normalizes uint to float (1 reads as 2^-32): a file compare refuses.
        oiio("ids-normalized-float.exr", flat, "-d", "float")
        oiio("colour-partial.exr", flat, "--ch", "R,B,Z")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    gltf_seeds()
    exr_seeds(os.path.abspath(sys.argv[1]))
    for target in sorted(os.listdir(CORPUS)):
        folder = os.path.join(CORPUS, target)
        files = os.listdir(folder)
        size = sum(os.path.getsize(os.path.join(folder, f)) for f in files)
        print(f"{target}: {len(files)} seeds, {size} bytes")
