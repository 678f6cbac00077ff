// The resolve's colour filter (SPEC §3, §4): a pixel's colour is the mean
// of its samples' premultiplied colours, summed from 0 in sample order and
// divided by the sample count — the same IEEE operations, in the same
// order, as the per-sample loop it replaces, so the same bits.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace rastray {

// out[p] = (0 + samples[p·spp] + … + samples[p·spp + spp − 1]) / spp for
// p < pixels, in SIMD lanes (Highway, chosen at run time).
void boxFilter(const glm::vec4* samples, int spp, size_t pixels, glm::vec4* out);

// boxFilter with samples[i] read as 0 where covered[i] == uncovered (and
// not read at all there): the same bits as boxFilter over a copy of
// `samples` with those entries set to 0. For a caller that does not write
// its empty samples (raster/resolve.h, the lean form).
// With `shareUniform`, a pixel whose samples all hold one covered value
// reads its first sample's colour for every sample (the others are not
// read): the bits of boxFilter over a copy where they hold that colour too
// (shading once per pixel: such a pixel's samples share one colour).
void boxFilterCovered(const glm::vec4* samples, const uint32_t* covered, uint32_t uncovered, int spp,
                      size_t pixels, glm::vec4* out, bool shareUniform = false);

}  // namespace rastray
