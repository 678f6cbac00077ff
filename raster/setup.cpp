#include "raster/setup.h"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <stdexcept>

#include "common/error.h"
#include "common/parallel.h"
#include "common/sampling.h"
#include "common/triangle_plane.h"
#include "raster/depth.h"
#include "raster/huge_pages.h"
#include "raster/setup_vertex_codes.h"
#include "raster/setup_planes.h"

namespace rastray {

SampleGrid makeSampleGrid(int spp, int width, int height) {
  SampleGrid g;
  g.spp = spp;
  try {
    g.positions = samplePositions(spp);
  } catch (const std::invalid_argument& e) {
    throw InputError("command line", "--spp", e.what());
  }
  // The denominators are 16 (Direct3D patterns) or 2n (grids).
  const int64_t base = int64_t(1) << kSubpixelBits;
  int64_t denominator = 16;
  if (spp > 16) denominator = 2 * int64_t(std::lround(std::sqrt(double(spp))));
  g.k = denominator / std::gcd(denominator, base);
  g.unitsPerPixel = base * g.k;
  for (const glm::dvec2& p : g.positions) {
    const glm::i64vec2 o(std::llround(p.x * double(g.unitsPerPixel)),
                         std::llround(p.y * double(g.unitsPerPixel)));
    if (double(o.x) != p.x * double(g.unitsPerPixel) || double(o.y) != p.y * double(g.unitsPerPixel))
      throw InputError("command line", "--spp", "sample position not on the fixed-point grid");
    g.offsets.push_back(o);
  }
  g.safePixels = double(kMaxCoordinateUnits / g.unitsPerPixel);
  const double limit = double((int64_t(1) << 20) / g.k);
  if (width > limit || height > limit)
    throw InputError("command line", "--size",
                     "image larger than " + std::to_string(int64_t(limit)) + " pixels at " +
                         std::to_string(spp) + " spp exceeds the rasterizer's fixed-point range");
  g.guardPixels = g.safePixels - 2.0 - double(std::max(width, height));
  return g;
}

namespace {

using Double2 = ClipPair;  // raster/clip.h

// The plane through (x[i], y[i], a[i]), with its origin at vertex 0.
PlaneCoefficients makeCoefficients(const double x[3], const double y[3], const double a[3], double area2) {
  PlaneCoefficients p;
  p.v0 = a[0];
  p.dx = ((a[1] - a[0]) * (y[2] - y[0]) - (a[2] - a[0]) * (y[1] - y[0])) / area2;
  p.dy = ((a[2] - a[0]) * (x[1] - x[0]) - (a[1] - a[0]) * (x[2] - x[0])) / area2;
  return p;
}

Plane makePlane(const double x[3], const double y[3], const double a[3], double area2) {
  const PlaneCoefficients c = makeCoefficients(x, y, a, area2);
  return {c.v0, c.dx, c.dy, x[0], y[0]};
}

int64_t floorDiv(int64_t a, int64_t b) {
  // 256·k units per pixel, a power of two for every pattern but the odd
  // grids: then floor division is an arithmetic shift (C++17 leaves >> of
  // negatives implementation-defined; GCC and Clang shift arithmetically),
  // which spares the four 64-bit divisions per triangle.
  if ((b & (b - 1)) == 0) return a >> __builtin_ctzll(uint64_t(b));
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

// An image coordinate (pixels) on the fixed-point grid. Clamping only moves
// vertices that the guard-band clip left a rounding error beyond it; inside
// the range it is the identity.
int64_t snapUnits(double c, double U) {
  const double s = std::round(c * U);
  return int64_t(std::clamp(s, -double(kMaxCoordinateUnits), double(kMaxCoordinateUnits)));
}

// Whether the closed box [minX, maxX] × [minY, maxY] (units) holds a
// sample of the pixels [pmin, pmax]. A sample that passes the three edge
// tests lies in the closed triangle (E >= −bias >= 0), so in its box:
// without one, the triangle covers no sample.
bool boxHoldsSample(int64_t minX, int64_t maxX, int64_t minY, int64_t maxY, const glm::ivec2& pmin,
                    const glm::ivec2& pmax, const SampleGrid& grid) {
  const int64_t U = grid.unitsPerPixel;
  for (const glm::i64vec2& o : grid.offsets) {
    // Pixels p with min <= p·U + o <= max: from ceil((min − o)/U) to floor((max − o)/U).
    const int64_t x0 = std::max<int64_t>(pmin.x, -floorDiv(o.x - minX, U));
    const int64_t x1 = std::min<int64_t>(pmax.x, floorDiv(maxX - o.x, U));
    const int64_t y0 = std::max<int64_t>(pmin.y, -floorDiv(o.y - minY, U));
    const int64_t y1 = std::min<int64_t>(pmax.y, floorDiv(maxY - o.y, U));
    if (x0 <= x1 && y0 <= y1) return true;
  }
  return false;
}

// The integer half of setup, from the snapped vertices: area, facing,
// culling, pixel bounds, the vertex order of positive area (`order`) and
// the edge functions (their `original` flags are left false). With
// `dropSampleless`, NoSample where mayCoverSample would be false.
SetupOutcome setupEdges(const ClipSpace& space, const SampleGrid& grid, const glm::i64vec2 snapped[3],
                        CullMode cull, bool dropSampleless, int order[3], TriangleSetup* t) {
  const int64_t area2 = (snapped[1].x - snapped[0].x) * (snapped[2].y - snapped[0].y) -
                        (snapped[1].y - snapped[0].y) * (snapped[2].x - snapped[0].x);
  if (area2 == 0) return SetupOutcome::Degenerate;  // zero area after snapping: covers nothing
  t->frontFacing = area2 < 0;                       // CCW with y up = negative with y down
  if ((cull == CullMode::Back && !t->frontFacing) || (cull == CullMode::Front && t->frontFacing))
    return SetupOutcome::Culled;

  // Pixel bounds before any further work: triangles inside the guard band
  // but off the image (most of a scene for a cube-map face) stop here.
  const int64_t minX = std::min({snapped[0].x, snapped[1].x, snapped[2].x});
  const int64_t maxX = std::max({snapped[0].x, snapped[1].x, snapped[2].x});
  const int64_t minY = std::min({snapped[0].y, snapped[1].y, snapped[2].y});
  const int64_t maxY = std::max({snapped[0].y, snapped[1].y, snapped[2].y});
  t->pixelMin = {int(std::clamp<int64_t>(floorDiv(minX, grid.unitsPerPixel), 0, space.width)),
                 int(std::clamp<int64_t>(floorDiv(minY, grid.unitsPerPixel), 0, space.height))};
  t->pixelMax = {int(std::clamp<int64_t>(floorDiv(maxX, grid.unitsPerPixel), -1, space.width - 1)),
                 int(std::clamp<int64_t>(floorDiv(maxY, grid.unitsPerPixel), -1, space.height - 1))};
  if (t->pixelMin.x > t->pixelMax.x || t->pixelMin.y > t->pixelMax.y) return SetupOutcome::Offscreen;
  // Most sub-pixel triangles hold no sample in their box: known before
  // their edge functions are made.
  const bool searched =
      int64_t(t->pixelMax.x - t->pixelMin.x + 1) * (t->pixelMax.y - t->pixelMin.y + 1) * grid.spp <=
      kSampleSearchLimit;
  if (dropSampleless && searched && !boxHoldsSample(minX, maxX, minY, maxY, t->pixelMin, t->pixelMax, grid))
    return SetupOutcome::NoSample;

  // Reorder to positive area: swap vertices 1 and 2 of front faces.
  order[0] = 0;
  order[1] = area2 > 0 ? 1 : 2;
  order[2] = area2 > 0 ? 2 : 1;
  // |X|, |Y| <= 2^29 after the clamp: exact in int32.
  for (int i = 0; i < 3; ++i) t->vertex[i] = glm::ivec2(snapped[order[i]]);
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    EdgeFunction& e = t->edge[i];
    const int64_t x0 = t->vertex[i].x, y0 = t->vertex[i].y;
    const int64_t dx = t->vertex[j].x - x0, dy = t->vertex[j].y - y0;
    e.a = int32_t(-dy);  // |dy| <= 2^30 (setup.h)
    e.b = int32_t(dx);
    e.c = -(-dy * x0 + dx * y0);
    e.topLeft = (dy == 0 && dx > 0) || dy < 0;
    e.bias = e.topLeft ? 0 : -1;
    e.original = false;
  }
  if (dropSampleless && searched && !mayCoverSample(*t, grid)) return SetupOutcome::NoSample;
  return SetupOutcome::Ok;
}

// Marks the edges that are the original triangle's (both ends with a zero
// weight for the same corner) and returns the clip vertices in v's order.
void markOriginalEdges(const ClipVertex v[3], const int order[3], const ClipVertex* cv[3], TriangleSetup* t) {
  for (int i = 0; i < 3; ++i) cv[i] = &v[order[i]];
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    for (int k = 0; k < 3; ++k)
      if (cv[i]->bary[k] == 0.0 && cv[j]->bary[k] == 0.0) t->edge[i].original = true;
  }
}

// The image positions the planes are made over, in v's order, and twice
// the area they span in pixels² (positive). The unsnapped positions: depth
// and barycentrics then stay those of the true triangle (what a ray caster
// sees) to double precision; snapping only decides coverage. Slivers whose
// unsnapped area vanishes fall back to the snapped positions, whose area
// is exact in int64.
double planePositions(const SampleGrid& grid, const TriangleSetup& t, const glm::dvec2 image[3],
                      const int order[3], double x[3], double y[3]) {
  const double U = double(grid.unitsPerPixel);
  for (int i = 0; i < 3; ++i) {
    x[i] = image[order[i]].x;
    y[i] = image[order[i]].y;
  }
  const double areaPixels = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
  if (areaPixels > 0.0 && std::isfinite(areaPixels)) return areaPixels;
  for (int i = 0; i < 3; ++i) {
    x[i] = double(t.vertex[i].x) / U;
    y[i] = double(t.vertex[i].y) / U;
  }
  const int64_t area2 = (int64_t(t.vertex[1].x) - t.vertex[0].x) * (int64_t(t.vertex[2].y) - t.vertex[0].y) -
                        (int64_t(t.vertex[1].y) - t.vertex[0].y) * (int64_t(t.vertex[2].x) - t.vertex[0].x);
  return double(area2) / (U * U);
}

// The scalar reference of setupPlanes: one division per plane
// coefficient and per vertex attribute, in the order written.
void setupPlanesScalar(const SampleGrid& grid, const DepthSettings& ds, const ClipVertex v[3],
                       const glm::dvec2 image[3], const int order[3], TriangleSetup* t) {
  const ClipVertex* cv[3];
  markOriginalEdges(v, order, cv, t);

  double x[3], y[3], z[3], invW[3], dOverW[3], b1[3], b2[3];
  const double areaPixels = planePositions(grid, *t, image, order, x, y);
  for (int i = 0; i < 3; ++i) {
    const glm::dvec4& p = cv[i]->position;
    z[i] = windowDepth(ds.format, ds.projection, ds.znear, ds.zfar, p.z);
    invW[i] = 1.0 / p.w;
    dOverW[i] = p.z / p.w;
    b1[i] = cv[i]->bary.y / p.w;
    b2[i] = cv[i]->bary.z / p.w;
  }
  t->depth = makePlane(x, y, z, areaPixels);
  t->invW = makeCoefficients(x, y, invW, areaPixels);
  t->dOverW = makeCoefficients(x, y, dOverW, areaPixels);
  t->b1OverW = makeCoefficients(x, y, b1, areaPixels);
  t->b2OverW = makeCoefficients(x, y, b2, areaPixels);
  const double offset = polygonOffset(ds.format, ds.offsetFactor, ds.offsetUnits, t->maxDepthSlope(),
                                      std::max({z[0], z[1], z[2]}));
  // Positive offsets push away from the viewer: towards 1 conventionally, 0 reversed.
  t->depth.v0 += isReversed(ds.format) ? -offset : offset;
}

// The double half of setup, after setupEdges: which edges are the original
// triangle's, and the planes from the unsnapped image positions `image`
// (of v, in v's order). setupPlanesScalar's arithmetic, bit for bit, with
// fewer divider operations (22 scalar divisions there, the bulk of its
// time): the per-vertex 1/w and d/w, and the ten plane coefficients'
// divisions by the area, two to an SSE2 division (IEEE division is
// correctly rounded in every lane, so each quotient is the scalar one);
// b/w for a barycentric weight of exactly 1 is 1/w itself, and of exactly
// 0 with w > 0 is +0 (what 0/w gives), so unclipped vertices (unit
// weights) divide nothing more.
void setupPlanes(const SampleGrid& grid, const DepthSettings& ds, const ClipVertex v[3],
                 const glm::dvec2 image[3], const int order[3], TriangleSetup* t) {
  const ClipVertex* cv[3];
  markOriginalEdges(v, order, cv, t);

  double x[3], y[3];
  const double areaPixels = planePositions(grid, *t, image, order, x, y);
  // attr[0] = z, attr[1] = 1/w, attr[2] = d/w, attr[3] = b1/w, attr[4] = b2/w.
  double attr[5][3];
  Double2 perVertex[3];  // (1, 1), (1, d0), (d1, d2) over (w0, w1), (w2, w0), (w1, w2)
  {
    const glm::dvec4& p0 = cv[0]->position;
    const glm::dvec4& p1 = cv[1]->position;
    const glm::dvec4& p2 = cv[2]->position;
    const Double2 n0 = {1.0, 1.0}, n1 = {1.0, p0.z}, n2 = {p1.z, p2.z};
    const Double2 d0 = {p0.w, p1.w}, d1 = {p2.w, p0.w}, d2 = {p1.w, p2.w};
    perVertex[0] = n0 / d0;
    perVertex[1] = n1 / d1;
    perVertex[2] = n2 / d2;
    attr[1][0] = perVertex[0][0];
    attr[1][1] = perVertex[0][1];
    attr[1][2] = perVertex[1][0];
    attr[2][0] = perVertex[1][1];
    attr[2][1] = perVertex[2][0];
    attr[2][2] = perVertex[2][1];
  }
  for (int i = 0; i < 3; ++i) {
    const glm::dvec4& p = cv[i]->position;
    attr[0][i] = windowDepth(ds.format, ds.projection, ds.znear, ds.zfar, p.z);
    const auto overW = [&](double b) {
      if (b == 1.0) return attr[1][i];        // 1/w: the same division
      if (b == 0.0 && p.w > 0.0) return 0.0;  // 0/w for w > 0 (finite or +inf): +0
      return b / p.w;
    };
    attr[3][i] = overW(cv[i]->bary.y);
    attr[4][i] = overW(cv[i]->bary.z);
  }
  // The coefficients' numerators as makeCoefficients forms them, then
  // their divisions by the area in pairs (dx, dy of each plane).
  Double2 slope[5];
  for (int k = 0; k < 5; ++k) {
    const double* a = attr[k];
    const Double2 num = {(a[1] - a[0]) * (y[2] - y[0]) - (a[2] - a[0]) * (y[1] - y[0]),
                         (a[2] - a[0]) * (x[1] - x[0]) - (a[1] - a[0]) * (x[2] - x[0])};
    const Double2 area = {areaPixels, areaPixels};
    slope[k] = num / area;
  }
  t->depth = {attr[0][0], slope[0][0], slope[0][1], x[0], y[0]};
  t->invW = {attr[1][0], slope[1][0], slope[1][1]};
  t->dOverW = {attr[2][0], slope[2][0], slope[2][1]};
  t->b1OverW = {attr[3][0], slope[3][0], slope[3][1]};
  t->b2OverW = {attr[4][0], slope[4][0], slope[4][1]};
  const double offset = polygonOffset(ds.format, ds.offsetFactor, ds.offsetUnits, t->maxDepthSlope(),
                                      std::max({attr[0][0], attr[0][1], attr[0][2]}));
  // Positive offsets push away from the viewer: towards 1 conventionally, 0 reversed.
  t->depth.v0 += isReversed(ds.format) ? -offset : offset;
}

}  // namespace

