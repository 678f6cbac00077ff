// The planes of kept unclipped triangles in Highway double lanes
// (raster/setup_planes.cpp), for prepareTriangles' fast path
// (raster/setup.cpp): what setupChunkFast records per kept triangle, and the
// lanes that finish its setup.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>

#include "raster/setup.h"

namespace rastray {

// A triangle that needed no clipping and passed setupEdges: its setup
// (edges, bounds, ids, corners) is written, its planes not yet.
struct UnclippedTriangle {
  uint32_t setup;      // its index in the chunk's setups
  glm::uvec3 corners;  // the stored corners, in stored order
  bool swapped;        // setupEdges' vertex order is (0, 2, 1), else (0, 1, 2)
};

// For each triangle u of the n: setups[u.setup]'s centroidDepth and planes
// (depth with its polygon offset, 1/w, d/w, b1/w, b2/w), bit for bit
// setupChunkFast's scalar steps (clipOf, imageOf, setupPlanes) on every
// target: each lane the scalar operations in the scalar order (no
// contraction; IEEE division is correctly rounded in every lane). The
// lanes leave alone the triangles whose unsnapped image area is not
// positive and finite (planePositions' snapped fallback) or with a w not
// positive: their indices into `triangles` are written to `scalar`, their
// count returned, for the scalar steps.
size_t unclippedPlanes(const Scene& scene, const ClipSpace& space, const DepthSettings& depth,
                       const UnclippedTriangle* triangles, size_t n, TriangleSetup* setups, uint32_t* scalar);

}  // namespace rastray
