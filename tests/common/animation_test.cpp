// Animation frames (issue 22 item 3): sampling (STEP, LINEAR with slerp,
// CUBICSPLINE, clamping), node TRS channels, skins and morph targets as
// the loader flattens them at --time, and the refusal of bad animation
// data. The files are written here: glTF JSON and a .bin buffer beside it.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/gltf/animation.h"
#include "common/gltf/loader.h"
#include "common/scene.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using json = nlohmann::json;

// A glTF document under construction with one buffer: accessors are
// appended to the buffer (4-byte aligned), each in a bufferView of its own.
struct GltfBuilder {
  json doc = {{"asset", {{"version", "2.0"}}}};
  std::vector<uint8_t> bin;

  int accessor(const void* data, size_t bytes, size_t count, const char* type, int componentType,
               bool normalized = false) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t offset = bin.size();
    bin.resize(offset + bytes);
    std::memcpy(bin.data() + offset, data, bytes);
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
    json a = {{"bufferView", doc["bufferViews"].size() - 1},
              {"componentType", componentType},
              {"count", count},
              {"type", type}};
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return int(doc["accessors"].size() - 1);
  }
  int floats(const std::vector<float>& v, const char* type) {
    const size_t n = std::string(type) == "SCALAR" ? 1
                     : std::string(type) == "VEC3" ? 3
                     : std::string(type) == "VEC4" ? 4
                                                   : 16;
    return accessor(v.data(), v.size() * 4, v.size() / n, type, 5126);
  }
  int u16(const std::vector<uint16_t>& v, const char* type) {
    const size_t n = std::string(type) == "SCALAR" ? 1 : 4;
    return accessor(v.data(), v.size() * 2, v.size() / n, type, 5123);
  }
  // One node with a mesh of one TRIANGLES primitive; returns the node.
  int meshNode(const std::vector<float>& positions, const std::vector<uint16_t>& indices,
               json extraAttributes = {}, const std::vector<float>& normals = {}) {
    json attributes = extraAttributes.is_null() ? json::object() : extraAttributes;
    attributes["POSITION"] = floats(positions, "VEC3");
    if (!normals.empty()) attributes["NORMAL"] = floats(normals, "VEC3");
    doc["meshes"].push_back(
        {{"primitives", {{{"attributes", attributes}, {"indices", u16(indices, "SCALAR")}}}}});
    doc["nodes"].push_back({{"mesh", doc["meshes"].size() - 1}});
    return int(doc["nodes"].size() - 1);
  }
  // An animation of one channel; returns the animation's index.
  int animate(int node, const char* path, const std::vector<float>& times, const std::vector<float>& values,
              const char* type, const char* interpolation = "LINEAR") {
    const int input = floats(times, "SCALAR");
    const int output = floats(values, type);
    doc["animations"].push_back(
        {{"samplers", {{{"input", input}, {"output", output}, {"interpolation", interpolation}}}},
         {"channels", {{{"sampler", 0}, {"target", {{"node", node}, {"path", path}}}}}}});
    return int(doc["animations"].size() - 1);
  }
  std::string write(const std::string& name) const {
    const std::string path = test::scratchPath(name + ".gltf");
    json d = doc;
    d["buffers"] = {{{"uri", name + ".bin"}, {"byteLength", bin.size()}}};
    if (!d.contains("scenes")) {
      d["scenes"] = {{{"nodes", json::array()}}};
      for (size_t i = 0; i < d["nodes"].size(); ++i) d["scenes"][0]["nodes"].push_back(i);
    }
    std::ofstream(path) << d.dump();
    std::ofstream(test::scratchPath(name + ".bin"), std::ios::binary)
        .write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
    return path;
  }
};

Scene loadAt(const std::string& path, std::optional<double> time, int animation = -1) {
  PoseRequest pose;
  pose.time = time;
  pose.animation = animation;
  return loadScene(path, MemoryBudget::machineDefault(), pose);
}

const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

// A triangle whose node's translation x follows one sampler: the first
// vertex's x is that value.
std::string translatedTriangle(const char* name, const std::vector<float>& times,
                               const std::vector<float>& xs, const char* interpolation) {
  GltfBuilder b;
  const int node = b.meshNode(kTriangle, {0, 1, 2});
  std::vector<float> values;
  for (float x : xs) values.insert(values.end(), {x, 0.0f, 0.0f});
  b.animate(node, "translation", times, values, "VEC3", interpolation);
  return b.write(name);
}

