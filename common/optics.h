// Reflection, Snell refraction and the exact dielectric Fresnel equations
// (SPEC §5), as pure functions on unit vectors.
//
// Conventions: `incident` points along the travelling ray (towards the
// surface); `normal` is unit length and faces the side the ray comes from
// (dot(incident, normal) <= 0). eta = n_incident / n_transmitted: eta > 1
// means the ray leaves the denser medium (total internal reflection is
// possible); eta < 1 means it enters it.
#pragma once

#include <optional>

#include <glm/glm.hpp>

namespace rastray {

inline glm::dvec3 reflect(const glm::dvec3& incident, const glm::dvec3& normal) {
  return incident - 2.0 * glm::dot(incident, normal) * normal;
}

// Refracted direction by Snell's law (unit), or nothing on total internal
// reflection (sin²θt > 1).
std::optional<glm::dvec3> refract(const glm::dvec3& incident, const glm::dvec3& normal, double eta);

// Fraction of light reflected at a smooth dielectric boundary, unpolarised:
// the mean of the s and p Fresnel reflectances; 1 on total internal
// reflection. cosIncident = −dot(incident, normal) ∈ [0, 1]. Reflectance +
// transmittance = 1 by construction; at normal incidence it equals
// ((n1 − n2)/(n1 + n2))².
double fresnelDielectric(double cosIncident, double eta);

// The side a ray hits a triangle from, by the triangle's stored (CCW =
// front) orientation: entering a closed refractive mesh through its front.
inline bool isEntering(const glm::dvec3& direction, const glm::dvec3& geometricNormal) {
  return glm::dot(direction, geometricNormal) < 0.0;
}

}  // namespace rastray
