// primary_samples.h. Highway compiles the lane function once per SIMD
// target (foreach_target.h re-includes this file); the host code gathers
// each sample's setup planes into a block, runs the lanes and scatters.
// Built with -ffp-contract=off (the top-level CMakeLists.txt).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/primary_samples.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <cstddef>
#include <cstdint>
#include <vector>

#include <hwy/highway.h>

#include "common/primary_refinement-inl.h"
#include "common/run_lanes-inl.h"
#include "raster/primary_samples.h"

#ifndef RASTRAY_PRIMARY_SAMPLES_LANES
#define RASTRAY_PRIMARY_SAMPLES_LANES
namespace rastray {
namespace primary_detail {

constexpr size_t kBlock = 64;  // a multiple of every target's double lane count (2, 4, 8)

// The fused pass's block (primaryShadeHits). Consecutive samples mostly
// lie on one setup, so what is constant along a run of them (the setup's
// planes, the stored triangle's plane) is stored once per run in a table,
// and each lane holds only its position and its run: a vector of lanes on
// one run reads the table as broadcasts, a vector across runs gathers.
struct FusedBlock {
  size_t lanes = 0;
  alignas(64) double x[kBlock], y[kBlock];
  alignas(64) int64_t run[kBlock];  // non-decreasing within the block
  // Per run: the interpolation's inputs as SampleBlock's, then the stored
  // triangle's plane as the refinement reads it (RefinePlaneLanes).
  alignas(64) double x0[kBlock], y0[kBlock];
  alignas(64) double iw0[kBlock], iwx[kBlock], iwy[kBlock];
  alignas(64) double dw0[kBlock], dwx[kBlock], dwy[kBlock];
  alignas(64) double b10[kBlock], b1x[kBlock], b1y[kBlock];
  alignas(64) double b20[kBlock], b2x[kBlock], b2y[kBlock];
  alignas(64) double e1x[kBlock], e1y[kBlock], e1z[kBlock], e2x[kBlock], e2y[kBlock], e2z[kBlock];
  alignas(64) double sx[kBlock], sy[kBlock], sz[kBlock], qx[kBlock], qy[kBlock], qz[kBlock];
  alignas(64) double e2DotQ[kBlock], slot1[kBlock], slot2[kBlock];
  // Out, per lane: interpolated depth and barycentrics, the ray's
  // direction, the refined barycentrics and 1 where they replace the
  // interpolated ones.
  alignas(64) double depth[kBlock], b1[kBlock], b2[kBlock];
  alignas(64) double dirX[kBlock], dirY[kBlock], dirZ[kBlock];
  alignas(64) double rb1[kBlock], rb2[kBlock], refined[kBlock];
};

}  // namespace primary_detail
}  // namespace rastray
#endif

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

size_t SampleLanes() { return hn::Lanes(hn::ScalableTag<double>()); }

