#include "raster/shadow_map.h"

#include <tbb/blocked_range.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "common/interrupt.h"
#include "common/math_constants.h"
#include "common/parallel.h"
#include "common/sampling.h"

namespace rastray {

namespace {

constexpr DepthFormat kMapFormat = DepthFormat::FloatReversed;

// A camera at `eye` looking along `forward`.
Camera lightCamera(const glm::dvec3& eye, const glm::dvec3& forward, int size) {
  Camera c;
  c.width = c.height = size;
  c.aspect = 1.0;
  glm::dvec3 up = std::abs(forward.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, up));
  up = glm::cross(right, forward);
  c.worldFromView = glm::dmat4(glm::dvec4(right, 0.0), glm::dvec4(up, 0.0), glm::dvec4(-forward, 0.0),
                               glm::dvec4(eye, 1.0));
  c.viewFromWorld = glm::inverse(c.worldFromView);
  return c;
}

// Perspective map cameras at `eye` along `forward` with full angle `yfov`.
Camera perspectiveLightCamera(const glm::dvec3& eye, const glm::dvec3& forward, double yfov, double znear,
                              int size) {
  Camera c = lightCamera(eye, forward, size);
  c.projection = Projection::Perspective;
  c.yfov = yfov;
  c.znear = znear;
  c.zfar = std::numeric_limits<double>::infinity();
  return c;
}

// A directional light's orthographic map, fitted to the scene's bounds as
// the light sees them: the box of the eight corners of `bounds` in the
// light's frame, x and y apart. A bounding sphere wastes resolution on
// flat scenes under a low light: a 2e3 × 1e5 plane lit 0.1° above its
// horizon spans 4 units across the light and 1e5 along it, so a square
// map over the sphere (texels 49 units wide) puts the whole plane and the
// 0.5-unit wall on it in one texel row, and the wall's shadow is lost.
// Fitted per axis, a row is 4/size units. Margins: 1e-3 of each extent
// (the corners are exact, the map's edge texels still cover them) and a
// floor of 1e-6 of the radius (a plane seen exactly edge-on).
Camera directionalLightCamera(const Bounds& bounds, const glm::dvec3& centre, double radius,
                              const glm::dvec3& direction, int size) {
  Camera c = lightCamera(centre, direction, size);
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  if (bounds.empty()) {
    lo = glm::dvec3(-radius);
    hi = glm::dvec3(radius);
  } else {
    for (int corner = 0; corner < 8; ++corner) {
      const glm::dvec3 p((corner & 1) ? bounds.hi.x : bounds.lo.x, (corner & 2) ? bounds.hi.y : bounds.lo.y,
                         (corner & 4) ? bounds.hi.z : bounds.lo.z);
      const glm::dvec3 v(c.viewFromWorld * glm::dvec4(p, 1.0));
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
  }
  const double floor = 1e-6 * radius;
  const glm::dvec3 half = glm::max(0.5 * (hi - lo) * 1.001, glm::dvec3(floor));
  const glm::dvec3 mid = 0.5 * (lo + hi);
  // The eye on the box's face towards the light, a margin before it.
  const glm::dvec3 eye = glm::dvec3(c.worldFromView * glm::dvec4(mid.x, mid.y, hi.z + half.z, 1.0));
  c = lightCamera(eye, direction, size);
  c.projection = Projection::Orthographic;
  c.xmag = half.x;
  c.ymag = half.y;
  c.znear = 0.0;
  c.zfar = 4.0 * half.z;
  return c;
}

// The cube faces' axes, in face order.
const glm::dvec3 kCubeAxes[kCubeFaces] = {glm::dvec3(1, 0, 0),  glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0),
                                          glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1),  glm::dvec3(0, 0, -1)};

