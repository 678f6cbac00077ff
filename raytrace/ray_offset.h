// Robust origins for secondary rays: no self-intersection, no magic epsilon.
//
// Method: Wächter & Binder, "A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems (2019), chapter 6. The hit point is
// rebuilt from the barycentrics (common/surface.h does that, in double;
// it is rounded to float here, the precision Embree traces in), then moved
// along the geometric normal by a fixed number of float ULPs per
// component (int_scale · n), so the offset scales with the magnitude of
// the coordinate: far from the origin it grows with the float spacing, and
// the ray cannot re-hit the surface it leaves. Components within `origin`
// of zero, where ULP steps become tiny (denormals), are offset by a fixed
// float_scale · n instead. The constants are the published ones.
//
// Side: the caller passes the normal of the side the new ray leaves on
// (+geometric normal for rays leaving through the front face, −geometric
// normal otherwise), see offsetSideNormal().
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>

namespace rastray {

struct RayOffsetConstants {
  static constexpr float kOrigin = 1.0f / 32.0f;         // below this |p|: fixed offset
  static constexpr float kFloatScale = 1.0f / 65536.0f;  // the fixed offset per unit normal
  static constexpr float kIntScale = 256.0f;             // ULPs per unit normal
};

namespace detail {
inline int32_t floatBits(float f) {
  int32_t i;
  std::memcpy(&i, &f, sizeof i);
  return i;
}
inline float bitsFloat(int32_t i) {
  float f;
  std::memcpy(&f, &i, sizeof f);
  return f;
}
}  // namespace detail

// Ray Tracing Gems ch. 6 `offset_ray`: the origin of a ray leaving point p
// on the side of unit normal n.
inline glm::vec3 offsetRayOrigin(const glm::vec3& p, const glm::vec3& n) {
  using C = RayOffsetConstants;
  glm::vec3 out;
  for (int k = 0; k < 3; ++k) {
    // Moving the integer representation by ±ofs changes the float by ofs
    // ULPs away from (or towards) zero, whichever the normal asks for.
    const int32_t ofs = static_cast<int32_t>(C::kIntScale * n[k]);
    const float pi = detail::bitsFloat(detail::floatBits(p[k]) + (p[k] < 0.0f ? -ofs : ofs));
    out[k] = std::fabs(p[k]) < C::kOrigin ? p[k] + C::kFloatScale * n[k] : pi;
  }
  return out;
}

// The normal of the side a ray with this direction leaves on: the
// geometric normal if it leaves through the front (CCW) face, else its
// negation.
inline glm::dvec3 offsetSideNormal(const glm::dvec3& geometricNormal, const glm::dvec3& direction) {
  return glm::dot(direction, geometricNormal) >= 0.0 ? geometricNormal : -geometricNormal;
}

}  // namespace rastray
