// Reflection, Snell refraction, exact Fresnel and total internal
// reflection: the functions of common/optics.h alone (the ray caster's use
// of them is tested in tests/raytrace/optics_test.cpp).
#include "common/optics.h"

#include <cmath>

#include <gtest/gtest.h>

namespace rastray {
namespace {

// Fresnel transmittance computed independently from the reflectance
// (the amplitude transmission coefficients with the power factor
// n2 cosθt / n1 cosθi), so R + T = 1 is a real check.
double fresnelTransmittance(double cosI, double eta) {
  const double sin2T = eta * eta * (1.0 - cosI * cosI);
  if (sin2T >= 1.0) return 0.0;
  const double cosT = std::sqrt(1.0 - sin2T);
  // n1 = eta, n2 = 1.
  const double ts = 2.0 * eta * cosI / (eta * cosI + cosT);
  const double tp = 2.0 * eta * cosI / (cosI + eta * cosT);
  const double factor = cosT / (eta * cosI);
  return 0.5 * factor * (ts * ts + tp * tp);
}

TEST(Optics, FresnelAtNormalIncidenceMatchesClosedForm) {
  for (double n : {1.33, 1.5, 2.4}) {
    const double expected = ((n - 1.0) / (n + 1.0)) * ((n - 1.0) / (n + 1.0));
    EXPECT_NEAR(fresnelDielectric(1.0, 1.0 / n), expected, 1e-15) << "entering n " << n;
    EXPECT_NEAR(fresnelDielectric(1.0, n), expected, 1e-15) << "leaving n " << n;
  }
}

TEST(Optics, ReflectanceAndTransmittanceSumToOne) {
  for (double eta : {1.0 / 1.5, 1.5, 1.0 / 2.4})
    for (int i = 0; i <= 100; ++i) {
      const double cosI = i / 100.0;
      const double R = fresnelDielectric(cosI, eta);
      const double T = fresnelTransmittance(cosI, eta);
      ASSERT_GE(R, 0.0);
      ASSERT_LE(R, 1.0);
      if (cosI > 0.0) {
        EXPECT_NEAR(R + T, 1.0, 1e-12) << "eta " << eta << " cosI " << cosI;
      }
    }
  // Grazing incidence reflects everything.
  EXPECT_NEAR(fresnelDielectric(0.0, 1.0 / 1.5), 1.0, 1e-12);
}

TEST(Optics, TotalInternalReflectionJustPastTheCriticalAngle) {
  const double eta = 1.5;  // leaving glass
  const double critical = std::asin(1.0 / eta);
  const glm::dvec3 n(0.0, 0.0, 1.0);
  for (double delta : {1e-6, 1e-3, 0.01}) {
    const double past = critical + delta, before = critical - delta;
    const glm::dvec3 dPast(std::sin(past), 0.0, -std::cos(past));
    const glm::dvec3 dBefore(std::sin(before), 0.0, -std::cos(before));
    EXPECT_FALSE(refract(dPast, n, eta).has_value()) << "delta " << delta;
    EXPECT_EQ(fresnelDielectric(std::cos(past), eta), 1.0);
    const auto t = refract(dBefore, n, eta);
    ASSERT_TRUE(t.has_value()) << "delta " << delta;
    EXPECT_LT(fresnelDielectric(std::cos(before), eta), 1.0);
    // Snell: n1 sinθi = n2 sinθt, with the refracted ray on the far side.
    EXPECT_NEAR(std::sqrt(t->x * t->x + t->y * t->y), eta * std::sin(before), 1e-9);
    EXPECT_LT(t->z, 0.0);
  }
}

TEST(Optics, SnellsLawHoldsEnteringGlass) {
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

TEST(Optics, ReflectMirrorsAboutTheNormal) {
  const glm::dvec3 r = reflect(glm::normalize(glm::dvec3(1.0, -1.0, 0.0)), glm::dvec3(0.0, 1.0, 0.0));
  EXPECT_NEAR(r.x, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(r.y, std::sqrt(0.5), 1e-15);
}

}  // namespace
}  // namespace rastray
