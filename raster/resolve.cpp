// resolve.h. Highway compiles the lean form's 1-spp row once per SIMD
// target (foreach_target.h re-includes this file); the rest is host code.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/resolve.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <cstddef>
#include <cstdint>
#include <cstring>

#include <hwy/highway.h>

#include "raster/resolve.h"

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The lean form at 1 spp, one row piece of `width` pixels: a vector of
// pixels won by one setup (a large triangle's inside) or by none (the
// background) is written whole; others pixel by pixel. Colour (0 + c) / 1
// as boxFilter, depth and ids as resolveTileLean's loop for several spp.
void LanesLeanRow1(const float* color, const float* depthIn, const uint32_t* winners,
                   const TriangleSetup* setups, size_t width, float* colorOut, float* depthOut,
                   uint32_t* instanceOut, uint32_t* triangleOut) {
  const hn::ScalableTag<float> df;
  const hn::RebindToUnsigned<decltype(df)> du;
  const size_t N = hn::Lanes(df);
  const auto zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const SampleHit none;
  const auto noSetup = hn::Set(du, kNoSetup);
  // Colour vector k of N pixels holds pixels k·N/4 + lane/4: the winners'
  // lanes to repeat across each pixel's four channels.
  const auto quarter = hn::ShiftRight<2>(hn::Iota(du, 0));
  size_t i = 0;
  for (; i + N <= width; i += N) {
    const uint32_t first = winners[i];
    const auto w = hn::LoadU(du, winners + i);
    if (!hn::AllTrue(du, hn::Eq(w, hn::Set(du, first)))) {
      // Mixed: colour and depth in lanes (0 + (covered ? c : 0); x / 1
      // is x after the sum), the ids per pixel from the setups.
      for (size_t k = 0; k < 4; ++k) {
        const auto idx = hn::IndicesFromVec(du, hn::Add(quarter, hn::Set(du, uint32_t(k * N / 4))));
        const auto covered = hn::RebindMask(df, hn::Ne(hn::TableLookupLanes(w, idx), noSetup));
        hn::StoreU(hn::Add(zero, hn::IfThenElseZero(covered, hn::LoadU(df, color + 4 * i + k * N))), df,
                   colorOut + 4 * i + k * N);
      }
      hn::StoreU(hn::IfThenElse(hn::RebindMask(df, hn::Ne(w, noSetup)), hn::LoadU(df, depthIn + i),
                                hn::Set(df, none.depth)),
                 df, depthOut + i);
      uint32_t last = kNoSetup, instance = none.instance, triangle = none.triangle;
      for (size_t j = i; j < i + N; ++j) {
        if (winners[j] != last) {
          last = winners[j];
          instance = last == kNoSetup ? none.instance : setups[last].instance;
          triangle = last == kNoSetup ? none.triangle : setups[last].triangle;
        }
        instanceOut[j] = instance;
        triangleOut[j] = triangle;
      }
      continue;
    }
    if (first == kNoSetup) {
      for (size_t k = 0; k < 4; ++k)
        hn::StoreU(hn::Div(hn::Add(zero, zero), one), df, colorOut + 4 * i + k * N);
      hn::StoreU(hn::Set(df, none.depth), df, depthOut + i);
      hn::StoreU(hn::Set(du, none.instance), du, instanceOut + i);
      hn::StoreU(hn::Set(du, none.triangle), du, triangleOut + i);
      continue;
    }
    for (size_t k = 0; k < 4; ++k)
      hn::StoreU(hn::Div(hn::Add(zero, hn::LoadU(df, color + 4 * i + k * N)), one), df,
                 colorOut + 4 * i + k * N);
    hn::StoreU(hn::LoadU(df, depthIn + i), df, depthOut + i);
    hn::StoreU(hn::Set(du, setups[first].instance), du, instanceOut + i);
    hn::StoreU(hn::Set(du, setups[first].triangle), du, triangleOut + i);
  }
  for (; i < width; ++i) {
    const uint32_t w = winners[i];
    const bool covered = w != kNoSetup;
    for (size_t k = 0; k < 4; ++k) colorOut[4 * i + k] = (0.0f + (covered ? color[4 * i + k] : 0.0f)) / 1.0f;
    depthOut[i] = covered ? depthIn[i] : none.depth;
    instanceOut[i] = covered ? setups[w].instance : none.instance;
    triangleOut[i] = covered ? setups[w].triangle : none.triangle;
  }
}

