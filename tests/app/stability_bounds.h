// The bounds the stability tests hold each row to, written in the tests:
// the study's own verdict (Row::pass) is checked too, but a threshold
// loosened in app/studies/ no longer loosens the test with it.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "app/studies/stability.h"

namespace rastray::stability::test {

// "case / variant", for failure messages.
inline std::string where(const Row& r) { return r.caseName + " / " + r.variant; }

// Row::measures[name]; a failure (and NaN) when the study did not record it.
inline double measure(const Row& r, const std::string& name) {
  const auto it = r.measures.find(name);
  if (it == r.measures.end()) {
    ADD_FAILURE() << where(r) << ": no measure \"" << name << "\"";
    return NAN;
  }
  return it->second;
}

// Whether the row's variant starts with `prefix` ("raster", "hybrid 4 spp").
inline bool isVariant(const Row& r, const std::string& prefix) { return r.variant.rfind(prefix, 0) == 0; }

// Every row: no NaN or Inf in colour, depth or deep samples.
inline void expectFinite(const Row& r) { EXPECT_EQ(r.nanInf, 0u) << where(r); }

// Visibility measured against the reference, and no genuine mismatch.
inline void expectNoGenuine(const Row& r) {
  EXPECT_EQ(r.genuine, 0) << where(r) << ": agreement " << r.agreement;
}

// Shadow maps and shadow rays against the double-precision reference:
// no leak, acne on at most `acneShare` of the samples checked, and enough
// samples checked to mean something.
inline void expectShadowBound(const Row& r, double acneShare = 1e-3) {
  const double checked = measure(r, "shadow samples checked");
  EXPECT_GT(checked, 100.0) << where(r);
  EXPECT_EQ(r.leaks, 0) << where(r) << " of " << checked;
  EXPECT_LE(double(r.acne), acneShare * checked) << where(r) << " of " << checked;
}

// Runs `bounds` on every row, then checks that the study agrees (its
// property stated and held).
inline void expectRows(const std::vector<Row>& rows, const std::function<void(const Row&)>& bounds) {
  ASSERT_FALSE(rows.empty());
  for (const Row& r : rows) {
    expectFinite(r);
    bounds(r);
    EXPECT_TRUE(r.pass) << where(r) << ": " << r.property << " (" << r.metricName << " = " << r.metric
                        << ", genuine " << r.genuine << ", acne " << r.acne << ", leaks " << r.leaks << ")";
  }
}

}  // namespace rastray::stability::test
