#include "compare/visibility.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "common/sampling.h"

namespace rastray {

namespace {

// Both frames in one shape: per pixel, `slots` samples, each with its hit
// layers front to back (background entries dropped).
struct LayeredFrame {
  int width = 0, height = 0, slots = 1;
  std::vector<uint64_t> offsets;  // width·height·slots + 1
  std::vector<HitRecord> hits;
  std::vector<glm::vec4> colors;  // per hit, premultiplied (deep frames; empty for flat ones)
  // Per slot: 1 + the index of the layer the renderer stopped looking
  // behind (DeepSample::cutOff); 0: it did not stop early.
  std::vector<uint32_t> cutOff;

  size_t slot(int x, int y, int s) const {
    return (size_t(y) * size_t(width) + size_t(x)) * size_t(slots) + size_t(s);
  }
  const HitRecord* begin(size_t slot) const { return hits.data() + offsets[slot]; }
  size_t layerCount(size_t slot) const { return offsets[slot + 1] - offsets[slot]; }
};

std::string pixelName(int x, int y) { return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")"; }

LayeredFrame fromFlat(const FlatImage& image) {
  LayeredFrame f;
  f.width = image.width;
  f.height = image.height;
  const size_t n = size_t(image.width) * size_t(image.height);
  f.cutOff.assign(n, 0);
  f.offsets.reserve(n + 1);
  f.offsets.push_back(0);
  for (size_t i = 0; i < n; ++i) {
    HitRecord h{image.instance[i], image.triangle[i], image.depth[i]};
    if (h.isHit()) f.hits.push_back(h);
    f.offsets.push_back(uint64_t(f.hits.size()));
  }
  return f;
}

LayeredFrame fromDeep(const DeepImage& image, int spp, const std::string& name) {
  LayeredFrame f;
  f.width = image.width;
  f.height = image.height;
  f.slots = spp;
  const size_t pixels = size_t(image.width) * size_t(image.height);
  f.offsets.assign(pixels * size_t(spp) + 1, 0);
  // Count hits per slot, then fill (the DeepImage order is already front to
  // back within each sample).
  std::vector<uint32_t> counts(pixels * size_t(spp), 0);
  for (size_t p = 0; p < pixels; ++p) {
    for (uint64_t i = image.offsets[p]; i < image.offsets[p + 1]; ++i) {
      const DeepSample& d = image.samples[i];
      if (d.sample >= uint32_t(spp)) {
        const int x = int(p % size_t(image.width)), y = int(p / size_t(image.width));
        throw InputError(name, pixelName(x, y),
                         "sample index " + std::to_string(d.sample) + " >= " + std::to_string(spp) + " spp");
      }
      if (HitRecord{d.instance, d.triangle, d.depth}.isHit()) ++counts[p * size_t(spp) + d.sample];
    }
  }
  for (size_t s = 0; s < counts.size(); ++s) f.offsets[s + 1] = f.offsets[s] + counts[s];
  f.hits.resize(f.offsets.back());
  f.colors.resize(f.offsets.back());
  f.cutOff.assign(counts.size(), 0);
  std::vector<uint64_t> next(f.offsets.begin(), f.offsets.end() - 1);
  for (size_t p = 0; p < pixels; ++p)
    for (uint64_t i = image.offsets[p]; i < image.offsets[p + 1]; ++i) {
      const DeepSample& d = image.samples[i];
      const HitRecord h{d.instance, d.triangle, d.depth};
      const size_t slot = p * size_t(spp) + d.sample;
      if (!h.isHit()) continue;
      if (d.cutOff) f.cutOff[slot] = next[slot] - f.offsets[slot] + 1;
      f.colors[next[slot]] = d.color;
      f.hits[next[slot]++] = h;
    }
  return f;
}

void checkSize(int wa, int ha, int wb, int hb, const FrameNames& names) {
  if (wa != wb || ha != hb)
    throw InputError(names.b, "",
                     "size " + std::to_string(wb) + "x" + std::to_string(hb) + " differs from " + names.a +
                         " (" + std::to_string(wa) + "x" + std::to_string(ha) + ")");
}

// Every hit must name a triangle of the scene the classifier projects.
void checkIds(const LayeredFrame& f, const Scene& scene, const std::string& name) {
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x)
      for (int s = 0; s < f.slots; ++s) {
        const size_t slot = f.slot(x, y, s);
        for (size_t k = 0; k < f.layerCount(slot); ++k) {
          const HitRecord& h = f.begin(slot)[k];
          if (h.instance < scene.instances.size() && h.triangle < scene.instances[h.instance].triangleCount)
            continue;
          throw InputError(name, pixelName(x, y),
                           "hit (instance " + std::to_string(h.instance) + ", triangle " +
                               std::to_string(h.triangle) + ") is not in scene " + scene.path + " (" +
                               std::to_string(scene.instances.size()) + " instances)");
        }
      }
}

uint64_t packId(const HitRecord& h) { return (uint64_t(h.instance) << 32) | h.triangle; }

// Aligns two front-to-back layer lists by a longest common subsequence of
// their (instance, triangle) keys. Returns index pairs in order; an index
// equal to the list's size stands for "nothing". Lists are a few layers
// long, so the quadratic table is cheap.
std::vector<std::pair<size_t, size_t>> alignLayers(const HitRecord* a, size_t na, const HitRecord* b,
                                                   size_t nb) {
  std::vector<std::pair<size_t, size_t>> out;
  if (na == 0 && nb == 0) {
    out.emplace_back(0, 0);  // both empty: one empty layer agrees
    return out;
  }
  std::vector<size_t> lcs((na + 1) * (nb + 1), 0);
  auto at = [&](size_t i, size_t j) -> size_t& { return lcs[i * (nb + 1) + j]; };
  for (size_t i = na; i-- > 0;)
    for (size_t j = nb; j-- > 0;)
      at(i, j) = a[i].sameSurface(b[j]) ? at(i + 1, j + 1) + 1 : std::max(at(i + 1, j), at(i, j + 1));
  size_t i = 0, j = 0;
  std::vector<size_t> onlyA, onlyB;
  auto flush = [&]() {
    const size_t n = std::max(onlyA.size(), onlyB.size());
    for (size_t k = 0; k < n; ++k)
      out.emplace_back(k < onlyA.size() ? onlyA[k] : na, k < onlyB.size() ? onlyB[k] : nb);
    onlyA.clear();
    onlyB.clear();
  };
  while (i < na || j < nb) {
    if (i < na && j < nb && a[i].sameSurface(b[j])) {
      flush();
      out.emplace_back(i++, j++);
    } else if (j >= nb || (i < na && at(i + 1, j) >= at(i, j + 1))) {
      onlyA.push_back(i++);
    } else {
      onlyB.push_back(j++);
    }
  }
  flush();
  return out;
}

// IDs in the 3×3 neighbourhood of a pixel, all samples and layers; kNoId
// for a sample with no hit.
std::vector<uint64_t> neighbourhoodIds(const LayeredFrame& f, int x, int y) {
  std::vector<uint64_t> ids;
  for (int ny = std::max(0, y - 1); ny <= std::min(f.height - 1, y + 1); ++ny)
    for (int nx = std::max(0, x - 1); nx <= std::min(f.width - 1, x + 1); ++nx)
      for (int s = 0; s < f.slots; ++s) {
        const size_t slot = f.slot(nx, ny, s);
        if (f.layerCount(slot) == 0) ids.push_back(packId(HitRecord{}));
        for (size_t k = 0; k < f.layerCount(slot); ++k) ids.push_back(packId(f.begin(slot)[k]));
      }
  return ids;
}

ImageSpaceEvidence imageSpaceEvidence(const LayeredFrame& fa, const LayeredFrame& fb, int x, int y,
                                      const HitRecord& a, const HitRecord& b) {
  const std::vector<uint64_t> na = neighbourhoodIds(fa, x, y), nb = neighbourhoodIds(fb, x, y);
  auto contains = [](const std::vector<uint64_t>& ids, uint64_t id) {
    return std::find(ids.begin(), ids.end(), id) != ids.end();
  };
  ImageSpaceEvidence e;
  e.edgeNearby = contains(na, packId(b)) && contains(nb, packId(a));
  return e;
}

// Compares two layered frames slot by slot into one report: each slot's
// front surfaces (the sample) and its layers aligned by (instance,
// triangle), with depth errors on agreeing layers and the colour of layers
// one renderer cut off.
class LayeredComparison {
 public:
  LayeredComparison(const LayeredFrame& fa, const LayeredFrame& fb,
                    const std::vector<glm::dvec2>& slotPositions, const std::vector<int>& slotSamples,
                    const ClassifierSettings& settings)
      : fa_(fa), fb_(fb), slotPositions_(slotPositions), slotSamples_(slotSamples), classifier_(settings) {
    r_.width = fa.width;
    r_.height = fa.height;
    r_.geometric = classifier_.geometric();
    r_.depthFormat = settings.depthFormat;
    r_.planes = settings.planes;
    r_.edgeDistance = settings.edgeDistance;
  }

