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

// The setup planes of lanes i.. of the block at their positions:
// PlaneCoefficients::at, (v0 + dx·(x − x0)) + dy·(y − y0), with the run's
// coefficients (a broadcast or a gather, RunLanes).
template <class D>
class PlanesAt {
 public:
  PlanesAt(D d, const primary_detail::FusedBlock* b, size_t i)
      : get(d, b->run, i),
        ox_(hn::Sub(hn::Load(d, b->x + i), get(b->x0))),
        oy_(hn::Sub(hn::Load(d, b->y + i), get(b->y0))) {}
  HWY_INLINE hn::Vec<D> operator()(const double* v0, const double* dx, const double* dy) const {
    return hn::Add(hn::Add(get(v0), hn::Mul(get(dx), ox_)), hn::Mul(get(dy), oy_));
  }
  // The interpolated depth, viewDepthAt: (d/w) / (1/w).
  HWY_INLINE hn::Vec<D> depth(const primary_detail::FusedBlock* b) const {
    return hn::Div((*this)(b->dw0, b->dwx, b->dwy), (*this)(b->iw0, b->iwx, b->iwy));
  }
  // The interpolated barycentrics, baryAt: (b/w) · (1 / (1/w)).
  HWY_INLINE void bary(const primary_detail::FusedBlock* b, hn::Vec<D>* b1, hn::Vec<D>* b2) const {
    const auto inv = hn::Div(hn::Set(D(), 1.0), (*this)(b->iw0, b->iwx, b->iwy));
    *b1 = hn::Mul((*this)(b->b10, b->b1x, b->b1y), inv);
    *b2 = hn::Mul((*this)(b->b20, b->b2x, b->b2y), inv);
  }

  const RunLanes<D> get;  // the block's other per-run tables

 private:
  hn::Vec<D> ox_, oy_;
};

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
  const hn::Rebind<float, decltype(d)> df;  // the float outputs, one per double lane
  const size_t N = hn::Lanes(d);
  const auto one = hn::Set(d, 1.0), two = hn::Set(d, 2.0);
  const auto width = hn::Set(d, c->width), height = hn::Set(d, c->height);
  const auto sx = hn::Set(d, c->scale.x), sy = hn::Set(d, c->scale.y);
  const auto m0x = hn::Set(d, c->m0.x), m0y = hn::Set(d, c->m0.y), m0z = hn::Set(d, c->m0.z);
  const auto m1x = hn::Set(d, c->m1.x), m1y = hn::Set(d, c->m1.y), m1z = hn::Set(d, c->m1.z);
  const auto cx = hn::Set(d, c->constantPart.x), cy = hn::Set(d, c->constantPart.y);
  const auto cz = hn::Set(d, c->constantPart.z);
  for (size_t i = 0; i < b->lanes; i += N) {
    hn::Store(hn::DemoteTo(df, PlanesAt<decltype(d)>(d, b, i).depth(b)), df, b->depth + i);

    hn::Vec<decltype(d)> vx, vy;
    if (b->haveView) {
      vx = hn::Load(d, b->vx + i);
      vy = hn::Load(d, b->vy + i);
    } else {
      const auto x = hn::Load(d, b->x + i), y = hn::Load(d, b->y + i);
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
  }
  // The refinement in a second loop over the block: each loop's chain of
  // divisions is shorter, so more vectors are in flight at once.
  for (size_t i = 0; i < b->lanes; i += N) {
    const RunLanes<decltype(d)> get(d, b->run, i);
    const auto dirX = hn::Load(d, b->dirX + i), dirY = hn::Load(d, b->dirY + i),
               dirZ = hn::Load(d, b->dirZ + i);
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
    // The interpolated barycentrics (a division) only where they are read.
    if (b->wantInterpolated || !hn::AllTrue(d, ok)) {
      hn::Vec<decltype(d)> b1, b2;
      PlanesAt<decltype(d)>(d, b, i).bary(b, &b1, &b2);
      hn::Store(b1, d, b->b1 + i);
      hn::Store(b2, d, b->b2 + i);
      rb1 = hn::IfThenElse(ok, rb1, b1);
      rb2 = hn::IfThenElse(ok, rb2, b2);
    }
    hn::Store(hn::DemoteTo(df, rb1), df, b->kb1 + i);
    hn::Store(hn::DemoteTo(df, rb2), df, b->kb2 + i);
  }
}

