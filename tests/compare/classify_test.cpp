// The mismatch classes one at a time, on scenes built in code, and the
// depth-format resolution formulas against values worked by hand.
#include "compare/classify.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/math_constants.h"
#include "frames.h"

namespace rastray {
namespace {

using test::quadScene;

HitRecord hit(uint32_t instance, uint32_t triangle, float depth) { return {instance, triangle, depth}; }

TEST(DepthResolution, FloatReversedPerspectiveInfiniteFar) {
  // s = n/d = 0.01 lies in [2^-7, 2^-6): ulp 2^-30; |dz/dd| = n/d² = 0.001.
  const DepthPlanes planes{true, Projection::Perspective, 0.1, std::numeric_limits<double>::infinity()};
  EXPECT_DOUBLE_EQ(depthResolution(DepthFormat::FloatReversed, planes, 10.0), std::ldexp(1.0, -30) / 0.001);
  // The plane-free bound d·2^-23 holds.
  EXPECT_LE(depthResolution(DepthFormat::FloatReversed, planes, 10.0), 10.0 * std::ldexp(1.0, -23));
}

TEST(DepthResolution, ConventionalFormatsPerspective) {
  const DepthPlanes planes{true, Projection::Perspective, 0.1, std::numeric_limits<double>::infinity()};
  // z = 1 − n/d = 0.99: unorm24 step 2^-24, float ulp(0.99) = 2^-24; slope 0.001.
  EXPECT_DOUBLE_EQ(depthResolution(DepthFormat::Unorm24, planes, 10.0), std::ldexp(1.0, -24) / 0.001);
  EXPECT_DOUBLE_EQ(depthResolution(DepthFormat::Float, planes, 10.0), std::ldexp(1.0, -24) / 0.001);
  EXPECT_DOUBLE_EQ(depthResolution(DepthFormat::Unorm16, planes, 10.0), std::ldexp(1.0, -16) / 0.001);
  // Finite far: slope n f / ((f − n) d²) = 0.1·100 / (99.9·100).
  const DepthPlanes finite{true, Projection::Perspective, 0.1, 100.0};
  EXPECT_DOUBLE_EQ(depthResolution(DepthFormat::Unorm24, finite, 10.0),
                   std::ldexp(1.0, -24) / (0.1 * 100.0 / (99.9 * 100.0)));
}

TEST(DepthResolution, OrthographicIsLinear) {
  const DepthPlanes planes{true, Projection::Orthographic, 0.125, 1.0};
  EXPECT_DOUBLE_EQ(depthResolution(DepthFormat::Unorm16, planes, 0.5), std::ldexp(1.0, -16) * 0.875);
  // Reversed s = (f − d)/(f − n) = 0.5/0.875 ≈ 0.571: ulp 2^-24.
  EXPECT_DOUBLE_EQ(depthResolution(DepthFormat::FloatReversed, planes, 0.5), std::ldexp(1.0, -24) * 0.875);
}

TEST(DepthResolution, WithoutPlanesOnlyFloatReversedHasABound) {
  const DepthPlanes unknown;
  EXPECT_DOUBLE_EQ(depthResolution(DepthFormat::FloatReversed, unknown, 3.0), 3.0 * std::ldexp(1.0, -23));
  EXPECT_TRUE(std::isinf(depthResolution(DepthFormat::Unorm24, unknown, 3.0)));
}

TEST(DepthResolution, Ulp32) {
  EXPECT_EQ(ulp32(1.0), std::ldexp(1.0, -23));
  EXPECT_EQ(ulp32(0.5), std::ldexp(1.0, -24));
  EXPECT_EQ(ulp32(0.0), std::ldexp(1.0, -149));
  EXPECT_EQ(ulp32(3.0), std::ldexp(1.0, -22));
}

class QuadClassifier : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    scene = quadScene(GetParam());
    camera = makeCamera(scene, {}, 8, 8);
    settings.scene = &scene;
    settings.camera = &camera;
    settings.planes = {true, camera.projection, camera.znear, camera.zfar};
  }
  Scene scene;
  Camera camera;
  ClassifierSettings settings;
};

TEST_P(QuadClassifier, SampleOnTheSharedDiagonalIsAnEdgeTie) {
  MismatchClassifier c(settings);
  // Pixel (4, 3)'s centre (4.5, 3.5) is world (0.125, 0.125): on the diagonal.
  EXPECT_NEAR(c.distanceToSharedEdge({4.5, 3.5}, hit(0, 0, 0.5f), hit(0, 1, 0.5f)), 0.0, 1e-12);
  EXPECT_EQ(c.classify({4.5, 3.5}, hit(0, 0, 0.5f), hit(0, 1, 0.5f), {}), MismatchClass::SharedEdgeTie);
  // 1/32 pixel off the diagonal along x: distance 1/32 / √2, still within 1/16.
  EXPECT_EQ(c.classify({4.5 + 1.0 / 32.0, 3.5}, hit(0, 0, 0.5f), hit(0, 1, 0.5f), {}),
            MismatchClass::SharedEdgeTie);
}

