// Shadow rays in packets (RayOptions::shadowPackets,
// LightVisibility::transmittances): the first occlusion query of up to 16
// rays goes to Embree as one rtcOccluded16. Embree's packet and
// single-ray triangle and box tests are separate code, and hybrid shares
// this path with the ray caster (crossval's `hybrid d` must stay 0), so
// every packet lane must decide exactly what rtcOccluded1 decides. They do
// on the bundled scenes, not 1e6 units from the origin: packets are off by
// default.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "common/gltf/loader.h"
#include "raytrace/ray_caster.h"
#include "test_scenes.h"
#include "tests/test_labels.h"

namespace rastray {
namespace {

std::vector<std::string> bundledScenes() {
  std::vector<std::string> paths;
  for (const char* dir : {"", "/stiff"})
    for (const auto& entry : std::filesystem::directory_iterator(std::string(RASTRAY_SCENES) + dir))
      if (entry.path().extension() == ".gltf") paths.push_back(entry.path().string());
  std::sort(paths.begin(), paths.end());
  return paths;
}

bool sameBits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Points on every surface of the scene: on each triangle (a stride over
// them keeps it to about 3000) the centroid, near each corner and on each
// edge, where shadow rays graze neighbours and seams; and 3000 more
// spread by area (large receivers: the floor under a glass sphere).
std::vector<SurfacePoint> surfacePoints(const Scene& scene) {
  const glm::vec2 bary[] = {{1.0f / 3, 1.0f / 3}, {0.98f, 0.01f}, {0.01f, 0.98f}, {0.01f, 0.01f},
                            {0.5f, 0.5f},         {0.0f, 0.5f},   {0.5f, 0.0f}};
  std::vector<SurfacePoint> points;
  std::vector<std::pair<uint32_t, uint32_t>> triangles;  // (instance, triangle within it)
  std::vector<double> area;                              // running sum
  const size_t stride = std::max<size_t>(1, scene.triangleCount() * 7 / 3000);
  for (uint32_t i = 0; i < scene.instances.size(); ++i)
    for (uint32_t t = 0; t < scene.instances[i].triangleCount; ++t) {
      if (t % stride == 0)
        for (const glm::vec2& b : bary)
          points.push_back(makeSurfacePoint(scene, SampleHit{i, t, 0.0f, b.x, b.y}));
      const SurfacePoint c = makeSurfacePoint(scene, SampleHit{i, t, 0.0f, 0.0f, 0.0f});
      const SurfacePoint u = makeSurfacePoint(scene, SampleHit{i, t, 0.0f, 1.0f, 0.0f});
      const SurfacePoint v = makeSurfacePoint(scene, SampleHit{i, t, 0.0f, 0.0f, 1.0f});
      triangles.push_back({i, t});
      area.push_back((area.empty() ? 0.0 : area.back()) +
                     glm::length(glm::cross(u.position - c.position, v.position - c.position)));
    }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int k = 0; k < 3000 && !area.empty() && area.back() > 0.0; ++k) {
    const size_t j =
        size_t(std::lower_bound(area.begin(), area.end(), uniform(rng) * area.back()) - area.begin());
    const double r = std::sqrt(uniform(rng)), q = uniform(rng);  // uniform over the triangle
    const auto& [i, t] = triangles[std::min(j, triangles.size() - 1)];
    points.push_back(makeSurfacePoint(scene, SampleHit{i, t, 0.0f, float(r * (1.0 - q)), float(r * q)}));
  }
  return points;
}

struct Tally {
  size_t rays = 0, blocked = 0, lit = 0, partial = 0;
};

// Each light's shadow rays from `points`: alone, in one batch (packets of
// 16 in order) and in a shuffled batch (other packet mates).
void expectPacketsAgree(const std::string& name, const Scene& scene, const std::vector<SurfacePoint>& points,
                        Tally* tally) {
  RayCaster caster(scene, analyzeScene(scene));
  RayOptions options;
  options.shadowPackets = true;  // off by default (RayOptions::shadowPackets says why)
  caster.bind(makeCamera(scene, {}, 16, 16), options);
  std::mt19937 rng(7);
  for (size_t l = 0; l < scene.lights.size(); ++l) {
    const Light& light = scene.lights[l];
    const size_t n = points.size();
    std::vector<const SurfacePoint*> ptrs(n);
    std::vector<glm::dvec3> toLight(n);
    std::vector<double> distance(n);
    for (size_t k = 0; k < n; ++k) {
      ptrs[k] = &points[k];
      if (light.type == LightType::Directional) {
        toLight[k] = -light.direction;
        distance[k] = std::numeric_limits<double>::infinity();
      } else {
        const glm::dvec3 v = light.position - points[k].position;
        distance[k] = glm::length(v);
        toLight[k] = v / distance[k];
      }
    }
    std::vector<glm::vec3> single(n), batch(n), shuffled(n);
    for (size_t k = 0; k < n; ++k)
      single[k] = caster.transmittance(points[k], int(l), toLight[k], distance[k]);
    caster.transmittances(int(l), n, ptrs.data(), toLight.data(), distance.data(), batch.data());
    std::vector<size_t> order(n);
    std::iota(order.begin(), order.end(), size_t(0));
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<const SurfacePoint*> p2(n);
    std::vector<glm::dvec3> t2(n);
    std::vector<double> d2(n);
    for (size_t k = 0; k < n; ++k) {
      p2[k] = ptrs[order[k]];
      t2[k] = toLight[order[k]];
      d2[k] = distance[order[k]];
    }
    std::vector<glm::vec3> out2(n);
    caster.transmittances(int(l), n, p2.data(), t2.data(), d2.data(), out2.data());
    for (size_t k = 0; k < n; ++k) shuffled[order[k]] = out2[k];
    caster.throwIfError();
    for (size_t k = 0; k < n; ++k) {
      ASSERT_TRUE(sameBits(batch[k], single[k]))
          << name << " light " << l << " point " << k << ": packet (" << batch[k].r << ", " << batch[k].g
          << ", " << batch[k].b << ") single (" << single[k].r << ", " << single[k].g << ", " << single[k].b
          << ")";
      ASSERT_TRUE(sameBits(shuffled[k], single[k]))
          << name << " light " << l << " point " << k << ", shuffled";
      ++tally->rays;
      if (single[k] == glm::vec3(0.0f))
        ++tally->blocked;
      else if (single[k] == glm::vec3(1.0f))
        ++tally->lit;
      else
        ++tally->partial;
    }
  }
}

RASTRAY_TEST_LABELS_OF(ShadowPackets, PacketAndSingleRaysDecideEveryShadowRayOfTheBundledScenesAlike, "slow");
TEST(ShadowPackets, PacketAndSingleRaysDecideEveryShadowRayOfTheBundledScenesAlike) {
  Tally tally;
  size_t scenes = 0;
  for (const std::string& path : bundledScenes()) {
    const Scene scene = loadScene(path);
    if (scene.lights.empty()) continue;
    ++scenes;
    expectPacketsAgree(path, scene, surfacePoints(scene), &tally);
  }
  // Not vacuous: lit scenes, and rays blocked, unoccluded and through glass.
  EXPECT_GE(scenes, 5u);
  EXPECT_GT(tally.blocked, 1000u);
  EXPECT_GT(tally.lit, 1000u);
  EXPECT_GT(tally.partial, 100u);
  std::printf("%zu scenes, %zu rays: %zu blocked, %zu unoccluded, %zu through transmissive surfaces\n",
              scenes, tally.rays, tally.blocked, tally.lit, tally.partial);
}

// The ray-cast and hybrid images of every lit bundled scene with shadow
// packets are the single rays' images, bit for bit, with the same ray
// counts.
RASTRAY_TEST_LABELS_OF(ShadowPackets, RayCastFramesWithShadowPacketsAreTheSingleRaysFrames, "slow");
TEST(ShadowPackets, RayCastFramesWithShadowPacketsAreTheSingleRaysFrames) {
  size_t scenes = 0;
  for (const std::string& path : bundledScenes()) {
    const Scene scene = loadScene(path);
    if (scene.lights.empty()) continue;
    ++scenes;
    const Camera camera = makeCamera(scene, {}, 48, 36);
    RayOptions options;
    options.spp = 2;
    options.shadowPackets = true;
    RayCaster caster(scene, analyzeScene(scene));
    caster.bind(camera, options);
    const RenderOutput packets = caster.render();
    options.shadowPackets = false;
    caster.bind(camera, options);
    const RenderOutput single = caster.render();
    ASSERT_EQ(packets.image.color.size(), single.image.color.size()) << path;
    EXPECT_EQ(std::memcmp(packets.image.color.data(), single.image.color.data(),
                          packets.image.color.size() * sizeof(packets.image.color[0])),
              0)
        << path;
    EXPECT_EQ(packets.counters.get("rays.shadow"), single.counters.get("rays.shadow")) << path;
  }
  EXPECT_GE(scenes, 5u);
}

}  // namespace
}  // namespace rastray
