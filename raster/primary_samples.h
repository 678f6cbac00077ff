// The deferred shading's per-sample inputs for a batch of depth-test
// winners: the interpolated hit (TileRenderer::interpolatedHit: depth and
// barycentrics from the setup's 1/w planes) and the primary ray through the
// sample (PrimaryRays), computed in double SIMD lanes chosen at run time
// (Highway, as common/shading_kernel.h). The same IEEE operations in the
// same order, no contraction (-ffp-contract=off), so every sample gets the
// scalar reference's bits on every target; a sample's result does not
// depend on its batch (tests/raster/primary_samples_test.cpp). Why: these
// were two divisions and two square roots per sample, one sample at a time,
// the largest part of the shade stage (docs/PERFORMANCE.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "common/camera.h"
#include "common/hit.h"
#include "common/scene.h"
#include "common/shading_kernel.h"
#include "raster/coverage.h"
#include "raster/setup.h"

namespace rastray {

// The camera's constants the lanes need, as PrimaryRays derives them.
struct PrimaryRayConstants {
  explicit PrimaryRayConstants(const Camera& camera);
  const Camera* camera;
  bool perspective;
  double width, height;  // the image size, as ndcFromImage converts it
  glm::dvec2 scale;      // camera.ndcScale()
  glm::dvec3 eye;
  glm::dvec3 m0, m1;        // worldFromView's first two columns (xyz)
  glm::dvec3 constantPart;  // m2·(−1) + m3·0, per component
};

// The scalar reference of the lanes' first steps: hits[i] =
// interpolatedHit(setups[winners[i]], positions[i]) and rays[i] =
// PrimaryRays(camera)(positions[i]), one sample at a time.
void primarySamplesReference(const PrimaryRayConstants& camera, const TriangleSetup* setups,
                             const uint32_t* winners, const glm::dvec2* positions, size_t count,
                             SampleHit* hits, Ray* rays);

// The deferred shading's inputs in one pass: hits[i] as
// primarySamplesReference gives them, and out[i] = refinePrimaryHit(scene, ray_i, hits[i],
// footprints[i]) with ray_i = PrimaryRays(camera)(positions[i]), as
// refinePrimaryHits would give it, bit for bit. For a perspective camera
// each block of samples is gathered once (the setup's planes and the
// stored triangle's plane, looked up once per run of samples on one
// triangle) and runs interpolation, primary ray and refinement in the same
// double lanes, without materialising the rays; otherwise the two calls.
void primaryShadeHits(const PrimaryRayConstants& camera, const Scene& scene, const TriangleSetup* setups,
                      const uint32_t* winners, const glm::dvec2* positions, const glm::dvec2* footprints,
                      size_t count, SampleHit* hits, ShadeHit* out);

namespace primary_detail {

constexpr size_t kBlock = kPrimaryHitBlock;  // a multiple of every target's double lane count (2, 4, 8)

// The fused pass's block (PrimaryBatch). Consecutive samples mostly lie on
// one setup, so what is constant along a run of them (the setup's planes,
// the stored triangle's plane) is stored once per run in a table, and each
// lane holds only its position and its run: a vector of lanes on one run
// reads the table as broadcasts, a vector across runs gathers.
struct FusedBlock {
  size_t lanes = 0;
  alignas(64) double x[kBlock], y[kBlock];
  alignas(64) int64_t run[kBlock];    // non-decreasing within the block
  alignas(64) int32_t run32[kBlock];  // the same, for the kernel
  // The view-plane vector (ndc · scale) per lane, when every lane has it
  // (`haveView`: added by addRow from per-tile tables, the operations of
  // the lanes); else the lanes compute it from x and y.
  bool haveView = false;
  alignas(64) double vx[kBlock], vy[kBlock];
  // Per run: the interpolation's inputs, then the stored triangle's plane
  // as the refinement reads it (RefinePlaneLanes).
  alignas(64) double x0[kBlock], y0[kBlock];
  alignas(64) double iw0[kBlock], iwx[kBlock], iwy[kBlock];
  alignas(64) double dw0[kBlock], dwx[kBlock], dwy[kBlock];
  alignas(64) double b10[kBlock], b1x[kBlock], b1y[kBlock];
  alignas(64) double b20[kBlock], b2x[kBlock], b2y[kBlock];
  alignas(64) double e1x[kBlock], e1y[kBlock], e1z[kBlock], e2x[kBlock], e2y[kBlock], e2z[kBlock];
  alignas(64) double sx[kBlock], sy[kBlock], sz[kBlock], qx[kBlock], qy[kBlock], qz[kBlock];
  alignas(64) double e2DotQ[kBlock], slot1[kBlock], slot2[kBlock];
  // Whether the interpolated barycentrics are wanted (PrimaryBatch::hit);
  // else the lanes compute them only where the refinement fails.
  bool wantInterpolated = true;
  // Whether the kernel's inputs are wanted (PrimaryBatch::wantShadingInputs):
  // else the per-run refinement planes are not filled and the lanes
  // compute the interpolation alone (the depth, and the interpolated
  // barycentrics when wanted).
  bool wantShadingInputs = true;
  // Out, per lane: the interpolated depth (as a float), the ray's
  // direction, the barycentrics the kernel shades with (float: the refined
  // ones where the refinement succeeds, else the interpolated ones) and,
  // when wanted, the interpolated barycentrics.
  alignas(64) float depth[kBlock], kb1[kBlock], kb2[kBlock];
  alignas(64) double dirX[kBlock], dirY[kBlock], dirZ[kBlock];
  alignas(64) double b1[kBlock], b2[kBlock];
};

}  // namespace primary_detail

// The fused pass a block of up to kPrimaryHitBlock samples at a time, the
// block filled by the caller sample by sample (the winner loop: no
// per-sample request arrays), its results handed to the shading kernel as
// struct of arrays (PrimaryHitBlock: no ShadeHit per sample). The same
// bits as primaryShadeHits, which runs through it.
class PrimaryBatch {
 public:
  // `planes`, when given, holds each setup's stored-triangle plane for
  // camera.eye (prepareTriangles' RefinePlaneRequest; the same bits as
  // computing it here), read instead of computed.
  PrimaryBatch(const PrimaryRayConstants& camera, const Scene& scene, const TriangleSetup* setups,
               const RefinePlane* planes = nullptr);
  ~PrimaryBatch();
  PrimaryBatch(const PrimaryBatch&) = delete;
  PrimaryBatch& operator=(const PrimaryBatch&) = delete;