double xAt(const std::string& path, double t) { return loadAt(path, t).worldPositions[0].x; }

TEST(AnimationSampling, StepHoldsEachKeyUntilTheNext) {
  const std::string path = translatedTriangle("step", {0, 1, 2}, {0, 10, 20}, "STEP");
  EXPECT_EQ(xAt(path, -1.0), 0.0);  // before the first key: clamped
  EXPECT_EQ(xAt(path, 0.0), 0.0);
  EXPECT_EQ(xAt(path, 0.5), 0.0);
  EXPECT_EQ(xAt(path, 1.0), 10.0);  // exactly on a key: that key
  EXPECT_EQ(xAt(path, 1.999), 10.0);
  EXPECT_EQ(xAt(path, 2.0), 20.0);
  EXPECT_EQ(xAt(path, 7.0), 20.0);  // after the last: clamped
}

TEST(AnimationSampling, LinearInterpolatesBetweenKeys) {
  const std::string path = translatedTriangle("linear", {0, 1, 3}, {0, 10, 30}, "LINEAR");
  EXPECT_EQ(xAt(path, -2.0), 0.0);
  EXPECT_EQ(xAt(path, 0.0), 0.0);
  EXPECT_NEAR(xAt(path, 0.25), 2.5, 1e-12);
  EXPECT_EQ(xAt(path, 1.0), 10.0);
  EXPECT_NEAR(xAt(path, 2.5), 25.0, 1e-12);
  EXPECT_EQ(xAt(path, 3.0), 30.0);
  EXPECT_EQ(xAt(path, 3.5), 30.0);
  // Without --time no animation plays: the node's own (absent) translation.
  EXPECT_EQ(loadAt(path, std::nullopt).worldPositions[0].x, 0.0);
}

// CUBICSPLINE keys (in-tangent, value, out-tangent), tangents per second:
// x(0) = 0 with out-tangent 1, x(2) = 4 with in-tangent 3 is the cubic
// x(t) = t²/2 + t (x' = t + 1). The first in-tangent and the last
// out-tangent are never used (99).
TEST(AnimationSampling, CubicSplineFollowsTheHermiteCurveWithTangentsScaledByTheInterval) {
  GltfBuilder b;
  const int node = b.meshNode(kTriangle, {0, 1, 2});
  b.animate(node, "translation", {0, 2}, {99, 0, 0, 0, 0, 0, 1, 0, 0, 3, 0, 0, 4, 0, 0, 99, 0, 0}, "VEC3",
            "CUBICSPLINE");
  const std::string path = b.write("cubic");
  const auto x = [](double t) { return t * t / 2 + t; };
  for (double t : {0.0, 0.5, 1.0, 1.5, 2.0}) EXPECT_NEAR(xAt(path, t), x(t), 1e-6) << "t = " << t;
  EXPECT_EQ(xAt(path, -1.0), 0.0);
  EXPECT_EQ(xAt(path, 9.0), 4.0);
}

// Slerp against a hand-computed quaternion: a third of the way from the
// identity to 90° about +Z is 30° about +Z, (0, 0, sin 15°, cos 15°).
// A normalised lerp would give 28.3°.
TEST(AnimationSampling, SlerpOfAQuarterTurn) {
  const double s45 = std::sqrt(0.5);
  const glm::dquat q = slerpShortest(glm::dquat(1, 0, 0, 0), glm::dquat(s45, 0, 0, s45), 1.0 / 3.0);
  const double half = 15.0 * 3.14159265358979323846 / 180.0;
  EXPECT_NEAR(q.w, std::cos(half), 1e-12);
  EXPECT_NEAR(q.z, std::sin(half), 1e-12);
  EXPECT_NEAR(q.x, 0.0, 1e-15);
  EXPECT_NEAR(q.y, 0.0, 1e-15);
  // −b is the same rotation: the shorter arc gives the same result.
  const glm::dquat r = slerpShortest(glm::dquat(1, 0, 0, 0), -glm::dquat(s45, 0, 0, s45), 1.0 / 3.0);
  EXPECT_NEAR(r.w, q.w, 1e-12);
  EXPECT_NEAR(r.z, q.z, 1e-12);
}

