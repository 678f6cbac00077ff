// glTF animations sampled at a time (glTF 2.0 §3.11 and Appendix C), and
// the pose they give the nodes. The scene builder (scene_builder.cpp) reads
// the samplers from the file, checks them with checkAnimationSampler, asks
// poseAt for the pose a PoseRequest names (common/scene.h: --time,
// --animation) and flattens the scene once at that pose, skins and morph
// targets applied, so both renderers see the same geometry.
//
// Conventions
// - Time in seconds, double. Outside a sampler's key range its value is
//   clamped to the first or last key (the spec's rule).
// - Quaternions are glm::dquat (w, x, y, z); glTF stores (x, y, z, w).
//   Rotation results are normalised: LINEAR rotation is a slerp on the
//   shorter arc, STEP and CUBICSPLINE results are renormalised.
// - CUBICSPLINE keys are (in-tangent, value, out-tangent) triples; the
//   tangents are scaled by the interval between the two keys (Appendix C).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "common/scene.h"

namespace rastray {

enum class Interpolation { Step, Linear, CubicSpline };
enum class AnimatedProperty { Translation, Rotation, Scale, Weights };

// "STEP", "LINEAR", "CUBICSPLINE"; nullopt for anything else.
std::optional<Interpolation> parseInterpolation(const std::string& name);
// "translation", "rotation", "scale", "weights"; nullopt for anything else.
std::optional<AnimatedProperty> parseAnimatedProperty(const std::string& name);

struct AnimationSampler {
  Interpolation interpolation = Interpolation::Linear;
  std::vector<double> input;  // key times, strictly increasing
  // Key values, `width` components each (3 translation and scale, 4
  // rotation as glTF's x, y, z, w, the target count for weights); for
  // CUBICSPLINE three per key: in-tangent, value, out-tangent.
  std::vector<double> output;
  size_t width = 0;
};

struct AnimationChannel {
  uint32_t sampler = 0;
  uint32_t node = 0;
  AnimatedProperty property = AnimatedProperty::Translation;
};

struct Animation {
  std::string name;
  std::vector<AnimationSampler> samplers;
  std::vector<AnimationChannel> channels;
  AnimationSummary summary() const;
};

// Throws InputError(file, element, ...) unless the sampler's keys are
// finite and strictly increasing and its output holds exactly one value
// (CUBICSPLINE: three) of `width` components per key. `element` names the
// sampler ("animation 0 sampler 1").
void checkAnimationSampler(const AnimationSampler& sampler, const std::string& file,
                           const std::string& element);

// The sampler's value at time `t` (width components). `rotation`: the
// value is a quaternion (x, y, z, w): LINEAR slerps, and the result is
// normalised.
std::vector<double> sampleAt(const AnimationSampler& sampler, double t, bool rotation);

// Spherical linear interpolation from a to b by u in [0, 1], on the
// shorter arc (b negated when a·b < 0); normalised.
glm::dquat slerpShortest(const glm::dquat& a, const glm::dquat& b, double u);

// What the played channels set on one node; unset parts keep the node's
// own TRS and weights.
struct NodePose {
  std::optional<glm::dvec3> translation;
  std::optional<glm::dquat> rotation;
  std::optional<glm::dvec3> scale;
  std::optional<std::vector<double>> weights;
};

// The pose at request.time, one entry per node: the channels of every
// animation (or only request.animation) in file order, a later channel on
// the same node and property overriding an earlier one. All entries are
// empty when request.time is nullopt. request.animation must be -1 or
// an index into `animations` (the builder checks it).
std::vector<NodePose> poseAt(const std::vector<Animation>& animations, const PoseRequest& request,
                             size_t nodeCount);

}  // namespace rastray
