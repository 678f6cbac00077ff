// Scene generators of the stability study's geometry cases
// (app/studies/stability_cases_geometry.cpp): sub-pixel triangles, slivers,
// pixel-aligned tilings, grazing views and scaled scenes. Deterministic:
// the same parameters give the same file, byte for byte (a fixed-seed
// generator, no clock, no platform RNG).
//
// The "pixel" scenes use an orthographic camera at the origin looking down
// −Z whose view volume is exactly the image: xmag = W/2, ymag = H/2, so
// the world point (x, y, z) appears at image position (x + W/2, H/2 − y).
// Vertices on multiples of 1/2 (pixel corners and the 1-spp sample
// positions, pixel centres) and of 1/16 (the Direct3D sample patterns) are
// exact in float, and the camera at the origin makes the render-origin
// rebasing exact too: the renderers see exactly the positions written.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "common/gltf/writer.h"

namespace rastray::stability {

// Image size of the pixel scenes (world units are pixels).
struct PixelFrame {
  int width = 128, height = 128;
  // World x, y of an image position, and back.
  glm::dvec2 world(glm::dvec2 image) const { return {image.x - width / 2.0, height / 2.0 - image.y}; }
  glm::dvec2 image(glm::dvec2 world) const { return {world.x + width / 2.0, height / 2.0 - world.y}; }
  // The orthographic camera described above; geometry lives at z = −1.
  GltfCamera camera() const;
};

// Sub-pixel triangles: instance 0 a closed UV sphere of
// `sphereSegments` × sphereSegments/2 quads (each about half a pixel across
// at 96×96), instance 1 `dustCount` isolated triangles in front of it with
// edges log-uniform from 1e-3 to 1 pixel (the top end sample-sized), random
// positions and orientations. Perspective camera; image 96×96.
constexpr int kSubpixelImageSize = 96;
GltfScene subpixelScene(int sphereSegments, int dustCount, uint32_t seed);

// Slivers, in a PixelFrame, every material BLEND with alpha 1/2 (so every
// covering triangle is its own layer and a doubly covered sample shows):
//   instance 0: a closed fan around a pixel centre, boundary on a circle of
//     `radius` pixels: 24 directions at multiples of 15° (the axes and
//     diagonals pass through sample positions) with, after every third one,
//     a cluster of slivers of apex angles 1e-2 .. `minAngle` (aspect ratio
//     longest edge / height = 1 / angle, up to 1e6), on both sides;
//   instances 1..3: bands one pixel row of samples runs through, heights
//     2e-2, 2e-4, 2e-6 pixels, 72 pixels long, cut into a triangle strip
//     whose diagonals cross the sample row at sample positions (aspect
//     ratios 1e2, 1e4, 1e6).
struct SliverLayout {
  PixelFrame frame{160, 128};
  glm::dvec2 fanCentre{-36.5, 22.5};  // world; a pixel centre
  double radius = 36.0;
  double minAngle = 1e-6;
  std::vector<glm::dvec2> fanBoundary;  // world, counter-clockwise (filled by sliverScene)
};
GltfScene sliverScene(SliverLayout* layout);

// Pixel-aligned tiling, in a PixelFrame, BLEND alpha 1/2, double-sided,
// alternate triangles wound clockwise: instance 0 covers the rectangle
// `lo`..`hi` (world, on the 1/2 grid) with a grid of `cell`-pixel cells
// whose inner vertices sit on pixel corners or pixel centres, jittered by
// multiples of 1/2 pixel (seeded), each cell cut along alternating
// diagonals. Every vertex is a multiple of 1/2: exact in float, and every
// sample position of the 1, 2, 4, 8 and 16 spp patterns is a multiple of
// 1/16, so the exact top-left owner of each sample is computable in
// integers (`triangles` keeps the corners, world, in triangle-ID order).
struct TilingLayout {
  PixelFrame frame{64, 64};
  glm::dvec2 lo{-23.5, -23.5}, hi{24.5, 24.5};  // sample rows and columns: ties on the outline too
  double cell = 3.0;
  std::vector<std::array<glm::dvec2, 3>> triangles;  // filled by pixelAlignedScene
};
GltfScene pixelAlignedScene(TilingLayout* layout, uint32_t seed);

// A plane y = 0 from x = −1e3..1e3, z = −1e5..10, seen from 1 unit above
// with the view axis `angleDegrees` from its normal (89.9: 0.1° below the
// horizon), yfov `yfovDegrees`, authored normals. textured: a 1-unit
// checker (8×8 texels per square, REPEAT, trilinear) lit straight from
// above. Otherwise lit: a low wall (0.2 × 0.5 units, 50..2e4 ahead) left of
// the view casting shadows, one directional light 45° from the normal and
// one `angleDegrees` from it (grazing light).
GltfScene grazingScene(bool textured, double angleDegrees, double yfovDegrees);

// A lit scene (floor, box, sphere of radius 0.8 with flat normals, one
// directional light, camera in the file) about 8 units across, every
// position and the camera scaled by `scale` about the origin. The light's
// direction does not scale, so the unit scene is the reference of every
// scale.
GltfScene scaledScene(double scale);

}  // namespace rastray::stability
