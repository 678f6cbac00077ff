#include "common/shading.h"

#include <algorithm>
#include <cmath>

#include "common/math_constants.h"
#include "common/optics.h"

namespace rastray {

const char* toString(RayKind kind) {
  switch (kind) {
    case RayKind::Primary:
      return "primary";
    case RayKind::Shadow:
      return "shadow";
    case RayKind::Reflection:
      return "reflection";
    case RayKind::Refraction:
      return "refraction";
    case RayKind::Transparency:
      return "transparency";
  }
  return "?";
}

void LightVisibility::transmittances(int lightIndex, size_t n, const SurfacePoint* const* points,
                                     const glm::dvec3* toLight, const double* distance,
                                     glm::vec3* out) const {
  for (size_t k = 0; k < n; ++k) out[k] = transmittance(*points[k], lightIndex, toLight[k], distance[k]);
}

Shader::Shader(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
               const ShadingOptions& options, const LightVisibility* visibility,
               const SecondaryRayTracer* secondary)
    : scene_(scene),
      camera_(camera),
      options_(options),
      visibility_(visibility),
      secondary_(secondary),
      textures_(analysis.textureSet(scene)),
      eyeLight_(analysis.eyeLight) {}

Shader::Shader(const Shader& shading, const LightVisibility* visibility, const SecondaryRayTracer* secondary)
    : Shader(shading) {
  visibility_ = visibility;
  secondary_ = secondary;
}

glm::vec4 Shader::baseColor(const SurfacePoint& p, const TextureFootprint& footprint) const {
  glm::vec4 c = p.material->baseColorFactor;
  if (p.material->baseColorTexture >= 0 && !textures_->empty())
    c *= textures_->sample(p.material->baseColorTexture, p.uv, footprint, options_.textureFilter);
  return c * p.color;  // glTF: factor × texture × COLOR_0
}

glm::vec3 Shader::emission(const SurfacePoint& p, const TextureFootprint& footprint) const {
  glm::vec3 e = p.material->emissive;
  if (p.material->emissiveTexture >= 0 && !textures_->empty() && e != glm::vec3(0.0f))
    e *= glm::vec3(textures_->sample(p.material->emissiveTexture, p.uv, footprint, options_.textureFilter));
  return e;
}

Shader::SurfaceMaps Shader::surfaceMaps(const SurfacePoint& p, const TextureFootprint& footprint) const {
  const Material& m = *p.material;
  SurfaceMaps s;
  s.shadingNormal = p.shadingNormal;
  s.metallic = m.metallic;
  s.roughness = m.roughness;
  if (textures_->empty()) return s;
  if (m.metallicRoughnessTexture >= 0) {
    const glm::vec4 texel =
        textures_->sample(m.metallicRoughnessTexture, p.uv, footprint, options_.textureFilter);
    s.metallic *= texel.b;  // glTF: metalness in B, roughness in G
    s.roughness *= texel.g;
  }
  if (m.occlusionTexture >= 0) {
    const float r = textures_->sample(m.occlusionTexture, p.uv, footprint, options_.textureFilter).r;
    s.occlusion = 1.0f + m.occlusionStrength * (r - 1.0f);
  }
  if (m.normalTexture >= 0 && p.tangent != glm::dvec4(0.0)) {
    const glm::vec4 texel = textures_->sample(m.normalTexture, p.uv, footprint, options_.textureFilter);
    // glTF: normalize((2·texel − 1) ⊙ (scale, scale, 1)), in double from here.
    const glm::dvec3 local =
        glm::dvec3(2.0 * double(texel.r) - 1.0, 2.0 * double(texel.g) - 1.0, 2.0 * double(texel.b) - 1.0) *
        glm::dvec3(m.normalScale, m.normalScale, 1.0);
    const glm::dvec3 n = p.shadingNormal;
    // Gram-Schmidt: the interpolated tangent made perpendicular to n.
    const glm::dvec3 t = glm::dvec3(p.tangent) - n * glm::dot(n, glm::dvec3(p.tangent));
    const double tl = glm::length(t);
    if (tl > 0.0 && std::isfinite(tl)) {
      const glm::dvec3 tangent = t / tl;
      const glm::dvec3 bitangent = glm::cross(n, tangent) * p.tangent.w;
      const glm::dvec3 mapped = tangent * local.x + bitangent * local.y + n * local.z;
      const double ml = glm::length(mapped);
      if (ml > 0.0 && std::isfinite(ml))
        s.shadingNormal = mapped / ml;  // zero (a 0.5 grey texel and scale 0): keep n
    }
  }
  return s;
}

float Shader::coverageAlpha(const SurfacePoint& p, const TextureFootprint& footprint) const {
  if (p.material->alphaMode == AlphaMode::Opaque) return 1.0f;
  return baseColor(p, footprint).a;
}

glm::vec3 Shader::shadowTransmittance(const SurfacePoint& p) const {
  const Material& m = *p.material;
  const glm::vec4 c = baseColor(p, TextureFootprint{});
  const float alpha = m.alphaMode == AlphaMode::Blend ? c.a : 1.0f;
  return glm::vec3(1.0f - alpha) + alpha * m.transmission * glm::vec3(c);
}

glm::vec3 Shader::directLight(const SurfacePoint& p, const glm::dvec3& n, const glm::dvec3& direction,
                              const glm::vec3& albedo) const {
  if (eyeLight_) {
    // A light at the eye: no falloff, no shadows, so exposure does not
    // depend on the scene's scale.
    return albedo * float(std::abs(glm::dot(n, direction)));
  }
  glm::dvec3 sum(0.0);
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    const Light& light = scene_.lights[i];
    glm::dvec3 toLight;
    double distance, irradiance = light.intensity;
    if (light.type == LightType::Directional) {
      toLight = -light.direction;
      distance = std::numeric_limits<double>::infinity();
    } else {
      const glm::dvec3 d = light.position - p.position;
      distance = glm::length(d);
      if (!(distance > 0.0)) continue;
      toLight = d / distance;
      irradiance /= distance * distance;
      if (light.range > 0.0f) {
        // glTF's recommended range window: smooth to zero at `range`.
        const double r = distance / light.range;
        irradiance *= std::clamp(1.0 - r * r * r * r, 0.0, 1.0);
      }
      if (light.type == LightType::Spot) {
        const double cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
        const double cd = glm::dot(light.direction, -toLight);
        const double t = std::clamp((cd - cosOuter) / std::max(1e-6, cosInner - cosOuter), 0.0, 1.0);
        irradiance *= t * t;
      }
    }
    const double cosTheta = glm::dot(n, toLight);
    if (!(cosTheta > 0.0) || !(irradiance > 0.0)) continue;
    glm::dvec3 v(1.0);
    if (visibility_) v = glm::dvec3(visibility_->transmittance(p, int(i), toLight, distance));
    sum += glm::dvec3(light.color) * v * (irradiance * cosTheta);
  }
  return albedo * glm::vec3(sum * kInvPi);
}

