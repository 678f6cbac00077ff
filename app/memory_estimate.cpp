#include "app/memory_estimate.h"

#include <algorithm>
#include <cmath>

#include <tbb/info.h>

#include "raster/bin.h"
#include "raster/setup.h"
#include "raster/tile_renderer.h"

namespace rastray {

namespace {

// Sizes of what the renderers allocate per unit, in bytes. Where a
// structure is private to a renderer the figure is measured (peak RSS per
// unit on scenes of 10^5–10^6 triangles) and rounded up.
constexpr uint64_t kFlatPixelBytes = sizeof(glm::vec4) + sizeof(float) + 2 * sizeof(uint32_t);
constexpr uint64_t kDepthTargetSampleBytes = 2 * sizeof(uint32_t);  // key + winner
constexpr uint64_t kShadowTexelBytes = sizeof(uint32_t);            // keys only
// Deep samples are gathered per tile (rasterizer) or per tile and thread
// (ray caster; measured 48 bytes per entry) and then assembled into one
// DeepImage: gathered and assembled copies exist at once.
constexpr uint64_t kDeepEntryBytes = sizeof(DeepSample);
constexpr uint64_t kDeepGatherBytes[2] = {sizeof(DeepSample), 48};  // raster, ray caster
// Writing a deep EXR: OIIO's DeepData holds a second copy of the samples
// (9 channels of 4 bytes), and it and OpenEXR keep per-pixel counts and
// per-channel pointers (measured: about 140 bytes per pixel).
constexpr uint64_t kDeepWriteEntryBytes = 9 * 4;
constexpr uint64_t kDeepWritePixelBytes = 140;
// Writing a flat image: OIIO's converted copy (EXR: RGBA half or float,
// Z, two ids; PNG: RGBA8 and row pointers).
constexpr uint64_t kExrWritePixelBytes = 28;
constexpr uint64_t kPngWritePixelBytes = 8;
// A triangle is binned into every tile its box touches: a few on average.
constexpr uint64_t kBinBytesPerTriangle = 4 * sizeof(uint32_t);
// Embree's BVH over triangles with the geometry buffers it shares
// (measured: 50–60 bytes per triangle at build quality medium).
constexpr uint64_t kBvhBytesPerTriangle = 96;
// Mip chains of decoded textures: linear float RGBA, 4/3 of the base level.
constexpr uint64_t kMipTexelBytes = sizeof(glm::vec4) * 4 / 3 + 1;

uint64_t pixelsOf(const RenderSettings& s) {
  return uint64_t(s.camera.width()) * uint64_t(s.camera.height());
}
uint64_t samplesOf(const RenderSettings& s) { return mulSat(pixelsOf(s), uint64_t(s.spp)); }

int threadsOf(const RenderSettings& s) {
  return s.threads > 0 ? s.threads : tbb::info::default_concurrency();
}

bool transparent(const Material& m) { return m.alphaMode == AlphaMode::Blend || m.isRefractive(); }

// The polygon `in` clipped to the half plane a·p + c >= 0 (Sutherland–Hodgman).
std::vector<glm::dvec3> clipPolygon(const std::vector<glm::dvec3>& in, const glm::dvec3& a, double c) {
  std::vector<glm::dvec3> out;
  for (size_t i = 0; i < in.size(); ++i) {
    const glm::dvec3& p = in[i];
    const glm::dvec3& q = in[(i + 1) % in.size()];
    const double dp = glm::dot(a, p) + c, dq = glm::dot(a, q) + c;
    if (dp >= 0) out.push_back(p);
    if ((dp >= 0) != (dq >= 0)) out.push_back(p + (q - p) * (dp / (dp - dq)));
  }
  return out;
}

// Pixels a triangle covers: clipped to the near plane in view space, then
// projected and clipped to the image rectangle.
double coveredPixels(const Camera& camera, const glm::dvec2& scale, const glm::dvec3 (&world)[3]) {
  std::vector<glm::dvec3> poly;
  for (const glm::dvec3& w : world) poly.push_back(glm::dvec3(camera.viewFromWorld * glm::dvec4(w, 1.0)));
  poly = clipPolygon(poly, {0, 0, -1}, -camera.znear);  // z <= -znear
  if (poly.size() < 3) return 0.0;
  const bool perspective = camera.projection == Projection::Perspective;
  for (glm::dvec3& p : poly) {
    const double depth = perspective ? -p.z : 1.0;
    const glm::dvec2 image = camera.imageFromNdc({p.x / (scale.x * depth), p.y / (scale.y * depth)});
    p = glm::dvec3(image, 0.0);
  }
  poly = clipPolygon(poly, {1, 0, 0}, 0.0);
  poly = clipPolygon(poly, {-1, 0, 0}, double(camera.width));
  poly = clipPolygon(poly, {0, 1, 0}, 0.0);
  poly = clipPolygon(poly, {0, -1, 0}, double(camera.height));
  double twiceArea = 0.0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3& p = poly[i];
    const glm::dvec3& q = poly[(i + 1) % poly.size()];
    twiceArea += p.x * q.y - q.x * p.y;
  }
  return std::abs(twiceArea) * 0.5;
}

uint64_t textureTexels(const Scene& scene) {
  uint64_t texels = 0;
  for (const TextureImage& image : scene.images)
    texels = addSat(texels, uint64_t(image.width) * uint64_t(image.height));
  return texels;
}

void addRasterParts(const Scene& scene, const RenderSettings& s, double layers, RenderMemory& m) {
  const uint64_t triangles = scene.triangleCount();
  const uint64_t setupBytes = mulSat(triangles, sizeof(TriangleSetup));
  m.transient.add("triangle setups", setupBytes);
  m.transient.add("tile bins", mulSat(triangles, kBinBytesPerTriangle));
  m.transient.add("depth target", mulSat(samplesOf(s), kDepthTargetSampleBytes));
  if (s.raster.shadows == ShadowMode::Map && !scene.lights.empty()) {
    // Every face of every light's map stays until the frame ends; one
    // face's setups and a candidate mask exist while it is drawn.
    uint64_t faces = 0;
    for (const Light& light : scene.lights) faces += light.type == LightType::Point ? 6 : 1;
    const uint64_t texels = uint64_t(s.raster.shadowMapSize) * uint64_t(s.raster.shadowMapSize);
    m.transient.add("shadow maps", mulSat(mulSat(faces, texels), kShadowTexelBytes));
    m.transient.add("shadow map setups", addSat(setupBytes, triangles));
  }
  if (layers > 0.0) {
    // Fragments and shaded layers of the tiles in flight, one per thread.
    const uint64_t tileSamples = uint64_t(kTileSize) * kTileSize * uint64_t(s.spp);
    const double perTile = double(tileSamples) * layers * double(sizeof(BlendFragment) + sizeof(BlendLayer));
    m.transient.add("transparency fragments", uint64_t(std::min(perTile * threadsOf(s), 1.8e19)));
  }
}

// Resident now + the parts of `frame` + `extra` + slack for what no
// structure accounts for: thread stacks and arenas, allocator rounding,
// vectors' spare capacity (32 MiB and 5 % of the rest).
MemoryEstimate withSlack(const RenderMemory& frame, const MemoryEstimate& extra) {
  MemoryEstimate total;
  total.add("resident now", currentRssBytes());
  for (const MemoryEstimate* e : {&frame.kept, &frame.transient, &extra})
    for (const auto& [part, bytes] : e->parts()) total.add(part, bytes);
  total.add("threads and allocator slack", addSat(uint64_t(32) << 20, total.total() / 20));
  return total;
}

}  // namespace