namespace {

template <bool kScalarPlanes>
SetupOutcome setUp(const ClipSpace& space, const SampleGrid& grid, const DepthSettings& ds,
                   const ClipVertex v[3], CullMode cull, TriangleSetup* t) {
  const double U = double(grid.unitsPerPixel);
  glm::dvec2 image[3];  // unsnapped image positions, reused by the planes
  glm::i64vec2 snapped[3];
  for (int i = 0; i < 3; ++i) {
    image[i] = space.imageOf(v[i].position);
    snapped[i] = {snapUnits(image[i].x, U), snapUnits(image[i].y, U)};
  }
  int order[3];
  const SetupOutcome o = setupEdges(space, grid, snapped, cull, false, order, t);
  if (o != SetupOutcome::Ok) return o;
  if (kScalarPlanes)
    setupPlanesScalar(grid, ds, v, image, order, t);
  else
    setupPlanes(grid, ds, v, image, order, t);
  return SetupOutcome::Ok;
}

}  // namespace

SetupOutcome setupTriangle(const ClipSpace& space, const SampleGrid& grid, const DepthSettings& ds,
                           const ClipVertex v[3], CullMode cull, TriangleSetup* t) {
  return setUp<false>(space, grid, ds, v, cull, t);
}

SetupOutcome setupTriangleScalarPlanes(const ClipSpace& space, const SampleGrid& grid,
                                       const DepthSettings& ds, const ClipVertex v[3], CullMode cull,
                                       TriangleSetup* t) {
  return setUp<true>(space, grid, ds, v, cull, t);
}

