// The frame: transform, clip and set up every triangle, bin them into
// tiles, prepare light visibility (shadow maps, the hybrid's rays, or
// none), run every tile's pipeline in parallel (tile_renderer.h), then the
// deep image, the wireframe overlay and the report.
#include "raster/rasterizer.h"

#include <tbb/enumerable_thread_specific.h>

#include <chrono>
#include <memory>
#include <string>

#include "common/error.h"
#include "common/interrupt.h"
#include "common/parallel.h"
#include "common/shading_kernel.h"
#include "raster/bin.h"
#include "raster/clip.h"
#include "raster/frame_buffers.h"
#include "raster/report.h"
#include "raster/setup.h"
#include "raster/shadow_map.h"
#include "raster/tile_renderer.h"
#include "raster/wireframe.h"

namespace rastray {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void checkOptions(const SceneAnalysis& analysis, const RasterOptions& options,
                  const LightVisibility* visibility) {
  if (options.transparency == TransparencyMode::Peel && options.peelLayers < 1)
    throw InputError("command line", "--transparency", "peel needs at least 1 layer");
  if (options.shadows == RasterShadows::Traced && !visibility && analysis.shadows)
    throw InputError(
        "command line", "--shadows",
        "rays needs the hybrid renderer (ray-traced visibility); the rasterizer offers map or none");
  if (options.shadows == RasterShadows::Map && options.shadowMapSize < 1)
    throw InputError("command line", "--shadow-map-size", "must be at least 1");
}

// How the camera pass learns whether a light reaches a point.
struct LightSetup {
  std::unique_ptr<ShadowMaps> maps;             // owned when rendered here
  const LightVisibility* visibility = nullptr;  // null: everything lit
  ShadowMapStats stats;
};

// Renders the shadow maps (--shadows map), takes the hybrid's traced
// visibility (rays) or none, and says which in `out`'s passes.
LightSetup prepareLights(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
                         const RasterOptions& options, const LightVisibility* traced, RenderOutput* out) {
  LightSetup lights;
  const bool shadowsNeeded = analysis.shadows && !analysis.eyeLight;
  if (shadowsNeeded && options.shadows == RasterShadows::Map) {
    const auto start = Clock::now();
    // Unlit shader for MASK coverage and shadow transmittance while the maps render.
    const Shader mapShader(scene, analysis, camera, options.shading, nullptr, nullptr);
    lights.maps = std::make_unique<ShadowMaps>(scene, options, &mapShader);
    lights.visibility = lights.maps.get();
    lights.stats = {lights.maps->mapCount(), lights.maps->trianglesRendered(),
                    lights.maps->attenuatingFragments()};
    out->timings.emplace_back("raster.shadow_maps", secondsSince(start));
    out->passesRun.push_back("shadow maps: " + std::to_string(lights.stats.maps) + " maps for " +
                             std::to_string(scene.lights.size()) + " lights");
  } else if (shadowsNeeded && options.shadows == RasterShadows::Traced) {
    lights.visibility = traced;
    out->passesRun.push_back("shadows: traced shadow rays (hybrid)");
  } else if (shadowsNeeded) {
    out->passesLeftOut.push_back("shadows: --shadows none");
  } else {
    out->passesLeftOut.push_back("shadow maps: " + analysis.decisions[size_t(Work::Shadows)].reason);
  }
  return lights;
}

}  // namespace

RenderOutput renderRaster(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
                          const RasterOptions& options, const SecondaryRayTracer* secondary,
                          const LightVisibility* visibility) {
  return renderRasterWithHits(scene, analysis, camera, options, nullptr, secondary, visibility);
}

