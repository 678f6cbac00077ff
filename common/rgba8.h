// Premultiplied linear RGBA (float) to straight sRGB-encoded RGBA8, the
// pixels of a PNG (SPEC §4): colour un-premultiplied (black where alpha is
// 0), clamped to [0, 1], encoded with the exact IEC 61966-2-1 curve
// (linearToSrgb, common/image.h) and rounded to a byte; alpha linear.
//
// encodeRgba8 runs in SIMD lanes (Highway, the widest target the CPU has,
// chosen at run time) and gives the same bytes as encodeRgba8Reference,
// the scalar definition, for every input: the byte of a channel is a
// monotone step function of the clamped straight value, so it is found
// from a table of the 255 step positions (exact floats, found by bisection
// over the scalar definition), bucketed by the float's top 16 bits so that
// a bucket holds at most one step (checked when the table is built).
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace rastray {

// out[4i..4i+3] = R, G, B, A bytes of pixel i, for i < n.
void encodeRgba8(const glm::vec4* premultiplied, size_t n, uint8_t* out);
void encodeRgba8Reference(const glm::vec4* premultiplied, size_t n, uint8_t* out);

// The scalar definition of one colour channel's byte from its straight
// (un-premultiplied) value: clamp to [0, 1], sRGB-encode, × 255 + 0.5,
// truncate. NaN encodes as 0.
uint8_t srgbByte(float straight);

}  // namespace rastray
