// Hidden-line wireframe, drawn with the depth buffer: the edges of
// the original triangles (not the internal edges of clipped pieces) drawn
// as 1-pixel lines over the shaded image. A line pixel is hidden when the
// surface in the depth buffer (centre sample) is nearer than the line,
// with the line pulled towards the viewer by a polygon offset so that
// edges lying on their own surface are not lost to z-fighting. With halo,
// every line is first drawn 3 pixels wide into a separate halo depth
// buffer; a thin line pixel is then dropped where a different, nearer line's
// halo covers it by more than the offset, leaving gaps where lines cross.
#pragma once

#include <vector>

#include "common/image.h"
#include "raster/coverage.h"

namespace rastray {

struct WireframeStyle {
  glm::vec4 color{0.0f, 0.0f, 0.0f, 1.0f};  // premultiplied
  bool halo = false;
  double offsetFactor = 2.0, offsetUnits = 4.0;  // magnitudes; lines always move towards the viewer
};

// Returns the number of line pixels drawn.
uint64_t drawWireframe(const std::vector<TriangleSetup>& setups, const SampleGrid& grid,
                       const DepthTarget& depth, DepthFormat format, const WireframeStyle& style,
                       FlatImage* image);

}  // namespace rastray
