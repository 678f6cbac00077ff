// The one shading model both renderers use (SPEC §5).
//
// For a surface point seen along direction d, with base colour C (factor ×
// sRGB-decoded texture × interpolated COLOR_0), emissive = emissive factor
// × strength × sRGB-decoded emissive texture, mirror weight
// w = metallic·(1 − roughness) and transmission t, the outgoing radiance is
//
//   L = emissive + (1 − w)(1 − t) · C/π · Σ_lights E_l · V_l · max(0, n·l)
//       + w · C · L_reflect
//       + (1 − w) t · (F · L_reflect + (1 − F) · C · L_refract)
//
// The three weights (1 − w)(1 − t), w and (1 − w)t sum to exactly 1, so a
// white surface in a white surround (a furnace) returns at most what
// arrives: the mirror (metal) part w comes first, as metals do not
// transmit, and the remaining dielectric part (1 − w) splits into
// refraction t and diffuse 1 − t (glTF's mix of the metal and dielectric
// lobes, with transmission inside the dielectric one).
//
// F is the exact dielectric Fresnel reflectance (common/optics.h), E_l
// the light's irradiance (point and spot: intensity / distance², with
// glTF's range window and spot cone falloff; directional: intensity) and
// V_l the light's transmittance from the renderer (shadow rays or shadow
// maps). Without lights, an eye light at the camera replaces the sum with
// C · |n·d| and casts no shadows. Rough metals are treated as Lambertian in
// C (only the mirror part reflects), so glTF's default material
// (metallic 1, roughness 1) renders white, not black.
//
// The maps (docs/MATERIALS.md), all per hit through the same footprint as
// the base colour: a normal map replaces n by the tangent-space normal
// (2·RGB − 1, x and y × scale) in the frame (T, cross(n, T)·w, n); a
// metallic-roughness map multiplies metallic by B and roughness by G
// before w is formed; an occlusion map's factor
// ao = 1 + strength·(R − 1) scales the light that stands for indirect
// light — the eye light's term and the reflected radiance L_reflect (w and
// Fresnel parts) — and never a punctual light's direct term, emission or
// refraction (glTF: occlusion applies to indirect lighting only).
//
// A surface's layer colour is premultiplied: (L·α, α), with α the base
// colour alpha for BLEND materials and 1 otherwise; MASK coverage is the
// renderer's decision (alpha >= cutoff), made with `coverageAlpha`.
#pragma once

#include <glm/glm.hpp>
#include <memory>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/scene.h"
#include "common/surface.h"
#include "common/texture.h"

namespace rastray {

enum class RayKind { Primary, Shadow, Reflection, Refraction, Transparency };
constexpr int kRayKindCount = 5;
const char* toString(RayKind kind);

// What shading asks a renderer about light visibility. Implemented with
// shadow rays by the ray caster and with shadow maps by the rasterizer.
class LightVisibility {
 public:
  virtual ~LightVisibility() = default;
  // Per-channel fraction of the light arriving at `point` (1: unoccluded;
  // BLEND occluders pass 1 − α, refractive ones transmission × C).
  // `toLight` is unit, `distance` the distance to the light (+inf for
  // directional lights).
  virtual glm::vec3 transmittance(const SurfacePoint& point, int lightIndex, const glm::dvec3& toLight,
                                  double distance) const = 0;
  // The same for n points of one light: out[k] = transmittance(*points[k],
  // lightIndex, toLight[k], distance[k]), bit for bit, each as if asked
  // alone (whatever else is in the batch), asked in order k = 0, 1, ….
  // The shading kernel calls it once per light with the lanes it lights.
  // This default asks one at a time; the ray caster traces the first
  // occlusion query of up to 14 rays as one packet (rtcOccluded16).
  virtual void transmittances(int lightIndex, size_t n, const SurfacePoint* const* points,
                              const glm::dvec3* toLight, const double* distance, glm::vec3* out) const;
};

// Radiance along secondary rays: implemented by the ray caster, and used by
// the rasterizer's shading in hybrid mode (SPEC: hybrid = rasterized
// primary visibility + traced secondary rays).
class SecondaryRayTracer {
 public:
  virtual ~SecondaryRayTracer() = default;
  // Radiance (linear RGB) arriving at `from` along unit `direction`,
  // composited front to back through transparent layers; black when the
  // ray leaves the scene. `depth` is the new ray's depth (primary = 0),
  // `throughput` the weight this radiance will be multiplied by.
  virtual glm::vec3 radiance(const SurfacePoint& from, const glm::dvec3& direction, RayKind kind, int depth,
                             float throughput) const = 0;
};

struct ShadingOptions {
  int maxDepth = 8;             // secondary rays deeper than this return black
  float minThroughput = 1e-3f;  // secondary rays with less weight are not traced
  // false: no reflection (mirror or Fresnel) or no refraction ray is traced,
  // at any depth; its part of the colour is black, as with maxDepth 0
  // (--no-reflection, --no-refraction: to see what each contributes).
  bool reflection = true;
  bool refraction = true;
  TextureFilter textureFilter = TextureFilter::Sampler;
  // true: both renderers shade every primary hit with the scalar double
  // Shader::shade (ShadingPath::Reference, common/shading_kernel.h)
  // instead of the float SIMD kernel: the reference the kernel's error
  // bound is stated against.
  bool referenceShading = false;
};

class Shader {
 public:
  // `visibility` may be null (everything lit); `secondary` may be null
  // (mirrors and glass then see black: the pure rasterizer has no rays).
  Shader(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
         const ShadingOptions& options, const LightVisibility* visibility,
         const SecondaryRayTracer* secondary);
  // The same shading (scene, camera, options, and the decoded textures,
  // shared) calling back into other visibility and secondary-ray objects:
  // how a renderer shades one traced pixel through callbacks that record
  // its rays, while its other pixels keep the first Shader.
  Shader(const Shader& shading, const LightVisibility* visibility, const SecondaryRayTracer* secondary);

