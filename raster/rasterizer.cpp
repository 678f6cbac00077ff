#include "raster/rasterizer.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "common/error.h"
#include "common/sampling.h"
#include "common/surface.h"
#include "raster/bin.h"
#include "raster/clip.h"
#include "raster/depth.h"
#include "raster/raster.h"
#include "raster/resolve.h"
#include "raster/setup.h"
#include "raster/shadow_map.h"
#include "raster/wireframe.h"

namespace rastray {

namespace {

struct ThreadCounters {
  DepthPassCounters opaque;
  uint64_t blendCoverageTests = 0;
  uint64_t blendSamplesTested = 0;  // covered BLEND samples tested against the opaque depth
  uint64_t fragmentsTransparent = 0;
  uint64_t shadedSamples = 0;
  uint64_t peelPasses = 0;
};

struct Fragment {
  uint32_t local;  // sample index within the tile
  double depth;    // view depth (perspective-correct)
  uint64_t id;     // (instance, triangle)
  uint32_t setup;
  uint32_t order;  // sorted mode: position in the painter's order
};

struct Layer {
  uint32_t local;
  uint32_t rank;  // front to back within the sample
  SampleHit hit;
  glm::vec4 color;
};

class Renderer {
 public:
  Renderer(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
           const RasterOptions& options, const Shader& shader, const SampleGrid& grid,
           const std::vector<TriangleSetup>& setups)
      : scene_(scene),
        analysis_(analysis),
        camera_(camera),
        options_(options),
        shader_(shader),
        grid_(grid),
        setups_(setups),
        centre_(centreSampleIndex(options.spp)) {}

  SampleHit hitAt(const TriangleSetup& t, const glm::dvec2& pos) const {
    const glm::dvec2 b = t.baryAt(pos.x, pos.y);
    return {t.instance, t.triangle, float(t.viewDepthAt(pos.x, pos.y)), float(b.x), float(b.y)};
  }

  // The depth that orders BLEND layers: the view depth of the stored
  // triangle's plane along the primary ray (intersectTrianglePlane, double),
  // the key the ray caster sorts its layers by, so both renderers order
  // layers alike, and coincident duplicates tie exactly and fall back to
  // (instance, triangle). The interpolated depth when the plane is missed.
  double layerDepth(const TriangleSetup& t, const glm::dvec2& pos) const {
    const Ray ray = camera_.primaryRay(pos);
    double th;
    glm::dvec2 b;
    if (intersectTrianglePlane(scene_, t.instance, t.triangle, ray, &th, &b) && th > 0.0) {
      const double d = th * ray.depthPerT;
      if (std::isfinite(d)) return d;
    }
    return t.viewDepthAt(pos.x, pos.y);
  }

  // The same inputs the ray caster shades from: the hit refined on the
  // stored triangle's plane along the primary ray through `pos`.
  SurfacePoint surfaceAt(const TriangleSetup& t, const glm::dvec2& pos, Ray* ray) const {
    *ray = camera_.primaryRay(pos);
    return makeSurfacePoint(scene_, refineHit(scene_, *ray, hitAt(t, pos)));
  }

  TextureFootprint footprint(const SurfacePoint& p, const glm::dvec2& pos) const {
    return analysis_.textures ? pixelFootprint(scene_, camera_, p, pos) : TextureFootprint{};
  }

  glm::vec4 shadeAt(const TriangleSetup& t, const glm::dvec2& pos, const glm::dvec2& footprintPos,
                    ThreadCounters& n) const {
    Ray ray;
    const SurfacePoint p = surfaceAt(t, pos, &ray);
    ++n.shadedSamples;
    return shader_.shade(p, ray.direction, footprint(p, footprintPos));
  }

  bool alphaCovered(const TriangleSetup& t, int px, int py, int s) const {
    const Material& m = scene_.materialOf(t.instance);
    if (m.alphaMode != AlphaMode::Mask) return true;
    const glm::dvec2 pos = glm::dvec2(px, py) + grid_.positions[size_t(s)];
    Ray ray;
    const SurfacePoint p = surfaceAt(t, pos, &ray);
    return shader_.coverageAlpha(p, footprint(p, pos)) >= m.alphaCutoff;
  }

