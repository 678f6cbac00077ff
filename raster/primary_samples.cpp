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

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

size_t SampleLanes() { return hn::Lanes(hn::ScalableTag<double>()); }

// Per lane: TriangleSetup::viewDepthAt and baryAt (PlaneCoefficients::at:
// (v0 + dx·(x − x0)) + dy·(y − y0)), then PrimaryRays::operator() for a
// perspective camera (ndcFromImage, the view-plane vector, worldFromView's
// columns, glm::normalize (v · (1 / √(v·v))); the ray's depthPerT is not
// needed, see below), then the
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

    hn::Vec<decltype(d)> vx, vy;
    if (b->haveView) {
      vx = hn::Load(d, b->vx + i);
      vy = hn::Load(d, b->vy + i);
    } else {
      const auto ndcX = hn::Sub(hn::Div(hn::Mul(two, x), width), one);
      const auto ndcY = hn::Sub(one, hn::Div(hn::Mul(two, y), height));
      vx = hn::Mul(ndcX, sx);
      vy = hn::Mul(ndcY, sy);
    }
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
    // depthPerT = 1 / length, with length = √((vx² + vy²) + 1) ≥ 1 (or
    // +inf, or NaN with NaN directions), only enters RefineOnPlane's test
    // that t · depthPerT is finite: with depthPerT in [0, 1] that holds
    // exactly when t is finite, which it also tests. So 1 gives the same
    // mask without a square root and a division per lane (tested against
    // refinePrimaryHit, which uses the ray's own depthPerT).
    const auto ok = RefineOnPlane(d, dirX, dirY, dirZ, one, pl, &rb1, &rb2);
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

PrimaryBatch::PrimaryBatch(const PrimaryRayConstants& camera, const Scene& scene, const TriangleSetup* setups,
                           const RefinePlane* planes)
    : camera_(camera),
      scene_(scene),
      setups_(setups),
      refinePlanes_(planes),
      // Not value-initialised (about 30 KB a tile): every lane and run
      // entry is written before it is read.
      block_(new primary_detail::FusedBlock),
      planes_(new Plane[size_t(1) << kPlaneCacheBits]),
      planeKeys_(new uint64_t[size_t(1) << kPlaneCacheBits]) {
  std::fill_n(planeKeys_.get(), size_t(1) << kPlaneCacheBits, kNoPlane);
  block_->haveView = true;  // until add() says otherwise
}

PrimaryBatch::~PrimaryBatch() = default;

size_t PrimaryBatch::addRow(const uint32_t* winners, size_t first, size_t n, int spp, int x0, int y,
                            const glm::dvec2* grid, uint32_t local0, uint32_t* localOut) {
  // The view-plane vector of every sample of the row, as the lanes would
  // compute it (ndcFromImage, then · scale): per column and sample once
  // per tile, per sample once per row.
  const size_t columns = n / size_t(spp) + 1;
  if (columnX0_ != x0 || columnSpp_ != spp || columnView_.size() < columns * size_t(spp)) {
    columnX0_ = x0;
    columnSpp_ = spp;
    columnView_.resize(columns * size_t(spp));
    for (size_t c = 0; c < columns; ++c)
      for (int s = 0; s < spp; ++s) {
        const double x = double(x0 + int(c)) + grid[s].x;
        columnView_[c * size_t(spp) + size_t(s)] = ((2.0 * x) / camera_.width - 1.0) * camera_.scale.x;
      }
  }
  if (rowY_ != y || rowSpp_ != spp || rowView_.empty()) {
    rowY_ = y;
    rowSpp_ = spp;
    rowView_.resize(size_t(spp));
    for (int s = 0; s < spp; ++s) {
      const double yy = double(y) + grid[s].y;
      rowView_[size_t(s)] = (1.0 - (2.0 * yy) / camera_.height) * camera_.scale.y;
    }
  }
  const double* const columnView = columnView_.data();
  const double* const rowView = rowView_.data();
  // The batch's state in locals (registers) for the loop.
  primary_detail::FusedBlock& b = *block_;
  size_t used = used_, runs = runs_;
  uint32_t last = lastWinner_;
  const double py = double(y);
  size_t i = first;
  int s = int(first % size_t(spp));
  double px = double(x0 + int(first / size_t(spp)));
  for (; i < n && used < primary_detail::kBlock; ++i) {
    const uint32_t win = winners[i];
    if (win != kNoSetup) {
      if (win != last || runs == 0) {
        // Small triangles make runs of one or two samples, each on a setup
        // (and its refinement plane) mostly not in cache: the one a few
        // samples on is fetched now.
        if (i + kRunPrefetch < n && winners[i + kRunPrefetch] != kNoSetup)
          prefetchRun(winners[i + kRunPrefetch]);
        fillRun(runs++, win);
        last = win;
      }
      // corner + grid position, as glm adds them
      b.x[used] = px + grid[s].x;
      b.y[used] = py + grid[s].y;
      b.run[used] = int64_t(runs - 1);
      b.vx[used] = columnView[i];
      b.vy[used] = rowView[s];
      localOut[used] = local0 + uint32_t(i);
      ++used;
    }
    if (++s == spp) {
      s = 0;
      px += 1.0;
    }
  }
  used_ = used;
  runs_ = runs;
  lastWinner_ = last;
  return i;
}