ProjectedCoverage projectedCoverage(const Scene& scene, const Camera& camera, bool withOpaque) {
  const glm::dvec2 scale = camera.ndcScale();
  double opaque = 0.0, transparentPixels = 0.0;
  for (const Instance& inst : scene.instances) {
    const bool isTransparent = transparent(scene.materials[inst.material]);
    if (!isTransparent && !withOpaque) continue;
    for (uint32_t t = 0; t < inst.triangleCount; ++t) {
      const glm::uvec3& tri = scene.triangles[inst.firstTriangle + t];
      const glm::dvec3 world[3] = {glm::dvec3(scene.positions[tri.x]), glm::dvec3(scene.positions[tri.y]),
                                   glm::dvec3(scene.positions[tri.z])};
      (isTransparent ? transparentPixels : opaque) += coveredPixels(camera, scale, world);
    }
  }
  const double imagePixels = double(camera.width) * double(camera.height);
  return {withOpaque ? std::min(1.0, opaque / imagePixels) : 1.0, transparentPixels / imagePixels};
}

RenderMemory estimateFrameMemory(const Scene& scene, const RenderSettings& s, RendererKind kind,
                                 bool keepSamples) {
  RenderMemory m;
  const Camera camera = makeCamera(scene, s.camera.overrides(), s.camera.width(), s.camera.height());
  // Only deep output needs the opaque coverage (one pass over every triangle).
  const ProjectedCoverage coverage = projectedCoverage(scene, camera, keepSamples);
  const double layers = coverage.transparentLayers;
  m.kept.add("image", mulSat(pixelsOf(s), kFlatPixelBytes));
  if (keepSamples) {
    // Every sample's opaque surface, where one is hit, and its transparent layers.
    m.deepEntries = double(samplesOf(s)) * (coverage.opaque + layers);
    const auto bytes = [&](uint64_t perEntry) {
      return uint64_t(std::min(m.deepEntries * perEntry, 1.8e19));
    };
    m.kept.add("deep samples", addSat(bytes(kDeepEntryBytes), mulSat(pixelsOf(s), sizeof(uint64_t))));
    m.transient.add("deep sample gathering", bytes(kDeepGatherBytes[kind == RendererKind::Raytrace]));
  }
  const uint64_t texels = textureTexels(scene);
  if (texels > 0) m.kept.add("mip chains", mulSat(texels, kMipTexelBytes));
  if (kind != RendererKind::Raytrace) addRasterParts(scene, s, layers, m);
  if (kind != RendererKind::Raster)
    m.transient.add("Embree BVH", mulSat(scene.triangleCount(), kBvhBytesPerTriangle));
  return m;
}

