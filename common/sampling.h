// Sample positions within a pixel (SPEC §3), the one table both renderers
// and the compare tool use.
//
// Positions are in pixel units from the pixel's top-left corner, y down.
// 1 spp: the centre. 2, 4, 8, 16 spp: the standard Direct3D multisample
// patterns (given there in 1/16 pixel from the centre, y down). n² spp for
// n > 4: the centres of an n×n grid. Every position is an exact multiple of
// 1/16 for the Direct3D patterns, and of 1/(2n) for the grids.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rastray {

// True for 1, 2, 4, 8, 16 and n² with n > 4.
bool isSupportedSampleCount(int spp);

// The sample positions for spp samples per pixel. Throws std::invalid_argument
// for an unsupported count (callers turn it into an InputError).
std::vector<glm::dvec2> samplePositions(int spp);

// The index of the sample nearest the pixel centre (ties: the lowest
// index); flat EXR files store this sample's Z and IDs (SPEC §6).
int centreSampleIndex(int spp);

// "1, 2, 4, 8, 16 or n² for n > 4", for messages.
std::string supportedSampleCounts();

}  // namespace rastray