bool mayCoverSampleReference(const TriangleSetup& t, const SampleGrid& grid) {
  const int64_t w = int64_t(t.pixelMax.x) - t.pixelMin.x + 1, h = int64_t(t.pixelMax.y) - t.pixelMin.y + 1;
  if (w * h * grid.spp > kSampleSearchLimit) return true;
  const int64_t U = grid.unitsPerPixel;
  for (int py = t.pixelMin.y; py <= t.pixelMax.y; ++py)
    for (int px = t.pixelMin.x; px <= t.pixelMax.x; ++px)
      for (const glm::i64vec2& o : grid.offsets) {
        // Inside the image: within setup.h's exact int64 range.
        const int64_t X = int64_t(px) * U + o.x, Y = int64_t(py) * U + o.y;
        if (t.edge[0].at(X, Y) + t.edge[0].bias >= 0 && t.edge[1].at(X, Y) + t.edge[1].bias >= 0 &&
            t.edge[2].at(X, Y) + t.edge[2].bias >= 0)
          return true;
      }
  return false;
}

bool mayCoverSample(const TriangleSetup& t, const SampleGrid& grid) {
  const int64_t w = int64_t(t.pixelMax.x) - t.pixelMin.x + 1, h = int64_t(t.pixelMax.y) - t.pixelMin.y + 1;
  if (w * h * grid.spp > kSampleSearchLimit) return true;
  // A sample that passes the three edge tests lies in the closed triangle
  // (E >= -bias >= 0), so in its vertices' box: only the samples of the
  // pixel bounds inside that box are tested (boxHoldsSample's ranges),
  // per sample position. The same answer as mayCoverSampleReference.
  const int64_t minX = std::min({t.vertex[0].x, t.vertex[1].x, t.vertex[2].x});
  const int64_t maxX = std::max({t.vertex[0].x, t.vertex[1].x, t.vertex[2].x});
  const int64_t minY = std::min({t.vertex[0].y, t.vertex[1].y, t.vertex[2].y});
  const int64_t maxY = std::max({t.vertex[0].y, t.vertex[1].y, t.vertex[2].y});
  const int64_t U = grid.unitsPerPixel;
  for (const glm::i64vec2& o : grid.offsets) {
    const int64_t x0 = std::max<int64_t>(t.pixelMin.x, -floorDiv(o.x - minX, U));
    const int64_t x1 = std::min<int64_t>(t.pixelMax.x, floorDiv(maxX - o.x, U));
    const int64_t y0 = std::max<int64_t>(t.pixelMin.y, -floorDiv(o.y - minY, U));
    const int64_t y1 = std::min<int64_t>(t.pixelMax.y, floorDiv(maxY - o.y, U));
    for (int64_t py = y0; py <= y1; ++py)
      for (int64_t px = x0; px <= x1; ++px) {
        // Inside the image: within setup.h's exact int64 range.
        const int64_t X = px * U + o.x, Y = py * U + o.y;
        if (t.edge[0].at(X, Y) + t.edge[0].bias >= 0 && t.edge[1].at(X, Y) + t.edge[1].bias >= 0 &&
            t.edge[2].at(X, Y) + t.edge[2].bias >= 0)
          return true;
      }
  }
  return false;
}