  VisibilityReport run() {
    const size_t pixels = size_t(fa_.width) * size_t(fa_.height);
    r_.pixels.assign(pixels, PixelVisibility::BothEmpty);
    r_.pixelDepthError.assign(pixels, std::nanf(""));
    for (int y = 0; y < fa_.height; ++y)
      for (int x = 0; x < fa_.width; ++x) {
        const size_t pixel = size_t(y) * size_t(fa_.width) + size_t(x);
        glm::dvec4 cutOffColor(0.0);  // this pixel's share of colour in cut-off layers
        for (int s = 0; s < fa_.slots; ++s)
          compareSlot({x, y, s, pixel, glm::dvec2(x, y) + slotPositions_[size_t(s)]}, cutOffColor);
        cutOffColor /= double(fa_.slots);
        const double share = std::max(std::max(std::fabs(cutOffColor.r), std::fabs(cutOffColor.g)),
                                      std::max(std::fabs(cutOffColor.b), std::fabs(cutOffColor.a)));
        sumCutOffColor_ += share;
        if (share > r_.cutOff.maxColor) {
          r_.cutOff.maxColor = share;
          r_.cutOff.maxX = x;
          r_.cutOff.maxY = y;
        }
      }
    if (pixels) r_.cutOff.meanColor = sumCutOffColor_ / double(pixels);
    if (r_.depth.count) {
      r_.depth.meanAbsolute = sumAbs_ / double(r_.depth.count);
      r_.depth.meanRelative = sumRel_ / double(r_.depth.count);
    }
    return std::move(r_);
  }

