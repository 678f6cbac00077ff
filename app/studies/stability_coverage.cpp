#include "app/studies/stability_coverage.h"

#include <cmath>
#include <stdexcept>

#include "common/hit.h"
#include "common/sampling.h"
#include "common/surface.h"
#include "common/texture.h"

namespace rastray::stability {

std::vector<std::vector<uint32_t>> trianglesPerSample(const DeepImage& deep, int spp, uint32_t instance) {
  std::vector<std::vector<uint32_t>> out(size_t(deep.width) * size_t(deep.height) * size_t(spp));
  for (size_t pixel = 0; pixel + 1 < deep.offsets.size(); ++pixel)
    for (uint64_t k = deep.offsets[pixel]; k < deep.offsets[pixel + 1]; ++k) {
      const DeepSample& s = deep.samples[k];
      if (s.instance == instance) out[pixel * size_t(spp) + s.sample].push_back(s.triangle);
    }
  return out;
}

glm::dvec2 sampleWorld(const PixelFrame& frame, const std::vector<glm::dvec2>& pattern, size_t index) {
  const size_t spp = pattern.size(), pixel = index / spp;
  const glm::dvec2 image(double(pixel % size_t(frame.width)), double(pixel / size_t(frame.width)));
  return frame.world(image + pattern[index % spp]);
}

namespace {

// Image position (y down) in 1/16 pixels, exactly.
glm::i64vec2 sixteenths(const PixelFrame& frame, glm::dvec2 world) {
  const glm::dvec2 v = frame.image(world) * 16.0;
  if (v != glm::floor(v)) throw std::logic_error("ownsByTopLeft: a position off the 1/16 pixel grid");
  return {int64_t(v.x), int64_t(v.y)};
}

int64_t edge(glm::i64vec2 a, glm::i64vec2 b, glm::i64vec2 p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

}  // namespace

bool ownsByTopLeft(const PixelFrame& frame, const std::array<glm::dvec2, 3>& triangle, glm::dvec2 p) {
  const glm::i64vec2 v[3] = {sixteenths(frame, triangle[0]), sixteenths(frame, triangle[1]),
                             sixteenths(frame, triangle[2])};
  const glm::i64vec2 q = sixteenths(frame, p);
  for (int i = 0; i < 3; ++i) {
    const glm::i64vec2 a = v[i], b = v[(i + 1) % 3], c = v[(i + 2) % 3];
    const int64_t ec = edge(a, b, c);
    if (ec == 0) return false;  // zero area
    const int64_t ep = edge(a, b, q);
    if (ep != 0) {
      if ((ep > 0) != (ec > 0)) return false;
      continue;
    }
    // On the edge's line (and, being inside the others, on the edge).
    const bool top = a.y == b.y && c.y > a.y;                     // triangle below, y down
    const bool left = a.y != b.y && (ec > 0) != (b.y - a.y > 0);  // triangle to its right
    if (!top && !left) return false;
  }
  return true;
}

double insideDistance(const std::vector<glm::dvec2>& polygon, glm::dvec2 p) {
  double d = INFINITY;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const glm::dvec2 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
    const double len = glm::length(b - a);
    if (len == 0.0) continue;
    // Left of a → b is inside for a counter-clockwise polygon.
    d = std::min(d, ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) / len);
  }
  return d;
}

LodStats textureLod(const Scene& scene, const Camera& camera, const DeepImage& deep, int spp) {
  LodStats stats;
  const TextureSet textures(scene);
  const std::vector<glm::dvec2> pattern = samplePositions(spp);
  for (size_t pixel = 0; pixel + 1 < deep.offsets.size(); ++pixel) {
    int lastSample = -1;
    for (uint64_t k = deep.offsets[pixel]; k < deep.offsets[pixel + 1]; ++k) {
      const DeepSample& s = deep.samples[k];
      if (int(s.sample) == lastSample || s.instance == kNoId) continue;  // front layer only
      lastSample = int(s.sample);
      const int texture = scene.materialOf(s.instance).baseColorTexture;
      if (texture < 0) continue;
      const glm::dvec2 image =
          glm::dvec2(double(pixel % size_t(deep.width)), double(pixel / size_t(deep.width))) +
          pattern[s.sample];
      const Ray ray = camera.primaryRay(image);
      SampleHit hit;
      hit.instance = s.instance;
      hit.triangle = s.triangle;
      hit.depth = s.depth;
      const SurfacePoint point = makeSurfacePoint(scene, refineHit(scene, ray, hit));
      const float lod = textures.levelOfDetail(texture, pixelFootprint(scene, camera, point, image));
      ++stats.samples;
      if (!std::isfinite(lod))
        ++stats.nonFinite;
      else
        stats.maxLod = std::max(stats.maxLod, double(lod));
    }
  }
  return stats;
}

}  // namespace rastray::stability