// LanesFusedPrimary's interpolation alone, for a block whose kernel reads
// no ray or refined hit (FusedBlock::wantShadingInputs false): the depth
// and, when wanted, the interpolated barycentrics, with its operations.
void LanesInterpolated(primary_detail::FusedBlock* b) {
  const hn::ScalableTag<double> d;
  const hn::Rebind<float, decltype(d)> df;
  const size_t N = hn::Lanes(d);
  for (size_t i = 0; i < b->lanes; i += N) {
    const PlanesAt<decltype(d)> at(d, b, i);
    hn::Store(hn::DemoteTo(df, at.depth(b)), df, b->depth + i);
    if (!b->wantInterpolated) continue;
    hn::Vec<decltype(d)> b1, b2;
    at.bary(b, &b1, &b2);
    hn::Store(b1, d, b->b1 + i);
    hn::Store(b2, d, b->b2 + i);
  }
}

// addRow's helpers. The end of the run of entries equal to `value` in
// w[i, limit): i itself when w[i] differs.
size_t LanesSpanEnd(const uint32_t* w, size_t i, size_t limit, uint32_t value) {
  const hn::ScalableTag<uint32_t> du;
  const size_t N = hn::Lanes(du);
  const auto v = hn::Set(du, value);
  for (; i + N <= limit; i += N) {
    const auto differs = hn::Ne(hn::LoadU(du, w + i), v);
    if (!hn::AllFalse(du, differs)) return i + size_t(hn::FindFirstTrue(du, differs));
  }
  while (i < limit && w[i] == value) ++i;
  return i;
}

