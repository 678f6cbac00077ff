// Colour differences between two frames, through OpenImageIO's
// ImageBufAlgo so the numbers match what `oiiotool --diff` and `idiff`
// print for the same pixels.
//
// Conventions
// - Inputs are linear, premultiplied RGBA (SPEC §4), compared as stored:
//   no sRGB encoding, no un-premultiplying. Deep frames are first
//   flattened the way a box-filter resolve does (flattenDeepColor).
// - ImageBufAlgo::compare over all four channels: mean |A − B|, RMS error
//   sqrt(mean (A − B)²), PSNR = 20·log10(1 / RMS) (peak value 1; +inf for
//   identical images) and the largest |A − B| with its pixel and channel.
// - Perceptual metric: ImageBufAlgo::compare_Yee, Hector Yee's perceptual
//   image difference (Yee 2004, "pdiff": a contrast-sensitivity and
//   visual-masking model over a Laplacian pyramid of luminance plus a
//   colour test), on RGB (alpha not used; premultiplied RGB is the image
//   over black) at OIIO's defaults: 100 cd/m² adaptation luminance and a
//   45° field of view. It reports the number of pixels a viewer would see
//   as different.
#pragma once

#include <cstdint>

#include "common/image.h"

namespace rastray {

struct ColorMetrics {
  double meanError = 0.0;
  double rmsError = 0.0;
  double psnr = 0.0;  // dB, +inf when identical
  double maxError = 0.0;
  int maxX = -1, maxY = -1;  // pixel of the largest error (row 0 at the top)
  int maxChannel = -1;       // 0 R, 1 G, 2 B, 3 A
  uint64_t pixels = 0;
  uint64_t differingPixels = 0;   // any channel differs at all
  uint64_t yeeFailingPixels = 0;  // perceptibly different (Yee)
  double yeeLuminance = 100.0;    // cd/m², the adaptation luminance used
  double yeeFieldOfView = 45.0;   // degrees
};

// Both images the same size (the caller checks). Throws std::runtime_error
// when OpenImageIO reports an error.
ColorMetrics compareColors(const FlatImage& a, const FlatImage& b);

// Composites each sample's layers front to back (over, premultiplied) and
// averages the spp samples of each pixel with equal weights; samples a file
// does not list count as transparent black. Z and IDs of the result are
// left empty (+inf, kNoId); hasColor is the deep image's.
FlatImage flattenDeepColor(const DeepImage& deep, int spp);

// Per-pixel largest |A − B| over RGBA, for the heat map.
std::vector<float> colorDifference(const FlatImage& a, const FlatImage& b);

// Colour agreement of two frames where their hits agree: every layer of
// every sample whose (instance, triangle) list, front to back, is identical
// in both. Separates shading differences from visibility differences
// (crossval: hybrid and the ray caster shade the same hits identically, so
// their maxError must be 0). Frames of the same size; spp is taken as the
// larger sample index + 1 of the two.
struct AgreeingColorStats {
  uint64_t layers = 0;    // layers compared
  double maxError = 0.0;  // largest |A − B| over RGBA
  int maxX = -1, maxY = -1;
};

AgreeingColorStats colorWhereHitsAgree(const DeepImage& a, const DeepImage& b);

}  // namespace rastray
