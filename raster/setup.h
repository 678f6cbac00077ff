// Triangle setup: fixed-point snapping, integer edge functions with the
// top-left fill rule, and the screen-space planes of depth, 1/w and the
// perspective-divided barycentrics.
//
// Fixed point. Vertices snap to 1/256 pixel (kSubpixelBits = 8). Samples
// must lie exactly on the same integer grid, so coordinates are kept in
// units of 1/(256·k) pixel, where k is the smallest integer that puts
// every sample position of the pattern on the grid: 1 for the Direct3D
// patterns (multiples of 1/16) and for n×n grids with 2n dividing 256,
// else 2n / gcd(2n, 256) (e.g. 5×5: k = 5).
//
// Overflow. Vertex and sample coordinates are clamped to |X|, |Y| <= L =
// 2^29 units (kMaxCoordinateUnits) measured from the image's top-left
// corner, i.e. 2^21 / k pixels: the largest safe coordinate is ±2,097,152
// pixels for k = 1. An edge function E(p) = a·px + b·py + c has |a|, |b|
// <= 2L = 2^30 (coordinate differences) and |c| = |a·x0 + b·y0| <= 2^60,
// so |a·px + b·py| <= 2^60 and |E| <= 2^61 < 2^63: every evaluation and
// every incremental step in int64 is exact. The guard band keeps vertices
// inside ±(2^21/k − 2) pixels (clip.h clips x/y beyond it), and the image
// itself must fit: W, H <= 2^20 / k (checked by makeSampleGrid).
//
// Orientation and fill rule. Image space has y down. Setup orders the
// vertices so that twice the signed area (x1−x0)(y2−y0) − (y1−y0)(x2−x0) is
// positive (clockwise as seen on screen); then inside means E >= 0 for all
// three edges E_ij(p) = (xj−xi)(py−yi) − (yj−yi)(px−xi). A sample exactly on
// an edge (E = 0) is covered only when the edge is
//   top:  horizontal (yj == yi) with xj > xi, the triangle below it (y larger),
//   left: yj < yi (the edge goes up the screen; the triangle lies to its right),
// which is the Direct3D/OpenGL top-left convention in y-down coordinates.
// Implemented as E + bias >= 0 with bias 0 for top-left edges and −1 else.
// Front-facing (CCW in world, seen from the front) triangles have negative
// area before the reordering: CCW with y up is clockwise with y down.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/scene.h"
#include "raster/clip.h"
#include "raster/options.h"

