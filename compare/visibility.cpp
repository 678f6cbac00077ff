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
  std::vector<uint32_t> offsets;  // width·height·slots + 1
  std::vector<HitRecord> hits;

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
  f.offsets.reserve(n + 1);
  f.offsets.push_back(0);
  for (size_t i = 0; i < n; ++i) {
    HitRecord h{image.instance[i], image.triangle[i], image.depth[i]};
    if (h.isHit()) f.hits.push_back(h);
    f.offsets.push_back(uint32_t(f.hits.size()));
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
    for (uint32_t i = image.offsets[p]; i < image.offsets[p + 1]; ++i) {
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
  std::vector<uint32_t> next(f.offsets.begin(), f.offsets.end() - 1);
  for (size_t p = 0; p < pixels; ++p)
    for (uint32_t i = image.offsets[p]; i < image.offsets[p + 1]; ++i) {
      const DeepSample& d = image.samples[i];
      const HitRecord h{d.instance, d.triangle, d.depth};
      if (h.isHit()) f.hits[next[p * size_t(spp) + d.sample]++] = h;
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

VisibilityReport compareLayered(const LayeredFrame& fa, const LayeredFrame& fb,
                                const std::vector<glm::dvec2>& slotPositions,
                                const std::vector<int>& slotSamples, const ClassifierSettings& settings,
                                const FrameNames& names) {
  if (settings.scene) {
    checkIds(fa, *settings.scene, names.a);
    checkIds(fb, *settings.scene, names.b);
  }
  MismatchClassifier classifier(settings);
  VisibilityReport r;
  r.width = fa.width;
  r.height = fa.height;
  r.geometric = classifier.geometric();
  r.depthFormat = settings.depthFormat;
  r.planes = settings.planes;
  r.edgeDistance = settings.edgeDistance;
  const size_t pixels = size_t(fa.width) * size_t(fa.height);
  r.pixels.assign(pixels, PixelVisibility::BothEmpty);
  r.pixelDepthError.assign(pixels, std::nanf(""));
  double sumAbs = 0.0, sumRel = 0.0;
  const HitRecord empty;
  for (int y = 0; y < fa.height; ++y)
    for (int x = 0; x < fa.width; ++x) {
      const size_t pixel = size_t(y) * size_t(fa.width) + size_t(x);
      PixelVisibility& vis = r.pixels[pixel];
      for (int s = 0; s < fa.slots; ++s) {
        const size_t slot = fa.slot(x, y, s);
        const size_t na = fa.layerCount(slot), nb = fb.layerCount(slot);
        const size_t layers = std::max<size_t>({na, nb, 1});
        for (size_t k = 0; k < layers; ++k) {
          const HitRecord& a = k < na ? fa.begin(slot)[k] : empty;
          const HitRecord& b = k < nb ? fb.begin(slot)[k] : empty;
          AgreementCounts* counts[2] = {&r.layers, k == 0 ? &r.samples : nullptr};
          if (a.sameSurface(b)) {
            for (AgreementCounts* c : counts)
              if (c) {
                ++c->compared;
                ++c->agreeing;
                c->bothEmpty += !a.isHit();
              }
            vis = std::max(vis, a.isHit() ? PixelVisibility::Agree : PixelVisibility::BothEmpty);
            if (a.isHit() && std::isfinite(a.depth) && std::isfinite(b.depth)) {
              const double absolute = std::fabs(double(a.depth) - double(b.depth));
              const double scale = std::max(double(a.depth), double(b.depth));
              const double relative = scale > 0.0 ? absolute / scale : 0.0;
              ++r.depth.count;
              sumAbs += absolute;
              sumRel += relative;
              if (absolute > r.depth.maxAbsolute || r.depth.maxAbsoluteX < 0) {
                r.depth.maxAbsolute = absolute;
                r.depth.maxAbsoluteX = x;
                r.depth.maxAbsoluteY = y;
              }
              r.depth.maxRelative = std::max(r.depth.maxRelative, relative);
              float& pe = r.pixelDepthError[pixel];
              if (std::isnan(pe) || float(absolute) > pe) pe = float(absolute);
            }
            continue;
          }
          const glm::dvec2 position = glm::dvec2(x, y) + slotPositions[size_t(s)];
          const ImageSpaceEvidence evidence =
              classifier.geometric() ? ImageSpaceEvidence{} : imageSpaceEvidence(fa, fb, x, y, a, b);
          const MismatchClass cls = classifier.classify(position, a, b, evidence);
          for (AgreementCounts* c : counts)
            if (c) {
              ++c->compared;
              ++c->mismatches[size_t(cls)];
            }
          vis = std::max(vis, toPixelVisibility(cls));
          auto& example = r.examples[size_t(cls)];
          if (!example) example = MismatchExample{x, y, slotSamples[size_t(s)], int(k), a, b};
        }
      }
    }
  if (r.depth.count) {
    r.depth.meanAbsolute = sumAbs / double(r.depth.count);
    r.depth.meanRelative = sumRel / double(r.depth.count);
  }
  return r;
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
