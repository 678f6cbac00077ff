// Where secondary and shadow rays start: no self-intersection, no magic
// epsilon. Two methods (RayOptions::offset, --ray-offset):
//
// ErrorBound (default): from conservative error bounds of the actual
// intersection, after pbrt-v4 (Triangle::InteractionFromIntersection,
// OffsetRayOrigin), with bounds for OUR computation and for Embree's:
//
// 1. The hit point. SurfacePoint::position is b0·p0 + b1·p1 + b2·p2 in
//    double over the stored float vertices p_i (common/surface.cpp), with
//    b0 = 1 − b1 − b2 in double. Whatever the barycentrics' own error (the
//    renderer's u, v; refinement; clamping), exact barycentrics summing to
//    1 put the point exactly in the plane of the float triangle: their
//    error only slides it within that plane. What leaves the plane is the
//    arithmetic: per component k, the sum rounds each term at most three
//    times, |error| ≤ γ3·Σ|b_i·p_ik|, and b0 is off by at most
//    γ2·(1 + |b1| + |b2|), which moves the point by that times |p_0k|
//    (γn = n·2⁻⁵³ / (1 − n·2⁻⁵³), double). Along the unit normal n that is
//    dPos = Σ_k |n_k|·pError_k (pbrt's d = dot(|n|, pError)): about 1e-16
//    of the vertex magnitudes, against pbrt's γ7 of float arithmetic.
// 2. Embree's own error. Embree 3 in robust mode (RTC_SCENE_FLAG_ROBUST,
//    raytrace/embree_scene.cpp) intersects with its Plücker test in float:
//    it rounds the vertices relative to the ray origin o, v_i = fl(p_i − o),
//    builds the normal from rounded edges and takes T = 2·dot(v_0, Ng),
//    den = 2·dot(Ng, D), t = T·rcp(den), and accepts tnear = 0 ≤ t. In
//    exact arithmetic T/2 = det(p_0 − o, p_1 − o, p_2 − o) = −h·|N| for an
//    origin at height h above the plane on the front side (N = cross(p1 −
//    p0, p2 − p0)): T < 0 < den for a ray leaving the front, so t < 0 and
//    the surface is not hit again. Embree's T/2 differs from det by at
//    most B, so its sign is right once h·|N| > B, where with u = 2⁻²⁴
//      B = u·Σ_ik |w_ik·cof_ik| + 4u²·per|W| + 8u·Σ_k |w_0k|·C_k
//    (w_i = p_i − o, cof their cofactors: the first-order change of a 3×3
//    determinant when every entry moves by u of itself; C_k bounds the
//    products in component k of the cross product Embree takes, over both
//    edge pairs it may pick, covering the rounded edges, the cross and
//    the dot product), plus an absolute 2⁻¹¹⁸·(1 + ΣR + ΣC) for results
//    flushed to zero (traversal runs with FTZ/DAZ on). The bound measures
//    the triangle RELATIVE TO THE ORIGIN: it scales with the triangle's
//    size (and shape: about 8u·aspect ratio·size for slivers), not with
//    its distance from the world origin; an axis-aligned floor needs next
//    to nothing, since every term then carries the origin's tiny height.
// 3. The rounding to float. The target q = P + (dPos + dEmbree)·n is
//    rounded to the nearest float in each component but one, m, the axis
//    where a float step moves the point least (height excess plus the
//    sideways move the correction needs, see compensatingAxis). Far from
//    the origin a coarse component rounds by up to half its spacing (0.03
//    at 1e6); instead of pushing that outward along n (pbrt's
//    NextFloatUp/Down, up to a full spacing times |n_k|) the height their
//    rounding gained or lost is given back on axis m, which is rounded
//    outward. Then the float origin is
//    CHECKED against step 2 in double (leavesWithoutRehit) and axis m moves
//    outward until it passes, so the guarantee does not rest on the
//    estimate.
//    Result: height above the float triangle's plane ≥ Embree's bound and
//    ≥ 2⁻¹²⁰ (t stays a normal float), at most that plus one float
//    spacing of o_m times |n_m|. Measured over random points of a
//    20-unit triangle: level floor 3e-36 anywhere (every term carries the
//    tiny height); floor sloped 1:5 ≤ 4e-6 at the origin and with x, z at
//    1e6 alike; a tilted triangle ≤ 1e-5 at the origin, ≤ 0.055 when all
//    its coordinates are near 1e6 (float spacing 0.0625 on every axis:
//    --origin camera avoids that). The RTG offset there: 16 units.
//    Not covered: rays leaving within ~Embree's den error of the plane
//    (|cos| ≲ 1e-5·shape), where den's sign is uncertain (the light
//    weight there is that cos), and triangles whose products underflow
//    float (edges ≲ 1e-12). Degenerate triangles (no plane) use FloatUlps.
//
// FloatUlps: Wächter & Binder, Ray Tracing Gems (2019) ch. 6: the hit
// point rounded to float, moved by int(256·n_k) float ULPs per component
// (1/65536·n_k within 1/32 of zero). The offset scales with the hit
// point's own coordinates: 16 units along an axis normal at 1e6, so
// shadow rays start beyond nearby occluders. Kept to show that failure.
//
// Side: the caller passes the unit normal of the side the new ray leaves
// on (offsetSideNormal()).
//
// The shadow terminator (RayOptions::terminator, --terminator): on a
// low-poly mesh with interpolated normals, a point near the light's
// terminator is shaded as lit (shading normal towards the light) while its
// flat triangle faces away, so a ray leaving it runs into the mesh: the
// facets show as a jagged shadow edge. terminatorLift() moves the point off
// the flat triangle towards the smooth surface the normals describe, after
// Hanika, "Hacking the Shadow Terminator" (Ray Tracing Gems II, 2021, ch.
// 4): the point projected onto the tangent plane of each vertex (only where
// it lies below that plane), blended with the barycentrics. The lift is
// applied BEFORE step 3 above, so the float origin is still rounded and
// checked against Embree's bound for the triangle's plane: it only adds
// height, never removes the guarantee. What it moves: nothing on flat
// meshes (vertex normal = face normal gives a zero lift) nor on concave
// ones (the tangent planes then lie below the triangle); on convex ones at
// most max_i dot(p_i − P, n_i) ≤ edge length · sin(angle between a vertex
// normal and the face), e.g. 0.0086·r on a 24×16 UV sphere of radius r.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>

