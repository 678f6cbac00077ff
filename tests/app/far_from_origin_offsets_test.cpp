// Ray origin offsets far from the origin (raytrace/ray_offset.h), on
// scenes written with their vertex data baked as absolute float32
// positions at x, z ≈ 1e6, rendered in process as `rastray render` would
// (the options parsed from an argument list).
//
// - A contact shadow: a floor through y = 0 and a box floating 0.01 above
//   it, one directional light. Every visible floor sample the box shadows
//   (by a double-precision test with a margin) must be dark and every one
//   it clearly does not must be exactly lit (acne 0), with --origin world
//   (the offsets alone must do it) and --origin camera, by the ray caster
//   and by hybrid (the same offsets, through the ray caster's interfaces).
//   On the level floor (normal along y, whose coordinate is small) the RTG
//   offset is harmless; on a floor sloped 1:5 its 256 ULPs of z ≈ 1e6 move
//   the origin 3 units sideways and 0.6 up, and the test asserts that it
//   fails there (shadow lost, lit samples darkened).
// - The lit scene (floor, box, sphere of radius 1.5 with flat
//   normals, one directional light), baked 1e6 from the origin, against
//   the same scene at the origin at 480×320: pixels off by more than 0.1.
#ifdef RASTRAY_HAVE_RENDERERS

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "app/engine/render_setup.h"
#include "app/studies/stability_far_scene.h"
#include "app/studies/stability_measure.h"
#include "common/gltf/writer.h"
#include "common/math_constants.h"
#include "common/sampling.h"
#include "common/surface.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

constexpr double kFar = 1e6;
constexpr double kGap = 0.01;  // the box floats this far above the floor
const glm::dvec3 kLightTravel = glm::normalize(glm::dvec3(0.6, -1.0, 0.4));
constexpr float kIntensity = 3.0f;
constexpr float kAlbedo = 0.8f;

std::string tempPath(const std::string& name) { return test::scratchPath(name); }

// A file removed when the test ends.
struct TempScene {
  std::string path;
  TempScene(const GltfScene& scene, const std::string& name) : path(tempPath(name)) { scene.write(path); }
  ~TempScene() {
    std::error_code ec;
    std::filesystem::remove(path, ec);
  }
};

void addQuad(GltfMesh& m, const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
             const glm::dvec3& p3) {
  const uint32_t base = uint32_t(m.positions.size());
  for (const glm::dvec3& p : {p0, p1, p2, p3})
    m.positions.push_back(glm::vec3(p));  // baked: float32 absolute
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

// --- the contact shadow ------------------------------------------------------

// A parallelogram face c + s·a + t·b, s, t in [0, 1], in double.
struct Face {
  glm::dvec3 c, a, b;
};

// The floor y = slope·(z − zc) around (xc, zc) and a box 2 × 1 × 2 whose
// bottom lies kGap above it (measured vertically: a prism sheared with the
// floor, its sides vertical).
struct ContactScene {
  double slope = 0.0;
  glm::dvec3 centre{kFar, 0.0, kFar};
  double floorY(double z) const { return slope * (z - centre.z); }
  glm::dvec3 boxCorner(int x, int y, int z) const {
    const double px = centre.x + (x ? 1.0 : -1.0), pz = centre.z + (z ? 1.0 : -1.0);
    return {px, floorY(pz) + kGap + (y ? 1.0 : 0.0), pz};
  }
  std::vector<Face> boxFaces() const {
    const auto c = [&](int x, int y, int z) { return boxCorner(x, y, z); };
    auto face = [](const glm::dvec3& o, const glm::dvec3& p, const glm::dvec3& q) {
      return Face{o, p - o, q - o};
    };
    return {face(c(0, 0, 0), c(1, 0, 0), c(0, 0, 1)), face(c(0, 1, 0), c(1, 1, 0), c(0, 1, 1)),
            face(c(0, 0, 0), c(1, 0, 0), c(0, 1, 0)), face(c(0, 0, 1), c(1, 0, 1), c(0, 1, 1)),
            face(c(0, 0, 0), c(0, 0, 1), c(0, 1, 0)), face(c(1, 0, 0), c(1, 0, 1), c(1, 1, 0))};
  }
  GltfScene gltf() const {
    GltfScene s;
    GltfMaterial floor, box;
    floor.baseColor = {kAlbedo, kAlbedo, kAlbedo, 1.0f};
    box.baseColor = {0.8f, 0.3f, 0.2f, 1.0f};
    s.materials = {floor, box};
    GltfMesh f;
    f.material = 0;
    const auto p = [&](double dx, double dz) {
      return glm::dvec3(centre.x + dx, floorY(centre.z + dz), centre.z + dz);
    };
    addQuad(f, p(-10, 10), p(10, 10), p(10, -10), p(-10, -10));  // counter-clockwise from above
    s.meshes.push_back(f);
    GltfMesh b;
    b.material = 1;
    const auto c = [&](int x, int y, int z) { return boxCorner(x, y, z); };
    addQuad(b, c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1));  // +z
    addQuad(b, c(1, 0, 0), c(0, 0, 0), c(0, 1, 0), c(1, 1, 0));  // -z
    addQuad(b, c(1, 0, 1), c(1, 0, 0), c(1, 1, 0), c(1, 1, 1));  // +x
    addQuad(b, c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0));  // -x
    addQuad(b, c(0, 1, 1), c(1, 1, 1), c(1, 1, 0), c(0, 1, 0));  // +y
    addQuad(b, c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1));  // -y
    s.meshes.push_back(b);
    GltfCamera camera;
    camera.eye = centre + glm::dvec3(3.0, 4.0, 5.0);
    camera.target = centre + glm::dvec3(0.5, 0.0, 0.5);
    camera.yfov = 0.6;
    camera.znear = 0.1;
    camera.zfar = 100.0;
    s.camera = camera;
    GltfLight light;
    light.direction = kLightTravel;
    light.intensity = kIntensity;
    s.lights = {light};
    return s;
  }
};