MemoryEstimate estimateRenderMemory(const Scene& scene, const RenderSettings& s) {
  return withSlack(estimateFrameMemory(scene, s, s.renderer, s.keepSamples), {});
}

MemoryEstimate estimateCrossvalMemory(const Scene& scene, const RenderSettings& s) {
  // The three frames' outputs stay until the comparison; their transient
  // structures exist one frame at a time.
  RenderMemory all;
  for (RendererKind kind : {RendererKind::Raster, RendererKind::Raytrace, RendererKind::Hybrid}) {
    const RenderMemory frame = estimateFrameMemory(scene, s, kind, true);
    for (const auto& [part, bytes] : frame.kept.parts())
      if (part != "mip chains" || kind == RendererKind::Raster) all.kept.add(part, bytes);  // one shared set
    if (frame.transient.total() > all.transient.total()) all.transient = frame.transient;
  }
  // The comparison's per-pixel maps (classes, |ΔZ|, colour error) and the
  // report's images: a few floats per pixel each.
  MemoryEstimate maps;
  maps.add("comparison maps", mulSat(pixelsOf(s), 64));
  return withSlack(all, maps);
}

MemoryEstimate estimateRenderCommandMemory(const Scene& scene, const RenderSettings& s, OutputFormat format) {
  const RenderMemory frame = estimateFrameMemory(scene, s, s.renderer, s.keepSamples);
  MemoryEstimate writing;
  switch (format) {
    case OutputFormat::Png:
      writing.add("PNG encoding", mulSat(pixelsOf(s), kPngWritePixelBytes));
      break;
    case OutputFormat::Exr:
      writing.add("EXR encoding", mulSat(pixelsOf(s), kExrWritePixelBytes));
      break;
    case OutputFormat::DeepExr:
      writing.add("deep EXR encoding",
                  addSat(uint64_t(std::min(frame.deepEntries * kDeepWriteEntryBytes, 1.8e19)),
                         mulSat(pixelsOf(s), kDeepWritePixelBytes)));
      break;
  }
  // The frame's transient structures are freed before the file is
  // written, but freed pages do not always return to the system (glibc
  // keeps them in its heaps): both phases are counted.
  MemoryEstimate total = withSlack(frame, {});
  for (const auto& [part, bytes] : writing.parts()) total.add(part, bytes);
  return total;
}

std::string describeRenderWork(const RenderSettings& s, const char* renderer) {
  return std::string("rendering ") + std::to_string(s.camera.width()) + "x" +
         std::to_string(s.camera.height()) + " at " + std::to_string(s.spp) + " spp (" + renderer + ")";
}

}  // namespace rastray
