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

#include <glm/glm.hpp>

#include "common/camera.h"
#include "common/hit.h"
#include "common/scene.h"
#include "common/shading_kernel.h"
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

// TileRenderer::interpolatedHit: depth and barycentrics at `pos` from the
// setup's planes, rounded to float.
inline SampleHit interpolatedSampleHit(const TriangleSetup& t, const glm::dvec2& pos) {
  const glm::dvec2 b = t.baryAt(pos.x, pos.y);
  return {t.instance, t.triangle, float(t.viewDepthAt(pos.x, pos.y)), float(b.x), float(b.y)};
}

}  // namespace rastray
