// The primary-hit shading kernel both renderers call (issue 20): a batch of
// primary hits shaded in float SIMD lanes, chosen at run time (Highway's
// HWY_DYNAMIC_DISPATCH over the targets this file is compiled for; no
// -march), with the scalar double Shader::shade (common/shading.h) kept
// beside it as the reference.
//
// What runs where, and why (precision):
//   double                   refinement on the stored triangle's plane
//                            (intersectTrianglePlane: far from the origin
//                            the ray's t must not lose the plane; in double
//                            SIMD lanes for a batch, primary_refinement.h),
//                            and per hit, in double SIMD lanes, the surface
//                            position (b0·p0 + b1·p1 + b2·p2, it becomes
//                            shadow-ray origins and shadow-map lookups),
//                            the vector to each point or spot light
//                            (light − position, rounded to float only
//                            after the subtraction) and the entering side
//                            (d·ng against the face normal, memoised per
//                            triangle).
//   float, SIMD lanes        COLOR_0 and shading-normal interpolation and
//                            normalisation, the facing normal, the eye
//                            light, each light's distance, direction,
//                            1/d² falloff, range window, spot cone and
//                            cosine, the Lambert sum, emission, the
//                            mirror/transmission weights and the BLEND
//                            premultiply.
//   float, scalar per lane   texture sampling and its pixel footprint (the
//                            footprint in double), only for lanes whose
//                            material samples a texture; each light's
//                            LightVisibility::transmittance (shadow rays or
//                            shadow maps; directions and distances in
//                            double) where the light reaches the lane.
//   Shader::shade (scalar)   the whole lane, when its material would trace
//                            secondary rays (mirror weight or transmission
//                            > 0, a SecondaryRayTracer, depth 0 < maxDepth)
//                            or is BLEND (layers keep the scalar path in
//                            both renderers), or has a normal, occlusion
//                            or metallic-roughness map (docs/MATERIALS.md),
//                            or when
//                            ShadingOptions::referenceShading is set.
//
// Invariants:
//   - Lane independence: a hit's colour is a function of that hit alone
//     (and the Shader), not of the other hits in its batch nor of the batch
//     size: the lanes use no cross-lane operation and a partial vector is
//     padded, never run through other code. Hybrid and ray-cast frames
//     call this kernel on the same refined hits, so they stay bit-identical.
//   - Only IEEE-exact float operations (+ − × ÷ √, min, max, |x|,
//     compares), and this file is compiled with -ffp-contract=off: no FMA,
//     no approximate reciprocal, so every dispatch target (Highway's
//     scalar one included) gives the same bits, which the tests check.
//   - Error against the double reference (Shader::shade), per channel of
//     the premultiplied colour: at most 1e-6 relative to max(1,
//     |reference|) (about 8 float ulps; measured worst 3.5e-7 on the
//     Cornell box, ≤ 1.2e-7 on the stiff scenes far-node/far-baked-1e6,
//     1e7, grazing-lit/textured-89.9, scale-1e-4/1e4). The float steps
//     each round once (6e-8); the position and the vector to a light are
//     rounded only after the double subtraction, so distance from the
//     origin costs no precision. Where the lit/unlit or facing decision
//     itself sits within a float rounding of its threshold (n·l = 0,
//     n·d = 0) a lane may take the other side; the tests allow 1 lane in
//     1000 beyond the bound and found none (tests/common/
//     shading_kernel_test.cpp, tests/raster, tests/raytrace).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "common/camera.h"
#include "common/hit.h"
#include "common/scene.h"

