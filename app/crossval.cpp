#include "app/crossval.h"

#include <algorithm>
#include <cmath>

#include "compare/classify.h"

namespace rastray {

namespace {

// The entries of one sample of one pixel: [begin, end) into samples.
struct SampleRange {
  uint64_t begin = 0, end = 0;
};

// Splits a pixel's entries (sorted by sample index first) by sample.
std::vector<SampleRange> splitBySample(const DeepImage& image, size_t pixel, uint32_t spp) {
  std::vector<SampleRange> ranges(spp);
  uint64_t i = image.offsets[pixel];
  const uint64_t end = image.offsets[pixel + 1];
  while (i < end) {
    const uint32_t s = image.samples[i].sample;
    uint64_t j = i;
    while (j < end && image.samples[j].sample == s) ++j;
    if (s < spp) ranges[s] = {i, j};
    i = j;
  }
  return ranges;
}

uint32_t sampleCount(const DeepImage& image) {
  uint32_t spp = 0;
  for (const DeepSample& s : image.samples) spp = std::max(spp, s.sample + 1);
  return spp;
}

}  // namespace

StoredDepthFormat storedDepthFormat(DepthFormat f) {
  switch (f) {
    case DepthFormat::FloatReversed:
      return StoredDepthFormat::FloatReversed;
    case DepthFormat::Float:
      return StoredDepthFormat::Float;
    case DepthFormat::Unorm24:
      return StoredDepthFormat::Unorm24;
    case DepthFormat::Unorm16:
      return StoredDepthFormat::Unorm16;
  }
  return StoredDepthFormat::FloatReversed;
}

AgreeingColorStats colorWhereHitsAgree(const DeepImage& a, const DeepImage& b) {
  AgreeingColorStats stats;
  const uint32_t spp = std::max(sampleCount(a), sampleCount(b));
  const size_t pixels = size_t(a.width) * size_t(a.height);
  for (size_t p = 0; p < pixels; ++p) {
    const auto ra = splitBySample(a, p, spp), rb = splitBySample(b, p, spp);
    for (uint32_t s = 0; s < spp; ++s) {
      const uint32_t n = ra[s].end - ra[s].begin;
      if (n != rb[s].end - rb[s].begin) continue;
      bool same = true;
      for (uint32_t k = 0; k < n && same; ++k) {
        const DeepSample& x = a.samples[ra[s].begin + k];
        const DeepSample& y = b.samples[rb[s].begin + k];
        same = x.instance == y.instance && x.triangle == y.triangle;
      }
      if (!same) continue;
      for (uint32_t k = 0; k < n; ++k) {
        const glm::vec4 d = glm::abs(a.samples[ra[s].begin + k].color - b.samples[rb[s].begin + k].color);
        const double e = std::max(std::max(d.r, d.g), std::max(d.b, d.a));
        ++stats.layers;
        if (e > stats.maxError) {
          stats.maxError = e;
          stats.maxX = int(p % size_t(a.width));
          stats.maxY = int(p / size_t(a.width));
        }
      }
    }
  }
  return stats;
}

CrossvalResult crossvalidate(const Scene& scene, const RenderSettings& settings,
                             const std::function<void(const std::string&)>& progress) {
  CrossvalResult r;
  r.scenePath = scene.path;
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };

  RenderSettings s = settings;
  s.keepSamples = true;
  s.renderer = RendererKind::Raster;
  say("raster");
  r.raster = renderScene(scene, s);
  s.renderer = RendererKind::Raytrace;
  say("raytrace");
  r.raytrace = renderScene(scene, s);
  s.renderer = RendererKind::Hybrid;
  s.raster.shadows = ShadowMode::Rays;
  say("hybrid");
  r.hybrid = renderScene(scene, s);
  r.camera = r.raytrace.camera;
  r.analysis = r.raytrace.analysis;

  say("compare");
  ClassifierSettings classifier;
  classifier.depthFormat = storedDepthFormat(settings.raster.depthFormat);
  classifier.planes = {true, r.camera.projection, r.camera.znear, r.camera.zfar};
  classifier.scene = &scene;
  classifier.camera = &r.camera;
  const FrameNames rasterNames{"raster", "raytrace"}, hybridNames{"hybrid", "raytrace"};
  r.rasterVsRay = compareVisibility(r.raster.output.samples, r.raytrace.output.samples, settings.spp,
                                    classifier, rasterNames);
  r.hybridVsRay = compareVisibility(r.hybrid.output.samples, r.raytrace.output.samples, settings.spp,
                                    classifier, hybridNames);
  r.rasterVsRayColor = compareColors(r.raster.output.image, r.raytrace.output.image);
  r.hybridVsRayColor = compareColors(r.hybrid.output.image, r.raytrace.output.image);
  r.hybridWhereAgree = colorWhereHitsAgree(r.hybrid.output.samples, r.raytrace.output.samples);
  r.rasterWhereAgree = colorWhereHitsAgree(r.raster.output.samples, r.raytrace.output.samples);
  return r;
}

}  // namespace rastray
