// Pass 2 of a tile: the BLEND layers of every sample, tested against the
// opaque depth of pass 1 without writing it, shaded, and listed front to
// back for compositing (tile_resolve.cpp). Three ways to find them:
//
//   exact    per-sample fragment lists sorted by (plane depth, instance,
//            triangle): the reference;
//   sorted   the painter's algorithm: whole triangles by centroid depth;
//   peel     depth peeling, N passes of one fragment per sample.
#include <algorithm>

#include "raster/tile_renderer.h"

namespace rastray {

// Calls f(fragment) for every covered sample of `triangles` in front of the
// opaque depth (the depth test without a write).
template <typename F>
void TileRenderer::forEachFragment(const TileSampleIndex& index, const std::vector<uint32_t>& triangles,
                                   const DepthTarget& target, CoverageScratch& scratch, ThreadCounters& n,
                                   F&& f) const {
  for (uint32_t setup : triangles) {
    const TriangleSetup& t = setups_[setup];
    const uint64_t id = t.id();
    n.blendCoverageTests +=
        forEachCoveredSample(coveragePath(), t, grid_, index.rect, scratch, [&](int px, int py, int s) {
          ++n.blendSamplesTested;
          const size_t i = target.index(px, py, s);
          const uint32_t key = sampleDepthKey(t, grid_, options_.depthFormat, px, py, s);
          const uint32_t stored = target.keys[i];
          if (key > stored) return;
          if (key == stored) {  // only a tie needs the stored winner's id (passesDepthTest)
            const uint32_t win = target.winners[i];
            if (!passesDepthTest(options_.depthFunc, key, id, stored,
                                 win == kNoSetup ? UINT64_MAX : setups_[win].id()))
              return;
          }
          const glm::dvec2 pos = glm::dvec2(px, py) + grid_.positions[size_t(s)];
          f(BlendFragment{index(px, py, s), planeDepth(t, pos), id, setup, 0});
        });
  }
}

BlendLayer TileRenderer::shadeLayer(const TileSampleIndex& index, const BlendFragment& f, uint32_t rank,
                                    ThreadCounters& n) const {
  const TriangleSetup& t = setups_[f.setup];
  const glm::dvec2 pos = samplePosition(index, f.local);
  const SampleHit hit = interpolatedHit(t, pos);
  return BlendLayer{f.local, rank, hit, shadeAt(hit, pos, pos, n)};
}

std::vector<BlendLayer> TileRenderer::transparencyPass(const TileSampleIndex& index,
                                                       const std::vector<uint32_t>& bin,
                                                       const DepthTarget& target, ThreadCounters& n) const {
  switch (options_.transparency) {
    case TransparencyMode::Exact:
      return exactLayers(index, bin, target, n);
    case TransparencyMode::Sorted:
      return sortedLayers(index, bin, target, n);
    case TransparencyMode::Peel:
      return peeledLayers(index, bin, target, n);
  }
  return {};
}

// Per-sample fragment lists sorted by (plane depth, instance, triangle).
std::vector<BlendLayer> TileRenderer::exactLayers(const TileSampleIndex& index,
                                                  const std::vector<uint32_t>& bin, const DepthTarget& target,
                                                  ThreadCounters& n) const {
  CoverageScratch scratch;
  std::vector<BlendFragment> fragments;
  forEachFragment(index, bin, target, scratch, n, [&](const BlendFragment& f) { fragments.push_back(f); });
  n.fragmentsTransparent += fragments.size();
  std::sort(fragments.begin(), fragments.end(), [](const BlendFragment& a, const BlendFragment& b) {
    if (a.local != b.local) return a.local < b.local;
    if (a.planeDepth != b.planeDepth) return a.planeDepth < b.planeDepth;
    return a.id < b.id;
  });
  return shadeInSampleOrder(index, fragments, n);
}

std::vector<BlendLayer> TileRenderer::shadeInSampleOrder(const TileSampleIndex& index,
                                                         const std::vector<BlendFragment>& fragments,
                                                         ThreadCounters& n) const {
  std::vector<BlendLayer> layers;
  layers.reserve(fragments.size());
  uint32_t rank = 0;
  for (size_t i = 0; i < fragments.size(); ++i) {
    rank = (i > 0 && fragments[i].local == fragments[i - 1].local) ? rank + 1 : 0;
    layers.push_back(shadeLayer(index, fragments[i], rank, n));
  }
  return layers;
}

// The painter's algorithm: whole triangles back to front by the view depth
// of their centroid, each composited over what is there. At a sample this
// is the list of covering fragments in that order, which is how it is
// recorded (reversed: front to back as the painter believes). Wrong
// wherever triangles interpenetrate or overlap cyclically: one centroid
// order cannot be right at every sample.
std::vector<BlendLayer> TileRenderer::sortedLayers(const TileSampleIndex& index,
                                                   const std::vector<uint32_t>& bin,
                                                   const DepthTarget& target, ThreadCounters& n) const {
  std::vector<uint32_t> order(bin);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const TriangleSetup &ta = setups_[a], &tb = setups_[b];
    if (ta.centroidDepth != tb.centroidDepth) return ta.centroidDepth > tb.centroidDepth;
    if (ta.id() != tb.id()) return ta.id() > tb.id();
    return a < b;
  });
  CoverageScratch scratch;
  std::vector<BlendFragment> fragments;
  uint32_t painted = 0;
  for (uint32_t setup : order) {
    forEachFragment(index, {setup}, target, scratch, n, [&](BlendFragment f) {
      f.order = painted;
      fragments.push_back(f);
    });
    ++painted;
  }
  n.fragmentsTransparent += fragments.size();
  // Painted last = in front: sort each sample's fragments by descending paint order.
  std::stable_sort(fragments.begin(), fragments.end(), [](const BlendFragment& a, const BlendFragment& b) {
    if (a.local != b.local) return a.local < b.local;
    return a.order > b.order;
  });
  return shadeInSampleOrder(index, fragments, n);
}