void PrimaryBatch::prefetchRun(uint32_t winner) const {
  // The bytes fillRun reads: the setup's ids and planes, the refinement plane.
  const char* t = reinterpret_cast<const char*>(&setups_[winner]);
  __builtin_prefetch(t);
  __builtin_prefetch(t + offsetof(TriangleSetup, depth));
  __builtin_prefetch(t + offsetof(TriangleSetup, dOverW));
  __builtin_prefetch(t + offsetof(TriangleSetup, b2OverW) + sizeof(PlaneCoefficients) - 1);
  if (refinePlanes_) {
    const char* p = reinterpret_cast<const char*>(&refinePlanes_[winner]);
    __builtin_prefetch(p);
    __builtin_prefetch(p + sizeof(RefinePlane) - 1);
  }
}

// Run r: its setup's planes and its stored triangle's plane.
void PrimaryBatch::fillRun(size_t r, uint32_t winner) {
  primary_detail::FusedBlock& b = *block_;
  const TriangleSetup& t = setups_[winner];
  runSetup_[r] = &t;
  b.x0[r] = t.depth.x0, b.y0[r] = t.depth.y0;
  b.iw0[r] = t.invW.v0, b.iwx[r] = t.invW.dx, b.iwy[r] = t.invW.dy;
  b.dw0[r] = t.dOverW.v0, b.dwx[r] = t.dOverW.dx, b.dwy[r] = t.dOverW.dy;
  b.b10[r] = t.b1OverW.v0, b.b1x[r] = t.b1OverW.dx, b.b1y[r] = t.b1OverW.dy;
  b.b20[r] = t.b2OverW.v0, b.b2x[r] = t.b2OverW.dx, b.b2y[r] = t.b2OverW.dy;
  runInstance_[r] = t.instance;
  runTriangle_[r] = t.triangle;
  if (refinePlanes_) {
    // Computed in setup (raster/setup.h: RefinePlane).
    const RefinePlane& p = refinePlanes_[winner];
    b.e1x[r] = p.e1.x, b.e1y[r] = p.e1.y, b.e1z[r] = p.e1.z;
    b.e2x[r] = p.e2.x, b.e2y[r] = p.e2.y, b.e2z[r] = p.e2.z;
    b.sx[r] = p.s.x, b.sy[r] = p.s.y, b.sz[r] = p.s.z;
    b.qx[r] = p.q.x, b.qy[r] = p.q.y, b.qz[r] = p.q.z;
    b.e2DotQ[r] = p.e2DotQ;
    b.slot1[r] = double(p.slot1);
    b.slot2[r] = double(p.slot2);
    return;
  }
  const size_t slot = (t.triangle * 2654435761u + t.instance * 40503u) >> (32 - kPlaneCacheBits);
  Plane& p = planes_[slot];
  const uint64_t key = t.id();
  if (planeKeys_[slot] != key) {
    planeKeys_[slot] = key;
    // glm: the same bits as intersectTrianglePlane's memo.
    const TrianglePlane plane = trianglePlane(scene_, t.instance, t.triangle);
    p.e1 = plane.e1;
    p.e2 = plane.e2;
    p.s = camera_.eye - plane.a;
    p.q = glm::cross(p.s, plane.e1);
    p.e2DotQ = glm::dot(plane.e2, p.q);
    p.slot1 = double(plane.slot1);
    p.slot2 = double(plane.slot2);
  }
  b.e1x[r] = p.e1.x, b.e1y[r] = p.e1.y, b.e1z[r] = p.e1.z;
  b.e2x[r] = p.e2.x, b.e2y[r] = p.e2.y, b.e2z[r] = p.e2.z;
  b.sx[r] = p.s.x, b.sy[r] = p.s.y, b.sz[r] = p.s.z;
  b.qx[r] = p.q.x, b.qy[r] = p.q.y, b.qz[r] = p.q.z;
  b.e2DotQ[r] = p.e2DotQ;
  b.slot1[r] = p.slot1;
  b.slot2[r] = p.slot2;
}

