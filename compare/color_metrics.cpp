#include "compare/color_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/oiio_module.h"

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

ColorMetrics compareColors(const FlatImage& a, const FlatImage& b) {
  ColorMetrics m;
  m.pixels = uint64_t(a.width) * uint64_t(a.height);
  if (m.pixels == 0) return m;
  const ImageDifference d = oiioModule().compareColors(a.width, a.height, a.color.data(), b.color.data(),
                                                       float(m.yeeLuminance), float(m.yeeFieldOfView));
  m.meanError = d.meanError;
  m.rmsError = d.rmsError;
  // OIIO's PSNR for a zero RMS is not +inf in every version: state it here.
  m.psnr = d.rmsError > 0.0 ? 20.0 * std::log10(1.0 / d.rmsError) : std::numeric_limits<double>::infinity();
  m.maxError = d.maxError;
  m.maxX = d.maxX;
  m.maxY = d.maxY;
  m.maxChannel = d.maxChannel;
  m.differingPixels = d.differingPixels;
  m.yeeFailingPixels = d.yeeFailingPixels;
  return m;
}

FlatImage flattenDeepColor(const DeepImage& deep, int spp) {
  FlatImage out(deep.width, deep.height);
  out.hasColor = deep.hasColor;
  const float weight = 1.0f / float(std::max(spp, 1));
  for (size_t p = 0; p + 1 < deep.offsets.size(); ++p) {
    glm::vec4 sum(0.0f), sample(0.0f);
    for (uint64_t i = deep.offsets[p]; i < deep.offsets[p + 1]; ++i) {
      const DeepSample& d = deep.samples[i];
      // Entries are sorted by (sample, depth): a new sample index closes the last one.
      if (i > deep.offsets[p] && d.sample != deep.samples[i - 1].sample) {
        sum += sample;
        sample = glm::vec4(0.0f);
      }
      sample += (1.0f - sample.a) * d.color;  // over(front = sample so far, back = this layer)
    }
    out.color[p] = (sum + sample) * weight;
  }
  return out;
}

std::vector<float> colorDifference(const FlatImage& a, const FlatImage& b) {
  std::vector<float> diff(a.color.size());
  for (size_t i = 0; i < diff.size(); ++i) {
    const glm::vec4 d = glm::abs(a.color[i] - b.color[i]);
    diff[i] = std::max(std::max(d.r, d.g), std::max(d.b, d.a));
  }
  return diff;
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

}  // namespace rastray