TEST(AnimationSampling, RotationChannelSlerpsAndNormalises) {
  GltfBuilder b;
  const int node = b.meshNode(kTriangle, {0, 1, 2});
  const float s45 = float(std::sqrt(0.5));
  // Key 1 has length 2: rotation results are normalised.
  b.animate(node, "rotation", {0, 3}, {0, 0, 0, 1, 0, 0, 2 * s45, 2 * s45}, "VEC4");
  const std::string path = b.write("rotation");
  const Scene s = loadAt(path, 1.0);
  const glm::dvec3 p = s.worldPositions[1];  // (1, 0, 0) turned by 30°
  const double a = 30.0 * 3.14159265358979323846 / 180.0;
  EXPECT_NEAR(p.x, std::cos(a), 1e-6);
  EXPECT_NEAR(p.y, std::sin(a), 1e-6);
  const glm::dvec3 end = loadAt(path, 3.0).worldPositions[1];
  EXPECT_NEAR(end.x, 0.0, 1e-6);
  EXPECT_NEAR(end.y, 1.0, 1e-6);
}

// A two-joint skin: joint 0 (node 1) at the origin, joint 1 (node 2, its
// child) at (0, 1, 0), bound there (inverse bind T(0, −1, 0)). Animation 0
// turns joint 1 by 90° about +Z over one second; animation 1 scales joint
// 0 by (2, 1, 1). Vertex 0 (1, 0, 0) follows joint 0, vertex 1 (1, 2, 0)
// joint 1, vertex 2 (0, 2, 0) both by halves. The mesh node's own
// translation (5, 0, 0) is ignored, as glTF requires for skinned meshes.
std::string twoJointSkin() {
  GltfBuilder b;
  const float r = float(1 / std::sqrt(2.0));
  const int joints = b.u16({0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, "VEC4");
  const int weights = b.floats({1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0}, "VEC4");
  b.meshNode({1, 0, 0, 1, 2, 0, 0, 2, 0}, {0, 1, 2}, {{"JOINTS_0", joints}, {"WEIGHTS_0", weights}},
             {r, r, 0, 1, 0, 0, 0, 1, 0});
  b.doc["nodes"][0]["skin"] = 0;
  b.doc["nodes"][0]["translation"] = {5, 0, 0};
  b.doc["nodes"].push_back({{"children", {2}}});                              // node 1: joint 0
  b.doc["nodes"].push_back({{"translation", {0, 1, 0}}});                     // node 2: joint 1
  const int ibm = b.floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0,  0, 1,  //
                            1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1},
                           "MAT4");
  b.doc["skins"] = {{{"joints", {1, 2}}, {"inverseBindMatrices", ibm}}};
  b.doc["scenes"] = {{{"nodes", {0, 1}}}};
  b.animate(2, "rotation", {0, 1}, {0, 0, 0, 1, 0, 0, r, r}, "VEC4");
  b.animate(1, "scale", {0, 1}, {1, 1, 1, 2, 1, 1}, "VEC3");
  return b.write("skin");
}

void expectNear(const glm::dvec3& a, const glm::dvec3& b, const char* what) {
  EXPECT_NEAR(a.x, b.x, 1e-6) << what;
  EXPECT_NEAR(a.y, b.y, 1e-6) << what;
  EXPECT_NEAR(a.z, b.z, 1e-6) << what;
}