// A map's lookup constants (ShadowMaps::Lookup).
ShadowMaps::Lookup lookupOf(const Camera& camera, const ClipSpace& space) {
  ShadowMaps::Lookup k;
  for (int c = 0; c < 4; ++c) k.column[c] = glm::dvec3(camera.viewFromWorld[c]);
  k.scale = space.scale;
  k.width = double(space.width);
  k.height = double(space.height);
  k.perspective = camera.projection == Projection::Perspective;
  k.znear = camera.znear;
  k.zfar = camera.zfar;
  k.sample = samplePositions(1)[0];
  return k;
}

// The receiver's normal in the map's view frame (the rotation of
// viewFromWorld), one order of operations for both lookups.
glm::dvec3 viewNormal(const ShadowMaps::Lookup& k, const glm::dvec3& normal) {
  return (k.column[0] * normal.x + k.column[1] * normal.y) + k.column[2] * normal.z;
}

// Receiver-plane depth: the view depth to compare with texel (x, y)'s key
// for the receiver point `view` (view depth d, view-space normal n). A
// texel holds its nearest surface's depth at its sample (its centre), not
// at the point up to half a texel away. d_c, the depth of the receiver's
// plane along the sample's ray, takes the receiver's own slope out of the
// comparison exactly, for any slope: a lit plane meets its own stored
// depth up to rounding, which the maps' constant and small slope bias
// cover (docs/SHADOWS.md "Shadow maps"). The result is min(d, d_c): where
// the plane runs away from the light towards the sample, a surface there
// nearer than d_c but farther than the point (a wall rising from a floor
// lit at a grazing angle: a concave corner) must not shadow the point, and
// the point's own surface, stored at d_c, still passes. Falls back to d
// where the plane gives no depth in front of the map (n zero, the texel's
// ray parallel to the plane, or the plane behind the near plane).
double receiverDepth(const ShadowMaps::Lookup& k, const glm::dvec3& view, double d, const glm::dvec3& n,
                     int x, int y) {
  if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) return d;
  // The sample's view x and y over depth (its NDC × scale).
  const double a = (2.0 * (double(x) + k.sample.x) / k.width - 1.0) * k.scale.x;
  const double b = (1.0 - 2.0 * (double(y) + k.sample.y) / k.height) * k.scale.y;
  double dc;
  if (!k.perspective)
    dc = d + (n.x * (a - view.x) + n.y * (b - view.y)) / n.z;  // the ray (a, b, −t)
  else
    dc = (n.x * view.x + n.y * view.y + n.z * view.z) / (n.x * a + n.y * b - n.z);  // the ray t·(a, b, −1)
  if (!(dc > k.znear) || !std::isfinite(dc)) return d;
  return std::min(d, dc);
}