  size_t size() const { return used_; }
  // The added samples' image positions, in the order added.
  const double* x() const { return block_->x; }
  const double* y() const { return block_->y; }
  bool full() const { return used_ == primary_detail::kBlock; }

  // Adds the sample at image position (x, y), won by setups[winner].
  void add(uint32_t winner, double x, double y) {
    block_->haveView = false;
    const size_t k = used_++;
    block_->x[k] = x;
    block_->y[k] = y;
    if (winner != lastWinner_ || runs_ == 0) {
      fillRun(runs_++, winner, k);
      lastWinner_ = winner;
    }
    block_->run[k] = int64_t(runs_ - 1);
    block_->run32[k] = int32_t(runs_ - 1);
  }

  // Adds the winners of samples [first, n) of one tile row: entry i is
  // sample i % spp of pixel x0 + i / spp in row y, at (x0 + i / spp, y) +
  // grid[i % spp], tile sample local0 + i, whose index goes to
  // localOut[k] for the batch's sample k; kNoSetup entries are skipped.
  // Stops when the block is full; returns where it stopped.
  size_t addRow(const uint32_t* winners, size_t first, size_t n, int spp, int x0, int y,
                const glm::dvec2* grid, uint32_t local0, uint32_t* localOut);

  // Runs the added samples through the lanes (perspective) or the scalar
  // reference steps (orthographic); then hit(k) and hits() hold their
  // results until clear().
  void run();
  // The interpolated hit of sample k (primaryShadeHits' `hits`).
  SampleHit hit(size_t k) const {
    const int64_t r = block_->run[k];
    return {runInstance_[r], runTriangle_[r], block_->depth[k], float(block_->b1[k]), float(block_->b2[k])};
  }
  // hit(k).depth alone (hit(k) needs wantInterpolated(true)).
  float depth(size_t k) const { return block_->depth[k]; }
  // depth(k) for every k < size().
  const float* depths() const { return block_->depth; }
  // Whether hit(k) is read (its interpolated barycentrics are computed);
  // true until set.
  void wantInterpolated(bool want) { block_->wantInterpolated = want; }
  // Whether the kernel reads the hits' directions and refined barycentrics
  // (PrimaryHitShader::needsHitInputs); true until set. Without them the
  // batch reads and computes the interpolation alone (no ray, no
  // refinement plane, no corners or face normal), and hits() hands the
  // kernel the runs' ids only. Set before adding samples.
  void wantShadingInputs(bool want) { block_->wantShadingInputs = want; }
  // The refined hits for the kernel; footprints and colour indices are the
  // caller's (per sample, in the order added). The per-hit inputs are the
  // block's own, padded for the kernel to read in place
  // (PrimaryHitBlock::run64, lanes); without shading inputs
  // (wantShadingInputs(false)) they, the corners and the face normals are
  // null.
  PrimaryHitBlock hits(const double* footprintX, const double* footprintY, const uint32_t* colorIndex);
  void clear() {
    used_ = 0;
    runs_ = 0;
    block_->haveView = true;
  }

