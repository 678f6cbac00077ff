// depth_lanes.h. Highway compiles the lanes once per SIMD target
// (foreach_target.h re-includes this file); the dispatch is below.
// Built with -ffp-contract=off (the top-level CMakeLists.txt): the
// products and sums of the plane stay apart, as in Plane::at.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/depth_lanes.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <cstddef>
#include <cstdint>

#include <hwy/highway.h>

#include "raster/depth_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

size_t LanesDepthBlock(const DepthBlockLanes& b, size_t from, size_t* lanes, DepthBlockTally* tally) {
  const hn::ScalableTag<double> dd;
  const hn::Rebind<float, decltype(dd)> df;
  const hn::Rebind<uint32_t, decltype(dd)> du;
  const size_t N = hn::Lanes(dd);
  static_assert(hn::MaxLanes(decltype(dd)()) <= 8, "a vector's cover bits within one byte");
  *lanes = N;
  const auto v0 = hn::Set(dd, b.v0), dx = hn::Set(dd, b.dx), dy = hn::Set(dd, b.dy);
  const auto x0 = hn::Set(dd, b.x0), y0 = hn::Set(dd, b.y0), px = hn::Set(dd, double(b.x));
  const auto zero = hn::Zero(dd), one = hn::Set(dd, 1.0);
  const auto oneBits = hn::Set(du, 0x3F800000u);  // depthKey's kOneBits: reversed key = kOneBits − bits
  const auto index = hn::Set(du, b.index);
  auto largest = hn::Zero(du);
  uint32_t written = 0;
  // Adds what was written to the tally; returns `v`.
  const auto finish = [&](size_t v) {
    tally->written += written;
    if (written != 0) {
      const uint32_t m = hn::GetLane(hn::MaxOfLanes(du, largest));
      tally->writtenMax = m > tally->writtenMax ? m : tally->writtenMax;
    }
    return v;
  };
  const size_t rowEntries = size_t(8 * b.spp), rows = size_t(b.rows);
  // Vector v is entries [k·N, k·N + N) of row j, v = k·rows + j: a
  // column of vectors shares its column terms.
  size_t v = from;
  for (size_t k = from / rows, j = from % rows; k * N < rowEntries; ++k, j = 0) {
    const size_t e = k * N;
    // Plane::at's operations in its order: (v0 + dx·((px + ox) − x0)) + dy·((py + oy) − y0).
    const auto x = hn::Add(hn::Add(px, hn::LoadU(dd, b.entryPixel + e)), hn::LoadU(dd, b.entryX + e));
    const auto column = hn::Add(v0, hn::Mul(dx, hn::Sub(x, x0)));
    const auto oy = hn::LoadU(dd, b.entryY + e);
    uint32_t* keyColumn = b.keys + e;
    uint32_t* winnerColumn = b.winners != nullptr ? b.winners + e : nullptr;
    for (; j < rows; ++j, ++v) {
      const auto z =
          hn::Add(column, hn::Mul(dy, hn::Sub(hn::Add(hn::Set(dd, double(b.y + int(j))), oy), y0)));
      // std::clamp(z, 0, 1): z < 0 ? 0 : (1 < z ? 1 : z).
      const auto low = hn::IfThenElse(hn::Lt(z, zero), zero, z);
      const auto clamped = hn::IfThenElse(hn::Lt(one, low), one, low);
      const auto bits = hn::BitCast(du, hn::DemoteTo(df, clamped));
      const auto key = b.reversed ? hn::Sub(oneBits, bits) : bits;
      uint32_t* keys = keyColumn + j * b.rowStride;
      const auto stored = hn::LoadU(du, keys);
      auto pass = hn::Lt(key, stored);
      auto tie = hn::Eq(key, stored);
      if (b.cover != nullptr) {
        const size_t bit = j * rowEntries + e;  // the vector's first bit (N <= 8 lanes: one byte)
        const uint8_t coverByte = uint8_t(b.cover[bit / 8] >> (bit % 8));
        const auto covered = hn::LoadMaskBits(du, &coverByte);
        pass = hn::And(pass, covered);
        tie = hn::And(tie, covered);
      }
      // A tie: the id rule decides, on the caller's side (keys only: fails).
      if (winnerColumn != nullptr && !hn::AllFalse(du, tie)) return finish(v);
      hn::BlendedStore(key, pass, du, keys);
      if (winnerColumn != nullptr) hn::BlendedStore(index, pass, du, winnerColumn + j * b.rowStride);
      written += uint32_t(hn::CountTrue(du, pass));
      largest = hn::Max(largest, hn::IfThenElseZero(pass, key));
    }
  }
  return finish(v);
}

size_t LanesDepthBlockCount() { return hn::Lanes(hn::ScalableTag<double>()); }

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

namespace rastray {

HWY_EXPORT(LanesDepthBlock);
HWY_EXPORT(LanesDepthBlockCount);

size_t depthBlockLanes(const DepthBlockLanes& block, size_t from, size_t* lanes, DepthBlockTally* tally) {
  return HWY_DYNAMIC_DISPATCH(LanesDepthBlock)(block, from, lanes, tally);
}

size_t depthBlockLaneCount() { return HWY_DYNAMIC_DISPATCH(LanesDepthBlockCount)(); }

}  // namespace rastray

#endif  // HWY_ONCE
