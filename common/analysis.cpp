#include "common/analysis.h"

#include <set>

namespace rastray {

const char* toString(Work work) {
  switch (work) {
    case Work::TransparencyPass:
      return "transparency pass";
    case Work::AlphaTest:
      return "alpha test";
    case Work::Shadows:
      return "shadows";
    case Work::ReflectionRays:
      return "reflection rays";
    case Work::RefractionRays:
      return "refraction rays";
    case Work::Textures:
      return "textures";
  }
  return "?";
}

bool SceneAnalysis::needs(Work work) const {
  for (const WorkDecision& d : decisions)
    if (d.work == work) return d.needed;
  return false;
}

std::shared_ptr<const TextureSet> SceneAnalysis::textureSet(const Scene& scene) const {
  if (!textures) return std::make_shared<const TextureSet>();
  return sharedTextures ? sharedTextures->get(scene) : std::make_shared<const TextureSet>(scene);
}

namespace {

// Materials (and the instances using them) that satisfy a predicate; only
// instances with at least one triangle count, so an unused material never
// switches work on.
template <typename Pred>
WorkDecision decide(const Scene& scene, Work work, const std::string& what, Pred pred) {
  std::set<uint32_t> materials;
  size_t instances = 0;
  for (const Instance& inst : scene.instances) {
    if (inst.triangleCount == 0 || !pred(scene.materials[inst.material])) continue;
    materials.insert(inst.material);
    ++instances;
  }
  WorkDecision d{work, !materials.empty(), {}};
  if (d.needed)
    d.reason = std::to_string(materials.size()) + " " + what + " material" +
               (materials.size() == 1 ? "" : "s") + " on " + std::to_string(instances) + " instance" +
               (instances == 1 ? "" : "s");
  else
    d.reason = "no " + what + " material";
  return d;
}

}  // namespace

SceneAnalysis analyzeScene(const Scene& scene) {
  SceneAnalysis a;
  a.decisions.push_back(decide(scene, Work::TransparencyPass, "BLEND",
                               [](const Material& m) { return m.alphaMode == AlphaMode::Blend; }));
  a.decisions.push_back(decide(scene, Work::AlphaTest, "MASK",
                               [](const Material& m) { return m.alphaMode == AlphaMode::Mask; }));

  WorkDecision shadows{Work::Shadows, !scene.lights.empty(), {}};
  shadows.reason = shadows.needed ? std::to_string(scene.lights.size()) + " punctual light" +
                                        (scene.lights.size() == 1 ? "" : "s")
                                  : "no light: eye light at the camera, no shadows";
  a.decisions.push_back(shadows);

  a.decisions.push_back(
      decide(scene, Work::ReflectionRays, "reflective", [](const Material& m) { return m.isReflective(); }));
  a.decisions.push_back(
      decide(scene, Work::RefractionRays, "refractive", [](const Material& m) { return m.isRefractive(); }));
  a.decisions.push_back(
      decide(scene, Work::Textures, "textured", [](const Material& m) { return m.isTextured(); }));

  a.transparency = a.needs(Work::TransparencyPass);
  a.alphaTest = a.needs(Work::AlphaTest);
  a.shadows = a.needs(Work::Shadows);
  a.reflection = a.needs(Work::ReflectionRays);
  a.refraction = a.needs(Work::RefractionRays);
  a.textures = a.needs(Work::Textures);
  a.eyeLight = scene.lights.empty();
  return a;
}

}  // namespace rastray