// The lean form at 4 spp, one row piece of `width` pixels: each pixel's
// depth and ids from its centre sample (`centre`), as resolveTileLean's
// loop for several spp, a vector of pixels at a time: the centre samples'
// winners and depths de-interleaved from the four samples of each pixel,
// the depth selected in lanes, the ids written whole where one setup (or
// none) won every centre sample of the vector, else pixel by pixel.
void LanesLeanCentre4(const float* depthIn, const uint32_t* winners, const TriangleSetup* setups,
                      size_t width, int centre, float* depthOut, uint32_t* instanceOut,
                      uint32_t* triangleOut) {
  const hn::ScalableTag<float> df;
  const hn::RebindToUnsigned<decltype(df)> du;
  const size_t N = hn::Lanes(df);
  const SampleHit none;
  const auto noSetup = hn::Set(du, kNoSetup);
  const auto noDepth = hn::Set(df, none.depth);
  size_t i = 0;
  for (; i + N <= width; i += N) {
    hn::Vec<decltype(du)> w0, w1, w2, w3;
    hn::LoadInterleaved4(du, winners + 4 * i, w0, w1, w2, w3);
    hn::Vec<decltype(df)> d0, d1, d2, d3;
    hn::LoadInterleaved4(df, depthIn + 4 * i, d0, d1, d2, d3);
    const auto w = centre == 0 ? w0 : centre == 1 ? w1 : centre == 2 ? w2 : w3;
    const auto d = centre == 0 ? d0 : centre == 1 ? d1 : centre == 2 ? d2 : d3;
    hn::StoreU(hn::IfThenElse(hn::RebindMask(df, hn::Ne(w, noSetup)), d, noDepth), df, depthOut + i);
    const uint32_t first = hn::GetLane(w);
    if (hn::AllTrue(du, hn::Eq(w, hn::Set(du, first)))) {
      hn::StoreU(hn::Set(du, first == kNoSetup ? none.instance : setups[first].instance), du,
                 instanceOut + i);
      hn::StoreU(hn::Set(du, first == kNoSetup ? none.triangle : setups[first].triangle), du,
                 triangleOut + i);
      continue;
    }
    for (size_t j = i; j < i + N; ++j) {
      const uint32_t win = winners[4 * j + size_t(centre)];
      instanceOut[j] = win == kNoSetup ? none.instance : setups[win].instance;
      triangleOut[j] = win == kNoSetup ? none.triangle : setups[win].triangle;
    }
  }
  for (; i < width; ++i) {
    const size_t c = 4 * i + size_t(centre);
    const uint32_t win = winners[c];
    depthOut[i] = win == kNoSetup ? none.depth : depthIn[c];
    instanceOut[i] = win == kNoSetup ? none.instance : setups[win].instance;
    triangleOut[i] = win == kNoSetup ? none.triangle : setups[win].triangle;
  }
}

// Copies `count` 4-byte words from `src` to `dst` (4-byte aligned) with
// non-temporal stores: 16 bytes at a time until `dst` is aligned to a
// whole vector, then whole vectors (64 bytes on AVX-512: one store per
// cache line), then 16 bytes at a time, and the last words under 16 bytes
// with plain stores. A line written by one wide store leaves the write-
// combining buffer whole, and takes one store-buffer entry instead of
// four: in the frame, the resolve's write of the image stalls the core on
// a full store buffer (docs/PERFORMANCE.md, "The resolve and the image
// write"). The words are copied, never computed with (bits kept).
void LanesStreamCopy(const uint32_t* src, uint32_t* dst, size_t count) {
  const hn::ScalableTag<uint32_t> d;
  const hn::CappedTag<uint32_t, 4> d4;
  const size_t N = hn::Lanes(d), N4 = hn::Lanes(d4);
  size_t i = 0;
  // Plain stores until 16-byte aligned (the image's rows are, except
  // where a plane of 4-byte values starts a row at another pixel).
  for (; i < count && reinterpret_cast<uintptr_t>(dst + i) % (N4 * sizeof(uint32_t)) != 0; ++i)
    std::memcpy(dst + i, src + i, sizeof(uint32_t));
  for (; i + N4 <= count && reinterpret_cast<uintptr_t>(dst + i) % (N * sizeof(uint32_t)) != 0; i += N4)
    hn::Stream(hn::LoadU(d4, src + i), d4, dst + i);
  for (; i + N <= count; i += N) hn::Stream(hn::LoadU(d, src + i), d, dst + i);
  for (; i + N4 <= count; i += N4) hn::Stream(hn::LoadU(d4, src + i), d4, dst + i);
  if (i < count) std::memcpy(dst + i, src + i, (count - i) * sizeof(uint32_t));
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

#include <algorithm>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "common/box_filter.h"

namespace rastray {

HWY_EXPORT(LanesLeanRow1);
HWY_EXPORT(LanesLeanCentre4);
HWY_EXPORT(LanesStreamCopy);

namespace {

// Copies `bytes` to `dst` with stores that bypass the caches
// (LanesStreamCopy: non-temporal stores of the widest vector `dst` is
// aligned to). The frame's image is written once per frame and is far
// larger than the caches: plain stores would first read every line of it
// from memory only to overwrite it. Callers end the tile with
// streamFence() before another thread may read the image.
void streamCopy(void* dst, const void* src, size_t bytes) {
  if (bytes % 4 != 0 || reinterpret_cast<uintptr_t>(dst) % 4 != 0) {
    std::memcpy(dst, src, bytes);
    return;
  }
  HWY_DYNAMIC_DISPATCH(LanesStreamCopy)
  (static_cast<const uint32_t*>(src), static_cast<uint32_t*>(dst), bytes / 4);
}

void streamFence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

}  // namespace

void resolveTile(const TileRect& rect, int spp, int centreSample, const TileSamples& samples,
                 FlatImage* image) {
  const TileSampleIndex local{rect, spp};
  // A tile row at a time (in pieces of at most kTileSize pixels), filtered
  // into the core's cache, then streamed out.
  glm::vec4 color[kTileSize];
  float depth[kTileSize];
  uint32_t instance[kTileSize], triangle[kTileSize];
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; x += kTileSize) {
      const size_t width = size_t(std::min(rect.x1 - x, kTileSize));
      // A tile row's samples and its image row are both contiguous.
      const size_t row = local(x, y, 0), first = image->index(x, y);
      boxFilter(samples.color.data() + row, spp, width, color);
      for (size_t i = 0; i < width; ++i) {
        const SampleHit& h = samples.front[row + i * size_t(spp) + size_t(centreSample)];
        depth[i] = h.depth;
        instance[i] = h.instance;
        triangle[i] = h.triangle;
      }
      streamCopy(image->color.data() + first, color, width * sizeof(glm::vec4));
      streamCopy(image->depth.data() + first, depth, width * sizeof(float));
      streamCopy(image->instance.data() + first, instance, width * sizeof(uint32_t));
      streamCopy(image->triangle.data() + first, triangle, width * sizeof(uint32_t));
    }
  }
  streamFence();
}

