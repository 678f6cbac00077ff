// Scene analysis (SPEC §8): before rendering, decide which passes and ray
// kinds a scene needs, from the materials, lights and textures its
// instances actually use. Renderers skip what is not needed, and their
// work counters show zero for it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "common/scene.h"
#include "common/texture.h"

namespace rastray {

enum class Work {
  TransparencyPass,  // BLEND surfaces: second raster pass, fragment lists, continuation rays
  AlphaTest,         // MASK surfaces: alpha-tested coverage, Embree filter callbacks
  Shadows,           // punctual lights: shadow rays or shadow maps
  ReflectionRays,    // mirror-reflective materials
  RefractionRays,    // transmissive dielectrics
  Textures,          // base colour and emissive textures: decoding and mip chains
};

const char* toString(Work work);

struct WorkDecision {
  Work work;
  bool needed = false;
  std::string reason;  // e.g. "2 BLEND materials on 3 instances" or "no BLEND material"
};

struct SceneAnalysis {
  bool transparency = false;
  bool alphaTest = false;
  bool shadows = false;
  bool reflection = false;
  bool refraction = false;
  bool textures = false;
  bool eyeLight = false;                // no light in the scene: lit from the camera, no shadows
  std::vector<WorkDecision> decisions;  // one per Work, in enum order
  std::shared_ptr<SharedTextureSet> sharedTextures = std::make_shared<SharedTextureSet>();

  // The decoded textures and mip chains of `scene` (the analysed scene),
  // built on the first call and shared by every copy of this analysis;
  // empty when the scene needs no textures.
  std::shared_ptr<const TextureSet> textureSet(const Scene& scene) const;

  bool secondaryRays() const { return reflection || refraction; }
  // Embree needs intersection/occlusion filters only for these.
  bool needsRayFilters() const { return alphaTest || transparency || refraction; }
  bool needs(Work work) const;
};

SceneAnalysis analyzeScene(const Scene& scene);

}  // namespace rastray