// Renders one map (a cube face, a spot or a directional light's map) of
// `size` texels a side seen by `c` into `*out`, from the triangles
// `filter` keeps; `*trianglesIn` the setup's input count. Maps are
// independent of each other.
void renderMap(const Scene& scene, const RasterOptions& options, const Shader* shader, CoveragePath path,
               const Camera& c, int size, const TriangleFilter& filter, ShadowMaps::Map* out,
               uint64_t* trianglesIn) {
  using Map = ShadowMaps::Map;
  using Attenuation = ShadowMaps::Attenuation;
  const SampleGrid grid = makeSampleGrid(1, size, size);
  Map& map = *out;
  map = Map{c,
            makeClipSpace(c, grid.guardPixels),
            {},
            BlockDepthMap(size, size, kMapFormat, grid.positions[0]),
            TileGrid(size, size),
            {},
            {}};
  map.lookup = lookupOf(map.camera, map.space);
  DepthSettings ds{
      kMapFormat, c.projection, c.znear, c.zfar, options.shadowBiasSlope, options.shadowBiasConstant};
  SetupCounters counters;
  const std::vector<TriangleSetup> setups =
      prepareTriangles(scene, map.space, grid, ds, options.cull, filter, &counters);
  *trianglesIn = counters.trianglesIn;
  const TileGrid& tiles = map.tiles;
  // BLEND and refractive surfaces attenuate instead of blocking (with a
  // shader to ask how much); everything else writes depth.
  const auto transmissive = [&](const TriangleSetup& t) {
    const Material& m = scene.materialOf(t.instance);
    return shader && (m.alphaMode == AlphaMode::Blend || m.isRefractive());
  };
  const auto bins =
      binTriangles(tiles, grid, setups, [&](const TriangleSetup& t) { return !transmissive(t); });
  const auto transmissiveBins = binTriangles(tiles, grid, setups, transmissive);
  const auto surfaceAt = [&](const TriangleSetup& t, int px, int py, int s) {
    const glm::dvec2 pos = glm::dvec2(px, py) + grid.positions[size_t(s)];
    const glm::dvec2 b = t.baryAt(pos.x, pos.y);
    SampleHit hit{t.instance, t.triangle, float(t.viewDepthAt(pos.x, pos.y)), float(b.x), float(b.y)};
    return makeSurfacePoint(scene, refineHit(scene, c.primaryRay(pos), hit));
  };
  // The alpha test only where a MASK material can use it: without one,
  // the depth pass runs its lean path (no call per sample).
  const bool anyMask = std::any_of(scene.materials.begin(), scene.materials.end(),
                                   [](const Material& m) { return m.alphaMode == AlphaMode::Mask; });
  AlphaTestFunction alphaTest;
  if (shader && anyMask)
    alphaTest = [&](const TriangleSetup& t, int px, int py, int s) {
      const Material& m = scene.materialOf(t.instance);
      if (m.alphaMode != AlphaMode::Mask) return true;
      return shader->coverageAlpha(surfaceAt(t, px, py, s), TextureFootprint{}) >= m.alphaCutoff;
    };
  map.attenuation.resize(size_t(tiles.count()));
  map.attenuationTexels.resize(size_t(tiles.count()));
  parallelFor(0, tiles.count(), [&](int tile) {
    if (stopRequested(options.cancel)) return;  // Ctrl-C or cancelled: the constructor throws
    DepthPassCounters dc;
    const TileRect rect = tiles.rect(tile);
    DepthOnlyTile depth(rect);
    depth.render(setups, bins[size_t(tile)], grid, kMapFormat, alphaTest, &dc, path);
    if (!transmissiveBins[size_t(tile)].empty()) depth.loadAll();  // key() below reads the buffer
    // Attenuating fragments in front of the opaque depth, kept per texel.
    std::vector<Attenuation>& found = map.attenuation[size_t(tile)];
    CoverageScratch scratch;
    for (uint32_t index : transmissiveBins[size_t(tile)]) {
      const TriangleSetup& t = setups[index];
      // Untextured, without vertex colours: the transmittance is the
      // material's, the same everywhere.
      const Material& m = scene.materialOf(t.instance);
      const bool constant = m.baseColorTexture < 0 && !scene.instanceOf(t.instance).hasColors;
      SurfacePoint any;
      any.material = &m;
      const glm::vec3 uniform = constant ? shader->shadowTransmittance(any) : glm::vec3(1.0f);
      forEachCoveredSample(t, grid, rect, scratch, [&](int px, int py, int s) {
        const size_t texel = map.depth.index(px, py);
        const uint32_t key = sampleDepthKey(t, grid, kMapFormat, px, py, s);
        if (key >= depth.key(px, py)) return;
        const glm::vec3 pass = constant ? uniform : shader->shadowTransmittance(surfaceAt(t, px, py, s));
        found.emplace_back(uint32_t(texel), key, pass);
      });
    }
    depth.store(&map.depth);
    // By (texel, key); stable: equal keys keep the order met.
    sortTileFragments(rect, size_t(map.depth.width), &found, &map.attenuationTexels[size_t(tile)]);
  });
  if (stopRequested(options.cancel)) return;  // the constructor throws
  map.depth.keepPlanes(setups);
}

}  // namespace

