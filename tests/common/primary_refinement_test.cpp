// refinePrimaryHits (common/primary_refinement.h): the batch in double
// SIMD lanes gives refinePrimaryHit's bits for every hit, on every
// compiled target, whatever the batch: planes ahead, behind, parallel to
// the ray, degenerate triangles, far from the origin, grazing rays.
#include "common/primary_refinement.h"

#include <gtest/gtest.h>

#include <hwy/targets.h>

#include <cstring>
#include <random>
#include <vector>

namespace rastray {
namespace {

// Random triangles: small ones near the origin and far from it (1e6),
// slivers, and degenerate ones (repeated corners), each its own instance.
Scene randomScene(std::mt19937& rng) {
  Scene s;
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  Instance inst;
  inst.triangleCount = 0;
  for (uint32_t i = 0; i < 60; ++i) {
    const float offset = i % 3 == 0 ? 1e6f : i % 3 == 1 ? 0.0f : 3e3f;
    const glm::vec3 c(offset + unit(rng), unit(rng), unit(rng) - 4.0f);
    glm::vec3 p0 = c + glm::vec3(unit(rng), unit(rng), unit(rng));
    glm::vec3 p1 = c + glm::vec3(unit(rng), unit(rng), unit(rng));
    glm::vec3 p2 =
        i % 7 == 0 ? p0 : c + glm::vec3(unit(rng), unit(rng), unit(rng)) * (i % 5 == 0 ? 1e-6f : 1.0f);
    const uint32_t first = uint32_t(s.positions.size());
    for (const glm::vec3& p : {p0, p1, p2}) {
      s.positions.push_back(p);
      s.normals.push_back(glm::vec3(0.0f));
      s.texcoords.push_back(glm::vec2(0.0f));
    }
    s.triangles.push_back({first, first + 1, first + 2});
  }
  inst.vertexCount = uint32_t(s.positions.size());
  inst.triangleCount = uint32_t(s.triangles.size());
  s.instances.push_back(inst);
  s.materials.push_back(Material{});
  return s;
}

bool sameBits(const ShadeHit& a, const ShadeHit& b) {
  return a.instance == b.instance && a.triangle == b.triangle && std::memcmp(&a.b1, &b.b1, 4) == 0 &&
         std::memcmp(&a.b2, &b.b2, 4) == 0 && a.direction == b.direction &&
         a.footprintPosition == b.footprintPosition && a.throughput == b.throughput;
}

TEST(PrimaryRefinement, BatchInDoubleLanesGivesRefinePrimaryHitsBits) {
  std::mt19937 rng(20);
  const Scene scene = randomScene(rng);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<uint32_t> pick(0, uint32_t(scene.triangles.size() - 1));
  std::vector<Ray> rays;
  std::vector<SampleHit> hits;
  std::vector<glm::dvec2> footprints;
  for (int k = 0; k < 3000; ++k) {
    // Runs of hits on one triangle (as tiles give them), and changes.
    const uint32_t triangle = k % 11 == 0 || hits.empty() ? pick(rng) : hits.back().triangle;
    const glm::uvec3 v = scene.triangles[triangle];
    const glm::dvec3 centre = (glm::dvec3(scene.positions[v.x]) + glm::dvec3(scene.positions[v.y]) +
                               glm::dvec3(scene.positions[v.z])) /
                              3.0;
    Ray ray;
    // A shared origin for most (a perspective camera), others scattered;
    // some rays point away from the plane, some lie nearly in it.
    ray.origin = k % 4 == 0 ? centre + glm::dvec3(unit(rng), unit(rng), 5.0) : glm::dvec3(centre.x, 0.0, 1.0);
    glm::dvec3 dir = centre + 0.3 * glm::dvec3(unit(rng), unit(rng), unit(rng)) - ray.origin;
    if (k % 13 == 0) dir = -dir;
    if (k % 17 == 0) dir = glm::dvec3(scene.positions[v.y]) - glm::dvec3(scene.positions[v.x]);
    ray.direction = glm::normalize(dir);
    ray.depthPerT = k % 19 == 0 ? 1e308 : 0.5 + 0.5 * unit(rng) * unit(rng);
    SampleHit hit{0, triangle, 1.0f, 0.25f, 0.5f};
    rays.push_back(ray);
    hits.push_back(hit);
    footprints.push_back(glm::dvec2(k % 640, k / 640));
  }
  std::vector<ShadeHit> expected(hits.size());
  for (size_t i = 0; i < hits.size(); ++i)
    expected[i] = refinePrimaryHit(scene, rays[i], hits[i], footprints[i]);
  size_t refined = 0, kept = 0;
  for (size_t i = 0; i < hits.size(); ++i)
    (expected[i].b1 == hits[i].b1 && expected[i].b2 == hits[i].b2 ? kept : refined)++;
  EXPECT_GT(refined, 1000u);
  EXPECT_GT(kept, 50u);  // behind, parallel, degenerate: the hit is kept
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    SCOPED_TRACE(hwy::TargetName(target));
    hwy::SetSupportedTargetsForTest(target);
    for (size_t batch : {size_t(1), size_t(5), size_t(64), hits.size()}) {
      std::vector<ShadeHit> out(hits.size());
      for (size_t first = 0; first < hits.size(); first += batch)
        refinePrimaryHits(scene, &rays[first], &hits[first], &footprints[first],
                          std::min(batch, hits.size() - first), &out[first]);
      for (size_t i = 0; i < hits.size(); ++i)
        ASSERT_TRUE(sameBits(out[i], expected[i])) << batch << " " << i;
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

}  // namespace
}  // namespace rastray