void resolveTileLean(const TileRect& rect, int spp, int centreSample, const TileSamples& samples,
                     const DepthTarget& target, const TriangleSetup* setups, FlatImage* image) {
  const TileSampleIndex local{rect, spp};
  glm::vec4 color[kTileSize];
  float depth[kTileSize];
  uint32_t instance[kTileSize], triangle[kTileSize];
  const SampleHit none;
  // The last winner's ids: consecutive pixels mostly share one.
  uint32_t last = kNoSetup, lastInstance = none.instance, lastTriangle = none.triangle;
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; x += kTileSize) {
      const size_t width = size_t(std::min(rect.x1 - x, kTileSize));
      const size_t row = local(x, y, 0), first = image->index(x, y);
      const uint32_t* winners = &target.winners[target.index(x, y, 0)];
      if (spp == 1) {
        HWY_DYNAMIC_DISPATCH(LanesLeanRow1)
        (&samples.color[row].x, samples.depth.data() + row, winners, setups, width, &color[0].x, depth,
         instance, triangle);
        streamCopy(image->color.data() + first, color, width * sizeof(glm::vec4));
        streamCopy(image->depth.data() + first, depth, width * sizeof(float));
        streamCopy(image->instance.data() + first, instance, width * sizeof(uint32_t));
        streamCopy(image->triangle.data() + first, triangle, width * sizeof(uint32_t));
        continue;
      }
      // Samples without a winner hold no colour: the full form's 0.
      boxFilterCovered(samples.color.data() + row, winners, kNoSetup, spp, width, color,
                       samples.uniformShared);
      if (spp == 4) {
        HWY_DYNAMIC_DISPATCH(LanesLeanCentre4)
        (samples.depth.data() + row, winners, setups, width, centreSample, depth, instance, triangle);
        streamCopy(image->color.data() + first, color, width * sizeof(glm::vec4));
        streamCopy(image->depth.data() + first, depth, width * sizeof(float));
        streamCopy(image->instance.data() + first, instance, width * sizeof(uint32_t));
        streamCopy(image->triangle.data() + first, triangle, width * sizeof(uint32_t));
        continue;
      }
      for (size_t i = 0; i < width; ++i) {
        const size_t c = i * size_t(spp) + size_t(centreSample);
        const uint32_t w = winners[c];
        if (w == kNoSetup) {
          depth[i] = none.depth;
          instance[i] = none.instance;
          triangle[i] = none.triangle;
          continue;
        }
        if (w != last) {
          last = w;
          lastInstance = setups[w].instance;
          lastTriangle = setups[w].triangle;
        }
        depth[i] = samples.depth[row + c];
        instance[i] = lastInstance;
        triangle[i] = lastTriangle;
      }
      streamCopy(image->color.data() + first, color, width * sizeof(glm::vec4));
      streamCopy(image->depth.data() + first, depth, width * sizeof(float));
      streamCopy(image->instance.data() + first, instance, width * sizeof(uint32_t));
      streamCopy(image->triangle.data() + first, triangle, width * sizeof(uint32_t));
    }
  }
  streamFence();
}

}  // namespace rastray

#endif  // HWY_ONCE