std::vector<Camera> cubeFaceCameras(const glm::dvec3& eye, int size, double znear) {
  std::vector<Camera> faces;
  // A hair over 90° so that the faces overlap at their seams.
  for (const glm::dvec3& d : kCubeAxes)
    faces.push_back(perspectiveLightCamera(eye, d, kPi / 2.0 + 2.0 / size, znear, size));
  return faces;
}

// A face's frustum is |u|, |v| <= t·depth around its axis
// (t = tan(fov/2), the face's NDC scale). A bit stays clear only when all
// three vertices lie beyond one side plane with t widened by 4/size (two
// texels) plus a rounding margin of 1e-9 of the vertices' extent: clipping
// keeps the polygon in that half-space, so every piece lies more than a
// texel outside the face and setup would find it off the image. So the
// faces set up only their own triangles (about a sixth of the scene each
// instead of all of it) and the maps come out bit-identical.
std::vector<uint8_t> cubeFaceCandidates(const Scene& scene, const glm::dvec3& eye, double t, int size) {
  std::vector<uint8_t> mask(scene.triangles.size(), 0);
  const double wide = t * (1.0 + 4.0 / double(size));
  parallelFor(tbb::blocked_range<size_t>(0, mask.size()), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const glm::uvec3 idx = scene.triangles[i];
      const glm::dvec3 d[3] = {glm::dvec3(scene.positions[idx.x]) - eye,
                               glm::dvec3(scene.positions[idx.y]) - eye,
                               glm::dvec3(scene.positions[idx.z]) - eye};
      double extent = 0.0;
      for (const glm::dvec3& v : d) extent = std::max(extent, std::abs(v.x) + std::abs(v.y) + std::abs(v.z));
      const double margin = 1e-9 * extent * (1.0 + wide);
      uint8_t bits = 0;
      for (int f = 0; f < kCubeFaces; ++f) {
        const int k = f / 2;
        const double sign = (f % 2 == 0) ? 1.0 : -1.0;
        bool reached = true;
        for (int side = 0; side < 4 && reached; ++side) {
          const int axis = (k + 1 + side / 2) % 3;
          const double s = (side % 2 == 0) ? 1.0 : -1.0;
          // Plane value wide·depth − s·u at each vertex; all below −margin: missed.
          bool missed = true;
          for (const glm::dvec3& v : d) missed = missed && wide * (sign * v[k]) - s * v[axis] < -margin;
          reached = !missed;
        }
        if (reached) bits |= uint8_t(1u << f);
      }
      mask[i] = bits;
    }
  });
  return mask;
}

ShadowTexel shadowMapTexel(const Scene& scene, int lightIndex, int size, const glm::dvec3& point) {
  const Light& light = scene.lights.at(size_t(lightIndex));
  Camera c;
  double width = 0.0, height = 0.0;
  if (light.type == LightType::Directional) {
    glm::dvec3 centre(0.0);
    double radius = 1.0;
    if (!scene.bounds.empty()) {
      centre = 0.5 * (scene.bounds.lo + scene.bounds.hi);
      radius = std::max(1e-6, 0.5 * glm::length(scene.bounds.hi - scene.bounds.lo));
    }
    c = directionalLightCamera(scene.bounds, centre, radius, light.direction, size);
    width = 2.0 * c.xmag / double(size);
    height = 2.0 * c.ymag / double(size);
  } else {
    // A perspective map: 2·tan(fov/2)/size per unit of depth along its
    // axis, at the point's depth.
    glm::dvec3 axis = light.direction;
    double fov = std::min(2.0 * double(light.outerConeAngle) + 0.01, kPi * 0.95);
    if (light.type == LightType::Point) {
      const glm::dvec3 d = point - light.position, a = glm::abs(d);
      const int k = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
      axis = kCubeAxes[2 * k + (d[k] > 0 ? 0 : 1)];
      fov = kPi / 2.0 + 2.0 / size;
    }
    c = lightCamera(light.position, axis, size);
    width = height =
        std::abs(glm::dot(point - light.position, axis)) * 2.0 * std::tan(0.5 * fov) / double(size);
  }
  return {glm::dvec3(c.worldFromView[0]) * width, glm::dvec3(c.worldFromView[1]) * height};
}

