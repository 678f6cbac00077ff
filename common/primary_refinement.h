// refinePrimaryHit (common/shading_kernel.h) for a batch of hits: the
// plane intersection (intersectTrianglePlane's Möller–Trumbore without the
// inside test) and refinedBarycentrics' test and clamp in double SIMD
// lanes, dispatched at run time like the shading kernel. The same IEEE
// operations in the same order and no contraction, so every hit gets
// refinePrimaryHit's bits (tests/common/primary_refinement_test.cpp), and
// a hit's result does not depend on its batch.
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

#include "common/camera.h"
#include "common/hit.h"
#include "common/scene.h"
#include "common/shading_kernel.h"

namespace rastray {

// out[i] = refinePrimaryHit(scene, rays[i], hits[i], footprintPositions[i]).
// Every hit must be valid.
void refinePrimaryHits(const Scene& scene, const Ray* rays, const SampleHit* hits,
                       const glm::dvec2* footprintPositions, size_t count, ShadeHit* out);

}  // namespace rastray
