// Shadow rays in packets (RayOptions::shadowPackets, on by default;
// LightVisibility::transmittances): the first occlusion query of up to 14
// rays goes to Embree as one rtcOccluded16, and a single ray as a packet
// of one. Hybrid shares this path with the ray caster but batches lit
// lanes differently (crossval's `hybrid d` must stay 0), so a lane's
// answer must not depend on its packet mates or its lane, and a batch must
// decide every ray as one by one does.
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
// 14 in order) and in a shuffled batch (other packet mates).
void expectPacketsAgree(const std::string& name, const Scene& scene, const std::vector<SurfacePoint>& points,
                        Tally* tally) {
  RayCaster caster(scene, analyzeScene(scene));
  RayOptions options;
  options.shadowPackets = true;
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
    options.spp = 2;  // shadowPackets: on by default
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

// FarFromOriginOffsets' contact scene, where packet and single-ray
// occlusion were found to disagree: a floor sloped 1:5, 1e6 units from the
// origin in x and z, and a 2×1×2 box floating 0.01 above it (a prism
// sheared along the slope), lit from (−0.6, 1, −0.4). The points: a grid
// on the floor around and under the box, where shadow rays pass through
// the gap.
struct ContactScene {
  Scene scene;
  std::vector<SurfacePoint> points;
};

ContactScene contactSceneAt1e6() {
  constexpr double kFar = 1e6, kSlope = 0.2, kGap = 0.01;
  const auto floorY = [&](double z) { return kSlope * (z - kFar); };
  test::SceneBuilder b;
  const uint32_t grey = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)));
  std::vector<glm::vec3> floor;
  for (const glm::dvec2 c :
       {glm::dvec2(-10, 10), glm::dvec2(10, 10), glm::dvec2(10, -10), glm::dvec2(-10, -10)})
    floor.emplace_back(glm::dvec3(kFar + c.x, floorY(kFar + c.y), kFar + c.y));
  const uint32_t floorInstance =
      b.addMesh(floor, {{0, 1, 2}, {0, 2, 3}}, grey);  // counter-clockwise from above
  std::vector<glm::vec3> box;                          // corner i: x = bit 0, y = bit 1, z = bit 2
  for (int i = 0; i < 8; ++i) {
    const double x = kFar + (i & 1 ? 1.0 : -1.0), z = kFar + (i & 4 ? 1.0 : -1.0);
    box.emplace_back(glm::dvec3(x, floorY(z) + kGap + (i & 2 ? 1.0 : 0.0), z));
  }
  const uint32_t boxInstance = b.addMesh(box,
                                         {{0, 2, 3},
                                          {0, 3, 1},
                                          {4, 5, 7},
                                          {4, 7, 6},
                                          {0, 1, 5},
                                          {0, 5, 4},
                                          {2, 6, 7},
                                          {2, 7, 3},
                                          {0, 4, 6},
                                          {0, 6, 2},
                                          {1, 3, 7},
                                          {1, 7, 5}},
                                         grey);
  b.addDirectionalLight(glm::dvec3(0.6, -1.0, 0.4), 3.0f);
  ContactScene cs{b.scene(), {}};
  cs.scene.path = "contact scene at 1e6";
  // Floor point (u, v): f0 + u·(f1 − f0) + v·(f3 − f0); triangle (0, 1, 2)
  // holds u ≥ v with barycentrics (u − v, v), triangle (0, 2, 3) the rest
  // with (u, v − u).
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const float u = 0.42f + 0.16f * float(i) / 39.0f, v = 0.42f + 0.16f * float(j) / 39.0f;
      const bool first = u >= v;
      const SampleHit h =
          first ? SampleHit{floorInstance, 0, 0.0f, u - v, v} : SampleHit{floorInstance, 1, 0.0f, u, v - u};
      cs.points.push_back(makeSurfacePoint(cs.scene, h));
    }
  // And on every face of the box, edges included (rays from its top edges
  // start in the planes of its sides).
  for (uint32_t t = 0; t < 12; ++t)
    for (int i = 0; i <= 10; ++i)
      for (int j = 0; i + j <= 10; ++j)
        cs.points.push_back(makeSurfacePoint(cs.scene, SampleHit{boxInstance, t, 0.0f, 0.1f * i, 0.1f * j}));
  return cs;
}

// Shadow rays that graze, 16 neighbouring points at a time sharing one
// direction (a coherent packet): a random tangent of the first point's
// surface tilted towards its normal's side by 1e-6 … 0.3 rad (or away from
// it, into neighbours), to infinity or a random distance; and for a
// directional light, each point towards it.
struct ShadowRays {
  std::vector<const SurfacePoint*> points;
  std::vector<glm::dvec3> toLight;
  std::vector<double> distance;
};