namespace rastray {

constexpr int kSubpixelBits = 8;
constexpr int64_t kMaxCoordinateUnits = int64_t(1) << 29;

// Sample positions of a pattern on the fixed-point grid.
struct SampleGrid {
  int spp = 1;
  int64_t k = 1;  // grid refinement over 1/256 pixel
  int64_t unitsPerPixel = 256;
  std::vector<glm::i64vec2> offsets;  // sample offsets from the pixel corner, units
  std::vector<glm::dvec2> positions;  // the same in pixels (common/sampling.h)
  double safePixels = 0.0;            // largest safe |coordinate| in pixels
  double guardPixels = 0.0;           // beyond the image edges before x/y clipping
};

// Throws InputError for an unsupported sample count or an image too large
// for the fixed-point range.
SampleGrid makeSampleGrid(int spp, int width, int height);

// An affine function of the image position (pixels): value at (x, y) =
// v0 + dx·(x − x0) + dy·(y − y0).
struct Plane {
  double v0 = 0.0, dx = 0.0, dy = 0.0;
  double x0 = 0.0, y0 = 0.0;
  double at(double x, double y) const { return v0 + dx * (x - x0) + dy * (y - y0); }
};

// A plane's coefficients without its origin: the planes of one setup all
// pass through the same vertex, so they share the origin stored once (in
// TriangleSetup::depth) and evaluate with the same arithmetic as Plane::at.
struct PlaneCoefficients {
  double v0 = 0.0, dx = 0.0, dy = 0.0;
  double at(double x, double y, double x0, double y0) const { return v0 + dx * (x - x0) + dy * (y - y0); }
};

// Range proof for the narrow types: a and b are differences of two clamped
// coordinates, |a|, |b| <= 2^30 < 2^31 (int32); c <= 2^60 needs int64. at()
// widens before multiplying, so every product is an exact int64.
struct EdgeFunction {
  int32_t a = 0, b = 0;  // E(p) = a·px + b·py + c, p in units
  int64_t c = 0;
  int8_t bias = 0;  // 0 for top-left edges, −1 else
  bool topLeft = false;
  bool original = false;  // lies on an edge of the original (unclipped) triangle
  int64_t at(int64_t px, int64_t py) const { return int64_t(a) * px + int64_t(b) * py + c; }
};

// One set-up triangle (or clipped piece): 304 bytes. What is not kept
// because it can be derived: the clip vertices' barycentrics (only
// `original` needs them), the parent's stored index (the instance's first
// triangle + `triangle`), the maximum depth slope (from the depth plane),
// and the interpolation planes' shared origin. The last 36 bytes (the
// stored triangle's corners and face normal) are read by the shading
// kernel only, once per run of samples, so the depth pass's lines are
// the same as without them.
struct TriangleSetup {
  uint32_t instance = 0, triangle = 0;
  glm::ivec2 vertex[3];                  // snapped, units; |X|, |Y| <= 2^29 fit int32
  EdgeFunction edge[3];                  // edge i runs vertex i → vertex (i+1) % 3
  glm::ivec2 pixelMin{0}, pixelMax{-1};  // inclusive pixel bounds, clipped to the image
  Plane depth;                           // window depth z (format space, polygon offset applied)
  // 1/w, d/w, b1/w, b2/w, all through depth's origin (depth.x0, depth.y0).
  PlaneCoefficients invW, dOverW, b1OverW, b2OverW;
  double centroidDepth = 0.0;  // view depth of the ORIGINAL triangle's centroid (sorted mode)
  bool frontFacing = true;
  bool fromClipping = false;
  // The stored (parent) triangle's corner indices, scene.triangle(instance,
  // triangle), and its unit face normal, triangleFaceNormal's bits
  // (faceNormalOfCorners in common/triangle_plane.h), as prepareTriangles
  // computes them while it holds the corners: the shading kernel takes
  // them per run instead of loading the indices and dividing by a square
  // root per triangle (PrimaryHitBlock::runCorners). kNoId corners: not
  // computed (setupTriangle alone leaves them).
  glm::uvec3 corners{kNoId};
  glm::dvec3 faceNormal{0.0, 0.0, 1.0};

