#include "common/gltf/animation.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace rastray {

std::optional<Interpolation> parseInterpolation(const std::string& name) {
  if (name == "STEP") return Interpolation::Step;
  if (name == "LINEAR") return Interpolation::Linear;
  if (name == "CUBICSPLINE") return Interpolation::CubicSpline;
  return std::nullopt;
}

std::optional<AnimatedProperty> parseAnimatedProperty(const std::string& name) {
  if (name == "translation") return AnimatedProperty::Translation;
  if (name == "rotation") return AnimatedProperty::Rotation;
  if (name == "scale") return AnimatedProperty::Scale;
  if (name == "weights") return AnimatedProperty::Weights;
  return std::nullopt;
}

AnimationSummary Animation::summary() const {
  AnimationSummary s;
  s.name = name;
  s.channels = uint32_t(channels.size());
  s.samplers = uint32_t(samplers.size());
  bool any = false;
  for (const AnimationSampler& sampler : samplers) {
    if (sampler.input.empty()) continue;
    s.start = any ? std::min(s.start, sampler.input.front()) : sampler.input.front();
    s.end = any ? std::max(s.end, sampler.input.back()) : sampler.input.back();
    any = true;
  }
  return s;
}

void checkAnimationSampler(const AnimationSampler& s, const std::string& file, const std::string& element) {
  const auto fail = [&](const std::string& message) { throw InputError(file, element, message); };
  if (s.input.empty()) fail("input has no keys");
  for (size_t k = 0; k < s.input.size(); ++k) {
    if (!std::isfinite(s.input[k]))
      fail("input time at key " + std::to_string(k) + " is " + (std::isnan(s.input[k]) ? "NaN" : "infinite"));
    if (k > 0 && !(s.input[k] > s.input[k - 1]))
      fail("input times not increasing at key " + std::to_string(k));
  }
  for (size_t i = 0; i < s.output.size(); ++i)
    if (!std::isfinite(s.output[i]))
      fail("output value " + std::to_string(i) + " is " + (std::isnan(s.output[i]) ? "NaN" : "infinite"));
  const size_t perKey = s.interpolation == Interpolation::CubicSpline ? 3 : 1;
  const size_t needed = s.input.size() * perKey * s.width;
  if (s.width == 0 || s.output.size() != needed) {
    const std::string have = std::to_string(s.width ? s.output.size() / s.width : s.output.size());
    fail(std::string("output ") + (s.output.size() < needed ? "too short" : "count mismatch") + ": " + have +
         " values for " + std::to_string(s.input.size()) + " input keys (" +
         (perKey == 3 ? "CUBICSPLINE needs 3 per key: " : "") + std::to_string(s.input.size() * perKey) +
         " needed)");
  }
}

glm::dquat slerpShortest(const glm::dquat& a, const glm::dquat& bIn, double u) {
  glm::dquat b = bIn;
  double d = glm::dot(a, b);
  if (d < 0.0) {  // q and −q are one rotation: take the shorter arc
    b = -b;
    d = -d;
  }
  glm::dquat r;
  if (d > 1.0 - 1e-12) {
    r = a * (1.0 - u) + b * u;  // nearly parallel: sin θ ≈ 0, lerp is exact to rounding
  } else {
    const double theta = std::acos(std::min(d, 1.0));
    const double s = std::sin(theta);
    r = a * (std::sin((1.0 - u) * theta) / s) + b * (std::sin(u * theta) / s);
  }
  return glm::normalize(r);
}

namespace {

// A key's quaternion, normalised: exporters round, and slerp's angle
// assumes unit length (the builder refuses zero keys).
glm::dquat quatAt(const double* v) { return glm::normalize(glm::dquat(v[3], v[0], v[1], v[2])); }

}  // namespace

std::vector<double> sampleAt(const AnimationSampler& s, double t, bool rotation) {
  const size_t w = s.width;
  const size_t keys = s.input.size();
  const bool cubic = s.interpolation == Interpolation::CubicSpline;
  // The value of key k (CUBICSPLINE: the middle of its triple).
  const auto value = [&](size_t k) { return s.output.data() + (cubic ? (3 * k + 1) * w : k * w); };
  std::vector<double> out(w);
  const auto normalised = [&](std::vector<double> v) {
    if (!rotation) return v;
    double n = 0.0;
    for (double x : v) n += x * x;
    n = std::sqrt(n);
    if (n > 0.0)
      for (double& x : v) x /= n;
    return v;
  };
  // Clamp outside the keys (glTF §3.11).
  if (keys == 1 || t <= s.input.front()) return normalised(std::vector<double>(value(0), value(0) + w));
  if (t >= s.input.back()) return normalised(std::vector<double>(value(keys - 1), value(keys - 1) + w));
  // The interval [k, k + 1] holding t: the first key after t, minus one.
  const size_t k = size_t(std::upper_bound(s.input.begin(), s.input.end(), t) - s.input.begin()) - 1;
  const double t0 = s.input[k], t1 = s.input[k + 1];
  const double dt = t1 - t0;
  const double u = (t - t0) / dt;
  const double* a = value(k);
  const double* b = value(k + 1);
  switch (s.interpolation) {
    case Interpolation::Step:
      out.assign(a, a + w);
      break;
    case Interpolation::Linear:
      if (rotation) {
        const glm::dquat q = slerpShortest(quatAt(a), quatAt(b), u);
        return {q.x, q.y, q.z, q.w};
      }
      for (size_t i = 0; i < w; ++i) out[i] = a[i] + (b[i] - a[i]) * u;
      break;
    case Interpolation::CubicSpline: {
      // Hermite basis (Appendix C): p(u) = (2u³ − 3u² + 1)·v_k + (u³ − 2u² + u)·dt·b_k
      //                                + (−2u³ + 3u²)·v_k+1 + (u³ − u²)·dt·a_k+1,
      // b_k the out-tangent of key k, a_k+1 the in-tangent of key k + 1.
      const double* outTangent = s.output.data() + (3 * k + 2) * w;
      const double* inTangent = s.output.data() + (3 * (k + 1)) * w;
      const double u2 = u * u, u3 = u2 * u;
      const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
      for (size_t i = 0; i < w; ++i)
        out[i] = h00 * a[i] + h10 * dt * outTangent[i] + h01 * b[i] + h11 * dt * inTangent[i];
      break;
    }
  }
  return normalised(std::move(out));
}

std::vector<NodePose> poseAt(const std::vector<Animation>& animations, const PoseRequest& request,
                             size_t nodeCount) {
  std::vector<NodePose> pose(nodeCount);
  if (!request.time) return pose;
  for (size_t a = 0; a < animations.size(); ++a) {
    if (request.animation >= 0 && size_t(request.animation) != a) continue;
    for (const AnimationChannel& c : animations[a].channels) {
      const AnimationSampler& s = animations[a].samplers[c.sampler];
      const bool rotation = c.property == AnimatedProperty::Rotation;
      const std::vector<double> v = sampleAt(s, *request.time, rotation);
      NodePose& p = pose[c.node];
      switch (c.property) {
        case AnimatedProperty::Translation:
          p.translation = glm::dvec3(v[0], v[1], v[2]);
          break;
        case AnimatedProperty::Rotation:
          p.rotation = glm::dquat(v[3], v[0], v[1], v[2]);
          break;
        case AnimatedProperty::Scale:
          p.scale = glm::dvec3(v[0], v[1], v[2]);
          break;
        case AnimatedProperty::Weights:
          p.weights = v;
          break;
      }
    }
  }
  return pose;
}

}  // namespace rastray