 private:
  // Where a pair is compared: pixel (x, y), slot s, the sample position.
  struct At {
    int x, y, s;
    size_t pixel;
    glm::dvec2 position;
  };

  // Records one compared pair (a layer, or the sample's front layers) in
  // `c`; returns its class (none: agreement). `inherited`: the class to
  // give a mismatch instead of classifying it.
  std::optional<MismatchClass> record(const At& at, const HitRecord& a, const HitRecord& b, size_t layer,
                                      AgreementCounts& c, bool isLayer,
                                      std::optional<MismatchClass> inherited = {}) {
    PixelVisibility& vis = r_.pixels[at.pixel];
    ++c.compared;
    if (a.sameSurface(b)) {
      ++c.agreeing;
      c.bothEmpty += !a.isHit();
      if (!isLayer) return std::nullopt;
      vis = std::max(vis, a.isHit() ? PixelVisibility::Agree : PixelVisibility::BothEmpty);
      if (a.isHit() && std::isfinite(a.depth) && std::isfinite(b.depth)) recordDepthError(at, a, b);
      return std::nullopt;
    }
    MismatchClass cls;
    if (inherited) {
      cls = *inherited;
    } else {
      const ImageSpaceEvidence evidence =
          classifier_.geometric() ? ImageSpaceEvidence{} : imageSpaceEvidence(fa_, fb_, at.x, at.y, a, b);
      cls = classifier_.classify(at.position, a, b, evidence);
    }
    ++c.mismatches[size_t(cls)];
    if (!isLayer) return cls;
    vis = std::max(vis, toPixelVisibility(cls));
    auto& example = r_.examples[size_t(cls)];
    if (!example) example = MismatchExample{at.x, at.y, slotSamples_[size_t(at.s)], int(layer), a, b};
    return cls;
  }

