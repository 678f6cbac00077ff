// The camera pass's depth test of a block eight pixels wide, in SIMD lanes
// (Highway, dispatched at run time): every entry of the block's rows (8
// pixels × spp samples, consecutive in the depth target) gets its key, is
// compared with the stored key and written where it passes and the
// triangle covers it, a vector at a time, with no per-sample branch or
// store.
//
// The same bits as the scalar sampleDepthKey (coverage.h): each lane
// evaluates Plane::at as (v0 + dx·((px + ox) − x0)) + dy·((py + oy) − y0),
// the same IEEE double operations in the same order (px + i is exact;
// -ffp-contract=off keeps products and sums apart), clamps as std::clamp
// does (z < 0 ? 0 : 1 < z ? 1 : z, so NaN and −0 pass through), converts
// to float rounding to nearest (VCVTPD2PS as CVTSD2SS) and forms depthKey's
// float or reversed-float key. Unorm formats are not taken here.
//
// A key equal to its stored key (a tie) is decided by the id rule
// (passesDepthTest), which needs the stored winner's setup: the lanes
// stop at a vector holding one and hand it back to the caller, which
// tests its entries one by one; then they go on from the next vector.
// Without winners (keys only) a tie fails and the lanes decide it.
#pragma once

#include <cstddef>
#include <cstdint>

namespace rastray {

struct DepthBlockLanes {
  // The depth plane (Plane's fields).
  double v0 = 0.0, dx = 0.0, dy = 0.0, x0 = 0.0, y0 = 0.0;
  int x = 0, y = 0, rows = 0;  // pixels [x, x + 8) × [y, y + rows)
  int spp = 1;
  // Per entry j < 8·spp of a row (pixel j / spp, sample j % spp): the
  // pixel's offset from x (j / spp) and the sample's position in its
  // pixel (SampleGrid::positions).
  const double* entryPixel = nullptr;
  const double* entryX = nullptr;
  const double* entryY = nullptr;
  bool reversed = true;  // DepthFormat::FloatReversed, else Float
  uint32_t index = 0;    // the setup written to `winners`
  // The entries the triangle covers, or nullptr: all of them. Row j's
  // 8·spp entries are bits j·8·spp + e of this bit string (bit k: bit
  // k % 8 of byte k / 8); at 1 spp it is block_coverage.h's mask.
  const uint8_t* cover = nullptr;
  uint32_t* keys = nullptr;     // the block's first entry (pixel x, y, sample 0)
  uint32_t* winners = nullptr;  // the same entry, or nullptr: keys only
  size_t rowStride = 0;         // entries from one pixel row to the next
};

// What the lanes wrote: the number of entries and their largest key.
struct DepthBlockTally {
  uint32_t written = 0, writtenMax = 0;
};

// Tests and writes the block's covered entries, vectors from number `from`
// on (entries [k·lanes, (k + 1)·lanes) of pixel row j are vector
// k·rows + j; `*lanes` receives the entries per vector) up to the first
// one with a tie (not written at all): returns its number, or the block's
// vector count when every vector from `from` on was done. Adds what it
// wrote to `tally`.
size_t depthBlockLanes(const DepthBlockLanes& block, size_t from, size_t* lanes, DepthBlockTally* tally);

// The entries per vector of the target depthBlockLanes runs on (for
// tests: 8·spp is a multiple of it).
size_t depthBlockLaneCount();

}  // namespace rastray
