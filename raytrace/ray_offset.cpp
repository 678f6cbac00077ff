#include "raytrace/ray_offset.h"

#include <algorithm>
#include <cfloat>
#include <cstring>
#include <limits>

#include "raytrace/ray_offset_lanes.h"

namespace rastray {

namespace {

using detail::kEvalSlack;
using detail::kU;  // float unit roundoff: Embree's arithmetic
using detail::kUnderflow;
constexpr double kUd = 0x1p-53;  // double unit roundoff: ours
// The least height: t = T·rcp(den) ≈ −height/cos must stay a normal
// float, since FTZ would make it −0 and tnear 0 ≤ −0 holds.
constexpr double kMinHeight = 0x1p-120;

constexpr double kInf = std::numeric_limits<double>::infinity();

double gammaD(int n) { return n * kUd / (1.0 - n * kUd); }

// What Embree's traversal reads: DAZ turns inputs below FLT_MIN into 0.
float daz(float x) { return std::fabs(x) < FLT_MIN ? 0.0f : x; }
glm::dvec3 dazd(const glm::vec3& v) { return {daz(v.x), daz(v.y), daz(v.z)}; }

using Vertices = std::array<glm::dvec3, 3>;

Vertices verticesOf(const FloatTriangle& t) { return {dazd(t[0]), dazd(t[1]), dazd(t[2])}; }

// The spacing of floats around x as traversal sees them (no denormals):
// 2^(exponent − 23), read from the bits (this runs for every ray).
double floatSpacing(double x) {
  const float f = float(x);
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  const int exponent = int((bits >> 23) & 0xffu);
  if (exponent == 0xff) return kInf;
  if (exponent == 0) return double(FLT_MIN);
  // 2^(exponent − 150), a normal double for every exponent 1…254: its
  // bits directly (the same value std::ldexp(1.0, exponent − 150) gives,
  // without the library call).
  const uint64_t doubleBits = uint64_t(exponent - 150 + 1023) << 52;
  double spacing;
  std::memcpy(&spacing, &doubleBits, sizeof spacing);
  return spacing;
}

// x rounded to a float on the side `direction` points to, never to a
// denormal (which DAZ would read as 0): outward to ±FLT_MIN or to 0.
float roundOutward(double x, double direction) {
  float f = float(x);
  if (direction > 0.0 && double(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  if (direction < 0.0 && double(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  if (f != 0.0f && std::fabs(f) < FLT_MIN) {
    if (direction > 0.0)
      f = f > 0.0f ? FLT_MIN : 0.0f;
    else
      f = f < 0.0f ? -FLT_MIN : 0.0f;
  }
  return f;
}

// Bounds on the magnitudes of the edges Embree computes, and on the
// products in each component of the cross product it takes of them.
struct EdgeBounds {
  std::array<glm::dvec3, 3> edge;  // |e_j(v)| per component, e0 = v2 − v0, e1 = v0 − v1, e2 = v1 − v2
  glm::dvec3 cross{0.0};           // C_k, over both pairs (e0, e1), (e1, e2) Embree may pick
  glm::dvec3 reach{0.0};           // R_k = max_i |w_ik|
};

EdgeBounds edgeBounds(const Vertices& w) {
  EdgeBounds b;
  const glm::dvec3 a0 = glm::abs(w[0]), a1 = glm::abs(w[1]), a2 = glm::abs(w[2]);
  // Embree's vertices are w(1 + δ), |δ| ≤ u: the difference of two moves
  // by at most u(|a| + |c|).
  b.edge[0] = glm::abs(w[2] - w[0]) + kU * (a2 + a0);
  b.edge[1] = glm::abs(w[0] - w[1]) + kU * (a0 + a1);
  b.edge[2] = glm::abs(w[1] - w[2]) + kU * (a1 + a2);
  const glm::dvec3 &e0 = b.edge[0], &e1 = b.edge[1], &e2 = b.edge[2];
  const glm::dvec3 c01(e0.y * e1.z + e0.z * e1.y, e0.z * e1.x + e0.x * e1.z, e0.x * e1.y + e0.y * e1.x);
  const glm::dvec3 c12(e1.y * e2.z + e1.z * e2.y, e1.z * e2.x + e1.x * e2.z, e1.x * e2.y + e1.y * e2.x);
  b.cross = glm::max(c01, c12);
  b.reach = glm::max(glm::max(a0, a1), a2);
  return b;
}

// The header's step 2 for origin o (as Embree reads it) and side sign s.
EmbreeSideMargin margin(const Vertices& p, const glm::dvec3& o, double s, double normalLength) {
  const Vertices w = {p[0] - o, p[1] - o, p[2] - o};
  const Vertices cof = {glm::cross(w[1], w[2]), glm::cross(w[2], w[0]), glm::cross(w[0], w[1])};
  const double det = glm::dot(w[0], cof[0]);  // = dot(p0 − o, N)
  double first = 0.0;
  for (size_t i = 0; i < 3; ++i) first += glm::dot(glm::abs(w[i]), glm::abs(cof[i]));
  const glm::dvec3 a0 = glm::abs(w[0]), a1 = glm::abs(w[1]), a2 = glm::abs(w[2]);
  const double permanent = a0.x * (a1.y * a2.z + a1.z * a2.y) + a0.y * (a1.x * a2.z + a1.z * a2.x) +
                           a0.z * (a1.x * a2.y + a1.y * a2.x);
  const EdgeBounds e = edgeBounds(w);
  const double normalTerm = glm::dot(a0, e.cross);
  EmbreeSideMargin m;
  m.volume = -s * det;
  m.bound = kU * first + 4.0 * kU * kU * permanent + 8.0 * kU * normalTerm +
            kEvalSlack * (first + permanent + normalTerm) +
            kUnderflow * (1.0 + e.reach.x + e.reach.y + e.reach.z + e.cross.x + e.cross.y + e.cross.z);
  m.normalLength = normalLength;
  return m;
}

bool certified(const EmbreeSideMargin& m) {
  return m.volume > m.bound && m.volume >= kMinHeight * m.normalLength;
}

// The axis that corrects the height after rounding: moving it one float
// step changes the height by spacing·|n_k| (the excess we may end with)
// and winning back the others' rounding, up to half a spacing·|n_j| each,
// moves the origin sideways by that over |n_k|. The cheapest sum wins: the
// normal's axis when the coordinates are alike, a near-zero coordinate
// with a good share of the normal far from the origin.
int compensatingAxis(const glm::dvec3& q, const glm::dvec3& n) {
  const glm::dvec3 spacing(floatSpacing(q.x), floatSpacing(q.y), floatSpacing(q.z));
  const glm::dvec3 halfStep = 0.5 * spacing * glm::abs(n);
  const double allHalfSteps = halfStep.x + halfStep.y + halfStep.z;
  int best = 0;
  double bestCost = kInf;
  for (int k = 0; k < 3; ++k) {
    if (n[k] == 0.0) continue;
    const double cost = 2.0 * halfStep[k] + (allHalfSteps - halfStep[k]) / std::abs(n[k]);
    if (cost < bestCost) {
      bestCost = cost;
      best = k;
    }
  }
  return best;
}

double sideSign(const Vertices& p, const glm::dvec3& side) {
  return glm::dot(side, glm::cross(p[1] - p[0], p[2] - p[0])) >= 0.0 ? 1.0 : -1.0;
}

// What errorBoundRayOrigin derives from the triangle alone: its vertices
// as Embree reads them, their normal N = cross(p1 − p0, p2 − p0) and |N|.
// Consecutive secondary rays mostly leave the triangle the previous one
// left, so each thread remembers the last triangle's, keyed by the bits of
// its float vertices (a memo hit is exactly what would be recomputed).
// A plain aggregate: thread storage starts zero-filled (valid false)
// without a per-access initialization check.
struct TriangleMemo {
  bool valid;
  uint32_t key[9];
  Vertices p;
  glm::dvec3 normal;
  double normalLength;
};
thread_local TriangleMemo triangleMemo;

inline uint32_t bitsOf(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

const TriangleMemo& triangleData(const FloatTriangle& t) {
  TriangleMemo& m = triangleMemo;
  uint32_t differ = m.valid ? 0u : 1u;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) differ |= m.key[3 * i + k] ^ bitsOf(t[size_t(i)][k]);
  if (differ != 0) {
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) m.key[3 * i + k] = bitsOf(t[size_t(i)][k]);
    m.p = verticesOf(t);
    m.normal = glm::cross(m.p[1] - m.p[0], m.p[2] - m.p[0]);
    m.normalLength = glm::length(m.normal);
    m.valid = true;
  }
  return m;
}

}  // namespace

EmbreeSideMargin embreeSideMargin(const FloatTriangle& triangle, const glm::vec3& o, const glm::dvec3& side) {
  const Vertices p = verticesOf(triangle);
  return margin(p, dazd(o), sideSign(p, side), glm::length(glm::cross(p[1] - p[0], p[2] - p[0])));
}

bool leavesWithoutRehit(const FloatTriangle& triangle, const glm::vec3& o, const glm::dvec3& side) {
  return certified(embreeSideMargin(triangle, o, side));
}

bool denominatorCertified(const FloatTriangle& triangle, const glm::vec3& o, const glm::dvec3& side,
                          const glm::vec3& direction) {
  const Vertices p = verticesOf(triangle);
  const glm::dvec3 origin = dazd(o), d = glm::abs(dazd(direction));
  const Vertices w = {p[0] - origin, p[1] - origin, p[2] - origin};
  const glm::dvec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
  const EdgeBounds e = edgeBounds(w);
  // den/2 against dot(N, D): the rounded dot product and cross product
  // (γ3 and 4u of C_k, as for T) and the normal of Embree's rounded
  // vertices against the true one (edges move by ≤ 2u·R_k each).
  glm::dvec3 edgeMax(0.0);
  for (const glm::dvec3& x : e.edge) edgeMax = glm::max(edgeMax, x);
  double moved = 0.0;
  for (int k = 0; k < 3; ++k) {
    const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    moved += d[k] * (e.reach[k1] * edgeMax[k2] + edgeMax[k1] * e.reach[k2]);
  }
  const double crossTerm = glm::dot(d, e.cross);
  const double bound = 8.0 * kU * crossTerm + 5.0 * kU * moved + kEvalSlack * (crossTerm + moved) +
                       kUnderflow * (1.0 + e.cross.x + e.cross.y + e.cross.z);
  return sideSign(p, side) * glm::dot(n, dazd(direction)) > bound;
}

glm::dvec3 terminatorLift(const FloatTriangle& triangle, const VertexNormals& normals,
                          const glm::dvec3& position, double b1, double b2, double s) {
  const double b[3] = {std::clamp(1.0 - b1 - b2, 0.0, 1.0), std::clamp(b1, 0.0, 1.0),
                       std::clamp(b2, 0.0, 1.0)};
  glm::dvec3 lift(0.0);
  for (size_t i = 0; i < 3; ++i) {
    const glm::dvec3 n = s * glm::dvec3(normals[i]);
    // How far P lies below the tangent plane at vertex i (0 when above):
    // projecting it onto that plane moves it by this along n.
    const double below = glm::dot(glm::dvec3(triangle[i]) - position, n);
    if (below > 0.0) lift += b[i] * below * n;
  }
  return lift;
}

bool liftedRayCrossesItsTriangle(const FloatTriangle& triangle, const glm::dvec3& position,
                                 const glm::dvec3& lift, const glm::dvec3& direction) {
  const glm::dvec3 p0(triangle[0]), e1 = glm::dvec3(triangle[1]) - p0, e2 = glm::dvec3(triangle[2]) - p0;
  const glm::dvec3 n = glm::cross(e1, e2);
  const double cosine = glm::dot(n, direction);
  if (cosine == 0.0) return false;  // parallel: never reaches the plane
  const glm::dvec3 o = position + lift;
  const double t = glm::dot(p0 - o, n) / cosine;
  if (!(t > 0.0)) return false;
  // Barycentrics of the crossing (Cramer's rule in the plane).
  const glm::dvec3 q = o + t * direction - p0;
  const double nn = glm::dot(n, n);
  const double u = glm::dot(glm::cross(q, e2), n) / nn, v = glm::dot(glm::cross(e1, q), n) / nn;
  constexpr double kMargin = 1e-5;
  return u >= -kMargin && v >= -kMargin && 1.0 - u - v >= -kMargin;
}

namespace {

// errorBoundRayOrigin in three parts, so a batch (errorBoundRayOrigins)
// can take the two margins between them in SIMD lanes.
struct OriginJob {
  Vertices p;  // as Embree reads them
  double normalLength = 0.0;
  double s = 1.0;  // sideSign(p, side)
  glm::dvec3 side{0.0}, lifted{0.0};
  double dPos = 0.0;
  bool degenerate = false;  // no plane to leave: `fallback` is the origin
  glm::vec3 fallback{0.0f};
};

// Step 1 (header), and what step 2 needs.
OriginJob startOrigin(const FloatTriangle& triangle, const glm::dvec3& position, float b1, float b2,
                      const glm::dvec3& side, const glm::dvec3& lift) {
  OriginJob j;
  const TriangleMemo& data = triangleData(triangle);
  j.p = data.p;
  j.normalLength = data.normalLength;
  j.side = side;
  j.lifted = position + lift;
  if (!(j.normalLength > 0.0) || !std::isfinite(j.normalLength)) {
    j.degenerate = true;
    j.fallback = floatUlpsRayOrigin(glm::vec3(position + lift), glm::vec3(side));  // no plane to leave
    return j;
  }
  j.s = glm::dot(side, data.normal) >= 0.0 ? 1.0 : -1.0;  // sideSign(p, side)

  // 1. How far the double hit point may lie off the plane (header).
  const double b0 = 1.0 - double(b1) - double(b2);
  const double weightError = gammaD(2) * (1.0 + std::abs(double(b1)) + std::abs(double(b2)));
  glm::dvec3 pError;
  for (int k = 0; k < 3; ++k)
    pError[k] = gammaD(3) * (std::abs(b0 * triangle[0][k]) + std::abs(double(b1) * triangle[1][k]) +
                             std::abs(double(b2) * triangle[2][k])) +
                weightError * std::abs(double(triangle[0][k]));
  j.dPos = glm::dot(glm::abs(side), pError);
  return j;
}

// Step 3's rounding, from `estimate`, margin(p, lifted, s, normalLength)'s
// bound: the float origin before its check; *axis the compensating axis.
glm::vec3 roundOrigin(const OriginJob& j, double estimate, int* axis) {
  // 2. Embree's bound, estimated at the hit point, as a height.
  const double dEmbree = std::max(estimate / j.normalLength, kMinHeight);

  // 3. Round, then check the float origin and move axis m outward until
  // it passes: the estimate above is only the starting point.
  const glm::dvec3& side = j.side;
  const glm::dvec3 q = j.lifted + (j.dPos + dEmbree) * side;
  const int m = compensatingAxis(q, side);
  // The others to nearest; whatever height their rounding gained or lost
  // (Σ (o_k − q_k)·n_k), axis m gives back or takes, then rounds outward.
  glm::vec3 o;
  double qm = q[m];
  for (int k = 0; k < 3; ++k) {
    if (k == m) continue;
    o[k] = daz(float(q[k]));
    qm -= (double(o[k]) - q[k]) * side[k] / side[m];
  }
  o[m] = roundOutward(qm, side[m]);
  *axis = m;
  return o;
}

// Step 3's check: moves axis m of `o` outward until it passes. `first`:
// margin(p, dazd(o), s, normalLength) when the caller has it.
glm::vec3 certifyOrigin(const OriginJob& j, glm::vec3 o, int m, const EmbreeSideMargin* first) {
  const glm::dvec3& side = j.side;
  double growth = 1.0;
  for (int i = 0; i < 64; ++i) {
    const EmbreeSideMargin c = i == 0 && first ? *first : margin(j.p, dazd(o), j.s, j.normalLength);
    if (certified(c)) break;
    // The height still missing, along axis m (G grows by |N_m| per unit).
    const double deficit = std::max(c.bound - c.volume, kMinHeight * c.normalLength - c.volume);
    const double step = growth * (deficit / c.normalLength) * (1.0 + 0x1p-20) / std::abs(side[m]);
    float next = roundOutward(double(o[m]) + std::copysign(step, side[m]), side[m]);
    if (next == o[m])
      next =
          roundOutward(double(std::nextafter(o[m], side[m] > 0.0 ? std::numeric_limits<float>::infinity()
                                                                 : -std::numeric_limits<float>::infinity())),
                       side[m]);
    o[m] = next;
    // Slivers: the bound grows as the origin moves; overshoot after a few
    // tries instead of creeping.
    if (i >= 4) growth *= 2.0;
  }
  return o;
}

}  // namespace

glm::vec3 errorBoundRayOrigin(const FloatTriangle& triangle, const glm::dvec3& position, float b1, float b2,
                              const glm::dvec3& side, const glm::dvec3& lift) {
  const OriginJob j = startOrigin(triangle, position, b1, b2, side, lift);
  if (j.degenerate) return j.fallback;
  int m = 0;
  const glm::vec3 o = roundOrigin(j, margin(j.p, j.lifted, j.s, j.normalLength).bound, &m);
  return certifyOrigin(j, o, m, nullptr);
}

void errorBoundRayOrigins(size_t n, const FloatTriangle* triangles, const glm::dvec3* positions,
                          const float* b1, const float* b2, const glm::dvec3* sides, const glm::dvec3* lifts,
                          glm::vec3* out) {
  constexpr size_t kBatch = detail::kOriginLanes;
  OriginJob jobs[kBatch];
  alignas(64) double soa[12][kBatch];  // p0 p1 p2 (x, y, z each), then the origin
  alignas(64) double det[kBatch], bound[kBatch];
  int axis[kBatch];
  for (size_t first = 0; first < n; first += kBatch) {
    const size_t m = std::min(kBatch, n - first);
    for (size_t k = 0; k < kBatch; ++k) {
      if (k < m) {
        jobs[k] = startOrigin(triangles[first + k], positions[first + k], b1[first + k], b2[first + k],
                              sides[first + k], lifts[first + k]);
      } else {
        jobs[k] = OriginJob{};  // padding: a zero triangle, computed and ignored
        jobs[k].degenerate = true;
      }
      for (int i = 0; i < 3; ++i)
        for (int c = 0; c < 3; ++c) soa[3 * i + c][k] = jobs[k].p[size_t(i)][c];
      for (int c = 0; c < 3; ++c) soa[9 + c][k] = jobs[k].lifted[c];
    }
    // 2. The estimate at the lifted point, in lanes.
    detail::embreeMarginLanes(soa, det, bound);
    for (size_t k = 0; k < m; ++k) {
      if (jobs[k].degenerate) continue;
      const glm::vec3 o = roundOrigin(jobs[k], bound[k], &axis[k]);
      out[first + k] = o;
      const glm::dvec3 od = dazd(o);
      for (int c = 0; c < 3; ++c) soa[9 + c][k] = od[c];
    }
    // 3. The first check of each rounded origin, in lanes.
    detail::embreeMarginLanes(soa, det, bound);
    for (size_t k = 0; k < m; ++k) {
      const OriginJob& j = jobs[k];
      if (j.degenerate) {
        out[first + k] = j.fallback;
        continue;
      }
      EmbreeSideMargin c;
      c.volume = -j.s * det[k];
      c.bound = bound[k];
      c.normalLength = j.normalLength;
      out[first + k] = certifyOrigin(j, out[first + k], axis[k], &c);
    }
  }
}

double seamTolerance(const FloatTriangle& own, const glm::dvec3& position, const glm::vec3& o) {
  const glm::dvec3 p0(own[0]);
  const double edges = glm::length(glm::dvec3(own[1]) - p0) + glm::length(glm::dvec3(own[2]) - p0);
  const glm::dvec3 a = glm::abs(position);
  return 0x1p-22 * edges + glm::length(glm::dvec3(o) - position) + 0x1p-45 * (a.x + a.y + a.z);
}

double planeDistance(const FloatTriangle& triangle, const glm::dvec3& point) {
  const glm::dvec3 p0(triangle[0]);
  const glm::dvec3 n = glm::cross(glm::dvec3(triangle[1]) - p0, glm::dvec3(triangle[2]) - p0);
  const double length = glm::length(n);
  if (!(length > 0.0)) return kInf;
  return std::abs(glm::dot(point - p0, n)) / length;
}

glm::dvec3 seamSide(const FloatTriangle& own, const FloatTriangle& other, const glm::dvec3& direction) {
  const glm::dvec3 p0(other[0]);
  const glm::dvec3 n = glm::normalize(glm::cross(glm::dvec3(other[1]) - p0, glm::dvec3(other[2]) - p0));
  double farthest = 0.0;
  for (const glm::vec3& v : own) {
    const double h = glm::dot(glm::dvec3(v) - p0, n);
    if (std::abs(h) > std::abs(farthest)) farthest = h;
  }
  // Coplanar within the plane's own rounding: the side the ray goes to.
  const glm::dvec3 a = glm::abs(p0);
  if (std::abs(farthest) <= 0x1p-40 * (1.0 + a.x + a.y + a.z)) farthest = glm::dot(direction, n);
  return farthest >= 0.0 ? n : -n;
}

glm::vec3 offsetOffPlanes(const FloatTriangle* triangles, const glm::dvec3* sides, size_t count,
                          glm::vec3 o) {
  glm::dvec3 sum(0.0);
  for (size_t i = 0; i < count; ++i) sum += sides[i];
  if (!(glm::length(sum) > 0.0)) return o;
  const glm::dvec3 u = glm::normalize(sum);
  double growth = 1.0;
  for (int iteration = 0; iteration < 64; ++iteration) {
    // The largest height still missing over the planes, along u.
    double step = 0.0;
    for (size_t i = 0; i < count; ++i) {
      const EmbreeSideMargin m = embreeSideMargin(triangles[i], o, sides[i]);
      if (certified(m)) continue;
      const double along = glm::dot(u, sides[i]);
      if (!(along > 0.0)) return o;  // no direction leaves them all
      const double deficit = std::max(m.bound - m.volume, kMinHeight * m.normalLength - m.volume);
      step = std::max(step, deficit / m.normalLength / along);
    }
    if (step == 0.0) break;
    step *= growth * (1.0 + 0x1p-20);
    for (int k = 0; k < 3; ++k) {
      if (u[k] == 0.0) continue;
      const float next = roundOutward(double(o[k]) + step * u[k], u[k]);
      o[k] = next != o[k]
                 ? next
                 : roundOutward(
                       double(std::nextafter(o[k], u[k] > 0.0 ? std::numeric_limits<float>::infinity()
                                                              : -std::numeric_limits<float>::infinity())),
                       u[k]);
    }
    if (iteration >= 4) growth *= 2.0;
  }
  return o;
}

}  // namespace rastray
