// Coverage checks of the stability study's geometry cases: which triangles
// of an instance cover each sample in a deep render (every BLEND layer is
// its own entry), the exact top-left owner of a sample in integers, and
// the texture level of detail each shaded sample used.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "app/studies/stability_geometry_scenes.h"
#include "common/camera.h"
#include "common/image.h"
#include "common/scene.h"

namespace rastray::stability {

// For every (pixel, sample index), row-major pixels then samples: the
// triangles of `instance` among the sample's layers, front to back.
std::vector<std::vector<uint32_t>> trianglesPerSample(const DeepImage& deep, int spp, uint32_t instance);

// The world position of sample `sample` of pixel `index` in a PixelFrame.
glm::dvec2 sampleWorld(const PixelFrame& frame, const std::vector<glm::dvec2>& pattern, size_t index);

// The triangles (corners in PixelFrame world units, multiples of 1/16)
// that own `p` (a multiple of 1/16) by the SPEC §3 fill rule, evaluated
// exactly in 64-bit integers: inside every edge, or on an edge that is a
// top edge (horizontal, the triangle below it in the image) or a left edge
// (not horizontal, the triangle to its right). Independent of the winding.
// Zero-area triangles own nothing.
bool ownsByTopLeft(const PixelFrame& frame, const std::array<glm::dvec2, 3>& triangle, glm::dvec2 p);

// Signed distance of p inside a convex polygon (counter-clockwise): the
// smallest distance to the lines of its edges, negative outside.
double insideDistance(const std::vector<glm::dvec2>& polygon, glm::dvec2 p);

// The texture level of detail (lambda, TextureSet::levelOfDetail) of every
// sample of a deep render whose front layer has a base colour texture,
// recomputed as the renderers compute it: the hit refined on its plane
// along the sample's camera ray, the footprint from the neighbouring pixel
// rays (pixelFootprint).
struct LodStats {
  uint64_t samples = 0;    // textured front layers
  uint64_t nonFinite = 0;  // lambda NaN or infinite
  double maxLod = -INFINITY;
};
LodStats textureLod(const Scene& scene, const Camera& camera, const DeepImage& deep, int spp);

}  // namespace rastray::stability