TEST(Skin, TwoJointsPlaceTheVerticesAtTheKnownPose) {
  const std::string path = twoJointSkin();
  // The bind pose: every vertex where the file has it, the node's
  // translation ignored.
  const Scene rest = loadAt(path, std::nullopt);
  ASSERT_EQ(rest.instances.size(), 1u);
  EXPECT_TRUE(rest.instances[0].skinned);
  expectNear(rest.worldPositions[0], {1, 0, 0}, "rest v0");
  expectNear(rest.worldPositions[1], {1, 2, 0}, "rest v1");
  expectNear(rest.worldPositions[2], {0, 2, 0}, "rest v2");
  // Joint 1 turned by 90°: (1, 2, 0) → (−1, 2, 0) about (0, 1, 0); vertex 2
  // blends (0, 2, 0) and (−1, 1, 0).
  const Scene turned = loadAt(path, 1.0, 0);
  expectNear(turned.worldPositions[0], {1, 0, 0}, "turned v0");
  expectNear(turned.worldPositions[1], {-1, 2, 0}, "turned v1");
  expectNear(turned.worldPositions[2], {-0.5, 1.5, 0}, "turned v2");
  expectNear(glm::dvec3(turned.normals[1]), {0, 1, 0}, "turned n1");  // (1, 0, 0) turned
  // Both animations: joint 0's scale (2, 1, 1) applies to joint 1 too.
  const Scene both = loadAt(path, 1.0);
  expectNear(both.worldPositions[0], {2, 0, 0}, "both v0");
  expectNear(both.worldPositions[1], {-2, 2, 0}, "both v1");
  // Normals by the inverse transpose, renormalised: (1, 1, 0)/√2 under
  // scale (2, 1, 1) is (1/2, 1, 0), normalised.
  const Scene scaled = loadAt(path, 1.0, 1);
  expectNear(glm::dvec3(scaled.normals[0]), glm::normalize(glm::dvec3(0.5, 1, 0)), "scaled n0");
  expectNear(scaled.worldPositions[1], {2, 2, 0}, "scaled v1");
}

// A unit cube (8 vertices) with two morph targets: target 0 lifts the top
// face (y = 1) by 1, target 1 pushes the +x face out by 1 and tilts the
// normal of vertex 0. Weights: the mesh's [0.5, 0], the node's [0.25, 1]
// overriding them, an animated weights channel overriding both.
std::string morphCube(bool nodeWeights, bool animated) {
  GltfBuilder b;
  std::vector<float> positions, normals, lift, push, tilt;
  for (int i = 0; i < 8; ++i) {
    const float x = float(i & 1), y = float((i >> 1) & 1), z = float((i >> 2) & 1);
    positions.insert(positions.end(), {x, y, z});
    normals.insert(normals.end(), {0, 0, 1});
    lift.insert(lift.end(), {0, y, 0});
    push.insert(push.end(), {x, 0, 0});
    tilt.insert(tilt.end(), {i == 0 ? 1.0f : 0.0f, 0, 0});
  }
  const std::vector<uint16_t> indices = {0, 1, 3, 0, 3, 2, 4, 7, 5, 4, 6, 7, 0, 4, 5, 0, 5, 1,
                                         2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};
  b.meshNode(positions, indices, {}, normals);
  const int liftAccessor = b.floats(lift, "VEC3");
  const int pushAccessor = b.floats(push, "VEC3");
  const int tiltAccessor = b.floats(tilt, "VEC3");
  b.doc["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", liftAccessor}},
                                                    {{"POSITION", pushAccessor}, {"NORMAL", tiltAccessor}}};
  b.doc["meshes"][0]["weights"] = {0.5, 0};
  if (nodeWeights) b.doc["nodes"][0]["weights"] = {0.25, 1};
  if (animated) b.animate(0, "weights", {0, 2}, {0, 0, 1, 0.5f}, "SCALAR");
  return b.write(std::string("morph") + (nodeWeights ? "-node" : "") + (animated ? "-animated" : ""));
}

TEST(MorphTargets, CubeMovesByTheKnownWeights) {
  // Vertex 3 is (1, 1, 0): lifted by target 0 and pushed by target 1.
  const Scene mesh = loadAt(morphCube(false, false), std::nullopt);
  EXPECT_TRUE(mesh.instances[0].morphed);
  expectNear(mesh.worldPositions[3], {1, 1.5, 0}, "mesh weights");
  expectNear(mesh.worldPositions[0], {0, 0, 0}, "mesh weights v0");
  const Scene node = loadAt(morphCube(true, false), std::nullopt);
  expectNear(node.worldPositions[3], {2, 1.25, 0}, "node weights override the mesh's");
  // Vertex 0's normal (0, 0, 1) + 1 × (1, 0, 0), renormalised.
  expectNear(glm::dvec3(node.normals[0]), glm::normalize(glm::dvec3(1, 0, 1)), "normal delta");
  // Animated at t = 1 (halfway): weights (0.5, 0.25) override the node's.
  const std::string animated = morphCube(true, true);
  expectNear(loadAt(animated, 1.0).worldPositions[3], {1.25, 1.5, 0}, "animated weights");
  expectNear(loadAt(animated, 5.0).worldPositions[3], {1.5, 2, 0}, "animated, clamped");
  expectNear(loadAt(animated, std::nullopt).worldPositions[3], {2, 1.25, 0}, "not playing: node weights");
}