RenderOutput renderRasterWithHits(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
                                  const RasterOptions& options, std::vector<SampleHit>* hits,
                                  const SecondaryRayTracer* secondary, const LightVisibility* visibility) {
  checkOptions(analysis, options, visibility);
  RenderOutput out;
  const SampleGrid grid = makeSampleGrid(options.spp, camera.width, camera.height);
  const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
  const DepthSettings depth{options.depthFormat, camera.projection,           camera.znear,
                            camera.zfar,         options.polygonOffsetFactor, options.polygonOffsetUnits};

  // The frame's shading, without its lights' visibility (prepared after
  // setup, below).
  const Shader shading(scene, analysis, camera, options.shading, nullptr, secondary);

  // Transform, clip, set up.
  auto start = Clock::now();
  SetupCounters sc;
  TriangleFilter filter;
  filter.blend = analysis.transparency;
  // Setups that cover no sample change no sample; the wireframe still
  // draws their edges, and a pixel trace reports their coverage tests.
  filter.keepSampleless = options.wireframe || options.trace.sink != nullptr;
  // Buffers kept between frames (raster/frame_buffers.h), when the caller
  // has a pool: the setups' storage now, the image and the wireframe's
  // depth target below.
  FrameBufferLease buffers(options.frameBuffers);
  std::vector<TriangleSetup>& setupStorage = buffers.setups();
  // The camera pass's refinement planes (raster/setup.h: RefinePlane),
  // computed in lanes while setup has the corners in cache. A perspective
  // camera only: the orthographic path refines with the scalar steps. Not
  // where the kernel reads no refined hit (an unlit, emissive scene:
  // PrimaryHitShader::needsHitInputs).
  RefinePlanes& planeStorage = buffers.planes();
  const bool storedPlanes = camera.projection == Projection::Perspective &&
                            PrimaryHitShader(shading, ShadingPath::Kernel).needsHitInputs();
  prepareTriangles(scene, space, grid, depth, options.cull, filter, &sc, SetupPath::Fast, &setupStorage,
                   {camera.eye(), storedPlanes ? &planeStorage : nullptr});
  const std::vector<TriangleSetup>& setups = setupStorage;
  out.timings.emplace_back("raster.setup", secondsSince(start));

  // Bin: OPAQUE and MASK apart from BLEND (built only when the scene has BLEND).
  start = Clock::now();
  const TileGrid tiles(camera.width, camera.height);
  const auto isBlend = [&](const TriangleSetup& t) {
    return scene.materialOf(t.instance).alphaMode == AlphaMode::Blend;
  };
  const auto opaqueBins =
      binTriangles(tiles, grid, setups, [&](const TriangleSetup& t) { return !isBlend(t); });
  std::vector<std::vector<uint32_t>> blendBins;
  if (analysis.transparency) blendBins = binTriangles(tiles, grid, setups, isBlend);
  out.timings.emplace_back("raster.bin", secondsSince(start));

  const LightSetup lights = prepareLights(scene, analysis, camera, options, visibility, &out);
  const Shader shader(shading, lights.visibility, secondary);
  describeCameraPasses(analysis, options, secondary != nullptr, &out);

  // Every tile: pass 1, shading, pass 2, compositing, resolve.
  start = Clock::now();
  const TileRenderer renderer(scene, analysis, camera, options, shader, grid, setups,
                              storedPlanes ? planeStorage.data() : nullptr);
  // A frame-sized depth target only where the wireframe reads it after
  // the tiles; otherwise each tile keeps a target of its own rectangle.
  // Reused storage holds the last frame's values: each tile clears its
  // rectangle of the target, and the resolve writes every pixel.
  bool targetCleared = false;
  DepthTarget* target =
      options.wireframe ? &buffers.target(camera.width, camera.height, options.spp, &targetCleared) : nullptr;
  out.image = buffers.image(camera.width, camera.height);
  std::vector<std::vector<DeepSample>> deep(options.keepSamples ? size_t(tiles.count()) : 0);
  std::vector<std::vector<uint32_t>> deepCounts(deep.size());
  tbb::enumerable_thread_specific<ThreadCounters> counters;
  if (hits) hits->assign(size_t(camera.width) * size_t(camera.height) * size_t(options.spp), SampleHit{});
  parallelFor(0, tiles.count(), [&](int tile) {
    // Ctrl-C (common/interrupt.h): the tiles not yet started are skipped,
    // and the unfinished image is thrown away below.
    if (stopRequested(options.cancel)) return;
    const size_t t = size_t(tile);
    const TileBins bins{opaqueBins[t], analysis.transparency ? &blendBins[t] : nullptr};
    const TileOutputs outputs{&out.image, options.keepSamples ? &deep[t] : nullptr,
                              options.keepSamples ? &deepCounts[t] : nullptr, hits};
    renderer.render(tiles.rect(tile), bins, target, !targetCleared, outputs, counters.local());
  });
  throwIfStopped(options.cancel);
  const double tileSeconds = secondsSince(start);
  out.timings.emplace_back("raster.tiles", tileSeconds);
  ThreadCounters total;
  for (const ThreadCounters& c : counters) total += c;
  {
    // The tile loop's wall time split among its passes in proportion to
    // their thread-seconds, so the parts add up to raster.tiles at any
    // thread count (as the ray caster splits primary and shade).
    const ThreadCounters& sum = total;
    const double busy = sum.depthSeconds + sum.shadeSeconds + sum.transparencySeconds + sum.resolveSeconds;
    const double scale = busy > 0.0 ? tileSeconds / busy : 0.0;
    out.timings.emplace_back("raster.tiles.depth", sum.depthSeconds * scale);
    out.timings.emplace_back("raster.tiles.shade", sum.shadeSeconds * scale);
    // Without BLEND materials pass 2 is only the compositing of opaque
    // samples: counted with the resolve.
    double resolve = sum.resolveSeconds;
    if (analysis.transparency)
      out.timings.emplace_back("raster.tiles.transparency", sum.transparencySeconds * scale);
    else
      resolve += sum.transparencySeconds;
    out.timings.emplace_back("raster.tiles.resolve", resolve * scale);
  }

  if (options.keepSamples) {
    out.samples = assembleDeepImage(tiles, deep, deepCounts);
    out.hasSamples = true;
  }

  uint64_t wirePixels = 0;
  if (options.wireframe) {
    WireframeStyle style;
    style.halo = options.halo;
    wirePixels = drawWireframe(setups, grid, *target, options.depthFormat, style, &out.image);
    out.passesRun.push_back(options.halo ? "wireframe: hidden lines removed, halos"
                                         : "wireframe: hidden lines removed");
  }

  reportCounters(sc, setups.size(), total, lights.stats, wirePixels, &out.counters);
  return out;
}

}  // namespace rastray
