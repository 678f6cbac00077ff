#include "common/optics.h"

#include <algorithm>
#include <cmath>

namespace rastray {

std::optional<glm::dvec3> refract(const glm::dvec3& incident, const glm::dvec3& normal, double eta) {
  const double cosI = std::clamp(-glm::dot(incident, normal), 0.0, 1.0);
  const double sin2T = eta * eta * std::max(0.0, 1.0 - cosI * cosI);
  if (sin2T > 1.0) return std::nullopt;  // total internal reflection
  const double cosT = std::sqrt(1.0 - sin2T);
  return glm::normalize(eta * incident + (eta * cosI - cosT) * normal);
}

double fresnelDielectric(double cosIncident, double eta) {
  const double cosI = std::clamp(cosIncident, 0.0, 1.0);
  const double sin2T = eta * eta * std::max(0.0, 1.0 - cosI * cosI);
  if (sin2T >= 1.0) return 1.0;
  const double cosT = std::sqrt(1.0 - sin2T);
  // With n1 = eta·n2: rs = (n1 cosI − n2 cosT)/(n1 cosI + n2 cosT), etc.
  const double rs = (eta * cosI - cosT) / (eta * cosI + cosT);
  const double rp = (cosI - eta * cosT) / (cosI + eta * cosT);
  return 0.5 * (rs * rs + rp * rp);
}

}  // namespace rastray
