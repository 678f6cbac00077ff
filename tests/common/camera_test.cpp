#include "common/camera.h"

#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "common/error.h"
#include "common/math_constants.h"

namespace rastray {
namespace {

Scene boxScene(glm::dvec3 lo, glm::dvec3 hi) {
  Scene s;
  s.bounds.extend(lo);
  s.bounds.extend(hi);
  return s;
}

TEST(Camera, DefaultCameraFitsTheBoundingSphere) {
  const Scene scene = boxScene({-1, -2, -3}, {3, 2, 1});
  const CameraModel m = defaultCameraModel(scene);
  const glm::dvec3 centre(1, 0, -1);
  const double radius = std::sqrt(16.0 + 16.0 + 16.0) / 2.0;
  const double distance = radius / std::sin(22.5 * kPi / 180.0);
  EXPECT_NEAR(m.yfov, kPi / 4, 1e-15);
  EXPECT_NEAR(m.znear, distance / 1000.0, 1e-12);
  EXPECT_TRUE(std::isinf(m.zfar));
  EXPECT_NEAR(m.worldFromCamera[3].x, centre.x, 1e-12);
  EXPECT_NEAR(m.worldFromCamera[3].z, centre.z + distance, 1e-12);
  EXPECT_EQ(m.origin, "default");

  // The sphere just touches the top of the view: the ray through the top
  // edge's centre passes at distance `radius` from the centre.
  const Camera cam = makeCamera(scene, {}, 100, 100);
  const Ray top = cam.primaryRay({50.0, 0.0});
  const glm::dvec3 toCentre = centre - top.origin;
  const double miss = glm::length(toCentre - glm::dot(toCentre, top.direction) * top.direction);
  EXPECT_NEAR(miss, radius, 1e-9);
}

TEST(Camera, EmptySceneGetsAUsableDefault) {
  const Camera cam = makeCamera(Scene{}, {}, 64, 48);
  EXPECT_GT(cam.znear, 0.0);
  EXPECT_TRUE(std::isfinite(cam.eye().z));
}

TEST(Camera, PrimaryRayStartsOnTheNearPlane) {
  Scene scene = boxScene({-1, -1, -1}, {1, 1, 1});
  CameraOverrides o;
  o.znear = 0.5;
  o.zfar = 10.0;
  const Camera cam = makeCamera(scene, o, 200, 100);
  for (glm::dvec2 px : {glm::dvec2(0, 0), glm::dvec2(100, 50), glm::dvec2(199.5, 13.25)}) {
    const Ray r = cam.primaryRay(px);
    EXPECT_NEAR(glm::length(r.direction), 1.0, 1e-14);
    const glm::dvec3 nearPoint =
        glm::dvec3(cam.viewFromWorld * glm::dvec4(r.origin + r.tNear * r.direction, 1.0));
    const glm::dvec3 farPoint =
        glm::dvec3(cam.viewFromWorld * glm::dvec4(r.origin + r.tFar * r.direction, 1.0));
    EXPECT_NEAR(-nearPoint.z, 0.5, 1e-12);
    EXPECT_NEAR(-farPoint.z, 10.0, 1e-9);
    EXPECT_NEAR(r.tNear * r.depthPerT, 0.5, 1e-12);
    // The ray projects back onto the image position it was made for.
    const glm::dvec2 ndc(nearPoint.x / (-nearPoint.z * cam.ndcScale().x),
                         nearPoint.y / (-nearPoint.z * cam.ndcScale().y));
    const glm::dvec2 back = cam.imageFromNdc(ndc);
    EXPECT_NEAR(back.x, px.x, 1e-9);
    EXPECT_NEAR(back.y, px.y, 1e-9);
  }
}

TEST(Camera, ImageYIsDownAndNdcYIsUp) {
  const Camera cam = makeCamera(boxScene({-1, -1, -1}, {1, 1, 1}), {}, 10, 10);
  EXPECT_EQ(cam.ndcFromImage({0, 0}), glm::dvec2(-1, 1));
  EXPECT_EQ(cam.ndcFromImage({10, 10}), glm::dvec2(1, -1));
  // The top row of the image looks up (+Y in world for the default camera).
  EXPECT_GT(cam.primaryRay({5, 0}).direction.y, 0.0);
}

TEST(Camera, OrthographicRaysAreParallel) {
  Scene scene;
  CameraModel m;
  m.projection = Projection::Orthographic;
  m.xmag = 2.0;
  m.ymag = 1.0;
  m.znear = 0.125;
  m.zfar = 1.0;
  scene.camera = m;
  const Camera cam = makeCamera(scene, {}, 64, 32);
  const Ray a = cam.primaryRay({0, 0}), b = cam.primaryRay({64, 32});
  EXPECT_EQ(a.direction, glm::dvec3(0, 0, -1));
  EXPECT_EQ(b.direction, glm::dvec3(0, 0, -1));
  EXPECT_EQ(a.origin, glm::dvec3(-2, 1, 0));
  EXPECT_EQ(b.origin, glm::dvec3(2, -1, 0));
  EXPECT_EQ(a.tNear, 0.125);
  EXPECT_EQ(a.tFar, 1.0);
}

TEST(Camera, OverridesLookAt) {
  CameraOverrides o;
  o.eye = glm::dvec3(10, 0, 0);
  o.target = glm::dvec3(0, 0, 0);
  o.yfovDegrees = 60.0;
  const Camera cam = makeCamera(boxScene({-1, -1, -1}, {1, 1, 1}), o, 32, 32);
  EXPECT_NEAR(cam.forward().x, -1.0, 1e-15);
  EXPECT_NEAR(cam.yfov, kPi / 3, 1e-15);
  const Ray centre = cam.primaryRay({16, 16});
  EXPECT_NEAR(centre.direction.x, -1.0, 1e-15);
}

// The perspective ray exactly as Camera::primaryRay computed it before
// PrimaryRays hoisted the camera-only part of the matrix product: the
// full glm expressions, which the hoisted path must match bit for bit.
Ray referencePerspectiveRay(const Camera& camera, glm::dvec2 image) {
  const glm::dvec2 ndc = camera.ndcFromImage(image);
  const glm::dvec2 scale = camera.ndcScale();
  const glm::dvec3 viewDir(ndc.x * scale.x, ndc.y * scale.y, -1.0);
  const double length = glm::length(viewDir);
  Ray ray;
  ray.origin = camera.eye();
  ray.direction = glm::normalize(glm::dvec3(camera.worldFromView * glm::dvec4(viewDir, 0.0)));
  ray.depthPerT = 1.0 / length;
  ray.tNear = camera.znear * length;
  ray.tFar = camera.zfar * length;
  return ray;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(Camera, PrimaryRaysMatchTheFullMatrixProductBitForBit) {
  const Scene scene = boxScene({-1, -1, -1}, {1, 1, 1});
  // Axis-aligned views have exact zeros in the matrix (signed zeros are
  // where a hoisted sum could differ); eyes with negative coordinates make
  // m3·0 a −0; oblique and far-away ones exercise rounding.
  std::vector<CameraOverrides> views(5);
  views[1].eye = glm::dvec3(-3, -2, -7);
  views[1].target = glm::dvec3(0.25, 0.5, -0.125);
  views[2].eye = glm::dvec3(1e6 + 0.3, -2e5, 7.7);
  views[2].target = glm::dvec3(0, 0, 0);
  views[2].up = glm::dvec3(0.1, 1, 0.2);
  views[3].eye = glm::dvec3(0, 5, 0);
  views[3].target = glm::dvec3(0, 0, 0);
  views[3].up = glm::dvec3(0, 0, -1);
  views[4].eye = glm::dvec3(-0.0, -4, -0.0);
  views[4].target = glm::dvec3(-0.0, 0, -0.0);
  views[4].up = glm::dvec3(1, 0, 0);
  views[4].zfar = 100.0;
  uint32_t state = 12345u;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24);
  };
  for (const CameraOverrides& o : views) {
    const Camera cam = makeCamera(scene, o, 97, 61);
    const PrimaryRays rays(cam);
    for (int i = 0; i < 4000; ++i) {
      // Pixel corners, centres and random points, some outside the image.
      const glm::dvec2 image = i < 200 ? glm::dvec2(i % 98, (i * 7) % 62) + 0.5 * double(i % 2)
                                       : glm::dvec2(next() * 120.0 - 10.0, next() * 80.0 - 10.0);
      const Ray a = rays(image), b = referencePerspectiveRay(cam, image);
      for (int k = 0; k < 3; ++k) {
        ASSERT_TRUE(sameBits(a.origin[k], b.origin[k]))
            << "view " << &o - views.data() << " image " << image.x;
        ASSERT_TRUE(sameBits(a.direction[k], b.direction[k]))
            << "view " << &o - views.data() << " image " << image.x << ", " << image.y << " axis " << k;
      }
      ASSERT_TRUE(sameBits(a.depthPerT, b.depthPerT));
      ASSERT_TRUE(sameBits(a.tNear, b.tNear));
      ASSERT_TRUE(sameBits(a.tFar, b.tFar));
      const Ray c = cam.primaryRay(image);
      ASSERT_TRUE(sameBits(c.direction.x, a.direction.x) && sameBits(c.direction.y, a.direction.y) &&
                  sameBits(c.direction.z, a.direction.z));
    }
  }
}

TEST(Camera, ImpossibleSettingsAreInputErrors) {
  const Scene s = boxScene({-1, -1, -1}, {1, 1, 1});
  auto expectError = [&](CameraOverrides o, const std::string& option) {
    try {
      makeCamera(s, o, 10, 10);
      ADD_FAILURE() << "no error for " << option;
    } catch (const InputError& e) {
      EXPECT_EQ(e.element(), option);
    }
  };
  CameraOverrides o;
  o.znear = 0.0;
  expectError(o, "--znear");
  o = {};
  o.znear = 2.0;
  o.zfar = 1.0;
  expectError(o, "--zfar");
  o = {};
  o.yfovDegrees = 180.0;
  expectError(o, "--yfov");
  o = {};
  o.eye = glm::dvec3(1, 2, 3);
  o.target = glm::dvec3(1, 2, 3);
  expectError(o, "--target");
  o = {};
  o.up = glm::dvec3(0, 0, 1);  // parallel to the default view direction
  expectError(o, "--up");
  EXPECT_THROW(makeCamera(s, {}, 0, 10), InputError);
}

}  // namespace
}  // namespace rastray
