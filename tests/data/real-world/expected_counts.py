#!/usr/bin/env python3
"""Expected scene-flattening counts for the real-world glTF files.

An independent implementation of SPEC §1 and §2 (Python 3 stdlib only),
written from the SPEC text, not from rastray's loader.  It writes
expected.json beside itself:

  {"FILE": {"instances": N, "triangles": N, "cameras": N, "lights": N,
            "nodes": N, "materials": N, ...more keys, see below...}}

Walk (SPEC §1): the scene is doc["scene"], or 0 when unset; when the file
has no "scenes", the roots are all nodes that are nobody's child, in index
order.  Depth-first: the scene's nodes in order, then each node's
"children" in order.

Keys:
  instances          (node with a mesh, primitive of mode 4/5/6) pairs met in
                     the walk; mode defaults to 4; modes 0-3 get none
  triangles          sum over instances: TRIANGLES n // 3, TRIANGLE_STRIP
                     max(n - 2, 0), TRIANGLE_FAN max(n - 2, 0), where n is the
                     index count, or the POSITION count when non-indexed
  skippedPrimitives  points/lines primitives met in the walk (per node visit)
  cameras            camera definitions in the file (len(doc["cameras"]))
  cameraNodes        visited nodes that carry a camera
  firstCameraNode    the node of the camera SPEC §2 uses (first camera node in
                     the walk), or null: no camera, SPEC §2 default camera
  firstCameraIndex   that node's camera index, or null
  firstCameraType    "perspective" / "orthographic", or null
  lights             visited nodes carrying a KHR_lights_punctual light
                     (light instances placed in the world)
  lightDefinitions   lights in the file's KHR_lights_punctual extension
  nodes              nodes in the file
  visitedNodes       nodes reached by the walk (counted per visit)
  meshes             meshes in the file
  materials          materials in the file
  defaultMaterialUsed  true when some instance's primitive has no "material"
                     (a renderer then needs one extra default material)
  sceneIndex         the scene walked, or -1 when the file has no scenes
  instanceList       per instance, in instance order: node, mesh, primitive,
                     mode, triangles
  ignored            what the file uses and rastray does not render (README,
                     "The scene model"), as {feature: count}: each
                     extension not in SUPPORTED by the objects that hold
                     it; {} when none. Normal, occlusion and
                     metallic-roughness textures are rendered
                     (docs/MATERIALS.md), not ignored.
                     Animations, skins and morph targets are played
                     (docs/ANIMATION.md), not ignored.

Usage:
  python3 expected_counts.py          write expected.json
  python3 expected_counts.py --check  exit 1 if expected.json is out of date
"""
import json
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "expected.json")

TRIANGLES, STRIP, FAN = 4, 5, 6
SUPPORTED = {"KHR_lights_punctual", "KHR_materials_transmission", "KHR_materials_ior",
             "KHR_materials_emissive_strength", "KHR_mesh_quantization"}


def ignored(doc):
    out = {}

    def note(feature, n=1):
        if n:
            out[feature] = out.get(feature, 0) + n

    def extensions(value):
        if isinstance(value, list):
            for v in value:
                extensions(v)
        elif isinstance(value, dict):
            for name in value.get("extensions", {}) if isinstance(value.get("extensions"), dict) else {}:
                note(name, name not in SUPPORTED)
            for key, v in value.items():
                if key != "extras":
                    extensions(v)

    extensions(doc)
    return out


def load_json(path):
    raw = open(path, "rb").read()
    if raw[:4] == b"glTF":
        # GLB: 12-byte header, then the JSON chunk first.
        json_len, json_type = struct.unpack_from("<II", raw, 12)
        if json_type != 0x4E4F534A:
            raise ValueError("%s: first GLB chunk is not JSON" % path)
        return json.loads(raw[20:20 + json_len].decode("utf-8"))
    return json.loads(raw.decode("utf-8"))


def roots_of(doc):
    """(scene index or -1, root node list) per SPEC §1."""
    nodes = doc.get("nodes", [])
    scenes = doc.get("scenes")
    if not scenes:
        children = set()
        for n in nodes:
            children.update(n.get("children", []))
        return -1, [i for i in range(len(nodes)) if i not in children]
    index = doc.get("scene", 0)
    return index, list(scenes[index].get("nodes", []))


def walk(doc, roots):
    """Yield node indices depth-first, children in order."""
    nodes = doc.get("nodes", [])
    stack = list(reversed(roots))
    while stack:
        i = stack.pop()
        yield i
        stack.extend(reversed(nodes[i].get("children", [])))


def primitive_triangles(doc, prim):
    mode = prim.get("mode", TRIANGLES)
    if "indices" in prim:
        n = doc["accessors"][prim["indices"]]["count"]
    else:
        n = doc["accessors"][prim["attributes"]["POSITION"]]["count"]
    if mode == TRIANGLES:
        return n // 3
    return max(n - 2, 0)  # strip and fan alike


def counts(doc):
    nodes = doc.get("nodes", [])
    meshes = doc.get("meshes", [])
    scene_index, roots = roots_of(doc)
    r = {
        "instances": 0, "triangles": 0, "cameras": len(doc.get("cameras", [])),
        "lights": 0, "nodes": len(nodes), "materials": len(doc.get("materials", [])),
        "skippedPrimitives": 0, "cameraNodes": 0, "firstCameraNode": None,
        "firstCameraIndex": None, "firstCameraType": None,
        "lightDefinitions": len(doc.get("extensions", {})
                                .get("KHR_lights_punctual", {}).get("lights", [])),
        "visitedNodes": 0, "meshes": len(meshes), "defaultMaterialUsed": False,
        "sceneIndex": scene_index, "instanceList": [], "ignored": ignored(doc),
    }
    for ni in walk(doc, roots):
        node = nodes[ni]
        r["visitedNodes"] += 1
        if "mesh" in node:
            for pi, prim in enumerate(meshes[node["mesh"]]["primitives"]):
                mode = prim.get("mode", TRIANGLES)
                if mode not in (TRIANGLES, STRIP, FAN):
                    r["skippedPrimitives"] += 1
                    continue
                t = primitive_triangles(doc, prim)
                r["instanceList"].append({"node": ni, "mesh": node["mesh"], "primitive": pi,
                                          "mode": mode, "triangles": t})
                r["instances"] += 1
                r["triangles"] += t
                if "material" not in prim:
                    r["defaultMaterialUsed"] = True
        if "camera" in node:
            r["cameraNodes"] += 1
            if r["firstCameraNode"] is None:
                r["firstCameraNode"] = ni
                r["firstCameraIndex"] = node["camera"]
                r["firstCameraType"] = doc["cameras"][node["camera"]]["type"]
        if "KHR_lights_punctual" in node.get("extensions", {}):
            r["lights"] += 1
    return r


def build():
    files = sorted(f for f in os.listdir(HERE) if f.endswith((".gltf", ".glb")))
    return {f: counts(load_json(os.path.join(HERE, f))) for f in files}


def render(result):
    return json.dumps(result, indent=2, sort_keys=False) + "\n"


def main(argv):
    text = render(build())
    if "--check" in argv[1:]:
        same = os.path.exists(OUT) and open(OUT, encoding="utf-8").read() == text
        print("expected.json is up to date" if same else "expected.json is OUT OF DATE")
        return 0 if same else 1
    with open(OUT, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)
    for name, c in build().items():
        print("%-32s inst %4d  tris %6d  cams %d (first node %s)  nodes %3d  mats %d"
              % (name, c["instances"], c["triangles"], c["cameras"], c["firstCameraNode"],
                 c["nodes"], c["materials"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