TEST_P(QuadClassifier, SampleAwayFromTheSharedEdgeIsNotATie) {
  MismatchClassifier c(settings);
  // Pixel (5, 4), centre world (0.375, −0.125): 0.354 world = 1.41 px from
  // the diagonal, ½ px from the quad's right edge. Different depths: genuine.
  EXPECT_NEAR(c.distanceToSharedEdge({5.5, 4.5}, hit(0, 0, 0.5f), hit(0, 1, 0.6f)), std::sqrt(2.0), 1e-9);
  EXPECT_EQ(c.classify({5.5, 4.5}, hit(0, 0, 0.5f), hit(0, 1, 0.6f), {}), MismatchClass::Genuine);
  // The same triangles at the same depth: a depth tie (coplanar).
  EXPECT_EQ(c.classify({5.5, 4.5}, hit(0, 0, 0.5f), hit(0, 1, 0.5f), {}), MismatchClass::DepthTie);
}

TEST_P(QuadClassifier, OuterEdgeIsASilhouette) {
  MismatchClassifier c(settings);
  // The quad's right edge x = 0.5 is image x = 6; 0.05 px inside it.
  EXPECT_NEAR(c.distanceToTriangleEdges({5.95, 4.5}, hit(0, 0, 0.5f)), 0.05, 1e-9);
  EXPECT_EQ(c.classify({5.95, 4.5}, hit(0, 0, 0.5f), HitRecord{}, {}), MismatchClass::SilhouetteEdge);
  // 0.1 px inside: beyond 1/16 px, genuine; an --edge-distance of 0.125 px makes it an edge.
  EXPECT_EQ(c.classify({5.9, 4.5}, hit(0, 0, 0.5f), HitRecord{}, {}), MismatchClass::Genuine);
  settings.edgeDistance = 0.125;
  MismatchClassifier wide(settings);
  EXPECT_EQ(wide.classify({5.9, 4.5}, hit(0, 0, 0.5f), HitRecord{}, {}), MismatchClass::SilhouetteEdge);
}

INSTANTIATE_TEST_SUITE_P(IndexedAndDuplicated, QuadClassifier, ::testing::Bool());

TEST(Classifier, PerspectiveEdgeProjection) {
  // A triangle at view depth 2 with a vertical edge at x = 0 under a 90°
  // perspective camera (8×8): the edge projects onto image column x = 4.
  Scene s;
  s.path = "persp";
  s.positions = {{0.0f, -1.0f, -2.0f}, {1.0f, -1.0f, -2.0f}, {0.0f, 1.0f, -2.0f}};
  s.triangles = {{0, 1, 2}};
  Instance inst;
  inst.vertexCount = 3;
  inst.triangleCount = 1;
  s.instances = {inst};
  s.materials = {Material{}};
  CameraModel cam;
  cam.yfov = kPi / 2.0;
  cam.znear = 0.5;
  s.camera = cam;
  const Camera camera = makeCamera(s, {}, 8, 8);
  ClassifierSettings settings;
  settings.scene = &s;
  settings.camera = &camera;
  settings.planes = {true, camera.projection, camera.znear, camera.zfar};
  MismatchClassifier c(settings);
  EXPECT_NEAR(c.distanceToTriangleEdges({4.25, 4.0}, hit(0, 0, 2.0f)), 0.25, 1e-9);
  EXPECT_NEAR(c.distanceToTriangleEdges({4.03, 4.0}, hit(0, 0, 2.0f)), 0.03, 1e-9);
}

// The float intersection bound grows as 1/cos θ towards grazing incidence
// and with the triangle's thinness, and is a few ULPs of t head-on.
TEST(Classifier, FloatIntersectionErrorGrowsAtGrazingAndForSlivers) {
  Scene s;
  s.path = "bound";
  s.positions = {{-1.0f, -1.0f, -2.0f}, {1.0f, -1.0f, -2.0f}, {0.0f, 1.0f, -2.0f},
                 {-1.0f, 0.0f, -2.0f},  {1.0f, 0.0f, -2.0f},  {1.0f, 1e-4f, -2.0f}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}};
  Instance inst;
  inst.vertexCount = 6;
  inst.triangleCount = 2;
  s.instances = {inst};
  s.materials = {Material{}};
  Ray ray;
  ray.direction = {0.0, 0.0, -1.0};
  const double headOn = floatIntersectionError(s, 0, 0, ray, 2.0);
  EXPECT_GT(headOn, 2.0 * 0x1p-24);
  EXPECT_LT(headOn, 2.0 * 64.0 * 0x1p-24);
  const double angle = std::acos(0.01);  // 89.4° from the normal
  ray.direction = {std::sin(angle), 0.0, -std::cos(angle)};
  EXPECT_NEAR(floatIntersectionError(s, 0, 0, ray, 2.0) / headOn, 100.0, 1.0);
  ray.direction = {0.0, 0.0, -1.0};
  EXPECT_GT(floatIntersectionError(s, 0, 1, ray, 2.0), 1000.0 * headOn);  // aspect 2e4 sliver
  ray.direction = {1.0, 0.0, 0.0};                                        // parallel to the plane
  EXPECT_TRUE(std::isinf(floatIntersectionError(s, 0, 0, ray, 2.0)));
}