ShadowMaps::ShadowMaps(const Scene& scene, const RasterOptions& options, const Shader* shader,
                       CoveragePath path)
    : scene_(scene) {
  const int size = options.shadowMapSize;
  glm::dvec3 centre(0.0);
  double radius = 1.0;
  if (!scene.bounds.empty()) {
    centre = 0.5 * (scene.bounds.lo + scene.bounds.hi);
    radius = std::max(1e-6, 0.5 * glm::length(scene.bounds.hi - scene.bounds.lo));
  }
  // Every light's maps, lights in order, one map after another, each over
  // its tiles in parallel. Maps in parallel too (nested loops) measured no
  // gain at the default size and made ThreadSanitizer report a race it
  // cannot trace (a worker's read of the main thread's stack, its history
  // lost).
  perLight_.resize(scene.lights.size());
  for (size_t l = 0; l < scene.lights.size(); ++l) {
    const Light& light = scene.lights[l];
    std::vector<Camera> cameras;
    if (light.type == LightType::Directional) {
      cameras.push_back(directionalLightCamera(scene.bounds, centre, radius, light.direction, size));
    } else {
      // Near plane: small against the scene, far: infinite.
      const double znear = std::max(1e-6, 1e-4 * radius);
      if (light.type == LightType::Spot)
        cameras.push_back(perspectiveLightCamera(
            light.position, light.direction, std::min(2.0 * double(light.outerConeAngle) + 0.01, kPi * 0.95),
            znear, size));
      else
        cameras = cubeFaceCameras(light.position, size, znear);
    }
    const bool cube = cameras.size() == kCubeFaces;
    std::vector<uint8_t> faces;  // a cube map's: which faces each triangle can reach
    if (cube) {
      const ClipSpace space = makeClipSpace(cameras[0], makeSampleGrid(1, size, size).guardPixels);
      faces = cubeFaceCandidates(scene, light.position, space.scale.x, size);
    }
    perLight_[l].resize(cameras.size());
    for (size_t f = 0; f < cameras.size(); ++f) {
      const TriangleFilter filter{true, true, cube ? &faces : nullptr, uint8_t(cube ? 1u << f : 0u)};
      uint64_t trianglesIn = 0;
      renderMap(scene, options, shader, path, cameras[f], size, filter, &perLight_[l][f], &trianglesIn);
      triangles_ += trianglesIn;
    }
  }
  throwIfStopped(options.cancel);
  for (const auto& maps : perLight_)
    for (const Map& m : maps) {
      maps_.push_back(&m);
      for (const auto& v : m.attenuation) attenuating_ += v.size();
    }
}

// The reference lookup: project with the general functions, then binary
// search the tile's fragments for the texel.
glm::vec3 ShadowMaps::litReference(const Map& map, const glm::dvec3& world, const glm::dvec3& normal) const {
  const glm::dvec3 view(map.camera.viewFromWorld * glm::dvec4(world, 1.0));
  const ClipVertex v = map.space.project(view, glm::dvec3(0.0));
  const glm::vec3 one(1.0f);
  if (!(v.position.z > map.camera.znear) || v.position.w <= 0.0) return one;  // behind the map: unshadowed
  const glm::dvec2 image = map.space.imageOf(v.position);
  const int x = int(std::floor(image.x)), y = int(std::floor(image.y));
  if (x < 0 || y < 0 || x >= map.depth.width || y >= map.depth.height) return one;
  const double d = receiverDepth(map.lookup, view, v.position.z, viewNormal(map.lookup, normal), x, y);
  const double z = windowDepth(kMapFormat, map.camera.projection, map.camera.znear, map.camera.zfar, d);
  const uint32_t key = depthKey(kMapFormat, z);
  const uint32_t texel = uint32_t(map.depth.index(x, y));
  if (key > map.depth.key(x, y)) return glm::vec3(0.0f);
  // Attenuation by the transmissive layers between the light and the point.
  const size_t tile = size_t(y / kTileSize) * size_t(map.tiles.tilesX) + size_t(x / kTileSize);
  const auto first = map.attenuation[tile].begin();
  const auto last = map.attenuation[tile].end();
  glm::vec3 t = one;
  auto it =
      std::lower_bound(first, last, texel, [](const Attenuation& a, uint32_t tx) { return a.texel < tx; });
  for (; it != last && it->texel == texel && it->key < key; ++it) t *= it->transmittance;
  return t;
}

