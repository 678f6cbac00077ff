// Shadow masks: where a render with shadows is darker than the same render
// without them (issue 24's method). A pixel is
// - unlit where the render without shadows is at most `minLit` × that
//   render's median over the pixels it shows lit at all (no light reaches
//   it, shadows or not: the background, surfaces facing away from every
//   light, a spot's outside);
// - shadowed where it is lit and the render with shadows is below `ratio`
//   (0.6) of the one without;
// - lit otherwise.
// Brightness is R + G + B. The masks of two renderers of the same scene and
// camera are compared pixel by pixel; the count that matters is the pixels
// lit in the reference (the "lit area") on which they differ.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/image.h"

namespace rastray {

enum class MaskValue : uint8_t { Unlit = 0, Lit = 1, Shadowed = 2 };

struct ShadowMaskOptions {
  double ratio = 0.6;
  double minLit = 1e-3;
};

struct ShadowMask {
  int width = 0, height = 0;
  std::vector<MaskValue> value;  // row 0 at the top
};

// Throws InputError when the two images differ in size.
ShadowMask shadowMask(const FlatImage& withShadows, const FlatImage& withoutShadows,
                      const ShadowMaskOptions& options = {});

struct ShadowMaskAgreement {
  size_t pixels = 0;
  size_t litReference = 0;        // lit or shadowed in the reference: the lit area
  size_t shadowedReference = 0;   // shadowed in the reference
  size_t shadowedOurs = 0;        // shadowed in ours
  size_t oursShadowedRefLit = 0;  // both reached by light; ours shadowed, the reference lit
  size_t oursLitRefShadowed = 0;  // both reached by light; ours lit, the reference shadowed
  size_t litInOneOnly = 0;        // unlit in one, lit or shadowed in the other
  size_t disagreeing() const { return oursShadowedRefLit + oursLitRefShadowed + litInOneOnly; }
  // disagreeing / litReference (0 when nothing is lit).
  double disagreeingFraction() const;
};

// Throws InputError when the masks differ in size.
ShadowMaskAgreement compareShadowMasks(const ShadowMask& ours, const ShadowMask& reference);

// The two masks side by side and their difference, one picture 3W × H:
// left ours, middle the reference (black unlit, white lit, dark grey
// shadowed), right the reference's mask dimmed with the disagreements in
// colour: red where ours is shadowed and the reference lit, cyan where ours
// is lit and the reference shadowed, yellow where light reaches one only.
FlatImage shadowMaskPicture(const ShadowMask& ours, const ShadowMask& reference);

}  // namespace rastray
