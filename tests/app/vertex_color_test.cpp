// scenes/vertex-colors.gltf through the real binary: both renderers show
// the interpolated COLOR_0, the vertex-alpha MASK cut and the emissive
// texture at known pixels, and agree with each other; `info` lists what a
// file uses and nothing renders.
#include <cmath>
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "common/image.h"
#include "run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using nlohmann::json;
using test::runRastray;

const std::string kScene = std::string(RASTRAY_SCENES) + "/vertex-colors.gltf";
constexpr int kSize = 64;

FlatImage render(const std::string& renderer) {
  const std::string out = test::scratchPath("vertex-colors-" + renderer + ".exr");
  const auto r = runRastray({"render", kScene, "--renderer", renderer, "--size", std::to_string(kSize),
                             std::to_string(kSize), "--float", "-o", out});
  EXPECT_EQ(r.status, 0) << r.err;
  return readExr(out);
}

// What the scene's four quads show at world (x, y) (scenes/generate.py,
// VC_QUADS): premultiplied linear RGBA under the eye light (n·d = 1), or
// nothing when (x, y) is within `margin` of an edge, the MASK cut or a
// texel boundary, where a pixel's single sample may fall either way.
bool expected(double x, double y, double margin, glm::vec4* c) {
  auto quad = [&](double x0, double y0, double* u, double* v) {
    *u = (x - x0) / 0.8;
    *v = (y - y0) / 0.8;
    return *u > margin && *u<1 - margin&& * v> margin && *v < 1 - margin;
  };
  auto away = [&](double a, double b) { return std::abs(a - b) > margin; };
  double u, v;
  if (quad(-0.9, 0.1, &u, &v)) {  // FloatRGB: COLOR_0 (u, v, 1 − u), white factor
    *c = glm::vec4(u, v, 1 - u, 1);
    return true;
  }
  if (quad(0.1, 0.1, &u, &v)) {  // ByteRGBA: (u, v, 1 − u, 1) × factor (1, 0.5, 1, 1)
    *c = glm::vec4(u, 0.5 * v, 1 - u, 1);
    return true;
  }
  if (quad(-0.9, -0.9, &u, &v) && away(u, 0.5)) {  // ShortMask: alpha u, cutoff 0.5
    *c = u > 0.5 ? glm::vec4(1, 1, 0, 1) : glm::vec4(0);
    return true;
  }
  if (quad(0.1, -0.9, &u, &v) && away(u, 0.5) && away(v, 0.5)) {  // Emissive: 2×2 texels, top row red, green
    const bool right = u > 0.5, top = v > 0.5;
    *c = top ? (right ? glm::vec4(0, 1, 0, 1) : glm::vec4(1, 0, 0, 1))
             : (right ? glm::vec4(1, 1, 1, 1) : glm::vec4(0, 0, 1, 1));
    return true;
  }
  return false;
}

TEST(VertexColors, BothRenderersShowColoursMaskAndEmissionAtKnownPixels) {
  const FlatImage raster = render("raster"), raytrace = render("raytrace");
  ASSERT_EQ(raster.width, kSize);
  ASSERT_EQ(raytrace.width, kSize);
  int checked = 0;
  for (int py = 0; py < kSize; ++py)
    for (int px = 0; px < kSize; ++px) {
      // Orthographic, xmag = ymag = 1: pixel centres at ±(k + 0.5)/32.
      const double x = -1.0 + (px + 0.5) * 2.0 / kSize, y = 1.0 - (py + 0.5) * 2.0 / kSize;
      const size_t i = raster.index(px, py);
      for (int k = 0; k < 4; ++k)
        ASSERT_NEAR(raster.color[i][k], raytrace.color[i][k], 1e-5f)
            << "renderers disagree at pixel (" << px << ", " << py << ") channel " << k;
      glm::vec4 want;
      if (!expected(x, y, 1.5 / (0.4 * kSize), &want)) continue;  // 1.5 pixels from any boundary
      ++checked;
      for (int k = 0; k < 4; ++k)
        ASSERT_NEAR(raster.color[i][k], want[k], 2e-3f)
            << "pixel (" << px << ", " << py << ") channel " << k << " at world (" << x << ", " << y << ")";
    }
  EXPECT_GT(checked, 4 * 200);  // most of each quad's 25×25 pixels
}

TEST(VertexColors, CrossvalFindsNoGenuineMismatch) {
  const auto r = runRastray({"crossval", kScene, "--size", "48", "48", "--spp", "4", "--json"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["scenes"].size(), 1u);
  const json& s = j["scenes"][0];
  EXPECT_EQ(s["rasterVsRaytrace"]["visibility"]["mismatches"]["genuine"], 0);
  EXPECT_LE(s["hybridVsRaytrace"]["color"]["maxWhereHitsAgree"].get<double>(), 1e-5);
}

TEST(InfoIgnored, ReadFeaturesAreNotListed) {
  const auto text = runRastray({"info", kScene});
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_EQ(text.out.find("ignored"), std::string::npos) << text.out;
  const auto r = runRastray({"info", kScene, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_TRUE(j["ignored"].empty()) << j["ignored"];
  EXPECT_EQ(j["materials"]["textured"], 1);  // the emissive texture
  int coloured = 0;
  for (const json& i : j["instanceList"]) coloured += i["vertexColors"].get<bool>();
  EXPECT_EQ(coloured, 3);
  bool texturesNeeded = false;
  for (const json& d : j["analysis"])
    if (d["work"] == "textures") texturesNeeded = d["needed"];
  EXPECT_TRUE(texturesNeeded);
}

TEST(InfoIgnored, ListsEachIgnoredFeatureWithItsCount) {
  // An extension on textureInfos that rastray does not implement (a made-up
  // vendor name: KHR_texture_transform, the real one, is implemented now),
  // and occlusion and metallic-roughness maps (rendered now) whose texture
  // has no image: listed per textureInfo, their factors apply alone.
  const json transform = {{"EXT_vendor_texture_info", {{"offset", {0.5, 0}}}}};
  const json doc = {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"EXT_vendor_texture_info", "KHR_materials_volume"}},
      {"textures", {json::object()}},
      {"materials",
       {{{"occlusionTexture", {{"index", 0}}},
         {"pbrMetallicRoughness", {{"metallicRoughnessTexture", {{"index", 0}, {"extensions", transform}}}}}},
        {{"occlusionTexture", {{"index", 0}, {"extensions", transform}}},
         {"extensions", {{"KHR_materials_volume", {{"thicknessFactor", 1}}}}}},
        {{"occlusionTexture", {{"index", 0}}}}}}};
  const std::string path = test::scratchPath("ignored-features.gltf");
  std::ofstream(path) << doc.dump();

  const auto text = runRastray({"info", path});
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("ignored    texture without a decodable image on 4 textureInfos; "
                          "EXT_vendor_texture_info on 2 textureInfos; KHR_materials_volume on 1 material\n"),
            std::string::npos)
      << text.out;

  const auto r = runRastray({"info", path, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json ignored = json::parse(r.out)["ignored"];
  ASSERT_EQ(ignored.size(), 3u) << ignored;
  EXPECT_EQ(ignored[0], json({{"feature", "texture without a decodable image"},
                              {"unit", "textureInfo"},
                              {"count", 4},
                              {"text", "texture without a decodable image on 4 textureInfos"}}));
  EXPECT_EQ(ignored[1]["feature"], "EXT_vendor_texture_info");
  EXPECT_EQ(ignored[1]["unit"], "textureInfo");
  EXPECT_EQ(ignored[1]["count"], 2);
}

}  // namespace
}  // namespace rastray