// The same operations as litReference, in the same order (so the same
// bits): glm's matrix product is (c0·x + c1·y) + (c2·z + c3·1) per row,
// ClipSpace::project and imageOf, and the reversed window depth formula of
// common/depth_formula.cpp; only the calls, the unused fourth row and the
// search over the whole tile are gone.
glm::vec3 ShadowMaps::lit(const Map& map, const glm::dvec3& world, const glm::dvec3& normal) const {
  static_assert(kMapFormat == DepthFormat::FloatReversed, "lit() inlines the reversed window depth");
  const Lookup& k = map.lookup;
  const glm::dvec3 view =
      (k.column[0] * world.x + k.column[1] * world.y) + (k.column[2] * world.z + k.column[3]);
  const double d = -view.z;
  const double w = k.perspective ? d : 1.0;
  const glm::vec3 one(1.0f);
  if (!(d > k.znear) || w <= 0.0) return one;  // behind the map: unshadowed
  const double ix = (view.x / k.scale.x / w + 1.0) * 0.5 * k.width;
  const double iy = (1.0 - view.y / k.scale.y / w) * 0.5 * k.height;
  const int x = int(std::floor(ix)), y = int(std::floor(iy));
  if (x < 0 || y < 0 || x >= map.depth.width || y >= map.depth.height) return one;
  const double dc = receiverDepth(k, view, d, viewNormal(k, normal), x, y);
  double z;  // reversedWindowDepth
  if (!k.perspective)
    z = (k.zfar - dc) / (k.zfar - k.znear);
  else if (std::isinf(k.zfar))
    z = k.znear / dc;
  else
    z = k.znear * (k.zfar - dc) / (dc * (k.zfar - k.znear));
  const uint32_t key = depthKey(kMapFormat, z);
  if (key > map.depth.key(x, y)) return glm::vec3(0.0f);
  // Attenuation by the transmissive layers between the light and the point:
  // the texel's fragments start where its tile's texel index says, no search.
  const size_t tile = size_t(y / kTileSize) * size_t(map.tiles.tilesX) + size_t(x / kTileSize);
  const std::vector<uint32_t>& starts = map.attenuationTexels[tile];
  glm::vec3 t = one;
  if (starts.empty()) return t;
  const size_t slot = size_t(y % kTileSize) * size_t(kTileSize) + size_t(x % kTileSize);
  const Attenuation* a = map.attenuation[tile].data();
  const Attenuation* last = a + starts[slot + 1];
  for (const Attenuation* it = a + starts[slot]; it != last && it->key < key; ++it) t *= it->transmittance;
  return t;
}