 private:
  void fillRun(size_t r, uint32_t winner, size_t firstLane);                // run r's table entry
  void fillRefinePlane(size_t r, const TriangleSetup& t, uint32_t winner);  // its stored triangle's plane
  void prefetchRun(uint32_t winner) const;                                  // what fillRun will read for it
  static constexpr size_t kRunPrefetch = 8;                                 // samples ahead in addRow

  const PrimaryRayConstants& camera_;
  const Scene& scene_;
  const TriangleSetup* setups_;
  const RefinePlane* refinePlanes_;
  std::unique_ptr<primary_detail::FusedBlock> block_;
  size_t used_ = 0, runs_ = 0;
  uint32_t lastWinner_ = 0;
  const TriangleSetup* runSetup_[primary_detail::kBlock];
  // Per run and per sample, for the kernel (after run()).
  uint32_t runInstance_[primary_detail::kBlock], runTriangle_[primary_detail::kBlock];
  glm::uvec3 runCorners_[primary_detail::kBlock];     // the setup's (TriangleSetup::corners)
  glm::dvec3 runFaceNormal_[primary_detail::kBlock];  // the setup's (TriangleSetup::faceNormal)
  uint32_t runFirst_[primary_detail::kBlock + 1];     // each run's first sample, then used_ (hits())
  // The stored triangle's plane as a run needs it (with the eye-dependent
  // terms as intersectTrianglePlane's memo computes them), for recent
  // triangles: a function of the triangle and the eye alone, cached by
  // triangle. Small triangles give runs of one or two samples, and a
  // tile's next row meets the same triangles again.
  struct Plane {
    glm::dvec3 e1, e2, s, q;
    double e2DotQ, slot1, slot2;
  };
  static constexpr int kPlaneCacheBits = 7;
  std::unique_ptr<Plane[]> planes_;        // uninitialised where planeKeys_ holds kNoPlane
  std::unique_ptr<uint64_t[]> planeKeys_;  // (instance << 32 | triangle) of each entry
  static constexpr uint64_t kNoPlane = ~uint64_t(0);
  // addRow's image positions and view-plane vectors per row entry: x and
  // vx per column and sample of the last x0, y and vy per entry of the
  // last row.
  std::vector<double> columnX_, columnView_;
  int columnX0_ = 0, columnSpp_ = 0;
  std::vector<double> rowYs_, rowView_;
  int rowY_ = 0, rowSpp_ = 0;
};

// TileRenderer::interpolatedHit: depth and barycentrics at `pos` from the
// setup's planes, rounded to float.
inline SampleHit interpolatedSampleHit(const TriangleSetup& t, const glm::dvec2& pos) {
  const glm::dvec2 b = t.baryAt(pos.x, pos.y);
  return {t.instance, t.triangle, float(t.viewDepthAt(pos.x, pos.y)), float(b.x), float(b.y)};
}

}  // namespace rastray
