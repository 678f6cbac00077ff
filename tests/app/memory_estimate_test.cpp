// The memory estimate's coverage pass (app/engine/memory_estimate.h): projected
// areas against hand-computed ones, clipping by the image and the near
// plane, and the same sum at any thread count.
#ifdef RASTRAY_HAVE_RENDERERS

#include "app/engine/memory_estimate.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <random>

#include "common/camera.h"
#include "common/scene.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

constexpr int kSize = 64;

// An empty scene seen by an orthographic camera whose view is [-1, 1]² at
// any depth in [0.125, 10], looking down −Z; material 0 opaque, 1 BLEND.
Scene orthoScene() {
  Scene s;
  s.path = "coverage";
  Material blend;
  blend.alphaMode = AlphaMode::Blend;
  s.materials = {Material{}, blend};
  CameraModel camera;
  camera.projection = Projection::Orthographic;
  camera.xmag = camera.ymag = 1.0;
  camera.znear = 0.125;
  camera.zfar = 10.0;
  s.camera = camera;
  return s;
}

// The axis-aligned rectangle [x0, x1] × [y0, y1] at depth z (view space)
// as two triangles of one instance.
void addRect(Scene& s, double x0, double y0, double x1, double y1, double z, uint32_t material) {
  Instance inst;
  inst.material = material;
  inst.firstVertex = uint32_t(s.positions.size());
  inst.firstTriangle = uint32_t(s.triangles.size());
  const uint32_t v = inst.firstVertex;
  for (const glm::dvec3& p :
       {glm::dvec3(x0, y0, z), glm::dvec3(x1, y0, z), glm::dvec3(x1, y1, z), glm::dvec3(x0, y1, z)}) {
    s.positions.push_back(glm::vec3(p));
    s.bounds.extend(p);
  }
  s.triangles.push_back({v, v + 1, v + 2});
  s.triangles.push_back({v, v + 2, v + 3});
  inst.vertexCount = 4;
  inst.triangleCount = 2;
  s.instances.push_back(inst);
}

ProjectedCoverage coverage(const Scene& s) {
  return projectedCoverage(s, makeCamera(s, {}, kSize, kSize), true);
}

TEST(ProjectedCoverage, ARectangleInsideCoversItsArea) {
  Scene s = orthoScene();
  addRect(s, -0.5, -0.5, 0.5, 0.5, -1.0, 0);  // a quarter of the view
  EXPECT_DOUBLE_EQ(coverage(s).opaque, 0.25);
  EXPECT_EQ(coverage(s).transparentLayers, 0.0);
}

TEST(ProjectedCoverage, TheImageBorderClips) {
  Scene s = orthoScene();
  addRect(s, 0.5, -0.5, 1.5, 0.5, -1.0, 0);  // half of it beyond the right border
  EXPECT_DOUBLE_EQ(coverage(s).opaque, 0.125);
  Scene corner = orthoScene();
  addRect(corner, -3.0, -3.0, -0.5, -0.5, -1.0, 0);  // over the lower-left corner
  EXPECT_DOUBLE_EQ(coverage(corner).opaque, 0.0625);
  Scene off = orthoScene();
  addRect(off, 1.5, -0.5, 2.5, 0.5, -1.0, 0);
  addRect(off, -0.5, 1.0, 0.5, 2.0, -1.0, 0);  // touching the top border only
  EXPECT_EQ(coverage(off).opaque, 0.0);
}

TEST(ProjectedCoverage, TheNearPlaneClips) {
  // A rectangle in the plane x = 0 would be edge-on; instead one tilted in
  // depth: y from -1 to 1 while z goes from -2 (inside) to +2 (behind the
  // eye). In an orthographic view the part in front of znear = 0.125 spans
  // y in [-1, -0.0625]: (1 - 0.0625) × 2 of the view's 4.
  Scene s = orthoScene();
  const uint32_t v = 0;
  for (const glm::dvec3& p :
       {glm::dvec3(-1, -1, -2), glm::dvec3(1, -1, -2), glm::dvec3(1, 1, 2), glm::dvec3(-1, 1, 2)}) {
    s.positions.push_back(glm::vec3(p));
    s.bounds.extend(p);
  }
  s.triangles = {{v, v + 1, v + 2}, {v, v + 2, v + 3}};
  Instance inst;
  inst.vertexCount = 4;
  inst.triangleCount = 2;
  s.instances = {inst};
  EXPECT_DOUBLE_EQ(coverage(s).opaque, (1.0 - 0.0625) * 2.0 / 4.0);
}

TEST(ProjectedCoverage, TransparentLayersAreCountedEach) {
  Scene s = orthoScene();
  for (int layer = 0; layer < 3; ++layer) addRect(s, -1, -1, 1, 1, -1.0 - layer, 1);
  addRect(s, -1, -1, 1, 1, -5.0, 0);
  const ProjectedCoverage c = coverage(s);
  EXPECT_DOUBLE_EQ(c.transparentLayers, 3.0);
  EXPECT_DOUBLE_EQ(c.opaque, 1.0);
  // Without the opaque pass only the transparent layers are summed.
  EXPECT_EQ(projectedCoverage(s, makeCamera(s, {}, kSize, kSize), false).opaque, 1.0);
}

// The pass runs in parallel over blocks of triangles; their sums are added
// in block order, so the result is the same to the bit on 1 and 2 threads.
TEST(ProjectedCoverage, TheSameSumOnOneAndTwoThreads) {
  Scene s = orthoScene();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> at(-1.5, 1.5), size(0.001, 0.3);
  for (int i = 0; i < 100'000; ++i) {
    const double x = at(rng), y = at(rng);
    addRect(s, x, y, x + size(rng), y + size(rng), -1.0, i % 3 == 0 ? 1 : 0);
  }
  ProjectedCoverage one, two;
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
    one = coverage(s);
  }
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    two = coverage(s);
  }
  EXPECT_EQ(one.transparentLayers, two.transparentLayers);
  EXPECT_EQ(one.opaque, two.opaque);
  EXPECT_GT(one.transparentLayers, 0.0);
}

}  // namespace
}  // namespace rastray

#endif  // RASTRAY_HAVE_RENDERERS
