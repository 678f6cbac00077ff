// Face culling (SPEC §3): which single-sided triangles a renderer drops.
// Both renderers apply it the same way, to every ray or sample: a triangle
// is front-facing when its stored vertices run counter-clockwise seen from
// the viewer (its normal cross(b − a, c − a) points towards the viewer).
#pragma once

#include "common/scene.h"

namespace rastray {

enum class CullMode { None, Back, Front };

// Whether a triangle of this material, seen from its front (or back), is
// dropped. Double-sided materials are never culled.
inline bool isCulled(CullMode cull, const Material& material, bool frontFacing) {
  if (material.doubleSided) return false;
  return (cull == CullMode::Back && !frontFacing) || (cull == CullMode::Front && frontFacing);
}

}  // namespace rastray
