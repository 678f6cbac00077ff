// Seeded random scenes for the cross-validation property test: random
// triangles, interpenetrating boxes, shared-edge fans and grids, duplicated
// faces, coplanar pairs; opaque, BLEND, MASK and glass materials; random
// cameras, including cameras inside geometry and near planes that cut
// triangles. The same seed gives the same file on every machine (own
// generator, no <random> distributions, whose results are unspecified).
#pragma once

#include <cstdint>

#include "common/gltf/writer.h"

namespace rastray::test {

// splitmix64: tiny, fast and identical everywhere.
class SceneRandom {
 public:
  explicit SceneRandom(uint64_t seed) : state_(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull) {}
  uint64_t next();
  double uniform(double lo = 0.0, double hi = 1.0);  // [lo, hi)
  int below(int n);                                  // [0, n)
  bool chance(double p) { return uniform() < p; }
  glm::vec3 point(double extent);  // uniform in the cube [-extent, extent]^3
  glm::dvec3 direction();          // uniform on the unit sphere

 private:
  uint64_t state_;
};

// What a generated scene holds, for messages.
struct RandomSceneSummary {
  int objects = 0, triangles = 0, blend = 0, mask = 0, glass = 0, lights = 0;
  bool cameraInside = false;
};

GltfScene randomScene(uint64_t seed, RandomSceneSummary* summary = nullptr);

}  // namespace rastray::test