// How deep the ray x + t·d, t > 0, passes inside the face (its distance
// from the nearest edge, in world units; negative outside, −inf when it
// does not reach the plane).
double insideDistance(const Face& f, const glm::dvec3& x, const glm::dvec3& d) {
  const glm::dvec3 n = glm::cross(f.a, f.b);
  const double den = glm::dot(n, d);
  if (den == 0.0) return -INFINITY;
  const double t = glm::dot(n, f.c - x) / den;
  if (!(t > 0.0)) return -INFINITY;
  const glm::dvec3 q = x + t * d - f.c;
  // q = s·a + u·b
  const double area2 = glm::dot(n, n);
  const double s = glm::dot(glm::cross(q, f.b), n) / area2, u = glm::dot(glm::cross(f.a, q), n) / area2;
  const double area = std::sqrt(area2);
  const double toB = area / glm::length(f.b), toA = area / glm::length(f.a);
  return std::min({s * toB, (1.0 - s) * toB, u * toA, (1.0 - u) * toA});
}

struct ShadowCounts {
  int shadowed = 0, shadowedDark = 0;  // samples the box shadows by more than the margin; of them dark
  int lit = 0, acne = 0;               // samples clearly lit; of them not exactly lit
  std::string describe() const {
    return std::to_string(shadowedDark) + " of " + std::to_string(shadowed) + " shadowed samples dark, " +
           std::to_string(acne) + " of " + std::to_string(lit) + " lit samples darkened";
  }
};

