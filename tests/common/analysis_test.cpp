#include "common/analysis.h"

#include <gtest/gtest.h>

namespace rastray {
namespace {

Scene sceneWith(std::vector<Material> materials, size_t lights = 0) {
  Scene s;
  s.materials = std::move(materials);
  for (size_t i = 0; i < s.materials.size(); ++i) {
    Instance inst;
    inst.material = uint32_t(i);
    inst.triangleCount = 1;
    s.instances.push_back(inst);
  }
  s.lights.resize(lights);
  return s;
}

TEST(Analysis, PlainOpaqueSceneNeedsNothingExtra) {
  const SceneAnalysis a = analyzeScene(sceneWith({Material{}}));
  EXPECT_FALSE(a.transparency);
  EXPECT_FALSE(a.alphaTest);
  EXPECT_FALSE(a.shadows);
  EXPECT_FALSE(a.reflection);
  EXPECT_FALSE(a.refraction);
  EXPECT_FALSE(a.textures);
  EXPECT_TRUE(a.eyeLight);
  EXPECT_FALSE(a.needsRayFilters());
  ASSERT_EQ(a.decisions.size(), 6u);
  EXPECT_EQ(a.decisions[0].reason, "no BLEND material");
}

TEST(Analysis, EachMaterialKindSwitchesOnItsWork) {
  Material blend, mask, mirror, glass, textured;
  blend.alphaMode = AlphaMode::Blend;
  mask.alphaMode = AlphaMode::Mask;
  mirror.metallic = 1.0f;
  mirror.roughness = 0.0f;
  glass.transmission = 1.0f;
  textured.baseColorTexture = 0;
  const SceneAnalysis a = analyzeScene(sceneWith({blend, mask, mirror, glass, textured}, 2));
  EXPECT_TRUE(a.transparency);
  EXPECT_TRUE(a.alphaTest);
  EXPECT_TRUE(a.shadows);
  EXPECT_TRUE(a.reflection);
  EXPECT_TRUE(a.refraction);
  EXPECT_TRUE(a.textures);
  EXPECT_FALSE(a.eyeLight);
  EXPECT_EQ(a.decisions[0].reason, "1 BLEND material on 1 instance");
  EXPECT_EQ(a.decisions[2].reason, "2 punctual lights");
}

TEST(Analysis, UnusedMaterialsDoNotSwitchWorkOn) {
  Scene s = sceneWith({Material{}});
  Material blend;
  blend.alphaMode = AlphaMode::Blend;
  s.materials.push_back(blend);  // defined, used by no instance
  Instance empty;
  empty.material = 1;
  empty.triangleCount = 0;  // an instance without triangles draws nothing
  s.instances.push_back(empty);
  EXPECT_FALSE(analyzeScene(s).transparency);
}

TEST(Analysis, RoughMetalIsNotAMirror) {
  Material m;  // glTF default: metallic 1, roughness 1
  EXPECT_EQ(m.mirrorWeight(), 0.0f);
  EXPECT_FALSE(analyzeScene(sceneWith({m})).reflection);
}

}  // namespace
}  // namespace rastray