  void recordDepthError(const At& at, const HitRecord& a, const HitRecord& b) {
    const double absolute = std::fabs(double(a.depth) - double(b.depth));
    const double scale = std::max(double(a.depth), double(b.depth));
    const double relative = scale > 0.0 ? absolute / scale : 0.0;
    ++r_.depth.count;
    sumAbs_ += absolute;
    sumRel_ += relative;
    if (absolute > r_.depth.maxAbsolute || r_.depth.maxAbsoluteX < 0) {
      r_.depth.maxAbsolute = absolute;
      r_.depth.maxAbsoluteX = at.x;
      r_.depth.maxAbsoluteY = at.y;
    }
    r_.depth.maxRelative = std::max(r_.depth.maxRelative, relative);
    float& pe = r_.pixelDepthError[at.pixel];
    if (std::isnan(pe) || float(absolute) > pe) pe = float(absolute);
  }

  // The colour a cut-off layer has in the renderer that reached it: the
  // layer's own premultiplied colour behind the transmittance in front of it.
  static glm::dvec4 cutOffLayerColor(const LayeredFrame& full, size_t slot, size_t layer) {
    if (full.colors.empty()) return glm::dvec4(0.0);
    const size_t first = full.offsets[slot];
    double transmittance = 1.0;
    for (size_t j = 0; j < layer; ++j) transmittance *= 1.0 - double(full.colors[first + j].a);
    return transmittance * glm::dvec4(full.colors[first + layer]);
  }

  void compareSlot(const At& at, glm::dvec4& cutOffColor) {
    const size_t slot = fa_.slot(at.x, at.y, at.s);
    const HitRecord* la = fa_.begin(slot);
    const HitRecord* lb = fb_.begin(slot);
    const HitRecord empty;
    const size_t na = fa_.layerCount(slot), nb = fb_.layerCount(slot);
    // The sample: its front surfaces.
    record(at, na ? la[0] : empty, nb ? lb[0] : empty, 0, r_.samples, false);
    // The layers, aligned by (instance, triangle): a surface one renderer
    // missed at an edge must not shift every layer behind it into a false
    // mismatch. The alignment is a longest common subsequence of the two
    // front-to-back lists; between matched layers, the unmatched ones are
    // paired in order, and the rest are compared with nothing.
    // Layers behind the last one of a renderer that declared a cut-off
    // there are cut off, not compared (see the header).
    const auto aligned = alignLayers(la, na, lb, nb);
    // Alignment entries after the one holding a side's cut-off layer.
    const uint32_t cutA = fa_.cutOff.empty() ? 0 : fa_.cutOff[slot];
    const uint32_t cutB = fb_.cutOff.empty() ? 0 : fb_.cutOff[slot];
    size_t behindA = aligned.size(), behindB = aligned.size();
    for (size_t k = 0; k < aligned.size(); ++k) {
      if (cutA && aligned[k].first + 1 == cutA) behindA = k + 1;
      if (cutB && aligned[k].second + 1 == cutB) behindB = k + 1;
    }
    // A list that ends early (its last layer opaque, where the other
    // renderer saw something else): the other's layers behind that point
    // were hidden by it, so they share the class of the mismatch at its
    // last layer (a silhouette one renderer caught and the other missed
    // hides or reveals everything behind it).
    size_t endA = aligned.size(), endB = aligned.size();
    for (size_t k = 0; k < aligned.size(); ++k) {
      if (na && aligned[k].first + 1 == na) endA = k;
      if (nb && aligned[k].second + 1 == nb) endB = k;
    }
    std::optional<MismatchClass> classAtEndA, classAtEndB;
    bool sampleCutOff = false;
    for (size_t k = 0; k < aligned.size(); ++k) {
      const auto [ia, ib] = aligned[k];
      const bool cutOffByA = k >= behindA && ia >= na && ib < nb;  // only B has it
      const bool cutOffByB = k >= behindB && ib >= nb && ia < na;
      if (cutOffByA || cutOffByB) {
        ++r_.layers.cutOff;
        sampleCutOff = true;
        r_.pixels[at.pixel] = std::max(r_.pixels[at.pixel], PixelVisibility::CutOff);
        cutOffColor += cutOffByA ? cutOffLayerColor(fb_, slot, ib) : cutOffLayerColor(fa_, slot, ia);
        continue;
      }
      std::optional<MismatchClass> inherited;
      if (ia >= na && k > endA && classAtEndA != MismatchClass::Genuine) inherited = classAtEndA;
      if (ib >= nb && k > endB && classAtEndB != MismatchClass::Genuine) inherited = classAtEndB;
      const auto cls = record(at, ia < na ? la[ia] : empty, ib < nb ? lb[ib] : empty, std::min(ia, ib),
                              r_.layers, true, inherited);
      if (k == endA) classAtEndA = cls;
      if (k == endB) classAtEndB = cls;
    }
    r_.cutOff.samples += sampleCutOff;
  }