// Classifies every floor pixel (instance 0) of a 1-spp render by a double
// test of its plane point against the box faces (in the render's frame:
// world minus the scene's origin), with a margin of 0.1 units: with
// --origin world a float origin near x, z = 1e6 lies on a 1/16 grid in x
// and z, and rounding it there moves where its shadow ray meets the box by
// up to about 0.08 (sideways 0.03 in x and z, along a ray rising 1 in 0.7).
ShadowCounts countShadows(const ContactScene& cs, const Scene& scene, const RenderRun& run) {
  constexpr double kMargin = 0.1;
  std::vector<Face> faces = cs.boxFaces();
  for (Face& f : faces) f.c -= scene.origin;
  const glm::dvec3 toLight = -kLightTravel;
  const glm::dvec2 position = samplePositions(1)[0];
  const FlatImage& image = run.output.image;
  ShadowCounts counts;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const size_t i = image.index(x, y);
      if (image.instance[i] != 0u) continue;
      const Ray ray = run.camera.primaryRay(glm::dvec2(x, y) + position);
      double t;
      glm::dvec2 b;
      if (!intersectTrianglePlane(scene, 0, image.triangle[i], ray, &t, &b)) continue;
      const glm::dvec3 p = ray.origin + t * ray.direction;
      double deepest = -INFINITY;
      for (const Face& f : faces) deepest = std::max(deepest, insideDistance(f, p, toLight));
      const glm::uvec3 tri = scene.triangle(0, image.triangle[i]);
      const glm::dvec3 n =
          glm::normalize(glm::cross(glm::dvec3(scene.positions[tri.y] - scene.positions[tri.x]),
                                    glm::dvec3(scene.positions[tri.z] - scene.positions[tri.x])));
      const float expected = float(kAlbedo * kIntensity * glm::dot(n, toLight) / kPi);
      const float seen = image.color[i].r;
      if (deepest > kMargin) {
        ++counts.shadowed;
        counts.shadowedDark += seen < 0.5f * expected;
      } else if (deepest < -kMargin) {
        ++counts.lit;
        counts.acne += std::abs(seen - expected) > 1e-3f * expected;
      }
    }
  return counts;
}

struct Rendered {
  Scene scene;
  RenderRun run;
};

Rendered render(const std::string& path, const std::vector<std::string>& args) {
  const RenderSettings settings = renderSettingsFrom(args);
  Rendered r;
  r.scene = loadSceneForRender(path, settings);
  r.run = renderScene(r.scene, settings);
  return r;
}

std::vector<std::string> contactArgs(const std::string& renderer, const std::string& origin,
                                     const std::string& offset) {
  return {"--renderer", renderer,   "--size", "160",          "120", "--spp",
          "1",          "--origin", origin,   "--ray-offset", offset};
}

void expectContactShadow(const ContactScene& cs, const std::string& name) {
  const TempScene file(cs.gltf(), name + ".gltf");
  for (const char* renderer : {"raytrace", "hybrid"})
    for (const char* origin : {"world", "camera"}) {
      const Rendered r = render(file.path, contactArgs(renderer, origin, "error-bound"));
      const ShadowCounts c = countShadows(cs, r.scene, r.run);
      SCOPED_TRACE(name + " " + renderer + " --origin " + origin + ": " + c.describe());
      EXPECT_GT(c.shadowed, 300);
      EXPECT_GT(c.lit, 3000);
      EXPECT_EQ(c.shadowedDark, c.shadowed);
      EXPECT_EQ(c.acne, 0);
    }
}

TEST(FarFromOriginOffsets, ContactShadowOnALevelFloorAt1e6) {
  ContactScene cs;
  expectContactShadow(cs, "level");
  // The RTG offset's best case: the floor's normal lies along y, whose
  // coordinate is 0, so it moves the origin by 1/65536 only.
  const TempScene file(cs.gltf(), "level-ulps.gltf");
  const Rendered r = render(file.path, contactArgs("raytrace", "world", "float-ulps"));
  const ShadowCounts c = countShadows(cs, r.scene, r.run);
  EXPECT_EQ(c.shadowedDark, c.shadowed) << c.describe();
  EXPECT_EQ(c.acne, 0) << c.describe();
}

TEST(FarFromOriginOffsets, ContactShadowOnASlopedFloorAt1e6) {
  ContactScene cs;
  cs.slope = 0.2;
  expectContactShadow(cs, "sloped");
  // The failure the error bound fixes: 256 ULPs of z ≈ 1e6 (50 of them
  // along n_z ≈ −0.2) start shadow rays 3 units away and 0.6 above.
  const TempScene file(cs.gltf(), "sloped-ulps.gltf");
  const Rendered r = render(file.path, contactArgs("raytrace", "world", "float-ulps"));
  const ShadowCounts c = countShadows(cs, r.scene, r.run);
  std::printf("sloped floor, float-ulps, --origin world: %s\n", c.describe().c_str());
  EXPECT_LT(c.shadowedDark, c.shadowed / 2) << c.describe();
  EXPECT_GT(c.acne, 100) << c.describe();
}