namespace rastray {

class Shader;

// One primary hit to shade. (b1, b2) are already refined on the stored
// triangle's plane along the primary ray (refinePrimaryHit), as
// surfacePointOnRay would refine them.
struct ShadeHit {
  uint32_t instance = kNoId;
  uint32_t triangle = kNoId;
  float b1 = 0.0f, b2 = 0.0f;
  glm::dvec3 direction{0.0, 0.0, -1.0};  // the primary ray's, unit, towards the surface
  glm::dvec2 footprintPosition{0.0};     // image position of the texture footprint (pixelFootprint)
  float throughput = 1.0f;               // passed to Shader::shade in lanes that fall back to it
};

// A renderer's hit refined along its primary ray (the steps of
// surfacePointOnRay: intersectTrianglePlane, refinedBarycentrics), for
// the kernel. `hit` must be valid. Returns the hit with the refined
// barycentrics (its depth unchanged), as surfacePointOnRay's point has them.
ShadeHit refinePrimaryHit(const Scene& scene, const Ray& ray, const SampleHit& hit,
                          const glm::dvec2& footprintPosition);

// Where a hit is shaded (ShadingOptions::referenceShading picks it for a
// whole frame; tests call both).
enum class ShadingPath {
  Kernel,     // the float SIMD lanes above, falling back per lane as stated
  Reference,  // Shader::shade for every hit (double)
};

// Premultiplied RGBA of hits[i] into colors[i] (depth 0), along `path`;
// the footprint is computed only for lanes whose material samples a
// texture (elsewhere it is unused: the same colour).
void shadePrimaryHits(const Shader& shader, const ShadeHit* hits, size_t count, glm::vec4* colors,
                      ShadingPath path);

// The same, scattered: the colour of hits[i] into colors[colorIndex[i]]
// (a tile's samples, without a contiguous copy in between).
void shadePrimaryHits(const Shader& shader, const ShadeHit* hits, size_t count, glm::vec4* colors,
                      const uint32_t* colorIndex, ShadingPath path);

// A block of at most kPrimaryHitBlock primary hits as struct of arrays,
// in runs of consecutive hits on one triangle: what the rasterizer's fused
// pass (raster/primary_samples.h) hands the kernel without building a
// ShadeHit per hit. Hit i is ShadeHit{runInstance[run[i]],
// runTriangle[run[i]], b1[i], b2[i], (dirX, dirY, dirZ)[i], (footprintX,
// footprintY)[i], throughput 1}; its colour goes to colors[colorIndex[i]].
constexpr size_t kPrimaryHitBlock = 64;
struct PrimaryHitBlock {
  size_t count = 0;
  const int32_t* run = nullptr;           // per hit: its run, non-decreasing
  const uint32_t* runInstance = nullptr;  // per run
  const uint32_t* runTriangle = nullptr;  // per run
  // Per hit: the direction (unit, towards the surface) and the refined
  // barycentrics; null when PrimaryHitShader::needsHitInputs() is false.
  const double *dirX = nullptr, *dirY = nullptr, *dirZ = nullptr;
  const float *b1 = nullptr, *b2 = nullptr;
  const double *footprintX = nullptr, *footprintY = nullptr;  // per hit: image position of the footprint
  const uint32_t* colorIndex = nullptr;                       // per hit
  // Optional: the first hit of each run (runs + 1 entries, the last one
  // `count`), so the kernel need not look for where runs change.
  size_t runs = 0;
  const uint32_t* runFirst = nullptr;
  // Optional, per run: the stored triangle's corner indices
  // (scene.triangle's) and unit face normal (triangleFaceNormal's bits),
  // where the caller has them (raster setup: TriangleSetup::corners), so
  // the kernel need not load the indices and compute the normal; a run
  // whose corners are kNoId takes the kernel's own.
  const glm::uvec3* runCorners = nullptr;
  const glm::dvec3* runFaceNormal = nullptr;
  // Optional, so the kernel can read the per-hit inputs in place instead
  // of copying them into its own block: each hit's run as int64 (`run`'s
  // values), and `lanes` ≥ count such that entries [count, lanes) of run,
  // run64, dirX/Y/Z, b1 and b2 hold a padding hit of the block's last run.
  // Read in place only with runFirst given and those arrays and run64
  // 64-byte aligned (the fused pass's block); else copied.
  const int64_t* run64 = nullptr;
  size_t lanes = 0;
};

// The kernel for blocks of hits (PrimaryHitBlock), built once per caller
// (a tile) instead of per batch: the same colours, bit for bit, as
// shadePrimaryHits on the same hits as ShadeHits (tested), with the
// per-run values (triangle, material, base colour and emission where no
// texture, vertex colour or visibility callback needs the hit's own)
// stored once per run instead of per hit.
class PrimaryHitShader {
 public:
  PrimaryHitShader(const Shader& shader, ShadingPath path);
  ~PrimaryHitShader();
  PrimaryHitShader(const PrimaryHitShader&) = delete;
  PrimaryHitShader& operator=(const PrimaryHitShader&) = delete;

  // Shades hits.count ≤ kPrimaryHitBlock hits into `colors`.
  void shade(const PrimaryHitBlock& hits, glm::vec4* colors);

  // Whether shade() reads the hits' directions and barycentrics. False
  // when every instance of the scene is shaded with one colour of its
  // material alone on the lanes' path (no texture, vertex colours or
  // scalar path; no diffuse term, or the eye light on a black base colour:
  // an emissive, unlit surface): a block's colours are then its runs'
  // instances' colours, the same bits as the lanes give (tested), and
  // PrimaryHitBlock's per-hit inputs may be null. Not cached: it looks
  // at every instance, so ask once per frame.
  bool needsHitInputs() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Tests only: whether kernels built from now on shade a block whose lights
// need no visibility callback (at most four lights, or the eye light) in
// two passes over its lanes (the default), or in the lanes' separate
// passes per step (their reference: the same bits, tested).
void setTwoPassShadingForTest(bool enabled);

// The SIMD target HWY_DYNAMIC_DISPATCH runs the lanes on here (Highway's
// name: AVX3, AVX2, SSE4, ...), for reports and tests.
const char* shadingKernelTarget();

}  // namespace rastray
