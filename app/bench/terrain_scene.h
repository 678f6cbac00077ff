// The crossover study's generated scenes: one deterministic surface — a
// bumpy terrain y = A sin(2πx/λ) cos(2πz/λ) (A = 0.06, λ = 0.5 scene units)
// seen from above at about 60° — tessellated into exactly the number of
// triangles asked for. The grid is laid out in screen space: its vertices
// are where rays through a regular grid of image points (the image plus a 3%
// margin on each side, so the bumps never uncover the background) meet the
// plane y = 0, then lifted onto the bumps. So every triangle covers about
// the same number of pixels (pixels / triangles), nearly all triangles are
// in view, and every tessellation shows the same picture: scenes of one
// aspect ratio differ only in their triangle count. The bumps' slopes (up to
// 37°) hide some of the surface at the far edge and, lit, cast shadows under
// the directional light. Unlit, the surface is emissive (one flat colour:
// the picture is uniform, the work is visibility, set-up and per-sample
// shading without lights).
// In the bench library: `rastray bench terrain:N` renders the unlit one (so
// do the peers in bench/peers/table.sh), and the crossover study
// (app/studies/sweep_crossover.h) sweeps their sizes.
#pragma once

#include <cstdint>

#include "common/gltf/writer.h"

namespace rastray::crossover {

// How `triangles` are laid out: a grid of `columns` × `rows` quads (two
// triangles each) over the image, then `partialQuads` quads and, for an
// odd count, one triangle in one more row just beyond the far edge (out of
// view; only counts whose half has no divisor near the grid's aspect need
// it — none of the powers of ten do).
struct GridShape {
  uint64_t columns = 0, rows = 0, partialQuads = 0;
  bool extraTriangle = false;
  uint64_t triangles() const { return 2 * (columns * rows + partialQuads) + (extraTriangle ? 1 : 0); }
};

// `aspect` = the grid's width / height in screen space. triangles >= 1.
GridShape gridShape(uint64_t triangles, double aspect);

// The scene with exactly `triangles` triangles laid out for images of
// `aspect` = width / height (throws std::invalid_argument for 0 triangles,
// more than 4·10^8 — past what a .glb holds — or an aspect outside
// 0.1..10). Lit: a grey diffuse material under one directional light (elevation 37°), so a frame
// needs shadows (a shadow map or shadow rays) and diffuse shading. Unlit:
// the same mesh and camera, an emissive material and no light, so a pixel's
// colour is its visible surface's flat colour: rendering it measures primary
// visibility with the least shading either renderer can do.
GltfScene crossoverScene(uint64_t triangles, bool lit, double aspect);

}  // namespace rastray::crossover