// Lanes [used, used + m) of the block from a span of row entries on run
// r: image positions and view-plane vectors copied from the row's tables
// (y and vy one value when `constantY`), the tile samples local, local + 1, ….
void LanesFillSpan(primary_detail::FusedBlock* b, size_t used, size_t m, const double* x, const double* vx,
                   const double* y, const double* vy, bool constantY, int32_t r, uint32_t local,
                   uint32_t* localOut) {
  const hn::ScalableTag<double> d;
  const hn::RebindToSigned<decltype(d)> di;
  const hn::Rebind<int32_t, decltype(d)> di32;
  const hn::Rebind<uint32_t, decltype(d)> du32;
  const size_t N = hn::Lanes(d);
  const auto run = hn::Set(di, int64_t(r));
  const auto run32 = hn::Set(di32, r);
  size_t k = 0;
  for (; k + N <= m; k += N) {
    const size_t o = used + k;
    hn::StoreU(hn::LoadU(d, x + k), d, b->x + o);
    hn::StoreU(hn::LoadU(d, vx + k), d, b->vx + o);
    hn::StoreU(constantY ? hn::Set(d, y[0]) : hn::LoadU(d, y + k), d, b->y + o);
    hn::StoreU(constantY ? hn::Set(d, vy[0]) : hn::LoadU(d, vy + k), d, b->vy + o);
    hn::StoreU(run, di, b->run + o);
    hn::StoreU(run32, di32, b->run32 + o);
    hn::StoreU(hn::Iota(du32, local + uint32_t(k)), du32, localOut + o);
  }
  for (; k < m; ++k) {
    const size_t o = used + k;
    b->x[o] = x[k];
    b->vx[o] = vx[k];
    b->y[o] = constantY ? y[0] : y[k];
    b->vy[o] = constantY ? vy[0] : vy[k];
    b->run[o] = int64_t(r);
    b->run32[o] = r;
    localOut[o] = local + uint32_t(k);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

#include <algorithm>

#include "common/primary_refinement.h"
#include "common/sampling.h"
#include "common/triangle_plane.h"

namespace rastray {

HWY_EXPORT(SampleLanes);
HWY_EXPORT(LanesFusedPrimary);
HWY_EXPORT(LanesInterpolated);
HWY_EXPORT(LanesSpanEnd);
HWY_EXPORT(LanesFillSpan);

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
  // Per entry i of the row: the sample's image position (corner + grid
  // position, as glm adds them: double(x0 + column) is the corner's x
  // exactly) and its view-plane vector as the lanes would compute it
  // (ndcFromImage, then · scale); x once per tile, y once per row.
  const size_t columns = n / size_t(spp) + 1;
  if (columnX0_ != x0 || columnSpp_ != spp || columnView_.size() < columns * size_t(spp)) {
    columnX0_ = x0;
    columnSpp_ = spp;
    columnX_.resize(columns * size_t(spp));
    columnView_.resize(columns * size_t(spp));
    for (size_t c = 0; c < columns; ++c)
      for (int s = 0; s < spp; ++s) {
        const double x = double(x0 + int(c)) + grid[s].x;
        columnX_[c * size_t(spp) + size_t(s)] = x;
        columnView_[c * size_t(spp) + size_t(s)] = ((2.0 * x) / camera_.width - 1.0) * camera_.scale.x;
      }
  }
  if (rowY_ != y || rowSpp_ != spp || rowView_.size() < n) {
    rowY_ = y;
    rowSpp_ = spp;
    // Per sample of a pixel; at several samples, repeated along the row
    // (at one, the spans below fill the block with the one value).
    const size_t entries = spp == 1 ? 1 : n;
    rowYs_.resize(entries);
    rowView_.resize(entries);
    double baseY[kMaxGridSide * kMaxGridSide], baseView[kMaxGridSide * kMaxGridSide];
    for (int k = 0; k < spp; ++k) {
      baseY[k] = double(y) + grid[k].y;
      baseView[k] = (1.0 - (2.0 * baseY[k]) / camera_.height) * camera_.scale.y;
    }
    for (size_t c = 0; c < entries; c += size_t(spp))
      for (size_t k = 0; k < size_t(spp) && c + k < entries; ++k) {
        rowYs_[c + k] = baseY[k];
        rowView_[c + k] = baseView[k];
      }
  }
  const double* const columnX = columnX_.data();
  const double* const columnView = columnView_.data();
  const double* const rowY = rowYs_.data();
  const double* const rowView = rowView_.data();
  // The batch's state in locals (registers) for the loop.
  primary_detail::FusedBlock& b = *block_;
  size_t used = used_, runs = runs_;
  uint32_t last = lastWinner_;
  size_t i = first;
  // A span of entries on one winner: the first 8 looked at here, a
  // longer one (a large triangle's row, a row of background) in lanes.
  const auto spanEnd = [winners](size_t from, size_t limit, uint32_t value) {
    const size_t quick = std::min(limit, from + 8);
    while (from < quick && winners[from] == value) ++from;
    return from == quick && from < limit ? HWY_DYNAMIC_DISPATCH(LanesSpanEnd)(winners, from, limit, value)
                                         : from;
  };
  while (i < n && used < primary_detail::kBlock) {
    const uint32_t win = winners[i];
    if (win == kNoSetup) {
      i = spanEnd(i + 1, n, kNoSetup);
      continue;
    }
    if (win != last || runs == 0) {
      // Small triangles make runs of one or two samples, each on a setup
      // (and its refinement plane) mostly not in cache: the one a few
      // samples on is fetched now.
      if (i + kRunPrefetch < n && winners[i + kRunPrefetch] != kNoSetup)
        prefetchRun(winners[i + kRunPrefetch]);
      fillRun(runs++, win, used);
      last = win;
    }
    // The span of entries from i on this winner that fits the block:
    // copied table to block.
    const size_t end = spanEnd(i + 1, std::min(n, i + (primary_detail::kBlock - used)), win);
    const size_t m = end - i;
    const int32_t r = int32_t(runs - 1);
    const size_t e = spp == 1 ? 0 : i;  // the row tables' entry
    if (m >= 8) {
      HWY_DYNAMIC_DISPATCH(LanesFillSpan)
      (&b, used, m, columnX + i, columnView + i, rowY + e, rowView + e, spp == 1, r, local0 + uint32_t(i),
       localOut);
    } else {
      for (size_t k = 0; k < m; ++k) {
        const size_t ek = spp == 1 ? 0 : i + k;
        b.x[used + k] = columnX[i + k];
        b.y[used + k] = rowY[ek];
        b.vx[used + k] = columnView[i + k];
        b.vy[used + k] = rowView[ek];
        b.run[used + k] = int64_t(r);
        b.run32[used + k] = r;
        localOut[used + k] = local0 + uint32_t(i + k);
      }
    }
    used += m;
    i = end;
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
  if (!block_->wantShadingInputs) return;
  __builtin_prefetch(t + sizeof(TriangleSetup) - 1);  // corners and face normal, for the kernel
  if (refinePlanes_) {
    const char* p = reinterpret_cast<const char*>(&refinePlanes_[winner]);
    __builtin_prefetch(p);
    __builtin_prefetch(p + sizeof(RefinePlane) - 1);
  }
}

// Run r: its setup's planes and, for the kernel's inputs, its stored
// triangle's plane, corners and face normal.
void PrimaryBatch::fillRun(size_t r, uint32_t winner, size_t firstLane) {
  primary_detail::FusedBlock& b = *block_;
  const TriangleSetup& t = setups_[winner];
  runSetup_[r] = &t;
  b.x0[r] = t.depth.x0, b.y0[r] = t.depth.y0;
  b.iw0[r] = t.invW.v0, b.iwx[r] = t.invW.dx, b.iwy[r] = t.invW.dy;
  b.dw0[r] = t.dOverW.v0, b.dwx[r] = t.dOverW.dx, b.dwy[r] = t.dOverW.dy;
  runFirst_[r] = uint32_t(firstLane);
  runInstance_[r] = t.instance;
  runTriangle_[r] = t.triangle;
  // The barycentric planes: the interpolated ones, and the refinement's
  // fallback where it fails.
  if (b.wantInterpolated || b.wantShadingInputs) {
    b.b10[r] = t.b1OverW.v0, b.b1x[r] = t.b1OverW.dx, b.b1y[r] = t.b1OverW.dy;
    b.b20[r] = t.b2OverW.v0, b.b2x[r] = t.b2OverW.dx, b.b2y[r] = t.b2OverW.dy;
  }
  if (!b.wantShadingInputs) return;
  runCorners_[r] = t.corners;
  runFaceNormal_[r] = t.faceNormal;
  fillRefinePlane(r, t, winner);
}

void PrimaryBatch::fillRefinePlane(size_t r, const TriangleSetup& t, uint32_t winner) {
  primary_detail::FusedBlock& b = *block_;
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
    if (b.wantShadingInputs)
      HWY_DYNAMIC_DISPATCH(LanesFusedPrimary)(&b, &camera_);
    else
      HWY_DYNAMIC_DISPATCH(LanesInterpolated)(&b);
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
    b.depth[k] = hits[k].depth;
    b.b1[k] = double(hits[k].b1);
    b.b2[k] = double(hits[k].b2);
    b.dirX[k] = refined[k].direction.x;
    b.dirY[k] = refined[k].direction.y;
    b.dirZ[k] = refined[k].direction.z;
    b.kb1[k] = refined[k].b1;
    b.kb2[k] = refined[k].b2;
  }
}

PrimaryHitBlock PrimaryBatch::hits(const double* footprintX, const double* footprintY,
                                   const uint32_t* colorIndex) {
  runFirst_[runs_] = uint32_t(used_);
  primary_detail::FusedBlock& b = *block_;
  PrimaryHitBlock h;
  h.runs = runs_;
  h.runFirst = runFirst_;
  h.count = used_;
  h.run = block_->run32;
  h.runInstance = runInstance_;
  h.runTriangle = runTriangle_;
  h.footprintX = footprintX;
  h.footprintY = footprintY;
  h.colorIndex = colorIndex;
  if (!b.wantShadingInputs) return h;
  // The kernel reads the per-hit inputs in place: lanes up to a multiple
  // of 16 (every target's float lane count divides it) hold a copy of the
  // last hit.
  const size_t lanes = std::min(primary_detail::kBlock, (used_ + 15) / 16 * 16);
  if (used_ > 0) {
    const size_t last = used_ - 1;
    for (size_t k = used_; k < lanes; ++k) {
      b.run[k] = b.run[last];
      b.run32[k] = b.run32[last];
      b.dirX[k] = b.dirX[last], b.dirY[k] = b.dirY[last], b.dirZ[k] = b.dirZ[last];
      b.kb1[k] = b.kb1[last], b.kb2[k] = b.kb2[last];
    }
  }
  h.run64 = b.run;
  h.lanes = lanes;
  h.runCorners = runCorners_;
  h.runFaceNormal = runFaceNormal_;
  h.dirX = b.dirX;
  h.dirY = b.dirY;
  h.dirZ = b.dirZ;
  h.b1 = b.kb1;
  h.b2 = b.kb2;
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
