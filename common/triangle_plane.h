// The canonical plane data of a stored triangle that
// intersectTrianglePlane (common/surface.h) intersects rays with, for the
// shading kernel's batched refinement (common/primary_refinement.h) and
// raster setup's refinement planes (raster/setup.h), which must give
// intersectTrianglePlane's bits; and the face normal without its memo.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "common/scene.h"

namespace rastray {

struct TrianglePlane {
  glm::dvec3 a, e1, e2;  // first canonical (lexicographic) corner, edges to the other two
  int slot1, slot2;      // canonical rank of stored corners 1 and 2
};

// The values intersectTrianglePlane uses for (instance, triangle), bit for
// bit (the same per-thread memo).
TrianglePlane trianglePlane(const Scene& scene, uint32_t instance, uint32_t triangle);

// The unit face normal of a stored triangle from its corners p_i =
// dvec3(scene.positions[corner i]) (CCW front; (0, 0, 1) when degenerate):
// triangleFaceNormal's bits (common/surface.h), without its memo. For
// callers that hold the corners already (raster setup stores it per setup
// for the shading kernel).
glm::dvec3 faceNormalOfCorners(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2);

}  // namespace rastray