// Hybrid traces its shadow rays through the ray caster's interfaces, from
// the same origins: where both see the same triangle they shade it
// identically, at 1e6 too.
TEST(FarFromOriginOffsets, HybridAgreesWithTheRayCaster) {
  ContactScene cs;
  cs.slope = 0.2;
  const TempScene file(cs.gltf(), "hybrid.gltf");
  for (const char* origin : {"world", "camera"}) {
    const Rendered ray = render(file.path, contactArgs("raytrace", origin, "error-bound"));
    const Rendered hybrid = render(file.path, contactArgs("hybrid", origin, "error-bound"));
    const FlatImage &a = ray.run.output.image, &b = hybrid.run.output.image;
    int same = 0;
    float worst = 0.0f;
    for (size_t i = 0; i < a.color.size(); ++i) {
      if (a.instance[i] != b.instance[i] || a.triangle[i] != b.triangle[i]) continue;
      ++same;
      const glm::vec4 d = glm::abs(a.color[i] - b.color[i]);
      worst = std::max({worst, d.r, d.g, d.b, d.a});
    }
    EXPECT_GT(same, int(a.color.size()) * 99 / 100) << origin;
    EXPECT_LE(worst, 1e-5f) << origin;
  }
}

// --- the lit scene -----------------------------------------------------------

// The stability study's far scene (app/studies/stability_far_scene.h) with the
// box and the sphere standing on the floor and no mirror: all moved by
// `offset`, baked into the float32 vertex data.
GltfScene litScene(const glm::dvec3& offset) {
  return stability::farScene({offset, /*baked=*/true, /*lift=*/0.0, /*mirror=*/false});
}

// Pixels whose colour differs by more than 0.1f in some channel (a NaN
// counts as different).
double fractionOff(const FlatImage& a, const FlatImage& b) { return stability::fractionOff(a, b, 0.1f); }

// The table row "baked into float32 vertex data, 1e6", for the ray
// caster. The offset moves every coordinate, the case, and x, z
// only (the floor at y = 0). Target < 1 % with the defaults; what remains
// is the float32 data itself (vertices rounded to 1/16 at 1e6 facet the
// sphere differently from the origin scene).
TEST(FarFromOriginOffsets, LitSceneBaked1e6OffByLessThanOnePercent) {
  const TempScene origin(litScene(glm::dvec3(0.0)), "lit-origin.gltf");
  const std::vector<std::string> size = {"--renderer", "raytrace", "--size", "480", "320", "--spp", "1"};
  const Rendered reference = render(origin.path, size);
  for (const glm::dvec3& offset : {glm::dvec3(kFar), glm::dvec3(kFar, 0.0, kFar)}) {
    const TempScene far(litScene(offset), "lit-far.gltf");
    double off[2][2];
    const char* origins[2] = {"camera", "world"};
    const char* methods[2] = {"error-bound", "float-ulps"};
    for (int o = 0; o < 2; ++o)
      for (int m = 0; m < 2; ++m) {
        std::vector<std::string> args = size;
        args.insert(args.end(), {"--origin", origins[o], "--ray-offset", methods[m]});
        off[o][m] = fractionOff(render(far.path, args).run.output.image, reference.run.output.image);
        std::printf(
            "lit scene baked at (%g, %g, %g): --origin %s --ray-offset %s: %.2f %% of pixels off by > 0.1\n",
            offset.x, offset.y, offset.z, origins[o], methods[m], 100.0 * off[o][m]);
      }
    EXPECT_LT(off[0][0], 0.01) << "defaults, offset " << offset.y;
    EXPECT_LT(off[1][0], 0.01) << "--origin world, error-bound, offset " << offset.y;
    // Offset in y too, the floor's normal axis: the RTG offset, 16 units up
    // from it there, loses the box's and the sphere's shadows.
    if (offset.y != 0.0) {
      EXPECT_GT(off[1][1], 0.02) << "--origin world, float-ulps";
    }
  }
}

}  // namespace
}  // namespace rastray

#endif  // RASTRAY_HAVE_RENDERERS