  const LayeredFrame& fa_;
  const LayeredFrame& fb_;
  const std::vector<glm::dvec2>& slotPositions_;
  const std::vector<int>& slotSamples_;
  MismatchClassifier classifier_;
  VisibilityReport r_;
  double sumAbs_ = 0.0, sumRel_ = 0.0, sumCutOffColor_ = 0.0;
};

VisibilityReport compareLayered(const LayeredFrame& fa, const LayeredFrame& fb,
                                const std::vector<glm::dvec2>& slotPositions,
                                const std::vector<int>& slotSamples, const ClassifierSettings& settings,
                                const FrameNames& names) {
  if (settings.scene) {
    checkIds(fa, *settings.scene, names.a);
    checkIds(fb, *settings.scene, names.b);
  }
  return LayeredComparison(fa, fb, slotPositions, slotSamples, settings).run();
}

void checkSpp(int spp) {
  if (!isSupportedSampleCount(spp))
    throw InputError(
        "command line", "--spp",
        std::to_string(spp) + " is not a supported sample count (" + supportedSampleCounts() + ")");
}

}  // namespace

PixelVisibility toPixelVisibility(MismatchClass c) {
  switch (c) {
    case MismatchClass::SilhouetteEdge:
      return PixelVisibility::SilhouetteEdge;
    case MismatchClass::SharedEdgeTie:
      return PixelVisibility::SharedEdgeTie;
    case MismatchClass::DepthTie:
      return PixelVisibility::DepthTie;
    case MismatchClass::NearFarPlane:
      return PixelVisibility::NearFarPlane;
    case MismatchClass::Genuine:
      return PixelVisibility::Genuine;
  }
  return PixelVisibility::Genuine;
}

VisibilityReport compareVisibility(const FlatImage& a, const FlatImage& b, int spp,
                                   const ClassifierSettings& settings, const FrameNames& names) {
  checkSize(a.width, a.height, b.width, b.height, names);
  if (settings.scene && spp <= 0)
    throw InputError(
        "command line", "--spp",
        "flat files with --scene need --spp (the centre sample's position depends on the pattern)");
  glm::dvec2 position(0.5);
  int sample = -1;
  if (spp > 0) {
    checkSpp(spp);
    sample = centreSampleIndex(spp);
    position = samplePositions(spp)[size_t(sample)];
  }
  VisibilityReport r = compareLayered(fromFlat(a), fromFlat(b), {position}, {sample}, settings, names);
  r.deep = false;
  r.spp = std::max(spp, 0);
  return r;
}

VisibilityReport compareVisibility(const DeepImage& a, const DeepImage& b, int spp,
                                   const ClassifierSettings& settings, const FrameNames& names) {
  checkSize(a.width, a.height, b.width, b.height, names);
  if (spp <= 0) {
    if (settings.scene)
      throw InputError("command line", "--spp", "deep files with --scene need --spp (sample positions)");
    uint32_t largest = 0;
    for (const DeepSample& d : a.samples) largest = std::max(largest, d.sample);
    for (const DeepSample& d : b.samples) largest = std::max(largest, d.sample);
    if (largest >= 4096)
      throw InputError(names.a, "", "sample index " + std::to_string(largest) + " too large: give --spp");
    spp = int(largest) + 1;
  } else {
    checkSpp(spp);
  }
  // Positions matter only for the geometric tests (a scene implies a
  // checked, supported spp); an inferred odd count gets pixel centres.
  std::vector<glm::dvec2> positions = isSupportedSampleCount(spp)
                                          ? samplePositions(spp)
                                          : std::vector<glm::dvec2>(size_t(spp), glm::dvec2(0.5));
  std::vector<int> samples(static_cast<size_t>(spp));
  for (int s = 0; s < spp; ++s) samples[size_t(s)] = s;
  VisibilityReport r = compareLayered(fromDeep(a, spp, names.a), fromDeep(b, spp, names.b), positions,
                                      samples, settings, names);
  r.deep = true;
  r.spp = spp;
  return r;
}

}  // namespace rastray