glm::vec4 Shader::shade(const SurfacePoint& p, const glm::dvec3& direction, const TextureFootprint& footprint,
                        int depth, float throughput) const {
  const Material& m = *p.material;
  const glm::vec4 base = baseColor(p, footprint);
  const glm::vec3 c(base);
  const float alpha = m.alphaMode == AlphaMode::Blend ? base.a : 1.0f;

  // Lighting uses the side facing the viewer; refraction needs the true
  // orientation to tell entering from leaving.
  const bool entering = isEntering(direction, p.geometricNormal);
  // The maps: normal, metallic-roughness, occlusion (header).
  const SurfaceMaps maps = m.hasSurfaceMaps() ? surfaceMaps(p, footprint)
                                              : SurfaceMaps{p.shadingNormal, m.metallic, m.roughness, 1.0f};
  const glm::dvec3 facing = entering ? maps.shadingNormal : -maps.shadingNormal;
  const glm::dvec3 facingGeometric = entering ? p.geometricNormal : -p.geometricNormal;
  // An interpolated normal may point away from the viewer at silhouettes;
  // fall back to the geometric one there, so no light leaks through.
  const glm::dvec3 n = glm::dot(facing, -direction) > 0.0 ? facing : facingGeometric;

  // The weights partition unity (header): the mirror part w first, then the
  // remaining dielectric (1 − w) splits into refraction and diffuse.
  const float w = Material::mirrorWeight(maps.metallic, maps.roughness);
  const float t = (1.0f - w) * m.transmission;
  glm::vec3 L = emission(p, footprint);
  const float diffuseWeight = (1.0f - w) * (1.0f - m.transmission);
  // Occlusion scales the eye light (the stand-in for ambient light), not a
  // punctual light's direct term.
  const glm::vec3 albedo = eyeLight_ ? c * maps.occlusion : c;
  if (diffuseWeight > 0.0f) L += diffuseWeight * directLight(p, n, direction, albedo);

  const bool canTrace = secondary_ && depth < options_.maxDepth;
  if ((w > 0.0f || t > 0.0f) && canTrace) {
    const double eta = entering ? 1.0 / m.ior : m.ior;  // n_incident / n_transmitted
    const double cosI = -glm::dot(direction, n);
    const double F = t > 0.0f ? fresnelDielectric(cosI, eta) : 0.0;
    const float reflectWeight = w + t * float(F);
    const glm::dvec3 reflected = reflect(direction, n);
    if (options_.reflection && reflectWeight * throughput >= options_.minThroughput) {
      // Mirrors tint by the base colour; Fresnel reflection of glass does not.
      const glm::vec3 tint = (w * c + glm::vec3(t * float(F))) / reflectWeight;
      const float weight = reflectWeight * glm::length(tint) / std::sqrt(3.0f);
      // Reflected light is indirect: the occlusion map scales it.
      L += reflectWeight * maps.occlusion * tint *
           secondary_->radiance(p, reflected, RayKind::Reflection, depth + 1, throughput * weight);
    }
    if (options_.refraction && t > 0.0f && F < 1.0) {
      const float refractWeight = t * float(1.0 - F);
      if (refractWeight * throughput >= options_.minThroughput) {
        if (const auto refracted = refract(direction, n, eta))
          L +=
              refractWeight * c *
              secondary_->radiance(p, *refracted, RayKind::Refraction, depth + 1, throughput * refractWeight);
      }
    }
  }
  return glm::vec4(L * alpha, alpha);
}

}  // namespace rastray
