// Deep layers are aligned by (instance, triangle) before they are compared:
// a transparent surface one renderer misses at its edge must cost one
// mismatching layer, not shift every layer behind it into a false
// "genuine" mismatch (seen on scenes/transparent-layers.gltf before).
#include <gtest/gtest.h>

#include "compare/visibility.h"

namespace rastray {
namespace {

// A 1×1 deep frame at 1 spp with the given (instance, depth) layers.
DeepImage onePixel(std::vector<std::pair<uint32_t, float>> layers) {
  DeepImage d;
  d.width = d.height = 1;
  d.offsets = {0, uint32_t(layers.size())};
  for (const auto& [instance, depth] : layers) {
    DeepSample s;
    s.instance = instance;
    s.triangle = 0;
    s.depth = depth;
    s.color = glm::vec4(0.5f);
    d.samples.push_back(s);
  }
  return d;
}

TEST(LayerAlignment, AMissingMiddleLayerCostsOneLayer) {
  const DeepImage a = onePixel({{2, 1.0f}, {1, 2.0f}, {0, 3.0f}});
  const DeepImage b = onePixel({{2, 1.0f}, {0, 3.0f}});
  const VisibilityReport r = compareVisibility(a, b, 1, ClassifierSettings{});
  EXPECT_EQ(r.layers.compared, 3u);
  EXPECT_EQ(r.layers.agreeing, 2u);  // instances 2 and 0 agree although 0 sits at index 2 vs 1
  EXPECT_EQ(r.samples.agreeing, 1u);
}

TEST(LayerAlignment, SwappedLayersStillDisagree) {
  // The painter's algorithm's failure: the same surfaces in the wrong order.
  const DeepImage a = onePixel({{1, 1.0f}, {2, 2.0f}});
  const DeepImage b = onePixel({{2, 1.0f}, {1, 2.0f}});
  const VisibilityReport r = compareVisibility(a, b, 1, ClassifierSettings{});
  EXPECT_EQ(r.layers.compared, 3u);  // one common layer, then each side's extra against nothing
  EXPECT_EQ(r.layers.agreeing, 1u);
  EXPECT_EQ(r.samples.agreeing, 0u);  // the front surfaces differ
}

TEST(LayerAlignment, UnmatchedRunsArePairedInOrder) {
  const DeepImage a = onePixel({{5, 1.0f}, {0, 3.0f}});
  const DeepImage b = onePixel({{6, 1.0f}, {0, 3.0f}});
  const VisibilityReport r = compareVisibility(a, b, 1, ClassifierSettings{});
  EXPECT_EQ(r.layers.compared, 2u);  // (5 vs 6), (0 vs 0)
  EXPECT_EQ(r.layers.agreeing, 1u);
}

}  // namespace
}  // namespace rastray
