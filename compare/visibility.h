// Visibility agreement between two frames on (instance, triangle), with
// every mismatch classified (compare/classify.h) and depth error statistics
// on the agreeing hits.
//
// Units compared
// - Flat frames: one unit per pixel, the sample nearest the pixel centre
//   (SPEC §6); its position is that sample's when spp is known, else unused.
// - Deep frames: every (pixel, sample index in [0, spp)) is a *sample*;
//   its *layers* are its hit entries front to back (entries with kNoId are
//   the background, not a layer). Layer k of one file is compared with
//   layer k of the other for k < max(layers A, layers B, 1): a sample with
//   no hit in either file counts as one empty layer, so layers compared >=
//   samples compared. A sample agrees when its front layers agree.
// - Both empty agrees. A hit against nothing is a mismatch like any other.
// - Cut off (SPEC §6): when a renderer stopped looking behind a layer (a
//   transmittance cut-off or a layer limit: DeepSample::cutOff), the other
//   renderer's layers aligned behind its last one are counted as cut off,
//   not compared: they are neither agreement nor mismatch, so a mismatch
//   count never exceeds what was compared. Their share of the colour (what
//   the other renderer composited from them) is reported in CutOffStats.
// Depth error statistics cover agreeing units where both depths are finite:
// absolute |ZA − ZB| and relative |ZA − ZB| / max(ZA, ZB) (0 when both are 0).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/image.h"
#include "compare/classify.h"

namespace rastray {

struct AgreementCounts {
  uint64_t compared = 0;
  uint64_t agreeing = 0;  // including bothEmpty
  uint64_t bothEmpty = 0;
  std::array<uint64_t, kMismatchClassCount> mismatches{};
  uint64_t cutOff = 0;  // layers behind a renderer's declared cut-off: not compared

  uint64_t mismatching() const { return compared - agreeing; }
  uint64_t count(MismatchClass c) const { return mismatches[size_t(c)]; }
  // 1 when nothing was compared (an empty image agrees with itself).
  double agreement() const { return compared ? double(agreeing) / double(compared) : 1.0; }
  double fraction(MismatchClass c) const { return compared ? double(count(c)) / double(compared) : 0.0; }
};

// The colour the cut-off layers carry in the renderer that did reach them:
// per pixel, the box filter over its samples of Σ T_k · C_k over the cut-off
// layers k (C_k premultiplied, T_k the transmittance in front of layer k).
struct CutOffStats {
  uint64_t samples = 0;      // samples with at least one cut-off layer
  double meanColor = 0.0;    // mean over all pixels of the largest RGBA channel of that share
  double maxColor = 0.0;     // largest over pixels
  int maxX = -1, maxY = -1;  // pixel of maxColor
};

struct DepthErrorStats {
  uint64_t count = 0;  // agreeing hits with both depths finite
  double meanAbsolute = 0.0, maxAbsolute = 0.0;
  double meanRelative = 0.0, maxRelative = 0.0;
  int maxAbsoluteX = -1, maxAbsoluteY = -1;  // pixel of maxAbsolute
};

// One mismatching unit, kept as the first example of its class (the report
// links it to `rastray explain`).
struct MismatchExample {
  int x = 0, y = 0;
  int sample = 0;  // index in the SPEC §3 pattern (flat: the centre sample, -1 if spp unknown)
  int layer = 0;
  HitRecord a, b;
};

// Per-pixel summary for the maps: the most severe class among the pixel's
// mismatching layers, or whether it agrees with a hit / is empty in both.
enum class PixelVisibility : uint8_t {
  BothEmpty,
  Agree,
  CutOff,  // agrees wherever both looked; one renderer stopped early
  SilhouetteEdge,
  SharedEdgeTie,
  DepthTie,
  NearFarPlane,
  Genuine,  // most severe last
};
PixelVisibility toPixelVisibility(MismatchClass c);

struct VisibilityReport {
  bool deep = false;
  int width = 0, height = 0;
  int spp = 0;  // samples per pixel used (deep: given or inferred); 0: unknown (flat without --spp)
  bool geometric = false;  // classification used scene geometry (else image space)
  DepthFormat depthFormat = DepthFormat::FloatReversed;
  DepthPlanes planes;
  double edgeDistance = kDefaultEdgeDistance;
  AgreementCounts samples;  // flat: pixels
  AgreementCounts layers;   // flat: the same as samples
  DepthErrorStats depth;
  CutOffStats cutOff;
  std::array<std::optional<MismatchExample>, kMismatchClassCount> examples;
  std::vector<PixelVisibility> pixels;  // width·height, row 0 at the top
  std::vector<float> pixelDepthError;   // max |ΔZ| over agreeing finite hits; NaN: none
};

// Names of the two inputs, for error messages (InputError names the file
// whose hit is not in the scene, or whose sample index is out of range).
struct FrameNames {
  std::string a = "A", b = "B";
};

// Flat frames of the same size. spp: the pattern the frames were rendered
// with, needed (> 0) when settings carry a scene, to place the centre
// sample. Throws InputError for a size mismatch (naming b), an ID outside
// the scene, or a missing spp with a scene (file "command line").
VisibilityReport compareVisibility(const FlatImage& a, const FlatImage& b, int spp,
                                   const ClassifierSettings& settings, const FrameNames& names = {});

// Deep frames of the same size. spp: the pattern, or 0 to infer it as
// (largest sample index in either file) + 1 (a guess: a file that omits
// empty samples may hide the last ones), refused with a scene, where
// sample positions must be right. Sample indices >= spp are an InputError.
VisibilityReport compareVisibility(const DeepImage& a, const DeepImage& b, int spp,
                                   const ClassifierSettings& settings, const FrameNames& names = {});

}  // namespace rastray