namespace rastray {

// The stored float vertices of one triangle, in stored order (the order
// Embree is given them).
using FloatTriangle = std::array<glm::vec3, 3>;

// ErrorBound: the origin of a ray leaving `position` (SurfacePoint::position,
// rebuilt from barycentrics (b1, b2) over `triangle`) on the side of unit
// normal `side`.
// `lift` (default none): a displacement of the point off the plane, on the
// side `side` points to (terminatorLift()); the origin is then checked at
// position + lift, as without it.
glm::vec3 errorBoundRayOrigin(const FloatTriangle& triangle, const glm::dvec3& position, float b1, float b2,
                              const glm::dvec3& side, const glm::dvec3& lift = glm::dvec3(0.0));

// errorBoundRayOrigin for n rays: out[k] = errorBoundRayOrigin(triangles[k],
// positions[k], b1[k], b2[k], sides[k], lifts[k]), bit for bit. The two
// Embree margins each origin needs (the estimate at the hit point, the
// check of the rounded origin) run 16 rays at a time in double SIMD lanes
// (ray_offset_lanes.h, every Highway target alike); an origin the check
// moves further continues alone.
void errorBoundRayOrigins(size_t n, const FloatTriangle* triangles, const glm::dvec3* positions,
                          const float* b1, const float* b2, const glm::dvec3* sides, const glm::dvec3* lifts,
                          glm::vec3* out);

// The unit vertex normals of one triangle, in stored order.
using VertexNormals = std::array<glm::vec3, 3>;

// Hanika's point on the smooth surface, as a displacement from `position`
// (b0·p0 + b1·p1 + b2·p2): Σ_i b_i · max(0, dot(p_i − P, s·n_i)) · s·n_i,
// with s = ±1 the side of the normals the ray leaves on (−1: a ray into
// the surface, e.g. refraction, lifted towards the back's tangent planes).
// Barycentrics are clamped to [0, 1]. In double from the float inputs:
// relative error ~1e-15 of the lift, which is itself 0 or positive along
// each s·n_i. Zero when every vertex normal is the face normal.
glm::dvec3 terminatorLift(const FloatTriangle& triangle, const VertexNormals& normals,
                          const glm::dvec3& position, double b1, double b2, double s);

// Whether a ray from position + lift along `direction`, where the lift is
// on the side of unit normal `liftSide` and the direction leaves through
// the other side, crosses the triangle's own plane inside the triangle
// (with a margin of 1e-5 in barycentrics): it would hit its own surface
// again, so the lift cannot be used for it.
bool liftedRayCrossesItsTriangle(const FloatTriangle& triangle, const glm::dvec3& position,
                                 const glm::dvec3& lift, const glm::dvec3& direction);

// Step 2 of the header for an origin `o` as Embree reads it (components
// below FLT_MIN are zero under DAZ): the side volume G = s·dot(o − p0, N)
// (s = ±1, the side `side` points to; G = height·|N|) and the bound B on
// Embree's error in T/2, both in the units of a determinant, and |N|.
struct EmbreeSideMargin {
  double volume = 0.0;
  double bound = 0.0;
  double normalLength = 0.0;
};
EmbreeSideMargin embreeSideMargin(const FloatTriangle& triangle, const glm::vec3& o, const glm::dvec3& side);

// Whether Embree's T has the side's sign, certified: G > B and the height
// G/|N| ≥ 2⁻¹²⁰ (so t = T/den does not flush to −0, which tnear 0 accepts).
bool leavesWithoutRehit(const FloatTriangle& triangle, const glm::vec3& o, const glm::dvec3& side);

// Whether Embree's den = 2·dot(Ng, D) has the sign of side·D, certified:
// true for every direction leaving more steeply than Embree's normal error
// (header, "not covered"). With leavesWithoutRehit, a ray from o along
// `direction` cannot hit the triangle again.
bool denominatorCertified(const FloatTriangle& triangle, const glm::vec3& o, const glm::dvec3& side,
                          const glm::vec3& direction);

// Concave seams. At a seam between two surfaces (a floor meeting a wall,
// a box standing on a floor) the hit point P lies on BOTH planes: on its
// own triangle T, and within its error on the neighbour N. The offset
// above lifts the origin off T's plane only, so it starts on N's plane or,
// by rounding, just behind it, and a ray leaving towards the room crosses
// N at t ≈ 0: a shadow ray is blocked by the wall it is leaving, and the
// seam shows as a dark 1-pixel line. In exact arithmetic a ray from a
// point on a plane meets that plane only at t = 0, so such a hit says
// nothing about occlusion: what decides is the side. Points of T near the
// seam lie on one side of N (seamSide); a ray going to that side leaves N
// and is not blocked by it, one going to the other side is (the light is
// behind N). The caster asks for the first hit of a blocked shadow ray (a
// radiance ray has it already); when it is such a seam neighbour, the
// origin moves off N's plane as well (offsetOffPlanes, the same certified
// margin as step 2) and the ray is traced again, up to three planes (a
// corner).

// How far from P a plane through P may pass and still be P's seam
// neighbour: the in-plane error of P (float barycentrics: 2⁻²⁴ of each
// edge, ×4 for margin) plus how far the origin `o` already moved from P,
// plus the double evaluation of a plane at coordinates of magnitude |P|.
double seamTolerance(const FloatTriangle& own, const glm::dvec3& position, const glm::vec3& o);

// The distance of `point` from the plane of `triangle`, in double (+inf
// when degenerate).
double planeDistance(const FloatTriangle& triangle, const glm::dvec3& point);

// The unit normal of the side of `other`'s plane that triangle `own` lies
// on (its vertex farthest from the plane decides); when `own` lies in that
// plane (coplanar neighbours), the side `direction` goes to.
glm::dvec3 seamSide(const FloatTriangle& own, const FloatTriangle& other, const glm::dvec3& direction);

// Moves float origin `o` along the sum of `sides` until every
// (triangles[i], sides[i]) pair is certified by leavesWithoutRehit; `o`
// unchanged when it already is, or when the sides admit no common
// direction.
glm::vec3 offsetOffPlanes(const FloatTriangle* triangles, const glm::dvec3* sides, size_t count, glm::vec3 o);

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

// FloatUlps: Ray Tracing Gems ch. 6 `offset_ray`, the origin of a ray
// leaving point p on the side of unit normal n.
inline glm::vec3 floatUlpsRayOrigin(const glm::vec3& p, const glm::vec3& n) {
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