void PrimaryBatch::run() {
  primary_detail::FusedBlock& b = *block_;
  if (used_ == 0) return;
  if (camera_.perspective) {
    // Padding: the last run again, at the image origin; never read back.
    const size_t vectorLanes = HWY_DYNAMIC_DISPATCH(SampleLanes)();
    b.lanes = (used_ + vectorLanes - 1) / vectorLanes * vectorLanes;
    for (size_t k = used_; k < b.lanes; ++k) {
      b.x[k] = b.y[k] = 0.0;
      b.run[k] = int64_t(runs_ - 1);
    }
    HWY_DYNAMIC_DISPATCH(LanesFusedPrimary)(&b, &camera_);
    for (size_t k = 0; k < used_; ++k) {
      const bool refined = b.refined[k] != 0.0;
      kb1_[k] = float(refined ? b.rb1[k] : b.b1[k]);
      kb2_[k] = float(refined ? b.rb2[k] : b.b2[k]);
      run32_[k] = int32_t(b.run[k]);
    }
    return;
  }
  // Orthographic rays: the reference steps, then the batched refinement.
  const PrimaryRays primary(*camera_.camera);
  SampleHit hits[primary_detail::kBlock];
  Ray rays[primary_detail::kBlock];
  ShadeHit refined[primary_detail::kBlock];
  const glm::dvec2 unused[primary_detail::kBlock] = {};
  for (size_t k = 0; k < used_; ++k) {
    const glm::dvec2 pos(b.x[k], b.y[k]);
    hits[k] = interpolatedSampleHit(*runSetup_[b.run[k]], pos);
    rays[k] = primary(pos);
  }
  refinePrimaryHits(scene_, rays, hits, unused, used_, refined);
  for (size_t k = 0; k < used_; ++k) {
    // Exact in double: hit(k) rounds them back to the same floats.
    b.depth[k] = double(hits[k].depth);
    b.b1[k] = double(hits[k].b1);
    b.b2[k] = double(hits[k].b2);
    b.dirX[k] = refined[k].direction.x;
    b.dirY[k] = refined[k].direction.y;
    b.dirZ[k] = refined[k].direction.z;
    kb1_[k] = refined[k].b1;
    kb2_[k] = refined[k].b2;
    run32_[k] = int32_t(b.run[k]);
  }
}

PrimaryHitBlock PrimaryBatch::hits(const double* footprintX, const double* footprintY,
                                   const uint32_t* colorIndex) const {
  PrimaryHitBlock h;
  h.count = used_;
  h.run = run32_;
  h.runInstance = runInstance_;
  h.runTriangle = runTriangle_;
  h.dirX = block_->dirX;
  h.dirY = block_->dirY;
  h.dirZ = block_->dirZ;
  h.b1 = kb1_;
  h.b2 = kb2_;
  h.footprintX = footprintX;
  h.footprintY = footprintY;
  h.colorIndex = colorIndex;
  return h;
}

void primaryShadeHits(const PrimaryRayConstants& camera, const Scene& scene, const TriangleSetup* setups,
                      const uint32_t* winners, const glm::dvec2* positions, const glm::dvec2* footprints,
                      size_t count, SampleHit* hits, ShadeHit* out) {
  const std::unique_ptr<PrimaryBatch> batch = std::make_unique<PrimaryBatch>(camera, scene, setups);
  for (size_t first = 0; first < count; first += primary_detail::kBlock) {
    const size_t used = std::min(primary_detail::kBlock, count - first);
    for (size_t k = 0; k < used; ++k)
      batch->add(winners[first + k], positions[first + k].x, positions[first + k].y);
    batch->run();
    const PrimaryHitBlock h = batch->hits(nullptr, nullptr, nullptr);
    for (size_t k = 0; k < used; ++k) {
      hits[first + k] = batch->hit(k);
      ShadeHit& r = out[first + k];
      r.instance = h.runInstance[h.run[k]];
      r.triangle = h.runTriangle[h.run[k]];
      r.b1 = h.b1[k];
      r.b2 = h.b2[k];
      r.direction = glm::dvec3(h.dirX[k], h.dirY[k], h.dirZ[k]);
      r.footprintPosition = footprints[first + k];
      r.throughput = 1.0f;
    }
    batch->clear();
  }
}

}  // namespace rastray

#endif  // HWY_ONCE
