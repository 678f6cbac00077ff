#include "common/camera.h"

#include <cmath>

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
