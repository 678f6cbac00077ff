// Sample positions within a pixel (SPEC §3), the one table both renderers
// and the compare tool use.
//
// Positions are in pixel units from the pixel's top-left corner, y down.
// 1 spp: the centre. 2, 4, 8, 16 spp: the standard Direct3D multisample
// patterns (given there in 1/16 pixel from the centre, y down). n² spp for
// 4 < n <= kMaxGridSide: the centres of an n×n grid. Every position is an
// exact multiple of 1/16 for the Direct3D patterns, and of 1/(2n) for the
// grids.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rastray {

// The largest grid side: at most 16×16 = 256 spp. Why a bound at all:
// every entry of the per-sample buffers and deep files grows with spp (a
// 1920×1080 deep frame at 256 spp is already 530 M entries per layer),
// and the rasterizer's fixed-point grid refines by k = 2n / gcd(2n, 256)
// (raster/setup.h), which shrinks its largest image as 2^20 / k; up to
// n = 16 k stays <= 15 (images up to 69,905 pixels across), beyond it
// grows without limit. 256 samples are far past the point where more
// samples change a visibility comparison.
constexpr int kMaxGridSide = 16;

// True for 1, 2, 4, 8, 16 and n² with 4 < n <= kMaxGridSide.
bool isSupportedSampleCount(int spp);

// The sample positions for spp samples per pixel. Throws std::invalid_argument
// for an unsupported count (callers turn it into an InputError).
std::vector<glm::dvec2> samplePositions(int spp);

// The index of the sample nearest the pixel centre (ties: the lowest
// index); flat EXR files store this sample's Z and IDs (SPEC §6).
int centreSampleIndex(int spp);

// "1, 2, 4, 8, 16 or n*n for 4 < n <= 16, at most 256", for messages.
std::string supportedSampleCounts();

}  // namespace rastray