void vertexCodesReference(const ClipSpace& space, double unitsPerPixel, const glm::vec3* positions,
                          size_t count, uint8_t* outside, SnappedVertex* snapped) {
  for (size_t v = 0; v < count; ++v) {
    const glm::dvec4 clip = space.clipOf(glm::dvec3(positions[v]));
    const uint8_t mask = outsidePlanes(space, clip);
    outside[v] = mask;
    if (mask != 0) continue;  // w may be <= 0: no image position
    const glm::dvec2 image = space.imageOf(clip);
    snapped[v] = {int32_t(snapUnits(image.x, unitsPerPixel)), int32_t(snapUnits(image.y, unitsPerPixel))};
  }
}

namespace {

// A run of one instance's triangles, set up together.
struct SetupChunk {
  uint32_t instance, first, count;
};

// What one chunk produced, handed from the parallel stage to the ordered one.
struct ChunkOutput {
  uint32_t inputs = 0;  // the chunk's triangles
  std::vector<TriangleSetup> setups;
  RefinePlanes planes;  // one per setup when the frame asks for them
  SetupCounters counters;
};

void add(const SetupCounters& from, SetupCounters* to) {
  to->trianglesIn += from.trianglesIn;
  to->degenerate += from.degenerate;
  to->culled += from.culled;
  to->outside += from.outside;
  to->clipped += from.clipped;
  to->fromClipping += from.fromClipping;
  to->guardBandClipped += from.guardBandClipped;
  to->noSample += from.noSample;
}

// What the frame's setup shares across chunks.
struct SetupContext {
  const Scene& scene;
  const ClipSpace& space;
  const SampleGrid& grid;
  const DepthSettings& depth;
  CullMode cull;
  const TriangleFilter& filter;
};

// The reference steps for one triangle of nonzero world area whose world
// positions are p: transform, clip, set up each fan piece, keep those that
// may cover a sample; a triangle that keeps no piece is counted by why.
void setupClipped(const SetupContext& c, CullMode instanceCull, uint32_t instance, uint32_t triangle,
                  const glm::uvec3& corners, const glm::dvec3 p[3], ChunkOutput* out) {
  SetupCounters& n = out->counters;
  const glm::dvec4 clip[3] = {c.space.clipOf(p[0]), c.space.clipOf(p[1]), c.space.clipOf(p[2])};
  const ClipResult cr = clipTriangle(c.space, clip);
  if (cr.outcome == ClipOutcome::Outside) {
    ++n.outside;
    return;
  }
  if (cr.outcome == ClipOutcome::Clipped) {
    ++n.clipped;
    if (cr.guardClipped) ++n.guardBandClipped;
    n.fromClipping += uint64_t(cr.count - 2);
  }
  TriangleSetup t;
  t.instance = instance;
  t.triangle = triangle;
  t.fromClipping = cr.outcome == ClipOutcome::Clipped;
  t.centroidDepth = (clip[0].z + clip[1].z + clip[2].z) / 3.0;
  t.corners = corners;
  t.faceNormal = faceNormalOfCorners(p[0], p[1], p[2]);
  bool culled = false, visible = false, degenerate = false, sampleless = false;
  for (int i = 1; i + 1 < cr.count; ++i) {
    const ClipVertex fan[3] = {cr.vertices[0], cr.vertices[i], cr.vertices[i + 1]};
    const SetupOutcome o = setupTriangle(c.space, c.grid, c.depth, fan, instanceCull, &t);
    if (o == SetupOutcome::Culled) culled = true;
    if (o == SetupOutcome::Degenerate) degenerate = true;
    if (o != SetupOutcome::Ok) continue;
    if (!c.filter.keepSampleless && !mayCoverSample(t, c.grid)) {
      sampleless = true;
      continue;
    }
    visible = true;
    out->setups.push_back(t);
  }
  if (!visible) {
    if (culled)
      ++n.culled;
    else if (degenerate && cr.count == 3)
      ++n.degenerate;  // zero area after snapping: sub-pixel sliver or edge-on
    else if (sampleless)
      ++n.noSample;
    else
      ++n.outside;
  }
}

// Per vertex of the scene (absolute index): the planes its clip position
// lies outside (clip.h's outsidePlanes) and, where that is none, its
// snapped image position, exactly as setupTriangle snaps it. Allocated
// without initialising: only the selected instances' vertices are written
// and read.
struct VertexCodes {
  std::unique_ptr<uint8_t[]> outside;
  std::unique_ptr<SnappedVertex[]> snapped;
};
static_assert(sizeof(uint8_t) + sizeof(SnappedVertex) == kSetupVertexCodeBytes);

// Loads a triangle's world positions; false when its world area is zero
// (isDegenerate in common/scene.h on the positions already loaded).
void loadPositions(const Scene& scene, const glm::uvec3& idx, glm::dvec3 p[3]) {
  p[0] = glm::dvec3(scene.positions[idx.x]);
  p[1] = glm::dvec3(scene.positions[idx.y]);
  p[2] = glm::dvec3(scene.positions[idx.z]);
}
bool loadTriangle(const Scene& scene, const glm::uvec3& idx, glm::dvec3 p[3]) {
  loadPositions(scene, idx, p);
  return glm::cross(p[1] - p[0], p[2] - p[0]) != glm::dvec3(0.0);
}

// The reference: transform, clip and set up one chunk's triangles in order.
void setupChunkReference(const SetupContext& c, const SetupChunk& chunk, ChunkOutput* out) {
  const Instance& inst = c.scene.instances[chunk.instance];
  const CullMode instanceCull = c.scene.materials[inst.material].doubleSided ? CullMode::None : c.cull;
  SetupCounters& n = out->counters;
  out->setups.reserve(chunk.count);  // one piece per triangle unless clipping splits it
  for (uint32_t k = chunk.first; k < chunk.first + chunk.count; ++k) {
    if (c.filter.candidates && !((*c.filter.candidates)[inst.firstTriangle + k] & c.filter.candidateBit))
      continue;
    ++n.trianglesIn;
    glm::dvec3 p[3];
    const glm::uvec3 idx = c.scene.triangles[inst.firstTriangle + k];
    if (!loadTriangle(c.scene, idx, p)) {
      ++n.degenerate;  // SPEC §1: zero world area covers nothing
      continue;
    }
    setupClipped(c, instanceCull, chunk.instance, k, idx, p, out);
  }
}

// The planes of a chunk's unclipped kept triangles (their setups written
// but for the planes and centroid depth): in lanes (unclippedPlanes), and
// the few the lanes leave by the scalar steps (clipOf, imageOf, setupPlanes
// with planePositions' snapped fallback), the same bits either way.
void unclippedChunkPlanes(const SetupContext& c, const std::vector<UnclippedTriangle>& unclipped,
                          ChunkOutput* out) {
  std::vector<uint32_t> scalar(unclipped.size());
  const size_t n = unclippedPlanes(c.scene, c.space, c.depth, unclipped.data(), unclipped.size(),
                                   out->setups.data(), scalar.data());
  for (size_t k = 0; k < n; ++k) {
    const UnclippedTriangle& u = unclipped[scalar[k]];
    glm::dvec3 p[3];
    loadPositions(c.scene, u.corners, p);
    const glm::dvec4 clip[3] = {c.space.clipOf(p[0]), c.space.clipOf(p[1]), c.space.clipOf(p[2])};
    TriangleSetup& t = out->setups[u.setup];
    t.centroidDepth = (clip[0].z + clip[1].z + clip[2].z) / 3.0;
    const ClipVertex v[3] = {
        {clip[0], glm::dvec3(1, 0, 0)}, {clip[1], glm::dvec3(0, 1, 0)}, {clip[2], glm::dvec3(0, 0, 1)}};
    const glm::dvec2 image[3] = {c.space.imageOf(clip[0]), c.space.imageOf(clip[1]),
                                 c.space.imageOf(clip[2])};
    const int order[3] = {0, u.swapped ? 2 : 1, u.swapped ? 1 : 2};
    setupPlanes(c.grid, c.depth, v, image, order, &t);
  }
}

// The same setups and counters as setupChunkReference, from the vertex
// codes: the outside, degenerate, culling, bounds and sample tests of a
// triangle that needs no clipping are integer work on its vertices' codes
// (its clip vertices are its own vertices, so setupTriangle would snap
// them to the same positions); only the kept triangles are transformed
// again for their planes, after the loop and in lanes across triangles
// (unclippedChunkPlanes). An instance without zero-area triangles (SPEC §1;
// Instance::degenerateCount, which the loader and rebaseScene keep) skips
// the world-area test, and its positions are loaded only for the
// triangles kept or clipped.
void setupChunkFast(const SetupContext& c, const VertexCodes& codes, const SetupChunk& chunk,
                    ChunkOutput* out) {
  const Instance& inst = c.scene.instances[chunk.instance];
  const CullMode instanceCull = c.scene.materials[inst.material].doubleSided ? CullMode::None : c.cull;
  SetupCounters& n = out->counters;
  // One piece per triangle unless clipping splits it: the chunk buffers are
  // small (at most kChunk setups) and reused through the heap.
  out->setups.reserve(chunk.count);
  // Reused: a kept setup has every field written below (setupEdges,
  // setupPlanes), and most triangles are rejected before it is touched.
  TriangleSetup t;
  t.instance = chunk.instance;
  t.fromClipping = false;
  std::vector<UnclippedTriangle> unclipped;
  unclipped.reserve(chunk.count);
  const bool anyDegenerate = inst.degenerateCount != 0;
  for (uint32_t k = chunk.first; k < chunk.first + chunk.count; ++k) {
    if (c.filter.candidates && !((*c.filter.candidates)[inst.firstTriangle + k] & c.filter.candidateBit))
      continue;
    ++n.trianglesIn;
    const glm::uvec3 idx = c.scene.triangles[inst.firstTriangle + k];
    glm::dvec3 p[3];
    if (anyDegenerate && !loadTriangle(c.scene, idx, p)) {
      ++n.degenerate;  // SPEC §1: zero world area covers nothing
      continue;
    }
    // Codes exist for the instance's own vertex range only.
    const glm::uvec3 local = idx - glm::uvec3(inst.firstVertex);
    if (local.x >= inst.vertexCount || local.y >= inst.vertexCount || local.z >= inst.vertexCount) {
      if (!anyDegenerate) loadPositions(c.scene, idx, p);
      setupClipped(c, instanceCull, chunk.instance, k, idx, p, out);
      continue;
    }
    const uint8_t m0 = codes.outside[idx.x], m1 = codes.outside[idx.y], m2 = codes.outside[idx.z];
    if (m0 & m1 & m2) {  // clipTriangle's trivial reject
      ++n.outside;
      continue;
    }
    if (m0 | m1 | m2) {  // needs clipping
      if (!anyDegenerate) loadPositions(c.scene, idx, p);
      setupClipped(c, instanceCull, chunk.instance, k, idx, p, out);
      continue;
    }
    t.triangle = k;
    const glm::i64vec2 snapped[3] = {{codes.snapped[idx.x].x, codes.snapped[idx.x].y},
                                     {codes.snapped[idx.y].x, codes.snapped[idx.y].y},
                                     {codes.snapped[idx.z].x, codes.snapped[idx.z].y}};
    int order[3];
    const SetupOutcome o =
        setupEdges(c.space, c.grid, snapped, instanceCull, !c.filter.keepSampleless, order, &t);
    if (o == SetupOutcome::Degenerate) {
      ++n.degenerate;  // zero area after snapping: sub-pixel sliver or edge-on
      continue;
    }
    if (o == SetupOutcome::Culled) {
      ++n.culled;
      continue;
    }
    if (o == SetupOutcome::Offscreen) {
      ++n.outside;
      continue;
    }
    if (o == SetupOutcome::NoSample) {
      ++n.noSample;
      continue;
    }
    t.corners = idx;  // faceNormal: the chunk's, in lanes below
    // Its clip vertices are its own (unit weights): every edge is the
    // original triangle's (markOriginalEdges). The planes: the chunk's, in
    // lanes below.
    for (EdgeFunction& e : t.edge) e.original = true;
    unclipped.push_back({uint32_t(out->setups.size()), idx, order[1] == 2});
    out->setups.push_back(t);
  }
  unclippedChunkPlanes(c, unclipped, out);
  // Every setup's (clipped pieces' again: the same bits).
  faceNormals(c.scene, out->setups.data(), out->setups.size());
}

// Fills `codes` for every vertex of the instances the chunks cover, in
// parallel, in lanes (vertexCodes: vertexCodesReference's bits).
void computeVertexCodes(const Scene& scene, const ClipSpace& space, const SampleGrid& grid,
                        const std::vector<uint32_t>& instances, VertexCodes* codes) {
  codes->outside.reset(new uint8_t[scene.positions.size()]);
  codes->snapped.reset(new SnappedVertex[scene.positions.size()]);
  adviseHugePages(codes->outside.get(), scene.positions.size());
  adviseHugePages(codes->snapped.get(), scene.positions.size() * sizeof(SnappedVertex));
  struct Range {
    size_t begin, end;
  };
  std::vector<Range> ranges;
  constexpr size_t kBlock = 16384;
  for (uint32_t i : instances) {
    const Instance& inst = scene.instances[i];
    const size_t end = std::min(scene.positions.size(), size_t(inst.firstVertex) + inst.vertexCount);
    for (size_t v = inst.firstVertex; v < end; v += kBlock) ranges.push_back({v, std::min(end, v + kBlock)});
  }
  const double U = double(grid.unitsPerPixel);
  parallelFor(size_t(0), ranges.size(), [&](size_t r) {
    const size_t v = ranges[r].begin;
    vertexCodes(space, U, &scene.positions[v], ranges[r].end - v, &codes->outside[v], &codes->snapped[v]);
  });
}

// The refinement planes of a chunk's setups, made in the pipeline's
// parallel stage while the chunk's setups and corners are still in cache
// (made after the pipeline, from the frame's array, each setup's first
// line was a cache miss: hundreds of MB written long before).
void chunkRefinePlanes(const Scene& scene, const glm::dvec3& eye, ChunkOutput* out) {
  out->planes.resize(out->setups.size());  // default-initialised: written right after
  refinePlanes(scene, out->setups.data(), out->setups.size(), eye, out->planes.data());
}

// Appends a chunk's planes: sized without writing, then one memmove
// (RefinePlane is trivially copyable). The storage grows as the setups'
// (`capacity`) when clipping made more setups than inputs.
void appendPlanes(const RefinePlanes& chunk, size_t capacity, RefinePlanes* planes) {
  if (planes->capacity() < capacity) planes->reserve(capacity);
  const size_t at = planes->size();
  planes->resize(at + chunk.size());
  std::copy(chunk.begin(), chunk.end(), planes->begin() + std::ptrdiff_t(at));
}

// `*v` emptied, with capacity for n elements: fresh storage is advised
// to use huge pages; reused storage was advised when it was made.
template <typename T, typename A>
void reserveReused(size_t n, std::vector<T, A>* v) {
  v->clear();
  if (v->capacity() >= n) return;
  std::vector<T, A>().swap(*v);
  v->reserve(n);
  adviseHugePages(v->data(), v->capacity() * sizeof(T));
}

}  // namespace

