#include "app/engine/memory_estimate.h"

#include <algorithm>
#include <cmath>

#include <tbb/info.h>

#include "common/parallel.h"
#include "raster/memory_estimate.h"
#include "raytrace/memory_estimate.h"

namespace rastray {

namespace {

// Sizes of the outputs and files, in bytes; each renderer sizes its own
// structures (raster/memory_estimate.h, raytrace/memory_estimate.h).
constexpr uint64_t kFlatPixelBytes = sizeof(glm::vec4) + sizeof(float) + 2 * sizeof(uint32_t);
constexpr uint64_t kDeepEntryBytes = sizeof(DeepSample);
// Writing a deep EXR: OIIO's DeepData holds a second copy of the samples
// (9 channels of 4 bytes), and it and OpenEXR keep per-pixel counts and
// per-channel pointers (measured: about 140 bytes per pixel).
constexpr uint64_t kDeepWriteEntryBytes = 9 * 4;
constexpr uint64_t kDeepWritePixelBytes = 140;
// Writing a flat image: OIIO's converted copy (EXR: RGBA half or float,
// Z, two ids; PNG: RGBA8 and row pointers).
constexpr uint64_t kExrWritePixelBytes = 28;
constexpr uint64_t kPngWritePixelBytes = 8;
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

// A convex polygon of at most 8 vertices: a triangle clipped by the near
// plane and the image's four sides gains at most one vertex per plane.
// Fixed-size, so the coverage pass allocates nothing per triangle.
struct ClipPolygon {
  glm::dvec2 v[8];
  glm::dvec2 w[8];  // scratch for clipping
  int n = 0;