void sortTileFragments(const TileRect& rect, size_t width, std::vector<ShadowMaps::Attenuation>* found,
                       std::vector<uint32_t>* texelStarts) {
  using A = ShadowMaps::Attenuation;
  std::vector<A>& v = *found;
  std::vector<uint32_t>& start = *texelStarts;
  if (v.empty()) {
    start.clear();
    return;
  }
  // Texel (x, y) of the rect: slot (y − y0)·kTileSize + (x − x0), in the
  // order of the map's texel index; computed once per fragment (texel
  // indices fit 32 bits: a 32-bit division). The buffers are the thread's
  // own, kept between tiles.
  const uint32_t w = uint32_t(width), x0 = uint32_t(rect.x0), y0 = uint32_t(rect.y0);
  thread_local std::vector<uint16_t> slots;
  thread_local std::vector<A> sorted;
  slots.resize(v.size());
  start.assign(size_t(kTileSize) * kTileSize + 1, 0);
  for (size_t i = 0; i < v.size(); ++i) {
    const uint32_t y = v[i].texel / w, x = v[i].texel - y * w;
    slots[i] = uint16_t((y - y0) * uint32_t(kTileSize) + (x - x0));
    ++start[size_t(slots[i]) + 1];
  }
  for (size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
  sorted.resize(v.size());
  {
    thread_local std::vector<uint32_t> next;
    next.assign(start.begin(), start.end() - 1);
    for (size_t i = 0; i < v.size(); ++i) sorted[next[slots[i]]++] = v[i];  // stable
  }
  // Each texel's run by key, stably (insertion sort: runs of a few).
  for (size_t t = 0; t + 1 < start.size(); ++t) {
    const size_t first = start[t], last = start[t + 1];
    for (size_t i = first + 1; i < last; ++i)
      for (size_t j = i; j > first && sorted[j].key < sorted[j - 1].key; --j)
        std::swap(sorted[j], sorted[j - 1]);
  }
  v.swap(sorted);  // the thread keeps the unsorted buffer for its next tile: no copy back
}

const ShadowMaps::Map& ShadowMaps::mapAt(size_t i) const { return *maps_.at(i); }

const ShadowMaps::Map& ShadowMaps::mapFor(int lightIndex, const glm::dvec3& toLight) const {
  const std::vector<Map>& maps = perLight_[size_t(lightIndex)];
  if (maps.size() == 1) return maps[0];
  // Cube map: the face of the major axis of the direction from the light.
  const glm::dvec3 d = -toLight;
  const glm::dvec3 a = glm::abs(d);
  int face;
  if (a.x >= a.y && a.x >= a.z)
    face = d.x > 0 ? 0 : 1;
  else if (a.y >= a.z)
    face = d.y > 0 ? 2 : 3;
  else
    face = d.z > 0 ? 4 : 5;
  return maps[size_t(face)];
}

glm::vec3 ShadowMaps::lightTransmittance(int lightIndex, const glm::dvec3& world, const glm::dvec3& normal,
                                         const glm::dvec3& toLight) const {
  if (perLight_[size_t(lightIndex)].empty()) return glm::vec3(1.0f);
  return lit(mapFor(lightIndex, toLight), world, normal);
}

void ShadowMaps::lightTransmittances(int lightIndex, size_t n, const glm::dvec3* world,
                                     const glm::dvec3* normal, const glm::dvec3* toLight,
                                     glm::vec3* out) const {
  if (perLight_[size_t(lightIndex)].empty()) {
    std::fill_n(out, n, glm::vec3(1.0f));
    return;
  }
  for (size_t i = 0; i < n; ++i) out[i] = lit(mapFor(lightIndex, toLight[i]), world[i], normal[i]);
}

glm::vec3 ShadowMaps::lightTransmittanceReference(int lightIndex, const glm::dvec3& world,
                                                  const glm::dvec3& normal, const glm::dvec3& toLight) const {
  if (perLight_[size_t(lightIndex)].empty()) return glm::vec3(1.0f);
  return litReference(mapFor(lightIndex, toLight), world, normal);
}

glm::vec3 ShadowMaps::transmittance(const SurfacePoint& point, int lightIndex, const glm::dvec3& toLight,
                                    double) const {
  return lightTransmittance(lightIndex, point.position, point.geometricNormal, toLight);
}

}  // namespace rastray
