#include "common/optics.h"

#include <cmath>

#include <gtest/gtest.h>

namespace rastray {
namespace {

TEST(Optics, FresnelAtNormalIncidence) {
  for (double n : {1.33, 1.5, 2.4}) {
    const double expected = std::pow((n - 1.0) / (n + 1.0), 2.0);
    EXPECT_NEAR(fresnelDielectric(1.0, 1.0 / n), expected, 1e-12) << "entering, n = " << n;
    EXPECT_NEAR(fresnelDielectric(1.0, n), expected, 1e-12) << "leaving, n = " << n;
  }
}

TEST(Optics, TotalInternalReflectionAtTheCriticalAngle) {
  const double n = 1.5;
  const double critical = std::asin(1.0 / n);
  const glm::dvec3 normal(0.0, 0.0, 1.0);
  auto incidentAt = [&](double theta) { return glm::dvec3(std::sin(theta), 0.0, -std::cos(theta)); };
  // Leaving glass (eta = n): refraction just before, TIR just past.
  EXPECT_TRUE(refract(incidentAt(critical - 1e-6), normal, n).has_value());
  EXPECT_FALSE(refract(incidentAt(critical + 1e-6), normal, n).has_value());
  EXPECT_EQ(fresnelDielectric(std::cos(critical + 1e-6), n), 1.0);
  EXPECT_LT(fresnelDielectric(std::cos(critical - 1e-3), n), 1.0);
}

TEST(Optics, SnellsLawHolds) {
  const glm::dvec3 normal(0.0, 0.0, 1.0);
  for (double theta : {0.0, 0.3, 0.7, 1.2, 1.5}) {
    const glm::dvec3 in(std::sin(theta), 0.0, -std::cos(theta));
    const auto out = refract(in, normal, 1.0 / 1.5);
    ASSERT_TRUE(out.has_value());
    EXPECT_NEAR(glm::length(*out), 1.0, 1e-12);
    const double sinT = std::sqrt(out->x * out->x + out->y * out->y);
    EXPECT_NEAR(1.0 * std::sin(theta), 1.5 * sinT, 1e-12) << theta;
    EXPECT_LT(out->z, 0.0);  // continues into the surface
  }
}

TEST(Optics, ReflectanceStaysInUnitRange) {
  for (double c = 0.0; c <= 1.0; c += 0.01)
    for (double eta : {1.0 / 1.5, 1.5}) {
      const double f = fresnelDielectric(c, eta);
      EXPECT_GE(f, 0.0);
      EXPECT_LE(f, 1.0);
    }
  // Grazing incidence reflects everything.
  EXPECT_NEAR(fresnelDielectric(0.0, 1.0 / 1.5), 1.0, 1e-12);
}

TEST(Optics, ReflectMirrorsAboutTheNormal) {
  const glm::dvec3 r = reflect(glm::normalize(glm::dvec3(1.0, -1.0, 0.0)), glm::dvec3(0.0, 1.0, 0.0));
  EXPECT_NEAR(r.x, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(r.y, std::sqrt(0.5), 1e-15);
}

}  // namespace
}  // namespace rastray