std::vector<TriangleSetup> prepareTriangles(const Scene& scene, const ClipSpace& space,
                                            const SampleGrid& grid, const DepthSettings& depth, CullMode cull,
                                            TriangleFilter filter, SetupCounters* counters, SetupPath path) {
  std::vector<TriangleSetup> setups;
  prepareTriangles(scene, space, grid, depth, cull, filter, counters, path, &setups);
  return setups;
}

void prepareTriangles(const Scene& scene, const ClipSpace& space, const SampleGrid& grid,
                      const DepthSettings& depth, CullMode cull, TriangleFilter filter,
                      SetupCounters* counters, SetupPath path, std::vector<TriangleSetup>* storage,
                      RefinePlaneRequest refine) {
  // Chunks of one instance's triangles, set up in parallel and appended in
  // chunk order by a pipeline: deterministic whatever the scheduling, and
  // only the chunks in flight (a few per thread) exist besides the result,
  // so the frame never holds two copies of its setups.
  constexpr uint32_t kChunk = 2048;
  std::vector<SetupChunk> chunks;
  std::vector<uint32_t> instances;  // those the filter selects
  size_t inputs = 0;
  for (uint32_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    const AlphaMode mode = scene.materials[inst.material].alphaMode;
    if (mode == AlphaMode::Blend ? !filter.blend : !filter.opaque) continue;
    instances.push_back(i);
    for (uint32_t f = 0; f < inst.triangleCount; f += kChunk)
      chunks.push_back({i, f, std::min(kChunk, inst.triangleCount - f)});
    inputs += inst.triangleCount;
  }
  const SetupContext context{scene, space, grid, depth, cull, filter};
  VertexCodes codes;
  if (path == SetupPath::Fast) computeVertexCodes(scene, space, grid, instances, &codes);
  // One setup per input triangle at most, unless clipping splits some: the
  // capacity is reserved once, and pages the setups never reach are never
  // touched (so they cost address space, not memory).
  std::vector<TriangleSetup>& setups = *storage;
  reserveReused(inputs, &setups);
  if (refine.planes) reserveReused(inputs, refine.planes);
  size_t next = 0, appendedInputs = 0;
  const size_t tokens = 4 * size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  // A chunk's output waits in its slot from the parallel stage to the ordered
  // one, which frees it: the stages pass only the chunk's index, and an
  // exception frees what was in flight with the slots.
  std::vector<std::unique_ptr<ChunkOutput>> outputs(chunks.size());
  // TBB's ordering stated to ThreadSanitizer (common/parallel.h), as libtbb
  // is not built for it: everything above happens before every stage call
  // and every stage call before the return (PipelineEdges); the calls of a
  // serial stage are ordered (edges through `next` and `setups`); a chunk's
  // parallel stage happens before its ordered one (edge through its slot).
  PipelineEdges edges;
  const auto take = [&](tbb::flow_control& fc) -> size_t {
    tsanAcquire(&next);
    if (next == chunks.size()) fc.stop();
    const size_t c = next++;
    tsanRelease(&next);
    return c;
  };
  const auto setUp = [&](size_t c) {
    if (c >= chunks.size()) return c;
    auto out = std::make_unique<ChunkOutput>();
    out->inputs = chunks[c].count;
    if (path == SetupPath::Fast)
      setupChunkFast(context, codes, chunks[c], out.get());
    else
      setupChunkReference(context, chunks[c], out.get());
    if (refine.planes) chunkRefinePlanes(scene, refine.eye, out.get());
    outputs[c] = std::move(out);
    tsanRelease(&outputs[c]);
    return c;
  };
  const auto append = [&](size_t c) {
    if (c >= chunks.size()) return;
    tsanAcquire(&outputs[c]);
    tsanAcquire(&setups);
    const std::unique_ptr<ChunkOutput> out = std::move(outputs[c]);
    appendedInputs += out->inputs;
    // Clipping made more pieces than the reserve foresaw: grow
    // once by what the remaining inputs can still need.
    if (setups.size() + out->setups.size() > setups.capacity())
      setups.reserve(setups.size() + out->setups.size() + (inputs - std::min(inputs, appendedInputs)));
    setups.insert(setups.end(), out->setups.begin(), out->setups.end());
    if (refine.planes) appendPlanes(out->planes, setups.capacity(), refine.planes);
    add(out->counters, counters);
    tsanRelease(&setups);
  };
  const auto filters = tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order, edges.stage(take)) &
                       tbb::make_filter<size_t, size_t>(tbb::filter_mode::parallel, edges.stage(setUp)) &
                       tbb::make_filter<size_t, void>(tbb::filter_mode::serial_in_order, edges.stage(append));
  edges.fork();
  tbb::parallel_pipeline(tokens, filters);
  edges.join();
}

}  // namespace rastray