  uint64_t id() const { return (uint64_t(instance) << 32) | triangle; }
  // max(|∂z/∂x|, |∂z/∂y|) before offset (the offset moves only depth.v0).
  double maxDepthSlope() const { return std::max(std::abs(depth.dx), std::abs(depth.dy)); }
  // Perspective-correct values at an image position.
  double invWAt(double x, double y) const { return invW.at(x, y, depth.x0, depth.y0); }
  double viewDepthAt(double x, double y) const { return dOverW.at(x, y, depth.x0, depth.y0) / invWAt(x, y); }
  glm::dvec2 baryAt(double x, double y) const {
    const double inv = 1.0 / invWAt(x, y);
    return {b1OverW.at(x, y, depth.x0, depth.y0) * inv, b2OverW.at(x, y, depth.x0, depth.y0) * inv};
  }
};

struct DepthSettings {
  DepthFormat format = DepthFormat::FloatReversed;
  Projection projection = Projection::Perspective;
  double znear = 0.0, zfar = 0.0;
  double offsetFactor = 0.0, offsetUnits = 0.0;
};

// Offscreen: no pixel of the image. NoSample: covers no sample
// (mayCoverSample false); only prepareTriangles' own steps tell it apart.
enum class SetupOutcome { Ok, Degenerate, Culled, Offscreen, NoSample };

// Pixel bounds of at most this many samples are searched for a covered
// sample; larger ones are assumed to cover one (mayCoverSample).
constexpr int kSampleSearchLimit = 64;

// Whether t may cover a sample of the image: false only when its pixel
// bounds hold at most kSampleSearchLimit samples and none of them passes
// the three edge tests (E + bias >= 0, coverage.h's rule), so no coverage
// walk would ever visit a sample of it. Reads only t's edges and pixel
// bounds. At 10^7 triangles on a 1080p image most triangles cover no
// sample: they are dropped before their planes are computed or stored.
bool mayCoverSample(const TriangleSetup& t, const SampleGrid& grid);

// The same by testing every sample of the pixel bounds (mayCoverSample
// tests only those inside the vertices' box): the equivalence tests' reference.
bool mayCoverSampleReference(const TriangleSetup& t, const SampleGrid& grid);

// Sets up one clipped triangle (three clip vertices with w > 0).
// `cull`: which facing to drop (None keeps both).
SetupOutcome setupTriangle(const ClipSpace& space, const SampleGrid& grid, const DepthSettings& depth,
                           const ClipVertex v[3], CullMode cull, TriangleSetup* out);

// The same with the planes' scalar reference (one division per plane
// coefficient and per vertex attribute, as written), which setupTriangle
// matches bit for bit with paired divisions and prepareTriangles' fast
// path with lanes across triangles (raster/setup_planes.h): for the
// equivalence tests (tests/raster/setup_test.cpp, setup_lanes_test.cpp).
SetupOutcome setupTriangleScalarPlanes(const ClipSpace& space, const SampleGrid& grid,
                                       const DepthSettings& depth, const ClipVertex v[3], CullMode cull,
                                       TriangleSetup* out);

struct SetupCounters {
  uint64_t trianglesIn = 0;
  uint64_t degenerate = 0;        // zero area in world space or after snapping
  uint64_t culled = 0;            // back/front-face culling
  uint64_t outside = 0;           // trivially outside the view volume or the image
  uint64_t clipped = 0;           // needed near/far or guard-band clipping
  uint64_t fromClipping = 0;      // triangles made by clipping (fan pieces)
  uint64_t guardBandClipped = 0;  // of the clipped, those beyond the guard band
  uint64_t noSample = 0;          // set up but cover no sample (mayCoverSample): not kept
};

// Which triangles to set up: by material class (Opaque covers OPAQUE and
// MASK) and, with `candidates` (one byte per stored triangle), only those
// whose byte has a bit of `candidateBit` set (a cube-map face's share).
struct TriangleFilter {
  bool opaque = true;
  bool blend = true;
  const std::vector<uint8_t>* candidates = nullptr;
  uint8_t candidateBit = 0;
  // Keep the setups that cover no sample (mayCoverSample false). Only what
  // draws more than samples needs them: the wireframe draws their edges and
  // a pixel trace reports their coverage tests.
  bool keepSampleless = false;
};

// How prepareTriangles works; both give the same setups and counters.
//   Reference  per triangle: transform its three vertices, clip, set up.
//   Fast       per vertex first (in parallel): clip position, outside
//              planes and snapped image position, once per vertex; then
//              per triangle, integer tests on those (outside, degenerate,
//              culled, off the image, no sample) before any plane is
//              computed. Triangles that need clipping take the reference
//              steps.
enum class SetupPath { Fast, Reference };

// What the fast path holds per vertex while it runs: the outside planes (1
// byte) and the snapped image position (2 × int32).
constexpr size_t kSetupVertexCodeBytes = 9;

// Transform (world → view in double), clip and set up every triangle of the
// scene that passes `filter`, in scene order (instance, triangle; clipped
// pieces in fan order), independently of the thread count. `cull` applies
// to single-sided materials only. Memory: the result (capacity reserved
// once for one setup per input triangle; pages never written cost no
// memory), a few chunks in flight per thread, and on the fast path
// kSetupVertexCodeBytes per vertex until it returns.
std::vector<TriangleSetup> prepareTriangles(const Scene& scene, const ClipSpace& space,
                                            const SampleGrid& grid, const DepthSettings& depth, CullMode cull,
                                            TriangleFilter filter, SetupCounters* counters,
                                            SetupPath path = SetupPath::Fast);

// The stored triangle's plane as the camera pass's refinement reads it
// (raster/primary_samples.h; RefinePlaneLanes in
// common/primary_refinement-inl.h): trianglePlane's edges e1, e2 and
// slots (common/triangle_plane.h), and the terms of a ray from `eye`,
// s = eye − a, q = s × e1, e2DotQ = e2 · q, bit for bit as
// intersectTrianglePlane's memo computes them. A function of the
// triangle's corners and the eye alone. 112 bytes.
struct RefinePlane {
  glm::dvec3 e1, e2, s, q;
  double e2DotQ;
  int32_t slot1, slot2;  // canonical rank of stored corners 1 and 2
};
static_assert(std::is_trivially_default_constructible<RefinePlane>::value,
              "RefinePlanes is sized without writing");

// An allocator whose value-construction leaves a trivial type unwritten:
// resizing RefinePlanes does not zero hundreds of MB that are written
// right after.
template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible<U>::value) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
using RefinePlanes = std::vector<RefinePlane, DefaultInitAllocator<RefinePlane>>;