TEST(Classifier, DepthTieFollowsTheFormat) {
  ClassifierSettings settings;
  settings.planes = {true, Projection::Orthographic, 0.125, 1.0};
  const float d = 0.5f;
  const float oneUlp = std::nextafter(d, 1.0f);
  // float-reversed at 0.5 (ortho 0.125..1): 2^-24·0.875 + 2^-24 ≈ 1.1e-7.
  MismatchClassifier fr(settings);
  EXPECT_EQ(fr.classify({0, 0}, hit(0, 0, d), hit(1, 0, oneUlp), {}), MismatchClass::DepthTie);
  EXPECT_EQ(fr.classify({0, 0}, hit(0, 0, d), hit(1, 0, d + 1e-5f), {}), MismatchClass::Genuine);
  // unorm16: 2^-16·0.875 ≈ 1.3e-5: the same 1e-5 difference is a tie.
  settings.depthFormat = DepthFormat::Unorm16;
  MismatchClassifier u16(settings);
  EXPECT_EQ(u16.classify({0, 0}, hit(0, 0, d), hit(1, 0, d + 1e-5f), {}), MismatchClass::DepthTie);
  EXPECT_EQ(u16.classify({0, 0}, hit(0, 0, d), hit(1, 0, d + 2e-5f), {}), MismatchClass::Genuine);
}

TEST(Classifier, NearAndFarPlanes) {
  ClassifierSettings settings;
  settings.planes = {true, Projection::Orthographic, 0.125, 1.0};
  MismatchClassifier c(settings);
  EXPECT_EQ(c.classify({0, 0}, hit(0, 0, 0.125f), HitRecord{}, {}), MismatchClass::NearFarPlane);
  EXPECT_EQ(c.classify({0, 0}, HitRecord{}, hit(0, 0, 0.1f), {}), MismatchClass::NearFarPlane);  // in front
  EXPECT_EQ(c.classify({0, 0}, hit(0, 0, 1.0f), HitRecord{}, {}), MismatchClass::NearFarPlane);  // on far
  EXPECT_EQ(c.classify({0, 0}, hit(0, 0, 1.5f), hit(1, 0, 0.5f), {}), MismatchClass::NearFarPlane);
  EXPECT_EQ(c.classify({0, 0}, hit(0, 0, 0.13f), HitRecord{}, {}), MismatchClass::Genuine);
  EXPECT_EQ(c.classify({0, 0}, hit(0, 0, 0.99f), HitRecord{}, {}), MismatchClass::Genuine);
  // Planes unknown: never this class.
  MismatchClassifier unknown(ClassifierSettings{});
  EXPECT_EQ(unknown.classify({0, 0}, hit(0, 0, 0.125f), HitRecord{}, {}), MismatchClass::Genuine);
}

TEST(Classifier, ImageSpaceFallback) {
  MismatchClassifier c(ClassifierSettings{});
  EXPECT_FALSE(c.geometric());
  ImageSpaceEvidence edge;
  edge.edgeNearby = true;
  EXPECT_EQ(c.classify({0, 0}, hit(0, 0, 0.5f), hit(0, 1, 0.7f), edge), MismatchClass::SharedEdgeTie);
  EXPECT_EQ(c.classify({0, 0}, hit(0, 0, 0.5f), hit(1, 1, 0.7f), edge), MismatchClass::SilhouetteEdge);
  EXPECT_EQ(c.classify({0, 0}, hit(0, 0, 0.5f), HitRecord{}, edge), MismatchClass::SilhouetteEdge);
  EXPECT_EQ(c.classify({0, 0}, hit(0, 0, 0.5f), hit(0, 1, 0.7f), {}), MismatchClass::Genuine);
}

TEST(Classifier, NamesRoundTrip) {
  for (auto f : {DepthFormat::FloatReversed, DepthFormat::Float, DepthFormat::Unorm24, DepthFormat::Unorm16})
    EXPECT_EQ(parseDepthFormat(toString(f)), f);
  EXPECT_FALSE(parseDepthFormat("float32"));
  EXPECT_STREQ(toString(MismatchClass::SharedEdgeTie), "shared-edge-tie");
}

}  // namespace
}  // namespace rastray
