// The lit scene far from the origin: built by the stability study's far
// cases (app/studies/stability_cases_far.cpp) and by the ray-offset tests
// (tests/app/far_from_origin_offsets_test.cpp), so that both measure the
// same geometry.
//
// Local units, before the offset: a 12 × 12 floor at y = 0; a 1.5 box and
// a sphere of radius 1.5 (24 × 12 facets, flat normals: no NORMAL
// attribute) `lift` above the floor; optionally a mirror (metallic 1,
// roughness 0) behind them; one directional light; the camera looks down
// at them from (0, 4, 8). Materials 0 floor, 1 box, 2 sphere, 3 mirror;
// meshes in that order.
#pragma once

#include <glm/glm.hpp>

#include "common/gltf/writer.h"

namespace rastray::stability {

struct FarSceneLayout {
  glm::dvec3 offset{0.0};  // added to every coordinate (camera included)
  // true: the offset is baked into the float32 vertex data (rounded there,
  // spacing 2^-4 at 1e6); false: it is kept exact in the node translations.
  bool baked = true;
  double lift = 0.0;  // the box and the sphere float this far above the floor
  bool mirror = false;
};

GltfScene farScene(const FarSceneLayout& layout);

}  // namespace rastray::stability
