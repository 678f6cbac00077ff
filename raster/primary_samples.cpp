// primary_samples.h. Highway compiles the lane function once per SIMD
// target (foreach_target.h re-includes this file); the host code gathers
// each sample's setup planes into a block, runs the lanes and scatters.
// Built with -ffp-contract=off (the top-level CMakeLists.txt).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/primary_samples.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <cstddef>

#include <hwy/highway.h>

#include "raster/primary_samples.h"

#ifndef RASTRAY_PRIMARY_SAMPLES_LANES
#define RASTRAY_PRIMARY_SAMPLES_LANES
namespace rastray {
namespace primary_detail {

constexpr size_t kBlock = 64;  // a multiple of every target's double lane count (2, 4, 8)

// One block, struct of arrays; partial blocks are padded with a harmless
// sample (never read back).
struct SampleBlock {
  size_t lanes = 0;
  // In: the image position, the setup's plane origin and its 1/w, d/w,
  // b1/w and b2/w coefficients (PlaneCoefficients: v0, dx, dy).
  alignas(64) double x[kBlock], y[kBlock], x0[kBlock], y0[kBlock];
  alignas(64) double iw0[kBlock], iwx[kBlock], iwy[kBlock];
  alignas(64) double dw0[kBlock], dwx[kBlock], dwy[kBlock];
  alignas(64) double b10[kBlock], b1x[kBlock], b1y[kBlock];
  alignas(64) double b20[kBlock], b2x[kBlock], b2y[kBlock];
  // Out: interpolated view depth and barycentrics (double, the host rounds
  // them to float as interpolatedHit does), the ray's direction, the length
  // of the view-plane vector and depthPerT = 1 / length.
  alignas(64) double depth[kBlock], b1[kBlock], b2[kBlock];
  alignas(64) double dirX[kBlock], dirY[kBlock], dirZ[kBlock], length[kBlock], depthPerT[kBlock];
};

}  // namespace primary_detail
}  // namespace rastray
#endif

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

size_t SampleLanes() { return hn::Lanes(hn::ScalableTag<double>()); }

// TriangleSetup::viewDepthAt and baryAt (PlaneCoefficients::at: (v0 +
// dx·(x − x0)) + dy·(y − y0)), then PrimaryRays::operator() for a
// perspective camera: ndcFromImage, the view-plane vector and its glm
// length ((x² + y²) + 1, the z² of −1 being exactly 1), worldFromView's
// columns, glm::normalize (v · (1 / √(v·v))) and 1 / length.
void LanesPrimarySamples(primary_detail::SampleBlock* b, const PrimaryRayConstants* c) {
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
    const auto x = hn::Load(d, b->x + i), y = hn::Load(d, b->y + i);
    const auto ox = hn::Sub(x, hn::Load(d, b->x0 + i)), oy = hn::Sub(y, hn::Load(d, b->y0 + i));
    const auto plane = [&](const double* v0, const double* dx, const double* dy) {
      return hn::Add(hn::Add(hn::Load(d, v0 + i), hn::Mul(hn::Load(d, dx + i), ox)),
                     hn::Mul(hn::Load(d, dy + i), oy));
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
    hn::Store(hn::Mul(wx, rinv), d, b->dirX + i);
    hn::Store(hn::Mul(wy, rinv), d, b->dirY + i);
    hn::Store(hn::Mul(wz, rinv), d, b->dirZ + i);
    hn::Store(length, d, b->length + i);
    hn::Store(hn::Div(one, length), d, b->depthPerT + i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

#include <algorithm>

namespace rastray {

HWY_EXPORT(SampleLanes);
HWY_EXPORT(LanesPrimarySamples);

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

void primarySamples(const PrimaryRayConstants& camera, const TriangleSetup* setups, const uint32_t* winners,
                    const glm::dvec2* positions, size_t count, SampleHit* hits, Ray* rays) {
  if (!camera.perspective) {
    primarySamplesReference(camera, setups, winners, positions, count, hits, rays);
    return;
  }
  using primary_detail::kBlock;
  thread_local primary_detail::SampleBlock b;
  const size_t vectorLanes = HWY_DYNAMIC_DISPATCH(SampleLanes)();
  const double znear = camera.camera->znear, zfar = camera.camera->zfar;
  for (size_t first = 0; first < count; first += kBlock) {
    const size_t used = std::min(kBlock, count - first);
    for (size_t k = 0; k < used; ++k) {
      const TriangleSetup& t = setups[winners[first + k]];
      const glm::dvec2& p = positions[first + k];
      b.x[k] = p.x, b.y[k] = p.y;
      b.x0[k] = t.depth.x0, b.y0[k] = t.depth.y0;
      b.iw0[k] = t.invW.v0, b.iwx[k] = t.invW.dx, b.iwy[k] = t.invW.dy;
      b.dw0[k] = t.dOverW.v0, b.dwx[k] = t.dOverW.dx, b.dwy[k] = t.dOverW.dy;
      b.b10[k] = t.b1OverW.v0, b.b1x[k] = t.b1OverW.dx, b.b1y[k] = t.b1OverW.dy;
      b.b20[k] = t.b2OverW.v0, b.b2x[k] = t.b2OverW.dx, b.b2y[k] = t.b2OverW.dy;
    }
    // Padding: 1/w = 1, everything else 0, at the image origin.
    b.lanes = (used + vectorLanes - 1) / vectorLanes * vectorLanes;
    for (size_t k = used; k < b.lanes; ++k) {
      b.x[k] = b.y[k] = b.x0[k] = b.y0[k] = 0.0;
      b.iw0[k] = 1.0, b.iwx[k] = b.iwy[k] = 0.0;
      b.dw0[k] = b.dwx[k] = b.dwy[k] = b.b10[k] = b.b1x[k] = b.b1y[k] = 0.0;
      b.b20[k] = b.b2x[k] = b.b2y[k] = 0.0;
    }
    HWY_DYNAMIC_DISPATCH(LanesPrimarySamples)(&b, &camera);
    for (size_t k = 0; k < used; ++k) {
      const TriangleSetup& t = setups[winners[first + k]];
      hits[first + k] = SampleHit{t.instance, t.triangle, float(b.depth[k]), float(b.b1[k]), float(b.b2[k])};
      Ray& r = rays[first + k];
      r.origin = camera.eye;
      r.direction = glm::dvec3(b.dirX[k], b.dirY[k], b.dirZ[k]);
      r.depthPerT = b.depthPerT[k];
      r.tNear = znear * b.length[k];
      r.tFar = zfar * b.length[k];  // inf stays inf
    }
  }
}

}  // namespace rastray

#endif  // HWY_ONCE