// The scalar reference: trianglePlane (its per-thread memo, its sorting
// network) then glm's cross and dot, one triangle at a time.
RefinePlane refinePlaneReference(const Scene& scene, uint32_t instance, uint32_t triangle,
                                 const glm::dvec3& eye);

// out[i] = refinePlaneReference(scene, setups[i].instance,
// setups[i].triangle, eye) for i < count, bit for bit on every target: the
// corners' sorting network as masked compare-exchanges and the products in
// Highway double lanes (the reference's operations in its order, no
// contraction).
void refinePlanes(const Scene& scene, const TriangleSetup* setups, size_t count, const glm::dvec3& eye,
                  RefinePlane* out);

// setups[i].faceNormal = faceNormalOfCorners of the positions of
// setups[i].corners (which must be stored corners, not kNoId) for i <
// count, bit for bit on every target: faceNormal's cross product, length
// and divisions in Highway double lanes, a block of triangles at a time
// (prepareTriangles' fast path, per chunk, instead of a square root and
// three dependent divisions per triangle).
void faceNormals(const Scene& scene, TriangleSetup* setups, size_t count);

// What the camera pass asks of setup besides the setups: planes[i] =
// refinePlaneReference(scene, setups[i].instance, setups[i].triangle, eye)
// for every setup, computed in lanes by the pipeline's parallel stage on
// each chunk's setups while they are in cache, and appended with them, so
// the fused pass reads one entry per run of samples instead of sorting
// corners on a cache miss. Storage reused as for the setups.
struct RefinePlaneRequest {
  glm::dvec3 eye{0.0};
  RefinePlanes* planes = nullptr;
};

// The same into `*setups`, whose previous contents are replaced and whose
// storage is reused when large enough: a caller that sets up frame after
// frame (raster/frame_buffers.h) does not map, fault in and zero fresh
// pages for every frame's setups (hundreds of MB at 10^6 triangles).
// With `refine.planes`, also the refinement planes of every setup.
void prepareTriangles(const Scene& scene, const ClipSpace& space, const SampleGrid& grid,
                      const DepthSettings& depth, CullMode cull, TriangleFilter filter,
                      SetupCounters* counters, SetupPath path, std::vector<TriangleSetup>* setups,
                      RefinePlaneRequest refine = {});

}  // namespace rastray