TEST(Animation, SummariesListNamesChannelsAndKeyRanges) {
  GltfBuilder b;
  const int node = b.meshNode(kTriangle, {0, 1, 2});
  b.animate(node, "translation", {0.5f, 2.5f}, {0, 0, 0, 1, 0, 0}, "VEC3");
  b.doc["animations"][0]["name"] = "Slide";
  const Scene s = loadAt(b.write("summary"), std::nullopt);
  ASSERT_EQ(s.animations.size(), 1u);
  EXPECT_EQ(s.animations[0].name, "Slide");
  EXPECT_EQ(s.animations[0].channels, 1u);
  EXPECT_EQ(s.animations[0].start, 0.5);
  EXPECT_EQ(s.animations[0].end, 2.5);
  // Played animations are not listed as ignored.
  for (const IgnoredFeature& f : s.ignored) EXPECT_EQ(f.feature.find("animation"), std::string::npos);
}

// tests/data/malformed/valid/animated.gltf (a fuzz seed): STEP translation
// of the skin's root joint, LINEAR rotation of its child, CUBICSPLINE
// morph weights with zero tangents (smoothstep between keys).
TEST(Animation, GeneratedSeedPlaysEveryKind) {
  const std::string path = test::testDataPath("malformed/valid/animated.gltf");
  struct Case {
    double time;
    glm::dvec3 lo, hi;
  };
  for (const Case& c : {Case{0.0, {0, 0, 0}, {1, 1, 0}}, Case{1.0, {0.5, 0, 1}, {1.5, 1.5, 1}},
                        Case{0.5, {0, 0, 0.5}, {1, 1 + 0.5 * std::sqrt(0.5), 0.5}},
                        Case{9.0, {0, 0.5, 0.5}, {1, 1.5, 0.5}}}) {
    const Scene s = loadAt(path, c.time);
    expectNear(s.bounds.lo, c.lo, "lo");
    expectNear(s.bounds.hi, c.hi, "hi");
  }
}

// ---- refusals: one InputError naming the file and the element ----------

std::string refusal(const std::string& path, std::optional<double> time = 0.0, int animation = -1) {
  try {
    loadAt(path, time, animation);
  } catch (const InputError& e) {
    if (e.file() != "command line") {
      EXPECT_EQ(e.file(), path);  // braces: gtest's macro is an if-else (-Wdangling-else)
    }
    return e.element() + ": " + e.message();
  }
  return "accepted";
}

TEST(AnimationRefusals, InputTimesNotIncreasing) {
  const std::string path = translatedTriangle("decreasing", {0, 1, 1, 2}, {0, 1, 2, 3}, "LINEAR");
  EXPECT_EQ(refusal(path), "animation 0 sampler 0: input times not increasing at key 2");
  // Refused whether or not it plays.
  EXPECT_EQ(refusal(path, std::nullopt), "animation 0 sampler 0: input times not increasing at key 2");
}

TEST(AnimationRefusals, OutputTooShortOrMismatched) {
  GltfBuilder b;
  const int node = b.meshNode(kTriangle, {0, 1, 2});
  b.animate(node, "translation", {0, 1, 2}, {0, 0, 0, 1, 0, 0}, "VEC3");
  EXPECT_EQ(refusal(b.write("short")),
            "animation 0 sampler 0: output too short: 2 values for 3 input keys (3 needed)");
  GltfBuilder c;
  const int n = c.meshNode(kTriangle, {0, 1, 2});
  c.animate(n, "translation", {0, 1}, {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4, 0, 0, 5, 0, 0, 6, 0, 0}, "VEC3",
            "CUBICSPLINE");
  EXPECT_EQ(
      refusal(c.write("cubic-count")),
      "animation 0 sampler 0: output count mismatch: 7 values for 2 input keys (CUBICSPLINE needs 3 per "
      "key: 6 needed)");
}