// Per lane: TriangleSetup::viewDepthAt and baryAt (PlaneCoefficients::at:
// (v0 + dx·(x − x0)) + dy·(y − y0)), then PrimaryRays::operator() for a
// perspective camera (ndcFromImage, the view-plane vector and its glm
// length ((x² + y²) + 1, the z² of −1 being exactly 1), worldFromView's
// columns, glm::normalize (v · (1 / √(v·v))) and 1 / length), then the
// refinement on the stored triangle's plane (RefineOnPlane) with that ray,
// in registers: the same operations as primarySamplesReference followed by
// refinePrimaryHits.
void LanesFusedPrimary(primary_detail::FusedBlock* b, const PrimaryRayConstants* c) {
  const hn::ScalableTag<double> d;
  const size_t N = hn::Lanes(d);
  const auto one = hn::Set(d, 1.0), two = hn::Set(d, 2.0);
  const auto width = hn::Set(d, c->width), height = hn::Set(d, c->height);
  const auto sx = hn::Set(d, c->scale.x), sy = hn::Set(d, c->scale.y);
  const auto m0x = hn::Set(d, c->m0.x), m0y = hn::Set(d, c->m0.y), m0z = hn::Set(d, c->m0.z);
  const auto m1x = hn::Set(d, c->m1.x), m1y = hn::Set(d, c->m1.y), m1z = hn::Set(d, c->m1.z);
  const auto cx = hn::Set(d, c->constantPart.x), cy = hn::Set(d, c->constantPart.y);
  const auto cz = hn::Set(d, c->constantPart.z);
  for (size_t i = 0; i < b->lanes; i += N) {
    const RunLanes<decltype(d)> get(d, b->run, i);  // per-run values: a broadcast or a gather
    const auto x = hn::Load(d, b->x + i), y = hn::Load(d, b->y + i);
    const auto ox = hn::Sub(x, get(b->x0)), oy = hn::Sub(y, get(b->y0));
    const auto plane = [&](const double* v0, const double* dx, const double* dy) {
      return hn::Add(hn::Add(get(v0), hn::Mul(get(dx), ox)), hn::Mul(get(dy), oy));
    };
    const auto invW = plane(b->iw0, b->iwx, b->iwy);
    hn::Store(hn::Div(plane(b->dw0, b->dwx, b->dwy), invW), d, b->depth + i);
    const auto inv = hn::Div(one, invW);
    hn::Store(hn::Mul(plane(b->b10, b->b1x, b->b1y), inv), d, b->b1 + i);
    hn::Store(hn::Mul(plane(b->b20, b->b2x, b->b2y), inv), d, b->b2 + i);

    const auto ndcX = hn::Sub(hn::Div(hn::Mul(two, x), width), one);
    const auto ndcY = hn::Sub(one, hn::Div(hn::Mul(two, y), height));
    const auto vx = hn::Mul(ndcX, sx), vy = hn::Mul(ndcY, sy);
    const auto length = hn::Sqrt(hn::Add(hn::Add(hn::Mul(vx, vx), hn::Mul(vy, vy)), one));
    const auto wx = hn::Add(hn::Add(hn::Mul(m0x, vx), hn::Mul(m1x, vy)), cx);
    const auto wy = hn::Add(hn::Add(hn::Mul(m0y, vx), hn::Mul(m1y, vy)), cy);
    const auto wz = hn::Add(hn::Add(hn::Mul(m0z, vx), hn::Mul(m1z, vy)), cz);
    const auto rinv =
        hn::Div(one, hn::Sqrt(hn::Add(hn::Add(hn::Mul(wx, wx), hn::Mul(wy, wy)), hn::Mul(wz, wz))));
    const auto dirX = hn::Mul(wx, rinv), dirY = hn::Mul(wy, rinv), dirZ = hn::Mul(wz, rinv);
    hn::Store(dirX, d, b->dirX + i);
    hn::Store(dirY, d, b->dirY + i);
    hn::Store(dirZ, d, b->dirZ + i);

    RefinePlaneLanes<hn::Vec<decltype(d)>> pl;
    pl.e1x = get(b->e1x), pl.e1y = get(b->e1y), pl.e1z = get(b->e1z);
    pl.e2x = get(b->e2x), pl.e2y = get(b->e2y), pl.e2z = get(b->e2z);
    pl.sx = get(b->sx), pl.sy = get(b->sy), pl.sz = get(b->sz);
    pl.qx = get(b->qx), pl.qy = get(b->qy), pl.qz = get(b->qz);
    pl.e2DotQ = get(b->e2DotQ);
    pl.slot1 = get(b->slot1), pl.slot2 = get(b->slot2);
    hn::Vec<decltype(d)> rb1, rb2;
    const auto ok = RefineOnPlane(d, dirX, dirY, dirZ, hn::Div(one, length), pl, &rb1, &rb2);
    hn::Store(rb1, d, b->rb1 + i);
    hn::Store(rb2, d, b->rb2 + i);
    hn::Store(hn::IfThenElseZero(ok, one), d, b->refined + i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

#include <algorithm>

#include "common/primary_refinement.h"
#include "common/triangle_plane.h"

namespace rastray {

HWY_EXPORT(SampleLanes);
HWY_EXPORT(LanesFusedPrimary);

PrimaryRayConstants::PrimaryRayConstants(const Camera& c)
    : camera(&c),
      perspective(c.projection == Projection::Perspective),
      width(double(c.width)),
      height(double(c.height)),
      scale(c.ndcScale()),
      eye(c.eye()) {
  const glm::dmat4& m = c.worldFromView;
  m0 = glm::dvec3(m[0]);
  m1 = glm::dvec3(m[1]);
  // As PrimaryRays computes it (signed zeros included).
  for (int k = 0; k < 3; ++k) constantPart[k] = m[2][k] * -1.0 + m[3][k] * 0.0;
}

void primarySamplesReference(const PrimaryRayConstants& camera, const TriangleSetup* setups,
                             const uint32_t* winners, const glm::dvec2* positions, size_t count,
                             SampleHit* hits, Ray* rays) {
  const PrimaryRays primary(*camera.camera);
  for (size_t i = 0; i < count; ++i) {
    hits[i] = interpolatedSampleHit(setups[winners[i]], positions[i]);
    rays[i] = primary(positions[i]);
  }
}

void primaryShadeHits(const PrimaryRayConstants& camera, const Scene& scene, const TriangleSetup* setups,
                      const uint32_t* winners, const glm::dvec2* positions, const glm::dvec2* footprints,
                      size_t count, SampleHit* hits, ShadeHit* out) {
  if (!camera.perspective) {
    // Orthographic rays: the reference, then the batched refinement.
    thread_local std::vector<Ray> rays;
    rays.resize(count);
    primarySamplesReference(camera, setups, winners, positions, count, hits, rays.data());
    refinePrimaryHits(scene, rays.data(), hits, footprints, count, out);
    return;
  }
  using primary_detail::kBlock;
  thread_local primary_detail::FusedBlock b;
  const size_t vectorLanes = HWY_DYNAMIC_DISPATCH(SampleLanes)();
  // The current stored triangle's plane, with the eye-dependent terms as
  // intersectTrianglePlane's memo computes them (glm: the same bits).
  uint32_t planeInstance = kNoId, planeTriangle = kNoId;
  TrianglePlane plane{};
  glm::dvec3 s(0.0), q(0.0);
  double e2DotQ = 0.0;
  const TriangleSetup* runSetup[kBlock];
  for (size_t first = 0; first < count; first += kBlock) {
    const size_t used = std::min(kBlock, count - first);
    int64_t runs = 0;
    uint32_t lastWinner = 0;  // a run starts at k = 0 whatever it holds
    for (size_t k = 0; k < used; ++k) {
      const uint32_t win = winners[first + k];
      const glm::dvec2& p = positions[first + k];
      b.x[k] = p.x, b.y[k] = p.y;
      if (win != lastWinner || runs == 0) {
        // A new run: its setup's planes and its stored triangle's plane.
        lastWinner = win;
        const int64_t r = runs++;
        const TriangleSetup& t = setups[win];
        runSetup[r] = &t;
        b.x0[r] = t.depth.x0, b.y0[r] = t.depth.y0;
        b.iw0[r] = t.invW.v0, b.iwx[r] = t.invW.dx, b.iwy[r] = t.invW.dy;
        b.dw0[r] = t.dOverW.v0, b.dwx[r] = t.dOverW.dx, b.dwy[r] = t.dOverW.dy;
        b.b10[r] = t.b1OverW.v0, b.b1x[r] = t.b1OverW.dx, b.b1y[r] = t.b1OverW.dy;
        b.b20[r] = t.b2OverW.v0, b.b2x[r] = t.b2OverW.dx, b.b2y[r] = t.b2OverW.dy;
        if (t.instance != planeInstance || t.triangle != planeTriangle) {
          plane = trianglePlane(scene, t.instance, t.triangle);
          s = camera.eye - plane.a;
          q = glm::cross(s, plane.e1);
          e2DotQ = glm::dot(plane.e2, q);
          planeInstance = t.instance;
          planeTriangle = t.triangle;
        }
        b.e1x[r] = plane.e1.x, b.e1y[r] = plane.e1.y, b.e1z[r] = plane.e1.z;
        b.e2x[r] = plane.e2.x, b.e2y[r] = plane.e2.y, b.e2z[r] = plane.e2.z;
        b.sx[r] = s.x, b.sy[r] = s.y, b.sz[r] = s.z;
        b.qx[r] = q.x, b.qy[r] = q.y, b.qz[r] = q.z;
        b.e2DotQ[r] = e2DotQ;
        b.slot1[r] = double(plane.slot1);
        b.slot2[r] = double(plane.slot2);
      }
      b.run[k] = runs - 1;
    }
    // Padding: the last run again, at the image origin; never read back.
    b.lanes = (used + vectorLanes - 1) / vectorLanes * vectorLanes;
    for (size_t k = used; k < b.lanes; ++k) {
      b.x[k] = b.y[k] = 0.0;
      b.run[k] = runs - 1;
    }
    HWY_DYNAMIC_DISPATCH(LanesFusedPrimary)(&b, &camera);
    for (size_t k = 0; k < used; ++k) {
      const TriangleSetup& t = *runSetup[b.run[k]];
      const SampleHit h{t.instance, t.triangle, float(b.depth[k]), float(b.b1[k]), float(b.b2[k])};
      hits[first + k] = h;
      ShadeHit& r = out[first + k];
      r.instance = h.instance;
      r.triangle = h.triangle;
      const bool refined = b.refined[k] != 0.0;
      r.b1 = refined ? float(b.rb1[k]) : h.b1;
      r.b2 = refined ? float(b.rb2[k]) : h.b2;
      r.direction = glm::dvec3(b.dirX[k], b.dirY[k], b.dirZ[k]);
      r.footprintPosition = footprints[first + k];
      r.throughput = 1.0f;
    }
  }
}

}  // namespace rastray

#endif  // HWY_ONCE
