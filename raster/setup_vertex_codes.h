// The per-vertex half of prepareTriangles' fast path (raster/setup.cpp):
// each vertex's clip code and snapped image position, computed once per
// vertex and shared by every triangle that uses it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>

#include "raster/clip.h"

namespace rastray {

// A vertex's snapped image position (units): |X|, |Y| <= 2^29 (snapUnits
// in raster/setup.cpp clamps).
struct SnappedVertex {
  int32_t x, y;
};

// For i < count, with clip = space.clipOf(positions[i]):
// outside[i] = outsidePlanes(space, clip) and, where that is 0,
// snapped[i] = the vertex's snapUnits(space.imageOf(clip)) at
// `unitsPerPixel` (what setupTriangle snaps it to). The scalar reference,
// one vertex at a time; snapped[i] is left unwritten where outside[i] != 0.
void vertexCodesReference(const ClipSpace& space, double unitsPerPixel, const glm::vec3* positions,
                          size_t count, uint8_t* outside, SnappedVertex* snapped);

// The same bits in Highway double lanes, a block of vertices at a time, on
// every target: the reference's operations in its order (glm's
// matrix-vector sums, the divisions, round half away from zero as
// std::round, the clamp), without contraction; snapped[i] is (0, 0) where
// outside[i] != 0.
void vertexCodes(const ClipSpace& space, double unitsPerPixel, const glm::vec3* positions, size_t count,
                 uint8_t* outside, SnappedVertex* snapped);

}  // namespace rastray
