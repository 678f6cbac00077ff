#include "compare/color_metrics.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

OIIO::ImageBuf toImageBuf(const FlatImage& image) {
  OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf buf(spec);
  // glm::vec4 is four packed floats: the RGBA scanline layout OIIO expects.
  static_assert(sizeof(glm::vec4) == 4 * sizeof(float), "vec4 must be packed RGBA");
  if (!buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, image.color.data()))
    throw std::runtime_error("OpenImageIO: " + buf.geterror());
  return buf;
}

}  // namespace

ColorMetrics compareColors(const FlatImage& a, const FlatImage& b) {
  ColorMetrics m;
  m.pixels = uint64_t(a.width) * uint64_t(a.height);
  if (m.pixels == 0) return m;
  const OIIO::ImageBuf ba = toImageBuf(a), bb = toImageBuf(b);
  // failthresh = warnthresh = 0: nfail counts every pixel that differs at all.
  const OIIO::ImageBufAlgo::CompareResults c = OIIO::ImageBufAlgo::compare(ba, bb, 0.0f, 0.0f);
  // CompareResults::error also reports "some pixel failed the threshold"
  // (with a threshold of 0: any difference), so real errors are read from
  // OpenImageIO's error state instead.
  if (OIIO::has_error()) throw std::runtime_error("OpenImageIO compare: " + OIIO::geterror());
  m.meanError = c.meanerror;
  m.rmsError = c.rms_error;
  // OIIO's PSNR for a zero RMS is not +inf in every version: state it here.
  m.psnr = c.rms_error > 0.0 ? 20.0 * std::log10(1.0 / c.rms_error) : std::numeric_limits<double>::infinity();
  m.maxError = c.maxerror;
  if (c.maxerror > 0.0) {
    m.maxX = c.maxx;
    m.maxY = c.maxy;
    m.maxChannel = c.maxc;
  }
  m.differingPixels = uint64_t(c.nfail);
  OIIO::ImageBufAlgo::CompareResults yee;
  const int failing =
      OIIO::ImageBufAlgo::compare_Yee(ba, bb, yee, float(m.yeeLuminance), float(m.yeeFieldOfView));
  if (failing < 0 || OIIO::has_error())
    throw std::runtime_error("OpenImageIO compare_Yee: " + OIIO::geterror());
  m.yeeFailingPixels = uint64_t(failing);
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