  // Keeps the half plane a·p + c >= 0 (Sutherland–Hodgman).
  void clip(const glm::dvec2& a, double c) {
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const glm::dvec2& p = v[i];
      const glm::dvec2& q = v[(i + 1) % n];
      const double dp = glm::dot(a, p) + c, dq = glm::dot(a, q) + c;
      if (dp >= 0) w[m++] = p;
      if ((dp >= 0) != (dq >= 0)) w[m++] = p + (q - p) * (dp / (dp - dq));
    }
    std::copy(w, w + m, v);
    n = m;
  }
  double area() const {
    double twice = 0.0;
    for (int i = 0; i < n; ++i) twice += v[i].x * v[(i + 1) % n].y - v[(i + 1) % n].x * v[i].y;
    return std::abs(twice) * 0.5;
  }
};

// Pixels a triangle covers: clipped to the near plane in view space, then
// projected and clipped to the image rectangle. Most triangles of a large
// scene lie wholly inside the image or wholly off one side of it; neither
// needs the clipper.
double coveredPixels(const Camera& camera, const glm::dvec2& scale, const glm::dvec3 (&world)[3]) {
  glm::dvec3 view[4];
  int n = 0;
  const glm::dvec3 v[3] = {glm::dvec3(camera.viewFromWorld * glm::dvec4(world[0], 1.0)),
                           glm::dvec3(camera.viewFromWorld * glm::dvec4(world[1], 1.0)),
                           glm::dvec3(camera.viewFromWorld * glm::dvec4(world[2], 1.0))};
  // Near plane z <= -znear in view space (3 vertices in, at most 4 out).
  for (int i = 0; i < 3; ++i) {
    const glm::dvec3& p = v[i];
    const glm::dvec3& q = v[(i + 1) % 3];
    const double dp = -p.z - camera.znear, dq = -q.z - camera.znear;
    if (dp >= 0) view[n++] = p;
    if ((dp >= 0) != (dq >= 0)) view[n++] = p + (q - p) * (dp / (dp - dq));
  }
  if (n < 3) return 0.0;
  const bool perspective = camera.projection == Projection::Perspective;
  const double width = camera.width, height = camera.height;
  ClipPolygon poly;
  glm::dvec2 lo(HUGE_VAL), hi(-HUGE_VAL);
  for (int i = 0; i < n; ++i) {
    const glm::dvec3& p = view[i];
    const double depth = perspective ? -p.z : 1.0;
    const glm::dvec2 image = camera.imageFromNdc({p.x / (scale.x * depth), p.y / (scale.y * depth)});
    poly.v[poly.n++] = image;
    lo = glm::min(lo, image);
    hi = glm::max(hi, image);
  }
  if (hi.x <= 0.0 || hi.y <= 0.0 || lo.x >= width || lo.y >= height) return 0.0;
  if (lo.x < 0.0) poly.clip({1, 0}, 0.0);
  if (hi.x > width) poly.clip({-1, 0}, width);
  if (lo.y < 0.0) poly.clip({0, 1}, 0.0);
  if (hi.y > height) poly.clip({0, -1}, height);
  return poly.area();
}

uint64_t textureTexels(const Scene& scene) {
  uint64_t texels = 0;
  for (const TextureImage& image : scene.images)
    texels = addSat(texels, uint64_t(image.width) * uint64_t(image.height));
  return texels;
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
  // Blocks of at most kBlock triangles of one instance, summed in parallel
  // and then added in block order: the same total whatever the threads.
  constexpr uint32_t kBlock = 1 << 15;
  struct Block {
    uint32_t instance, first, count;
  };
  std::vector<Block> blocks;
  for (uint32_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (!withOpaque && !transparent(scene.materials[inst.material])) continue;
    for (uint32_t t = 0; t < inst.triangleCount; t += kBlock)
      blocks.push_back({i, inst.firstTriangle + t, std::min(kBlock, inst.triangleCount - t)});
  }
  const glm::dvec2 scale = camera.ndcScale();
  std::vector<double> pixels(blocks.size());
  parallelFor(size_t(0), blocks.size(), [&](size_t b) {
    double sum = 0.0;
    for (uint32_t t = blocks[b].first; t < blocks[b].first + blocks[b].count; ++t) {
      const glm::uvec3& tri = scene.triangles[t];
      const glm::dvec3 world[3] = {glm::dvec3(scene.positions[tri.x]), glm::dvec3(scene.positions[tri.y]),
                                   glm::dvec3(scene.positions[tri.z])};
      sum += coveredPixels(camera, scale, world);
    }
    pixels[b] = sum;
  });
  double opaque = 0.0, transparentPixels = 0.0;
  for (size_t b = 0; b < blocks.size(); ++b)
    (transparent(scene.materials[scene.instances[blocks[b].instance].material]) ? transparentPixels
                                                                                : opaque) += pixels[b];
  const double imagePixels = double(camera.width) * double(camera.height);
  return {withOpaque ? std::min(1.0, opaque / imagePixels) : 1.0, transparentPixels / imagePixels};
}

ProjectedCoverage projectedCoverage(const Scene& scene, const RenderSettings& s, bool withOpaque) {
  return projectedCoverage(
      scene, makeCamera(scene, s.camera.overrides(), s.camera.width(), s.camera.height()), withOpaque);
}

RenderMemory estimateFrameMemory(const Scene& scene, const RenderSettings& s, RendererKind kind,
                                 bool keepSamples, const ProjectedCoverage& coverage) {
  RenderMemory m;
  const double layers = coverage.transparentLayers;
  m.kept.add("image", mulSat(pixelsOf(s), kFlatPixelBytes));
  if (keepSamples) {
    // Every sample's opaque surface, where one is hit, and its transparent layers.
    m.deepEntries = double(samplesOf(s)) * (coverage.opaque + layers);
    const auto bytes = [&](uint64_t perEntry) {
      return uint64_t(std::min(m.deepEntries * perEntry, 1.8e19));
    };
    m.kept.add("deep samples", addSat(bytes(kDeepEntryBytes), mulSat(pixelsOf(s), sizeof(uint64_t))));
    m.transient.add("deep sample gathering",
                    bytes(kind == RendererKind::Raytrace ? rayDeepGatherBytesPerSample()
                                                         : rasterDeepGatherBytesPerSample()));
  }
  const uint64_t texels = textureTexels(scene);
  if (texels > 0) m.kept.add("mip chains", mulSat(texels, kMipTexelBytes));
  if (kind != RendererKind::Raytrace)
    addRasterFrameMemory(scene, s.raster, samplesOf(s), layers, threadsOf(s), m.transient);
  if (kind != RendererKind::Raster) addRayFrameMemory(scene, m.transient);
  return m;
}

MemoryEstimate estimateRenderMemory(const Scene& scene, const RenderSettings& s) {
  // Only deep output needs the opaque coverage.
  const ProjectedCoverage coverage = projectedCoverage(scene, s, s.keepSamples);
  return withSlack(estimateFrameMemory(scene, s, s.renderer, s.keepSamples, coverage), {});
}

MemoryEstimate estimateCrossvalMemory(const Scene& scene, const RenderSettings& s) {
  // The three frames' outputs stay until the comparison; their transient
  // structures exist one frame at a time.
  // One camera, one coverage pass for the three.
  const ProjectedCoverage coverage = projectedCoverage(scene, s, true);
  RenderMemory all;
  for (RendererKind kind : {RendererKind::Raster, RendererKind::Raytrace, RendererKind::Hybrid}) {
    const RenderMemory frame = estimateFrameMemory(scene, s, kind, true, coverage);
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
  const RenderMemory frame =
      estimateFrameMemory(scene, s, s.renderer, s.keepSamples, projectedCoverage(scene, s, s.keepSamples));
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
