#include "raster/report.h"

#include <string>

namespace rastray {

namespace {

// "pass: reason" into passesRun when it runs, passesLeftOut when not.
void describe(RenderOutput* out, bool runs, const std::string& text) {
  (runs ? out->passesRun : out->passesLeftOut).push_back(text);
}

const char* transparencyName(TransparencyMode mode) {
  switch (mode) {
    case TransparencyMode::Exact:
      return "exact";
    case TransparencyMode::Sorted:
      return "sorted";
    case TransparencyMode::Peel:
      return "peel";
  }
  return "?";
}

}  // namespace

void describeCameraPasses(const SceneAnalysis& analysis, const RasterOptions& options, bool secondary,
                          RenderOutput* out) {
  const auto reason = [&](Work work) { return analysis.decisions[size_t(work)].reason; };
  out->passesRun.push_back("opaque pass: OPAQUE and MASK with depth writes");
  describe(out, analysis.alphaTest, "alpha test: " + reason(Work::AlphaTest));
  if (analysis.transparency)
    out->passesRun.push_back(std::string("transparency pass (") + transparencyName(options.transparency) +
                             "): " + reason(Work::TransparencyPass));
  else
    out->passesLeftOut.push_back("transparency pass: " + reason(Work::TransparencyPass));
  // Hybrid traces the kinds the scene needs and the options keep.
  const bool reflection = analysis.reflection && options.shading.reflection;
  const bool refraction = analysis.refraction && options.shading.refraction;
  if (secondary && analysis.reflection && !options.shading.reflection)
    out->passesLeftOut.push_back("reflection rays: --no-reflection");
  if (secondary && analysis.refraction && !options.shading.refraction)
    out->passesLeftOut.push_back("refraction rays: --no-refraction");
  if (secondary && (reflection || refraction))
    out->passesRun.push_back(std::string("secondary rays: traced (hybrid") +
                             (reflection && refraction ? ""
                              : reflection             ? ", reflection only"
                                                       : ", refraction only") +
                             ")");
  else if (secondary && (analysis.reflection || analysis.refraction))
    out->passesLeftOut.push_back("secondary rays: every kind the scene needs is switched off");
  else if (analysis.reflection || analysis.refraction)
    out->passesLeftOut.push_back("secondary rays: pure rasterizer (mirrors and glass see black)");
  else
    out->passesLeftOut.push_back("secondary rays: no reflective or refractive material");
  describe(out, analysis.textures, "textures: " + reason(Work::Textures));
}

void reportCounters(const SetupCounters& setup, uint64_t trianglesSetup, const ThreadCounters& tiles,
                    const ShadowMapStats& shadows, uint64_t wireframePixels, CounterSet* out) {
  CounterSet& k = *out;
  k.set("raster.triangles_in", setup.trianglesIn);
  k.set("raster.degenerate", setup.degenerate);
  k.set("raster.culled", setup.culled);
  k.set("raster.outside", setup.outside);
  k.set("raster.no_sample", setup.noSample);
  k.set("raster.clipped", setup.clipped);
  k.set("raster.guard_band_clipped", setup.guardBandClipped);
  k.set("raster.triangles_from_clipping", setup.fromClipping);
  k.set("raster.triangles_setup", trianglesSetup);
  k.set("raster.coverage_tests", tiles.opaque.coverageTests + tiles.blendCoverageTests);
  k.set("raster.samples_tested", tiles.opaque.samplesTested + tiles.blendSamplesTested);
  k.set("raster.samples_passed", tiles.opaque.samplesPassed + tiles.fragmentsTransparent);
  k.set("raster.alpha_rejected", tiles.opaque.alphaRejected);
  k.set("raster.fragments_opaque", tiles.opaque.samplesPassed);
  k.set("raster.fragments_transparent", tiles.fragmentsTransparent);
  k.set("raster.peel_tile_passes", tiles.peelPasses);
  k.set("raster.shadow_maps", shadows.maps);
  k.set("raster.shadow_map_triangles", shadows.triangles);
  k.set("raster.shadow_map_transmissive_fragments", shadows.transmissiveFragments);
  k.set("raster.shaded_samples", tiles.shadedSamples);
  k.set("raster.refined_samples", tiles.refinedSamples);
  k.set("raster.wireframe_pixels", wireframePixels);
}

}  // namespace rastray
