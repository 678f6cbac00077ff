#include "raster/wireframe.h"

#include <cmath>
#include <limits>

#include "common/sampling.h"

namespace rastray {

namespace {

struct LinePixel {
  int x, y;
  double nearness;  // larger = nearer, in window-depth units (orientation-free)
};

// Visits the pixels of edge e of t (DDA, one step per pixel along the major
// axis) with the line's own depth, pulled towards the viewer by `offset`.
template <typename F>
void walkEdge(const TriangleSetup& t, int e, const SampleGrid& grid, bool reversed, double offset, int width,
              int height, F&& f) {
  const double U = double(grid.unitsPerPixel);
  const glm::dvec2 a = glm::dvec2(t.vertex[e]) / U, b = glm::dvec2(t.vertex[(e + 1) % 3]) / U;
  const glm::dvec2 d = b - a;
  // Edges clipped to the guard band can be millions of pixels long: walk
  // only the part inside the image.
  double t0 = 0.0, t1 = 1.0;
  for (int axis = 0; axis < 2; ++axis) {
    const double lo = -1.0, hi = (axis == 0 ? width : height) + 1.0;
    if (d[axis] == 0.0) {
      if (a[axis] < lo || a[axis] > hi) return;
      continue;
    }
    double ta = (lo - a[axis]) / d[axis], tb = (hi - a[axis]) / d[axis];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return;
  const glm::dvec2 p0 = a + t0 * d, p1 = a + t1 * d;
  const int steps = int(std::ceil(std::max(std::abs(p1.x - p0.x), std::abs(p1.y - p0.y)))) + 1;
  for (int i = 0; i <= steps; ++i) {
    const glm::dvec2 p = p0 + (p1 - p0) * (double(i) / steps);
    const int x = int(std::floor(p.x)), y = int(std::floor(p.y));
    if (x < 0 || y < 0 || x >= width || y >= height) continue;
    const double z = t.depth.at(p.x, p.y);
    f(x, y, (reversed ? z : 1.0 - z) + offset);
  }
}

}  // namespace

uint64_t drawWireframe(const std::vector<TriangleSetup>& setups, const SampleGrid& grid,
                       const DepthTarget& depth, DepthFormat format, const WireframeStyle& style,
                       FlatImage* image) {
  const int W = image->width, H = image->height;
  const bool reversed = isReversed(format);
  const int centre = centreSampleIndex(grid.spp);
  // How far lines move towards the viewer: glPolygonOffset's amount, in
  // window depth (positive = nearer).
  const auto offsetOf = [&](const TriangleSetup& t) {
    const double U = double(grid.unitsPerPixel);
    double maxZ = 0.0;
    for (int i = 0; i < 3; ++i)
      maxZ = std::max(maxZ, t.depth.at(double(t.vertex[i].x) / U, double(t.vertex[i].y) / U));
    return polygonOffset(format, std::abs(style.offsetFactor), std::abs(style.offsetUnits), t.maxDepthSlope(),
                         std::min(1.0, maxZ));
  };
  // The surface's nearness at a pixel's first sample; nothing there: −inf.
  std::vector<double> surface(size_t(W) * size_t(H), -std::numeric_limits<double>::infinity());
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = depth.index(x, y, centre);
      if (depth.winners[i] == kNoSetup) continue;
      const TriangleSetup& t = setups[depth.winners[i]];
      const glm::dvec2 p = glm::dvec2(x, y) + grid.positions[size_t(centre)];
      const double z = t.depth.at(p.x, p.y);
      surface[size_t(y) * size_t(W) + size_t(x)] = reversed ? z : 1.0 - z;
    }

  std::vector<double> halo;
  std::vector<uint64_t> haloOwner;
  if (style.halo) {
    halo.assign(surface.size(), -std::numeric_limits<double>::infinity());
    haloOwner.assign(surface.size(), 0);
    for (size_t s = 0; s < setups.size(); ++s)
      for (int e = 0; e < 3; ++e) {
        if (!setups[s].edge[e].original) continue;
        const uint64_t owner = s * 3 + uint64_t(e);
        walkEdge(setups[s], e, grid, reversed, offsetOf(setups[s]), W, H, [&](int x, int y, double nearness) {
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int hx = x + dx, hy = y + dy;
              if (hx < 0 || hy < 0 || hx >= W || hy >= H) continue;
              const size_t i = size_t(hy) * size_t(W) + size_t(hx);
              if (nearness > halo[i]) {
                halo[i] = nearness;
                haloOwner[i] = owner;
              }
            }
        });
      }
  }

  uint64_t drawn = 0;
  for (size_t s = 0; s < setups.size(); ++s)
    for (int e = 0; e < 3; ++e) {
      if (!setups[s].edge[e].original) continue;
      const double offset = offsetOf(setups[s]);
      const uint64_t owner = s * 3 + uint64_t(e);
      walkEdge(setups[s], e, grid, reversed, offset, W, H, [&](int x, int y, double nearness) {
        const size_t i = size_t(y) * size_t(W) + size_t(x);
        if (nearness < surface[i]) return;  // hidden by a nearer surface
        // Halo: a different line nearer by more than the offset gaps this one.
        if (style.halo && haloOwner[i] != owner && halo[i] > nearness + offset) return;
        image->color[i] = style.color;
        ++drawn;
      });
    }
  return drawn;
}

}  // namespace rastray