  void renderTile(const TileRect& rect, const std::vector<uint32_t>& opaqueBin,
                  const std::vector<uint32_t>* blendBin, DepthTarget* target, FlatImage* image,
                  std::vector<DeepSample>* deep, std::vector<uint32_t>* deepCounts,
                  std::vector<SampleHit>* hits, ThreadCounters& n) const;

 private:
  void transparencyPass(const TileRect& rect, const std::vector<uint32_t>& bin, const DepthTarget& target,
                        std::vector<Layer>* layers, ThreadCounters& n) const;

  const Scene& scene_;
  const SceneAnalysis& analysis_;
  const Camera& camera_;
  const RasterOptions& options_;
  const Shader& shader_;
  const SampleGrid& grid_;
  const std::vector<TriangleSetup>& setups_;
  int centre_;
};

void Renderer::renderTile(const TileRect& rect, const std::vector<uint32_t>& opaqueBin,
                          const std::vector<uint32_t>* blendBin, DepthTarget* target, FlatImage* image,
                          std::vector<DeepSample>* deep, std::vector<uint32_t>* deepCounts,
                          std::vector<SampleHit>* hits, ThreadCounters& n) const {
  const int spp = grid_.spp;
  const int w = rect.x1 - rect.x0, h = rect.y1 - rect.y0;
  const glm::ivec2* debug = nullptr;
  if (options_.debugPixel && options_.debugPixel->x >= rect.x0 && options_.debugPixel->x < rect.x1 &&
      options_.debugPixel->y >= rect.y0 && options_.debugPixel->y < rect.y1) {
    debug = &*options_.debugPixel;
    std::fprintf(stderr, "tile   [%d, %d) x [%d, %d): %zu opaque/mask triangles binned, %zu blend\n", rect.x0,
                 rect.x1, rect.y0, rect.y1, opaqueBin.size(), blendBin ? blendBin->size() : size_t(0));
  }

  // Pass 1: OPAQUE and MASK, depth test and write.
  std::function<bool(const TriangleSetup&, int, int, int)> alphaTest;
  if (analysis_.alphaTest)
    alphaTest = [this](const TriangleSetup& t, int px, int py, int s) { return alphaCovered(t, px, py, s); };
  rasterDepthPass(setups_, opaqueBin, grid_, rect, options_.depthFormat, options_.depthFunc, alphaTest, debug,
                  target, &n.opaque);

  // Shade the visible opaque samples (deferred: only winners are shaded).
  TileSamples samples;
  const size_t count = size_t(w) * size_t(h) * size_t(spp);
  samples.color.assign(count, glm::vec4(0.0f));
  samples.front.assign(count, SampleHit{});
  std::vector<std::pair<uint64_t, glm::vec4>> pixelCache;  // shading rate pixel: one colour per triangle
  for (int py = rect.y0; py < rect.y1; ++py)
    for (int px = rect.x0; px < rect.x1; ++px) {
      pixelCache.clear();
      const glm::dvec2 corner(px, py);
      for (int s = 0; s < spp; ++s) {
        const uint32_t win = target->winners[target->index(px, py, s)];
        if (win == kNoSetup) continue;
        const TriangleSetup& t = setups_[win];
        const size_t local =
            (size_t(py - rect.y0) * size_t(w) + size_t(px - rect.x0)) * size_t(spp) + size_t(s);
        const glm::dvec2 pos = corner + grid_.positions[size_t(s)];
        samples.front[local] = hitAt(t, pos);
        glm::vec4 c;
        if (options_.shadingRate == ShadingRate::Pixel) {
          auto it = std::find_if(pixelCache.begin(), pixelCache.end(),
                                 [&](const auto& e) { return e.first == t.id(); });
          if (it != pixelCache.end()) {
            c = it->second;
          } else {
            // First covered sample of this triangle, footprint of the pixel centre (MSAA-like).
            c = shadeAt(t, pos, corner + glm::dvec2(0.5), n);
            pixelCache.emplace_back(t.id(), c);
          }
        } else {
          c = shadeAt(t, pos, pos, n);
        }
        samples.color[local] = c;
        if (debug && px == debug->x && py == debug->y)
          std::fprintf(stderr,
                       "  shade  sample %d: instance %u triangle %u view depth %.9g b (%.6f, %.6f) -> (%.4f, "
                       "%.4f, %.4f, %.4f)\n",
                       s, t.instance, t.triangle, double(samples.front[local].depth),
                       double(samples.front[local].b1), double(samples.front[local].b2), double(c.r),
                       double(c.g), double(c.b), double(c.a));
      }
    }

  // Pass 2: BLEND layers in front of the opaque depth, composited front to back.
  std::vector<Layer> layers;
  if (blendBin && !blendBin->empty()) transparencyPass(rect, *blendBin, *target, &layers, n);
  std::vector<glm::vec4> opaqueColor;
  if (!layers.empty()) {
    opaqueColor = samples.color;
    std::vector<glm::vec4> acc(count, glm::vec4(0.0f));
    std::vector<bool> hasFront(count, false);
    for (const Layer& l : layers) {
      acc[l.local] = over(acc[l.local], l.color);  // acc is in front of the new layer
      if (!hasFront[l.local]) {
        hasFront[l.local] = true;
        samples.front[l.local] = l.hit;
      }
    }
    for (size_t i = 0; i < count; ++i)
      if (hasFront[i]) samples.color[i] = over(acc[i], samples.color[i]);
  }

  if (debug) {
    const size_t base = (size_t(debug->y - rect.y0) * size_t(w) + size_t(debug->x - rect.x0)) * size_t(spp);
    for (const Layer& l : layers)
      if (l.local >= base && l.local < base + size_t(spp))
        std::fprintf(stderr,
                     "  blend  sample %zu layer %u: instance %u triangle %u view depth %.9g -> (%.4f, %.4f, "
                     "%.4f, %.4f)\n",
                     l.local - base, l.rank, l.hit.instance, l.hit.triangle, double(l.hit.depth),
                     double(l.color.r), double(l.color.g), double(l.color.b), double(l.color.a));
    for (int s = 0; s < spp; ++s) {
      const glm::vec4& c = samples.color[base + size_t(s)];
      std::fprintf(stderr, "  final  sample %d: (%.4f, %.4f, %.4f, %.4f)%s\n", s, double(c.r), double(c.g),
                   double(c.b), double(c.a), s == centre_ ? " (centre sample: Z and ids)" : "");
    }
  }

  resolveTile(rect, spp, centre_, samples, image);
  if (hits)
    for (int py = rect.y0; py < rect.y1; ++py)
      for (int px = rect.x0; px < rect.x1; ++px)
        for (int s = 0; s < spp; ++s)
          (*hits)[target->index(px, py, s)] =
              samples
                  .front[(size_t(py - rect.y0) * size_t(w) + size_t(px - rect.x0)) * size_t(spp) + size_t(s)];

  if (deep) {
    // Per pixel: for each sample its layers front to back, then the opaque surface.
    size_t li = 0;
    for (int py = rect.y0; py < rect.y1; ++py)
      for (int px = rect.x0; px < rect.x1; ++px) {
        uint32_t c = 0;
        for (int s = 0; s < spp; ++s) {
          const size_t local =
              (size_t(py - rect.y0) * size_t(w) + size_t(px - rect.x0)) * size_t(spp) + size_t(s);
          for (; li < layers.size() && layers[li].local == local; ++li, ++c) {
            const Layer& l = layers[li];
            // Peeling stops after its last pass: it did not look behind that layer.
            const bool cutOff = options_.transparency == TransparencyMode::Peel &&
                                l.rank + 1 == uint32_t(options_.peelLayers);
            deep->push_back({l.color, l.hit.depth, l.hit.instance, l.hit.triangle, uint32_t(s), cutOff});
          }
          const uint32_t win = target->winners[target->index(px, py, s)];
          if (win == kNoSetup) continue;
          const SampleHit hit = hitAt(setups_[win], glm::dvec2(px, py) + grid_.positions[size_t(s)]);
          const glm::vec4 col = opaqueColor.empty() ? samples.color[local] : opaqueColor[local];
          deep->push_back({col, hit.depth, hit.instance, hit.triangle, uint32_t(s)});
          ++c;
        }
        deepCounts->push_back(c);
      }
  }
}

void Renderer::transparencyPass(const TileRect& rect, const std::vector<uint32_t>& bin,
                                const DepthTarget& target, std::vector<Layer>* layers,
                                ThreadCounters& n) const {
  const int w = rect.x1 - rect.x0;
  const int spp = grid_.spp;
  CoverageScratch scratch;
  const auto localIndex = [&](int px, int py, int s) {
    return uint32_t((size_t(py - rect.y0) * size_t(w) + size_t(px - rect.x0)) * size_t(spp) + size_t(s));
  };
  // Calls f(fragment) for every covered BLEND sample in front of the opaque depth.
  const auto forEachFragment = [&](const std::vector<uint32_t>& triangles, auto&& f) {
    for (uint32_t index : triangles) {
      const TriangleSetup& t = setups_[index];
      const uint64_t id = t.id();
      n.blendCoverageTests += forEachCoveredSample(t, grid_, rect, scratch, [&](int px, int py, int s) {
        ++n.blendSamplesTested;
        const size_t i = target.index(px, py, s);
        const uint32_t key = sampleDepthKey(t, grid_, options_.depthFormat, px, py, s);
        const uint32_t win = target.winners[i];
        if (!passesDepthTest(options_.depthFunc, key, id, target.keys[i],
                             win == kNoSetup ? UINT64_MAX : setups_[win].id()))
          return;
        const glm::dvec2 pos = glm::dvec2(px, py) + grid_.positions[size_t(s)];
        f(Fragment{localIndex(px, py, s), layerDepth(t, pos), id, index, 0}, pos);
      });
    }
  };
  const auto makeLayer = [&](const Fragment& f, const glm::dvec2& pos, uint32_t rank) {
    const TriangleSetup& t = setups_[f.setup];
    return Layer{f.local, rank, hitAt(t, pos), shadeAt(t, pos, pos, n)};
  };
  const auto positionOf = [&](uint32_t local) {
    const uint32_t s = local % uint32_t(spp), pixel = local / uint32_t(spp);
    return glm::dvec2(rect.x0 + int(pixel % uint32_t(w)), rect.y0 + int(pixel / uint32_t(w))) +
           grid_.positions[s];
  };
  const auto frontToBack = [](const Fragment& a, const Fragment& b) {
    if (a.local != b.local) return a.local < b.local;
    if (a.depth != b.depth) return a.depth < b.depth;
    return a.id < b.id;
  };

  switch (options_.transparency) {
    case TransparencyMode::Exact: {
      // Per-sample fragment lists sorted by (depth, instance, triangle).
      std::vector<Fragment> fragments;
      forEachFragment(bin, [&](const Fragment& f, const glm::dvec2&) { fragments.push_back(f); });
      n.fragmentsTransparent += fragments.size();
      std::sort(fragments.begin(), fragments.end(), frontToBack);
      uint32_t rank = 0;
      for (size_t i = 0; i < fragments.size(); ++i) {
        rank = (i > 0 && fragments[i].local == fragments[i - 1].local) ? rank + 1 : 0;
        layers->push_back(makeLayer(fragments[i], positionOf(fragments[i].local), rank));
      }
      break;
    }
    case TransparencyMode::Sorted: {
      // The painter's algorithm: whole triangles back to front by the view
      // depth of their centroid, each composited over what is there. At a
      // sample this is the list of covering fragments in that order, which
      // is how it is recorded (reversed: front to back as the painter
      // believes). Wrong wherever triangles interpenetrate or overlap
      // cyclically: one centroid order cannot be right at every sample.
      std::vector<uint32_t> order(bin);
      std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        const TriangleSetup &ta = setups_[a], &tb = setups_[b];
        if (ta.centroidDepth != tb.centroidDepth) return ta.centroidDepth > tb.centroidDepth;
        if (ta.id() != tb.id()) return ta.id() > tb.id();
        return a < b;
      });
      std::vector<Fragment> fragments;
      uint32_t painted = 0;
      for (uint32_t index : order) {
        const std::vector<uint32_t> one{index};
        forEachFragment(one, [&](Fragment f, const glm::dvec2&) {
          f.order = painted;
          fragments.push_back(f);
        });
        ++painted;
      }
      n.fragmentsTransparent += fragments.size();
      // Painted last = in front: sort each sample's fragments by descending paint order.
      std::stable_sort(fragments.begin(), fragments.end(), [](const Fragment& a, const Fragment& b) {
        if (a.local != b.local) return a.local < b.local;
        return a.order > b.order;
      });
      uint32_t rank = 0;
      for (size_t i = 0; i < fragments.size(); ++i) {
        rank = (i > 0 && fragments[i].local == fragments[i - 1].local) ? rank + 1 : 0;
        layers->push_back(makeLayer(fragments[i], positionOf(fragments[i].local), rank));
      }
      break;
    }
    case TransparencyMode::Peel: {
      // Depth peeling: pass k keeps, per sample, the nearest fragment behind
      // the one peeled in pass k − 1, ordered by (depth, instance, triangle)
      // so coplanar layers peel one by one. No lists: one fragment per sample.
      const size_t count = size_t(w) * size_t(rect.y1 - rect.y0) * size_t(spp);
      std::vector<Fragment> peeled(count, Fragment{0, -1.0, 0, kNoSetup, 0});  // previous layer
      std::vector<Fragment> best(count);
      std::vector<Layer> found;
      for (int pass = 0; pass < options_.peelLayers; ++pass) {
        ++n.peelPasses;
        for (Fragment& b : best) b.setup = kNoSetup;
        forEachFragment(bin, [&](const Fragment& f, const glm::dvec2&) {
          ++n.fragmentsTransparent;
          const Fragment& prev = peeled[f.local];
          const bool behind = prev.setup == kNoSetup && prev.depth < 0.0
                                  ? true
                                  : (f.depth > prev.depth || (f.depth == prev.depth && f.id > prev.id));
          if (!behind) return;
          Fragment& b = best[f.local];
          if (b.setup == kNoSetup || f.depth < b.depth || (f.depth == b.depth && f.id < b.id)) b = f;
        });
        bool any = false;
        for (size_t i = 0; i < count; ++i) {
          if (best[i].setup == kNoSetup) continue;
          any = true;
          best[i].local = uint32_t(i);
          found.push_back(makeLayer(best[i], positionOf(uint32_t(i)), uint32_t(pass)));
          peeled[i] = best[i];
        }
        if (!any) break;
      }
      std::stable_sort(found.begin(), found.end(),
                       [](const Layer& a, const Layer& b) { return a.local < b.local; });
      *layers = std::move(found);
      break;
    }
  }
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
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point a) {
    return std::chrono::duration<double>(Clock::now() - a).count();
  };
  if (options.transparency == TransparencyMode::Peel && options.peelLayers < 1)
    throw InputError("command line", "--transparency", "peel needs at least 1 layer");
  if (options.shadows == ShadowMode::Rays && !visibility && analysis.shadows)
    throw InputError(
        "command line", "--shadows",
        "rays needs the hybrid renderer (ray-traced visibility); the rasterizer offers map or none");
  if (options.shadows == ShadowMode::Map && options.shadowMapSize < 1)
    throw InputError("command line", "--shadow-map-size", "must be at least 1");

  RenderOutput out;
  const SampleGrid grid = makeSampleGrid(options.spp, camera.width, camera.height);
  const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
  const DepthSettings depth{options.depthFormat, camera.projection,           camera.znear,
                            camera.zfar,         options.polygonOffsetFactor, options.polygonOffsetUnits};

  // Transform, clip, set up.
  auto start = Clock::now();
  SetupCounters sc;
  const std::vector<TriangleSetup> setups =
      prepareTriangles(scene, space, grid, depth, options.cull, {true, analysis.transparency}, &sc);
  out.timings.emplace_back("raster.setup", seconds(start));

  start = Clock::now();
  const TileGrid tiles(camera.width, camera.height);
  const auto isBlend = [&](const TriangleSetup& t) {
    return scene.materialOf(t.instance).alphaMode == AlphaMode::Blend;
  };
  const auto opaqueBins = binTriangles(tiles, setups, [&](const TriangleSetup& t) { return !isBlend(t); });
  std::vector<std::vector<uint32_t>> blendBins;
  if (analysis.transparency) blendBins = binTriangles(tiles, setups, isBlend);
  out.timings.emplace_back("raster.bin", seconds(start));

  // Light visibility: shadow maps, the hybrid's rays, or none.
  std::unique_ptr<ShadowMaps> maps;
  const LightVisibility* lightVisibility = nullptr;
  uint64_t shadowTriangles = 0, shadowMapCount = 0, shadowTransmissive = 0;
  const bool shadowsNeeded = analysis.shadows && !analysis.eyeLight;
  if (shadowsNeeded && options.shadows == ShadowMode::Map) {
    start = Clock::now();
    // Unlit shader for MASK coverage and shadow transmittance while the maps render.
    const Shader mapShader(scene, analysis, camera, options.shading, nullptr, nullptr);
    maps = std::make_unique<ShadowMaps>(scene, options, &mapShader);
    lightVisibility = maps.get();
    shadowTriangles = maps->trianglesRendered();
    shadowMapCount = maps->mapCount();
    shadowTransmissive = maps->attenuatingFragments();
    out.timings.emplace_back("raster.shadow_maps", seconds(start));
    out.passesRun.push_back("shadow maps: " + std::to_string(shadowMapCount) + " maps for " +
                            std::to_string(scene.lights.size()) + " lights");
  } else if (shadowsNeeded && options.shadows == ShadowMode::Rays) {
    lightVisibility = visibility;
    out.passesRun.push_back("shadows: traced shadow rays (hybrid)");
  } else if (shadowsNeeded) {
    out.passesLeftOut.push_back("shadows: --shadows none");
  } else {
    out.passesLeftOut.push_back("shadow maps: " + analysis.decisions[size_t(Work::Shadows)].reason);
  }
  const Shader shader(scene, analysis, camera, options.shading, lightVisibility, secondary);

  out.passesRun.push_back("opaque pass: OPAQUE and MASK with depth writes");
  if (analysis.alphaTest)
    out.passesRun.push_back("alpha test: " + analysis.decisions[size_t(Work::AlphaTest)].reason);
  else
    out.passesLeftOut.push_back("alpha test: " + analysis.decisions[size_t(Work::AlphaTest)].reason);
  if (analysis.transparency)
    out.passesRun.push_back(std::string("transparency pass (") +
                            (options.transparency == TransparencyMode::Exact    ? "exact"
                             : options.transparency == TransparencyMode::Sorted ? "sorted"
                                                                                : "peel") +
                            "): " + analysis.decisions[size_t(Work::TransparencyPass)].reason);
  else
    out.passesLeftOut.push_back("transparency pass: " +
                                analysis.decisions[size_t(Work::TransparencyPass)].reason);
  if (secondary && (analysis.reflection || analysis.refraction))
    out.passesRun.push_back("secondary rays: traced (hybrid)");
  else if (analysis.reflection || analysis.refraction)
    out.passesLeftOut.push_back("secondary rays: pure rasterizer (mirrors and glass see black)");
  else
    out.passesLeftOut.push_back("secondary rays: no reflective or refractive material");
  if (analysis.textures)
    out.passesRun.push_back("textures: " + analysis.decisions[size_t(Work::Textures)].reason);
  else
    out.passesLeftOut.push_back("textures: " + analysis.decisions[size_t(Work::Textures)].reason);

  // Raster every tile: pass 1, shading, pass 2, resolve.
  start = Clock::now();
  const Renderer renderer(scene, analysis, camera, options, shader, grid, setups);
  DepthTarget target(camera.width, camera.height, options.spp);
  out.image = FlatImage(camera.width, camera.height);
  std::vector<std::vector<DeepSample>> deep(options.keepSamples ? size_t(tiles.count()) : 0);
  std::vector<std::vector<uint32_t>> deepCounts(deep.size());
  tbb::enumerable_thread_specific<ThreadCounters> counters;
  if (hits) hits->assign(size_t(camera.width) * size_t(camera.height) * size_t(options.spp), SampleHit{});
  tbb::parallel_for(0, tiles.count(), [&](int tile) {
    const size_t t = size_t(tile);
    renderer.renderTile(tiles.rect(tile), opaqueBins[t], analysis.transparency ? &blendBins[t] : nullptr,
                        &target, &out.image, options.keepSamples ? &deep[t] : nullptr,
                        options.keepSamples ? &deepCounts[t] : nullptr, hits, counters.local());
  });
  out.timings.emplace_back("raster.tiles", seconds(start));

  if (options.keepSamples) {
    DeepImage& d = out.samples;
    d.width = camera.width;
    d.height = camera.height;
    std::vector<uint32_t> perPixel(size_t(camera.width) * size_t(camera.height));
    std::vector<size_t> tileStart(deep.size());
    for (int tile = 0; tile < tiles.count(); ++tile) {
      const TileRect r = tiles.rect(tile);
      size_t k = 0;
      for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x)
          perPixel[size_t(y) * size_t(camera.width) + size_t(x)] = deepCounts[size_t(tile)][k++];
    }
    d.offsets.assign(perPixel.size() + 1, 0);
    for (size_t i = 0; i < perPixel.size(); ++i) d.offsets[i + 1] = d.offsets[i] + perPixel[i];
    d.samples.resize(d.offsets.back());
    for (int tile = 0; tile < tiles.count(); ++tile) {
      const TileRect r = tiles.rect(tile);
      size_t k = 0;
      for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x) {
          const size_t p = size_t(y) * size_t(camera.width) + size_t(x);
          std::copy_n(deep[size_t(tile)].begin() + std::ptrdiff_t(k), perPixel[p],
                      d.samples.begin() + d.offsets[p]);
          k += perPixel[p];
        }
    }
    out.hasSamples = true;
  }

  uint64_t wirePixels = 0;
  if (options.wireframe) {
    WireframeStyle style;
    style.halo = options.halo;
    wirePixels = drawWireframe(setups, grid, target, options.depthFormat, style, &out.image);
    out.passesRun.push_back(options.halo ? "wireframe: hidden lines removed, halos"
                                         : "wireframe: hidden lines removed");
  }

  ThreadCounters total;
  for (const ThreadCounters& c : counters) {
    total.opaque.coverageTests += c.opaque.coverageTests;
    total.opaque.samplesTested += c.opaque.samplesTested;
    total.opaque.samplesPassed += c.opaque.samplesPassed;
    total.opaque.alphaRejected += c.opaque.alphaRejected;
    total.blendCoverageTests += c.blendCoverageTests;
    total.blendSamplesTested += c.blendSamplesTested;
    total.fragmentsTransparent += c.fragmentsTransparent;
    total.shadedSamples += c.shadedSamples;
    total.peelPasses += c.peelPasses;
  }
  CounterSet& k = out.counters;
  k.set("raster.triangles_in", sc.trianglesIn);
  k.set("raster.degenerate", sc.degenerate);
  k.set("raster.culled", sc.culled);
  k.set("raster.outside", sc.outside);
  k.set("raster.clipped", sc.clipped);
  k.set("raster.guard_band_clipped", sc.guardBandClipped);
  k.set("raster.triangles_from_clipping", sc.fromClipping);
  k.set("raster.triangles_setup", setups.size());
  k.set("raster.coverage_tests", total.opaque.coverageTests + total.blendCoverageTests);
  k.set("raster.samples_tested", total.opaque.samplesTested + total.blendSamplesTested);
  k.set("raster.samples_passed", total.opaque.samplesPassed + total.fragmentsTransparent);
  k.set("raster.alpha_rejected", total.opaque.alphaRejected);
  k.set("raster.fragments_opaque", total.opaque.samplesPassed);
  k.set("raster.fragments_transparent", total.fragmentsTransparent);
  k.set("raster.peel_tile_passes", total.peelPasses);
  k.set("raster.shadow_maps", shadowMapCount);
  k.set("raster.shadow_map_triangles", shadowTriangles);
  k.set("raster.shadow_map_transmissive_fragments", shadowTransmissive);
  k.set("raster.shaded_samples", total.shadedSamples);
  k.set("raster.wireframe_pixels", wirePixels);
  return out;
}

}  // namespace rastray
