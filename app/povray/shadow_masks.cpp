#include "app/povray/shadow_masks.h"

#include <algorithm>
#include <string>

#include "common/error.h"

namespace rastray {

namespace {

void checkSameSize(int w0, int h0, int w1, int h1, const char* what) {
  if (w0 != w1 || h0 != h1)
    throw InputError("shadow masks", what,
                     std::to_string(w0) + "x" + std::to_string(h0) + " against " + std::to_string(w1) + "x" +
                         std::to_string(h1));
}

double brightness(const glm::vec4& c) { return double(c.r) + double(c.g) + double(c.b); }

bool reached(MaskValue v) { return v != MaskValue::Unlit; }

}  // namespace

ShadowMask shadowMask(const FlatImage& withShadows, const FlatImage& withoutShadows,
                      const ShadowMaskOptions& options) {
  checkSameSize(withShadows.width, withShadows.height, withoutShadows.width, withoutShadows.height, "images");
  ShadowMask mask;
  mask.width = withShadows.width;
  mask.height = withShadows.height;
  // The median over the pixels light reaches: a point light's 1/d² makes
  // the brightest pixel (beside the light) no measure of the rest.
  std::vector<double> reached;
  for (const glm::vec4& c : withoutShadows.color)
    if (brightness(c) > 0.0) reached.push_back(brightness(c));
  double median = 0.0;
  if (!reached.empty()) {
    std::nth_element(reached.begin(), reached.begin() + long(reached.size() / 2), reached.end());
    median = reached[reached.size() / 2];
  }
  const double floor = options.minLit * median;
  mask.value.resize(withShadows.color.size(), MaskValue::Unlit);
  for (size_t i = 0; i < mask.value.size(); ++i) {
    const double unshadowed = brightness(withoutShadows.color[i]);
    if (!(unshadowed > floor)) continue;
    mask.value[i] =
        brightness(withShadows.color[i]) < options.ratio * unshadowed ? MaskValue::Shadowed : MaskValue::Lit;
  }
  return mask;
}

double ShadowMaskAgreement::disagreeingFraction() const {
  return litReference ? double(disagreeing()) / double(litReference) : 0.0;
}

ShadowMaskAgreement compareShadowMasks(const ShadowMask& ours, const ShadowMask& reference) {
  checkSameSize(ours.width, ours.height, reference.width, reference.height, "masks");
  ShadowMaskAgreement a;
  a.pixels = ours.value.size();
  for (size_t i = 0; i < ours.value.size(); ++i) {
    const MaskValue o = ours.value[i], r = reference.value[i];
    a.litReference += reached(r);
    a.shadowedReference += r == MaskValue::Shadowed;
    a.shadowedOurs += o == MaskValue::Shadowed;
    if (reached(o) != reached(r))
      ++a.litInOneOnly;
    else if (o == MaskValue::Shadowed && r == MaskValue::Lit)
      ++a.oursShadowedRefLit;
    else if (o == MaskValue::Lit && r == MaskValue::Shadowed)
      ++a.oursLitRefShadowed;
  }
  return a;
}

FlatImage shadowMaskPicture(const ShadowMask& ours, const ShadowMask& reference) {
  checkSameSize(ours.width, ours.height, reference.width, reference.height, "masks");
  const int w = ours.width, h = ours.height;
  FlatImage picture(3 * w, h);
  auto grey = [](MaskValue v) {
    const float g = v == MaskValue::Lit ? 1.0f : v == MaskValue::Shadowed ? 0.05f : 0.0f;
    return glm::vec4(g, g, g, 1.0f);
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = ours.width * size_t(y) + size_t(x);
      const MaskValue o = ours.value[i], r = reference.value[i];
      picture.color[picture.index(x, y)] = grey(o);
      picture.color[picture.index(w + x, y)] = grey(r);
      glm::vec4 d = grey(r) * glm::vec4(0.25f, 0.25f, 0.25f, 1.0f);
      if (reached(o) != reached(r))
        d = glm::vec4(1.0f, 1.0f, 0.0f, 1.0f);
      else if (o == MaskValue::Shadowed && r == MaskValue::Lit)
        d = glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
      else if (o == MaskValue::Lit && r == MaskValue::Shadowed)
        d = glm::vec4(0.0f, 1.0f, 1.0f, 1.0f);
      picture.color[picture.index(2 * w + x, y)] = d;
    }
  return picture;
}

}  // namespace rastray
