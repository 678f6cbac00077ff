// Internal to raytrace/ray_offset.cpp: the constants of the Embree margin
// (ray_offset.h, step 2) and that margin for a batch of rays in double SIMD
// lanes (ray_offset_lanes.cpp, Highway, chosen at run time).
#pragma once

#include <cstddef>

namespace rastray::detail {

constexpr double kU = 0x1p-24;  // float unit roundoff: Embree's arithmetic
// Evaluating the bounds in double: inputs are floats (their differences
// exact, or off by 2⁻⁵³), each product and sum rounds a few times more, so
// 2⁻⁴⁵ of the magnitudes involved covers it (against Embree's 2⁻²⁴).
constexpr double kEvalSlack = 0x1p-45;
// Results flushed to zero under FTZ lose less than FLT_MIN = 2⁻¹²⁶ each;
// a handful of them, scaled by at most the magnitudes R and C, stay below
// this times (1 + ΣR + ΣC).
constexpr double kUnderflow = 0x1p-118;

// Rays per batch of errorBoundRayOrigins: a multiple of every target's
// double lanes.
constexpr size_t kOriginLanes = 16;

// For each lane k, the triangle p_i = (soa[3i][k], soa[3i + 1][k],
// soa[3i + 2][k]) and the origin o = (soa[9][k], soa[10][k], soa[11][k]):
// det[k] = dot(p0 − o, N) and bound[k] = B of ray_offset.h step 2, with
// the scalar margin()'s operations in its order (bit for bit; every
// target).
void embreeMarginLanes(const double (*soa)[kOriginLanes], double* det, double* bound);

}  // namespace rastray::detail