  // Straight linear RGBA base colour (factor × texture × COLOR_0) at a point.
  glm::vec4 baseColor(const SurfacePoint& point, const TextureFootprint& footprint) const;
  // Emitted linear RGB (emissive × emissive texture) at a point; the
  // texture is filtered through the same footprint as the base colour's.
  glm::vec3 emission(const SurfacePoint& point, const TextureFootprint& footprint) const;
  // The material's maps at a point (docs/MATERIALS.md): the shading normal
  // (normal map), metallic and roughness (factor × texel) and the
  // occlusion factor; the plain material's values where it has no maps.
  struct SurfaceMaps {
    glm::dvec3 shadingNormal{0.0, 0.0, 1.0};
    float metallic = 0.0f, roughness = 1.0f;
    float occlusion = 1.0f;
  };
  SurfaceMaps surfaceMaps(const SurfacePoint& point, const TextureFootprint& footprint) const;
  // The alpha a renderer uses for MASK and BLEND coverage decisions.
  float coverageAlpha(const SurfacePoint& point, const TextureFootprint& footprint) const;

  // Premultiplied RGBA of the surface seen along `direction` (unit, from
  // the viewer towards the point), at ray depth `depth`.
  glm::vec4 shade(const SurfacePoint& point, const glm::dvec3& direction, const TextureFootprint& footprint,
                  int depth = 0, float throughput = 1.0f) const;

  // Light transmitted through a surface by a shadow ray (SPEC §5): 0 for
  // opaque and MASK-covered points, 1 − α for BLEND, transmission × C for
  // refractive ones.
  glm::vec3 shadowTransmittance(const SurfacePoint& point) const;

  const TextureSet& textures() const { return *textures_; }
  const ShadingOptions& options() const { return options_; }
  // What the shading kernel (common/shading_kernel.h) reads of this Shader.
  const Scene& scene() const { return scene_; }
  const Camera& camera() const { return camera_; }
  const LightVisibility* visibility() const { return visibility_; }
  const SecondaryRayTracer* secondary() const { return secondary_; }
  bool eyeLight() const { return eyeLight_; }

 private:
  glm::vec3 directLight(const SurfacePoint& p, const glm::dvec3& n, const glm::dvec3& direction,
                        const glm::vec3& albedo) const;

  const Scene& scene_;
  const Camera& camera_;
  ShadingOptions options_;
  const LightVisibility* visibility_;
  const SecondaryRayTracer* secondary_;
  std::shared_ptr<const TextureSet> textures_;  // never null; shared by the copies above
  bool eyeLight_;
};

}  // namespace rastray
