#include "raster/shadow_map.h"

#include <tbb/blocked_range.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "common/interrupt.h"
#include "common/math_constants.h"
#include "common/parallel.h"

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

// The cube faces' axes, in face order.
const glm::dvec3 kCubeAxes[kCubeFaces] = {glm::dvec3(1, 0, 0),  glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0),
                                          glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1),  glm::dvec3(0, 0, -1)};

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

ShadowMaps::ShadowMaps(const Scene& scene, const RasterOptions& options, const Shader* shader)
    : scene_(scene) {
  const int size = options.shadowMapSize;
  glm::dvec3 centre(0.0);
  double radius = 1.0;
  if (!scene.bounds.empty()) {
    centre = 0.5 * (scene.bounds.lo + scene.bounds.hi);
    radius = std::max(1e-6, 0.5 * glm::length(scene.bounds.hi - scene.bounds.lo));
  }
  perLight_.resize(scene.lights.size());
  for (size_t l = 0; l < scene.lights.size(); ++l) {
    const Light& light = scene.lights[l];
    std::vector<Camera> cameras;
    if (light.type == LightType::Directional) {
      Camera c = lightCamera(centre - light.direction * (2.0 * radius), light.direction, size);
      c.projection = Projection::Orthographic;
      c.xmag = c.ymag = radius * 1.001;
      c.znear = 0.0;
      c.zfar = 4.0 * radius;
      cameras.push_back(c);
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
    std::vector<uint8_t> faces;
    for (size_t f = 0; f < cameras.size(); ++f) {
      const Camera& c = cameras[f];
      const SampleGrid grid = makeSampleGrid(1, size, size);
      Map map{c, makeClipSpace(c, grid.guardPixels), DepthTarget(size, size, 1, true)};
      if (cube && faces.empty()) faces = cubeFaceCandidates(scene, light.position, map.space.scale.x, size);
      DepthSettings ds{
          kMapFormat, c.projection, c.znear, c.zfar, options.shadowBiasSlope, options.shadowBiasConstant};
      SetupCounters counters;
      const TriangleFilter filter{true, true, cube ? &faces : nullptr, uint8_t(cube ? 1u << f : 0u)};
      const std::vector<TriangleSetup> setups =
          prepareTriangles(scene, map.space, grid, ds, options.cull, filter, &counters);
      triangles_ += counters.trianglesIn;
      const TileGrid tiles(size, size);
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
      std::function<bool(const TriangleSetup&, int, int, int)> alphaTest;
      if (shader && anyMask)
        alphaTest = [&](const TriangleSetup& t, int px, int py, int s) {
          const Material& m = scene.materialOf(t.instance);
          if (m.alphaMode != AlphaMode::Mask) return true;
          return shader->coverageAlpha(surfaceAt(t, px, py, s), TextureFootprint{}) >= m.alphaCutoff;
        };
      std::vector<std::vector<Attenuation>> perTile(size_t(tiles.count()));
      parallelFor(0, tiles.count(), [&](int tile) {
        if (interruptRequested()) return;  // Ctrl-C: thrown below
        DepthPassCounters dc;
        const TileRect rect = tiles.rect(tile);
        rasterDepthPass(setups, bins[size_t(tile)], grid, rect, kMapFormat, DepthFunc::Less, alphaTest,
                        TraceRequest{}, &map.depth, &dc);
        // Attenuating fragments in front of the opaque depth, kept per texel.
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
            const size_t texel = map.depth.index(px, py, 0);
            const uint32_t key = sampleDepthKey(t, grid, kMapFormat, px, py, s);
            if (key >= map.depth.keys[texel]) return;
            const glm::vec3 pass = constant ? uniform : shader->shadowTransmittance(surfaceAt(t, px, py, s));
            perTile[size_t(tile)].push_back({uint32_t(texel), key, pass});
          });
        }
      });
      throwIfInterrupted();
      for (const auto& v : perTile) map.attenuation.insert(map.attenuation.end(), v.begin(), v.end());
      std::sort(map.attenuation.begin(), map.attenuation.end(),
                [](const Attenuation& a, const Attenuation& b) {
                  return a.texel != b.texel ? a.texel < b.texel : a.key < b.key;
                });
      attenuating_ += map.attenuation.size();
      perLight_[l].push_back(std::move(map));
    }
  }
  for (const auto& maps : perLight_)
    for (const Map& m : maps) maps_.push_back(&m);
}

glm::vec3 ShadowMaps::lit(const Map& map, const glm::dvec3& world) const {
  const glm::dvec3 view(map.camera.viewFromWorld * glm::dvec4(world, 1.0));
  const ClipVertex v = map.space.project(view, glm::dvec3(0.0));
  const glm::vec3 one(1.0f);
  if (!(v.position.z > map.camera.znear) || v.position.w <= 0.0) return one;  // behind the map: unshadowed
  const glm::dvec2 image = map.space.imageOf(v.position);
  const int x = int(std::floor(image.x)), y = int(std::floor(image.y));
  if (x < 0 || y < 0 || x >= map.depth.width || y >= map.depth.height) return one;
  const double z =
      windowDepth(kMapFormat, map.camera.projection, map.camera.znear, map.camera.zfar, v.position.z);
  const uint32_t key = depthKey(kMapFormat, z);
  const uint32_t texel = uint32_t(map.depth.index(x, y, 0));
  if (key > map.depth.keys[texel]) return glm::vec3(0.0f);
  // Attenuation by the transmissive layers between the light and the point.
  glm::vec3 t = one;
  auto it = std::lower_bound(map.attenuation.begin(), map.attenuation.end(), texel,
                             [](const Attenuation& a, uint32_t tx) { return a.texel < tx; });
  for (; it != map.attenuation.end() && it->texel == texel && it->key < key; ++it) t *= it->transmittance;
  return t;
}

glm::vec3 ShadowMaps::transmittance(const SurfacePoint& point, int lightIndex, const glm::dvec3& toLight,
                                    double) const {
  const std::vector<Map>& maps = perLight_[size_t(lightIndex)];
  if (maps.empty()) return glm::vec3(1.0f);
  if (maps.size() == 1) return lit(maps[0], point.position);
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
  return lit(maps[size_t(face)], point.position);
}

}  // namespace rastray