// Depth peeling: pass k keeps, per sample, the nearest fragment behind the
// one peeled in pass k − 1, ordered by (plane depth, instance, triangle) so
// coplanar layers peel one by one. No lists: one fragment per sample and
// pass; layers beyond options_.peelLayers are dropped.
std::vector<BlendLayer> TileRenderer::peeledLayers(const TileSampleIndex& index,
                                                   const std::vector<uint32_t>& bin,
                                                   const DepthTarget& target, ThreadCounters& n) const {
  const size_t count = index.count();
  std::vector<BlendFragment> peeled(count, BlendFragment{0, -1.0, 0, kNoSetup, 0});  // previous layer
  std::vector<BlendFragment> best(count);
  std::vector<BlendLayer> layers;
  CoverageScratch scratch;
  for (int pass = 0; pass < options_.peelLayers; ++pass) {
    ++n.peelPasses;
    for (BlendFragment& b : best) b.setup = kNoSetup;
    forEachFragment(index, bin, target, scratch, n, [&](const BlendFragment& f) {
      ++n.fragmentsTransparent;
      const BlendFragment& prev = peeled[f.local];
      const bool behind =
          prev.setup == kNoSetup && prev.planeDepth < 0.0
              ? true
              : (f.planeDepth > prev.planeDepth || (f.planeDepth == prev.planeDepth && f.id > prev.id));
      if (!behind) return;
      BlendFragment& b = best[f.local];
      if (b.setup == kNoSetup || f.planeDepth < b.planeDepth || (f.planeDepth == b.planeDepth && f.id < b.id))
        b = f;
    });
    bool any = false;
    for (size_t i = 0; i < count; ++i) {
      if (best[i].setup == kNoSetup) continue;
      any = true;
      best[i].local = uint32_t(i);
      layers.push_back(shadeLayer(index, best[i], uint32_t(pass), n));
      peeled[i] = best[i];
    }
    if (!any) break;
  }
  std::stable_sort(layers.begin(), layers.end(),
                   [](const BlendLayer& a, const BlendLayer& b) { return a.local < b.local; });
  return layers;
}

}  // namespace rastray