TEST(AnimationRefusals, NaNAndInfiniteKeyframes) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::string path = translatedTriangle("nan", {0, 1}, {0, nan}, "LINEAR");
  EXPECT_NE(refusal(path).find("animation 0 sampler 0 output (accessor 3): element 1 component 0 is NaN"),
            std::string::npos)
      << refusal(path);
  const std::string inf =
      translatedTriangle("inf", {0, std::numeric_limits<float>::infinity()}, {0, 1}, "LINEAR");
  EXPECT_NE(refusal(inf).find("animation 0 sampler 0 input (accessor 2): element 1 component 0 is infinite"),
            std::string::npos)
      << refusal(inf);
}

TEST(AnimationRefusals, BadInterpolationAndMissingNode) {
  std::string path = translatedTriangle("interp", {0, 1}, {0, 1}, "LINEAR");
  json doc = json::parse(test::slurp(path));
  doc["animations"][0]["samplers"][0]["interpolation"] = "SMOOTH";
  std::ofstream(path) << doc.dump();
  EXPECT_EQ(refusal(path),
            "animation 0 sampler 0: \"interpolation\" \"SMOOTH\" is not STEP, LINEAR or CUBICSPLINE");
  doc["animations"][0]["samplers"][0]["interpolation"] = "STEP";
  doc["animations"][0]["channels"][0]["target"]["node"] = 7;
  std::ofstream(path) << doc.dump();
  EXPECT_EQ(refusal(path),
            "animation 0 channel 0 target: \"node\" refers to node 7, which does not exist (1 nodes)");
}

TEST(AnimationRefusals, SkinJointsOutOfRangeAndSkinWithoutJoints) {
  std::string path = twoJointSkin();
  json doc = json::parse(test::slurp(path));
  doc["skins"][0]["joints"] = {1};  // vertex 1 names joint 1
  std::ofstream(path) << doc.dump();
  EXPECT_EQ(refusal(path),
            "mesh 0 primitive 0 JOINTS_0 (accessor 0): vertex 1 names joint 1; skin 0 has 1 joints");
  doc["skins"][0]["joints"] = json::array();
  std::ofstream(path) << doc.dump();
  EXPECT_EQ(refusal(path), "skin 0: has no joints");
}

TEST(AnimationRefusals, NaNSkinWeightsAndWrongMorphWeightCount) {
  GltfBuilder b;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int joints = b.u16({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, "VEC4");
  const int weights = b.floats({1, 0, 0, 0, nan, 0, 0, 0, 1, 0, 0, 0}, "VEC4");
  b.meshNode(kTriangle, {0, 1, 2}, {{"JOINTS_0", joints}, {"WEIGHTS_0", weights}});
  b.doc["nodes"][0]["skin"] = 0;
  b.doc["nodes"].push_back(json::object());
  b.doc["skins"] = {{{"joints", {1}}}};
  EXPECT_EQ(refusal(b.write("nan-weights"), std::nullopt),
            "mesh 0 primitive 0 WEIGHTS_0 (accessor 1): element 1 component 0 is NaN");
  GltfBuilder z;
  const int zj = z.u16({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, "VEC4");
  const int zw = z.floats({1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0}, "VEC4");
  z.meshNode(kTriangle, {0, 1, 2}, {{"JOINTS_0", zj}, {"WEIGHTS_0", zw}});
  z.doc["nodes"][0]["skin"] = 0;
  z.doc["nodes"].push_back(json::object());
  z.doc["skins"] = {{{"joints", {1}}}};
  EXPECT_EQ(refusal(z.write("zero-weights"), std::nullopt),
            "mesh 0 primitive 0 WEIGHTS_0 (accessor 1): vertex 1 has weights summing to 0");
  std::string morph = morphCube(true, false);
  json doc = json::parse(test::slurp(morph));
  doc["nodes"][0]["weights"] = {0.5, 0.5, 0.5};
  std::ofstream(morph) << doc.dump();
  EXPECT_EQ(refusal(morph, std::nullopt), "mesh 0: node 0 \"weights\" has 3 entries for 2 morph targets");
}

TEST(AnimationRefusals, AnimationIndexBeyondTheFile) {
  const std::string path = translatedTriangle("index", {0, 1}, {0, 1}, "LINEAR");
  EXPECT_EQ(refusal(path, 0.5, 3), "--animation: animation 3 does not exist: " + path + " has 1 animation");
}

}  // namespace
}  // namespace rastray