ShadowRays grazingRays(const Scene& scene, const std::vector<SurfacePoint>& points, std::mt19937& rng) {
  ShadowRays rays;
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double tilts[] = {1e-6, 1e-4, 1e-3, 1e-2, 0.1, 0.3, -1e-4};
  glm::dvec3 dir(0.0);
  double distance = 0.0;
  for (size_t k = 0; k < points.size(); ++k) {
    if (k % 16 == 0) {
      const glm::dvec3 n = points[k].geometricNormal;
      const glm::dvec3 a = std::abs(n.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
      const glm::dvec3 t1 = glm::normalize(glm::cross(n, a)), t2 = glm::cross(n, t1);
      const double phi = 6.283185307179586 * uniform(rng);
      const double tilt = tilts[size_t(uniform(rng) * 7.0) % 7];
      dir = glm::normalize(std::cos(tilt) * (std::cos(phi) * t1 + std::sin(phi) * t2) + std::sin(tilt) * n);
      distance = uniform(rng) < 0.5 ? std::numeric_limits<double>::infinity() : 0.1 + 30.0 * uniform(rng);
    }
    rays.points.push_back(&points[k]);
    rays.toLight.push_back(dir);
    rays.distance.push_back(distance);
  }
  if (!scene.lights.empty() && scene.lights[0].type == LightType::Directional)
    for (const SurfacePoint& p : points) {
      rays.points.push_back(&p);
      rays.toLight.push_back(-scene.lights[0].direction);
      rays.distance.push_back(std::numeric_limits<double>::infinity());
    }
  return rays;
}

// Every shadow ray's transmittance traced alone in lane 0 (what
// LightVisibility::transmittance does), alone in another lane, in
// coherent packets (neighbouring points, 14 to a packet, lanes permuted)
// and among random mates in random lanes: the same bits each time. Far
// from the origin, grazing, and from box edges lying in the planes of
// the box's sides, where Embree's packet-mode tests (16 lanes at once) and
// its single-ray tests (one lane against 4 triangles) round apart.
TEST(ShadowPackets, ALanesAnswerDependsNeitherOnItsLaneNorOnItsMates) {
  constexpr size_t kMates = 14;  // the ray caster's packets (raytrace/ray_caster_parts.h, kShadowPacket)
  std::vector<ContactScene> scenes;
  scenes.push_back(contactSceneAt1e6());
  for (const char* name : {"far-baked-1e6.gltf", "far-node-1e6.gltf", "grazing-lit-89.9.gltf"}) {
    ContactScene s{loadScene(test::scenePath(std::string("stiff/") + name)), {}};
    s.points = surfacePoints(s.scene);
    s.points.resize(std::min<size_t>(s.points.size(), 1200));
    scenes.push_back(std::move(s));
  }
  std::mt19937 rng(5);
  size_t rays = 0, blocked = 0, lit = 0;
  for (const ContactScene& cs : scenes) {
    const Scene& scene = cs.scene;
    const std::vector<SurfacePoint>& points = cs.points;
    const std::string name = scene.path;
    RayCaster caster(scene, analyzeScene(scene));
    caster.bind(makeCamera(scene, {}, 16, 16), RayOptions{});
    const ShadowRays r = grazingRays(scene, points, rng);
    const size_t n = r.points.size();
    std::vector<glm::vec3> alone(n);
    for (size_t k = 0; k < n; ++k)
      alone[k] = caster.transmittance(*r.points[k], 0, r.toLight[k], r.distance[k]);
    auto expectSame = [&](size_t k, const glm::vec3& got, const char* how) {
      ASSERT_TRUE(sameBits(got, alone[k]))
          << name << " ray " << k << " " << how << ": (" << got.r << ", " << got.g << ", " << got.b
          << ") alone in lane 0: (" << alone[k].r << ", " << alone[k].g << ", " << alone[k].b << ")";
    };
    int lanes[16];
    std::iota(lanes, lanes + 16, 0);
    glm::vec3 out[16];
    for (size_t k = 0; k < n; ++k) {  // alone in lane 1 + k % 15
      const int lane = int(1 + k % 15);
      caster.transmittancesInLanes(1, &r.points[k], &r.toLight[k], &r.distance[k], &lane, out);
      expectSame(k, out[0], "alone in another lane");
    }
    for (size_t first = 0; first + kMates <= n; first += kMates) {  // coherent mates, lanes permuted
      std::shuffle(lanes, lanes + 16, rng);
      caster.transmittancesInLanes(kMates, &r.points[first], &r.toLight[first], &r.distance[first], lanes,
                                   out);
      for (size_t k = 0; k < kMates; ++k) expectSame(first + k, out[k], "among coherent mates");
    }
    std::vector<size_t> order(n);
    std::iota(order.begin(), order.end(), size_t(0));
    std::shuffle(order.begin(), order.end(), rng);
    for (size_t first = 0; first < n;) {  // random mates, 2…14 of them, random lanes
      const size_t m = std::min<size_t>(n - first, 2 + rng() % (kMates - 1));
      const SurfacePoint* p[16];
      glm::dvec3 d[16];
      double t[16];
      for (size_t k = 0; k < m; ++k) {
        p[k] = r.points[order[first + k]];
        d[k] = r.toLight[order[first + k]];
        t[k] = r.distance[order[first + k]];
      }
      std::shuffle(lanes, lanes + 16, rng);
      caster.transmittancesInLanes(m, p, d, t, lanes, out);
      for (size_t k = 0; k < m; ++k) expectSame(order[first + k], out[k], "among random mates");
      first += m;
    }
    caster.throwIfError();
    for (const glm::vec3& a : alone) {
      ++rays;
      blocked += a == glm::vec3(0.0f);
      lit += a == glm::vec3(1.0f);
    }
  }
  // Not vacuous: rays blocked and rays that reach the light.
  EXPECT_GT(blocked, 500u);
  EXPECT_GT(lit, 500u);
  std::printf("%zu rays: %zu blocked, %zu unoccluded\n", rays, blocked, lit);
}

}  // namespace
}  // namespace rastray
