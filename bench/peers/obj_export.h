// The flattened scene as a Wavefront OBJ for Embree's viewer: the rebased
// float positions exactly as rastray stores them (printed with 9
// significant digits, which round-trips a float), one group per instance,
// triangles only, no normals or materials (the viewer's eye light shades
// with the geometric normal).
#pragma once

#include <string>

#include "common/scene.h"

namespace rastray::peers {

// Writes `scene` to `path` atomically (a temporary name beside it, then a
// rename). Throws InputError(path, "", message) when it cannot.
void writeObj(const Scene& scene, const std::string& path);

// The cache file for `scenePath` rebased on `origin`, in `workDir`:
// "<stem>-<16 hex digits>.obj", the digits a hash of the scene's canonical
// path, size, modification time and the origin's bits. A changed scene or
// another origin gets another name, so a cached file is never stale.
std::string cachedObjPath(const std::string& scenePath, const glm::dvec3& origin, const std::string& workDir);

}  // namespace rastray::peers
