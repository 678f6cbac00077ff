// The primary-hit shading kernel (shading_kernel.h). Highway compiles the
// lane functions below once per SIMD target (foreach_target.h re-includes
// this file); the host code at the end gathers hits into blocks of lanes,
// runs the lanes through HWY_DYNAMIC_DISPATCH and scatters the colours.
// Built with -ffp-contract=off (common/CMakeLists.txt): see the header's
// invariants.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "common/shading_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <cstddef>
#include <limits>

#include <hwy/highway.h>

#include "common/primary_refinement-inl.h"
#include "common/run_lanes-inl.h"
#include "common/shading_kernel.h"

#ifndef RASTRAY_SHADING_KERNEL_LANES
#define RASTRAY_SHADING_KERNEL_LANES
namespace rastray {
namespace kernel_detail {

// Lanes per block: a multiple of every target's float lane count (4, 8, 16),
// so a block is whole vectors; a partial block is padded (padLanes).
constexpr size_t kBlock = 64;
// Lights the two-pass lanes (LanesSurfaceLights) take; more take the
// separate passes.
constexpr size_t kTwoPassLights = 4;

// One block of lanes, struct of arrays. Filled by the host (gather), read
// and written by the lane functions.
struct LaneBlock {
  size_t used = 0;   // lanes holding a hit
  size_t lanes = 0;  // used rounded up to whole vectors of the running target: what the lanes run over
  size_t runs = 0;   // entries of the per-run table below
  // Inputs, per lane.
  alignas(64) int32_t run[kBlock];                                 // the lane's run; non-decreasing
  alignas(64) int64_t run64[kBlock];                               // the same, for double lanes
  alignas(64) double dirXd[kBlock], dirYd[kBlock], dirZd[kBlock];  // primary ray direction (unit)
  alignas(64) float b1[kBlock], b2[kBlock];                        // refined barycentrics
  // Per lane, from the above in double lanes (LanesSurface).
  alignas(64) float dirX[kBlock], dirY[kBlock], dirZ[kBlock];  // the direction, rounded
  alignas(64) float side[kBlock];  // +1 entering (d·ng < 0, in double), else −1
  alignas(64) float b0[kBlock];    // b0 = 1 − b1 − b2 in double, rounded
  alignas(64) double posX[kBlock], posY[kBlock],
      posZ[kBlock];  // b0·p0 + b1·p1 + b2·p2 (not with the eye light)
  alignas(64) float albedoR[kBlock], albedoG[kBlock], albedoB[kBlock];  // base colour RGB (scalar, as Shader)
  alignas(64) float emitR[kBlock], emitG[kBlock], emitB[kBlock];        // emission (scalar, as Shader)
  // Inputs, per run of lanes on one triangle (indexed by `run`): stored
  // once, read as a broadcast by a vector of lanes on one run, else
  // gathered (RunLanes, common/run_lanes-inl.h).
  alignas(64) float ngX[kBlock], ngY[kBlock], ngZ[kBlock];  // face normal (double, memoised), rounded
  alignas(64) float authored[kBlock];  // 1: interpolate the corner normals below, 0: the face normal
  alignas(64) float n0X[kBlock], n0Y[kBlock], n0Z[kBlock];
  alignas(64) float n1X[kBlock], n1Y[kBlock], n1Z[kBlock];
  alignas(64) float n2X[kBlock], n2Y[kBlock], n2Z[kBlock];
  alignas(64) float diffuseWeight[kBlock];  // (1 − w)(1 − t)
  // The material's base colour, emission and alpha (BLEND: base alpha;
  // else 1), read by every lane while `colourPerLane` is false (no lane
  // of the block needs its own: no texture, vertex colour or visibility
  // callback), else the per-lane values above are.
  alignas(64) float runAlbedoR[kBlock], runAlbedoG[kBlock], runAlbedoB[kBlock];
  alignas(64) float runEmitR[kBlock], runEmitG[kBlock], runEmitB[kBlock];
  alignas(64) float runAlpha[kBlock];
  bool colourPerLane = false;
  // Per run, in double: the face normal (memoised) and the corner positions.
  alignas(64) double ngXd[kBlock], ngYd[kBlock], ngZd[kBlock];
  alignas(64) double p0X[kBlock], p0Y[kBlock], p0Z[kBlock];
  alignas(64) double p1X[kBlock], p1Y[kBlock], p1Z[kBlock];
  alignas(64) double p2X[kBlock], p2Y[kBlock], p2Z[kBlock];
  // Per lane again.
  alignas(64) float alpha[kBlock];  // BLEND: base alpha; else 1
  // Per light, refilled for each light: light − position (the vector to the
  // light) in double, rounded.
  alignas(64) float toLightX[kBlock], toLightY[kBlock], toLightZ[kBlock];
  // The same for each of the first kTwoPassLights lights at once
  // (LanesSurfaceLights).
  alignas(64) float lightX[kTwoPassLights][kBlock], lightY[kTwoPassLights][kBlock],
      lightZ[kTwoPassLights][kBlock];
  // Per light: E·cosθ where the light reaches the lane (else 0), then the
  // host's transmittance V per channel.
  alignas(64) float weight[kBlock];
  alignas(64) float visR[kBlock], visG[kBlock], visB[kBlock];
  // Intermediate: the lighting normal, the Lambert sum.
  alignas(64) float nX[kBlock], nY[kBlock], nZ[kBlock];
  alignas(64) float sumR[kBlock], sumG[kBlock], sumB[kBlock];
  // Output: premultiplied RGBA.
  alignas(64) float outR[kBlock], outG[kBlock], outB[kBlock], outA[kBlock];
};

// A light's uniform parameters, in float (computed in double, rounded).
struct LaneLight {
  int type;  // 0 point, 1 spot, 2 directional
  float colorR, colorG, colorB;
  float intensity;
  float range;                // 0: none
  float spotX, spotY, spotZ;  // the way light travels (spot)
  float cosOuter;             // spot: t = (cd − cosOuter) / coneDenominator
  float coneDenominator;      // max(1e-6, cos inner − cos outer)
  float dirX, dirY, dirZ;     // directional: unit, towards the light
  double posX, posY, posZ;    // point, spot: the light's position (LanesToLight's operand)
};

// Where the two-pass lanes (LanesSurfaceLights, LanesLightsFinish) read each lane's inputs: the
// block's own arrays, or a PrimaryHitBlock's in place. Every array holds
// the block's `lanes` entries (padding included).
struct LaneInputs {
  const int32_t* run;    // per lane: its entry in the block's run tables
  const int64_t* run64;  // the same, for double lanes
  const double *dirX, *dirY, *dirZ;
  const float *b1, *b2;
};

// Batched refinement (primary_refinement.h): one block of lanes in double.
constexpr size_t kRefineBlock = 64;  // a multiple of every target's double lane count (2, 4, 8)
struct RefineBlock {
  size_t lanes = 0;  // used lanes rounded up to whole vectors (padded with a harmless plane)
  alignas(64) double ax[kRefineBlock], ay[kRefineBlock], az[kRefineBlock];  // canonical first corner
  alignas(64) double e1x[kRefineBlock], e1y[kRefineBlock], e1z[kRefineBlock];
  alignas(64) double e2x[kRefineBlock], e2y[kRefineBlock], e2z[kRefineBlock];
  // Where stored corners 1 and 2 rank canonically: slot 0 weighs 1 − u − w, 1 u, 2 w.
  alignas(64) double slot1[kRefineBlock], slot2[kRefineBlock];
  alignas(64) double ox[kRefineBlock], oy[kRefineBlock], oz[kRefineBlock];
  alignas(64) double dx[kRefineBlock], dy[kRefineBlock], dz[kRefineBlock];
  alignas(64) double depthPerT[kRefineBlock];
  // Out: the clamped barycentrics, and 1 where they replace the hit's.
  alignas(64) double b1[kRefineBlock], b2[kRefineBlock], refined[kRefineBlock];
};

}  // namespace kernel_detail
}  // namespace rastray
#endif

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using kernel_detail::LaneBlock;
using kernel_detail::LaneInputs;
using kernel_detail::LaneLight;

// Lanes per vector of the running target.
size_t KernelLanes() { return hn::Lanes(hn::ScalableTag<float>()); }

// The lanes' double-precision inputs, as Shader::shade and makeSurfacePoint
// compute them per hit: the entering side (glm::dot(d, ng) < 0, (x + y) +
// z), b0 = (1 − b1) − b2, the surface position (b0·p0 + b1·p1) + b2·p2 per
// component (with `positions`), and the direction rounded to float.
void LanesSurface(LaneBlock* b, bool positions) {
  const hn::ScalableTag<double> d;
  const hn::Rebind<float, decltype(d)> df;
  const size_t N = hn::Lanes(d);
  const auto zero = hn::Zero(d), one = hn::Set(d, 1.0), minusOne = hn::Set(d, -1.0);
  for (size_t i = 0; i < b->lanes; i += N) {
    const RunLanes<decltype(d)> get(d, b->run64, i);
    const auto dx = hn::Load(d, b->dirXd + i), dy = hn::Load(d, b->dirYd + i), dz = hn::Load(d, b->dirZd + i);
    const auto dot =
        hn::Add(hn::Add(hn::Mul(dx, get(b->ngXd)), hn::Mul(dy, get(b->ngYd))), hn::Mul(dz, get(b->ngZd)));
    hn::Store(hn::DemoteTo(df, hn::IfThenElse(hn::Lt(dot, zero), one, minusOne)), df, b->side + i);
    hn::Store(hn::DemoteTo(df, dx), df, b->dirX + i);
    hn::Store(hn::DemoteTo(df, dy), df, b->dirY + i);
    hn::Store(hn::DemoteTo(df, dz), df, b->dirZ + i);
    const auto b1 = hn::PromoteTo(d, hn::Load(df, b->b1 + i)), b2 = hn::PromoteTo(d, hn::Load(df, b->b2 + i));
    const auto b0 = hn::Sub(hn::Sub(one, b1), b2);
    hn::Store(hn::DemoteTo(df, b0), df, b->b0 + i);
    if (!positions) continue;
    const auto corner = [&](const double* p0, const double* p1, const double* p2, double* out) {
      hn::Store(hn::Add(hn::Add(hn::Mul(b0, get(p0)), hn::Mul(b1, get(p1))), hn::Mul(b2, get(p2))), d,
                out + i);
    };
    corner(b->p0X, b->p1X, b->p2X, b->posX);
    corner(b->p0Y, b->p1Y, b->p2Y, b->posY);
    corner(b->p0Z, b->p1Z, b->p2Z, b->posZ);
  }
}

// toLight = light − position per lane, in double, rounded once to float.
void LanesToLight(LaneBlock* b, double lightX, double lightY, double lightZ) {
  const hn::ScalableTag<double> d;
  const hn::Rebind<float, decltype(d)> df;
  const size_t N = hn::Lanes(d);
  const auto lx = hn::Set(d, lightX), ly = hn::Set(d, lightY), lz = hn::Set(d, lightZ);
  for (size_t i = 0; i < b->lanes; i += N) {
    hn::Store(hn::DemoteTo(df, hn::Sub(lx, hn::Load(d, b->posX + i))), df, b->toLightX + i);
    hn::Store(hn::DemoteTo(df, hn::Sub(ly, hn::Load(d, b->posY + i))), df, b->toLightY + i);
    hn::Store(hn::DemoteTo(df, hn::Sub(lz, hn::Load(d, b->posZ + i))), df, b->toLightZ + i);
  }
}

// The lighting normal of each lane (Shader::shade's n): the shading
// normal (authored, interpolated and normalised; else the face normal) on
// the viewer's side, or the face normal's when that one faces away.
// The lighting normal of lanes i.. (Shader::shade's n) from their
// barycentrics: the authored normal interpolated and normalised (else the
// face normal), on the viewer's side, or the face normal's when that one
// faces away. One function for both lane paths: their bits must agree.
template <class D, class Get>
HWY_INLINE void FacingNormal(D d, const LaneBlock* b, const Get& get, size_t i, hn::Vec<D> b0, hn::Vec<D> b1,
                             hn::Vec<D> b2, hn::Vec<D> dx, hn::Vec<D> dy, hn::Vec<D> dz, hn::Vec<D>* nx,
                             hn::Vec<D>* ny, hn::Vec<D>* nz) {
  const auto zero = hn::Zero(d);
  const auto inf = hn::Set(d, std::numeric_limits<float>::infinity());
  const auto sx =
      hn::Add(hn::Add(hn::Mul(b0, get(b->n0X)), hn::Mul(b1, get(b->n1X))), hn::Mul(b2, get(b->n2X)));
  const auto sy =
      hn::Add(hn::Add(hn::Mul(b0, get(b->n0Y)), hn::Mul(b1, get(b->n1Y))), hn::Mul(b2, get(b->n2Y)));
  const auto sz =
      hn::Add(hn::Add(hn::Mul(b0, get(b->n0Z)), hn::Mul(b1, get(b->n1Z))), hn::Mul(b2, get(b->n2Z)));
  const auto length = hn::Sqrt(hn::Add(hn::Add(hn::Mul(sx, sx), hn::Mul(sy, sy)), hn::Mul(sz, sz)));
  const auto gx = get(b->ngX), gy = get(b->ngY), gz = get(b->ngZ);
  // A zero (or overflowing) interpolated normal keeps the face normal.
  const auto useAuthored =
      hn::And(hn::Gt(get(b->authored), zero), hn::And(hn::Gt(length, zero), hn::Lt(length, inf)));
  const auto side = hn::Load(d, b->side + i);
  const auto fx = hn::Mul(side, hn::IfThenElse(useAuthored, hn::Div(sx, length), gx));
  const auto fy = hn::Mul(side, hn::IfThenElse(useAuthored, hn::Div(sy, length), gy));
  const auto fz = hn::Mul(side, hn::IfThenElse(useAuthored, hn::Div(sz, length), gz));
  // facing·(−d) > 0, written as facing·d < 0 (negation is exact).
  const auto facingDot = hn::Add(hn::Add(hn::Mul(fx, dx), hn::Mul(fy, dy)), hn::Mul(fz, dz));
  const auto faces = hn::Lt(facingDot, zero);
  *nx = hn::IfThenElse(faces, fx, hn::Mul(side, gx));
  *ny = hn::IfThenElse(faces, fy, hn::Mul(side, gy));
  *nz = hn::IfThenElse(faces, fz, hn::Mul(side, gz));
}

// Clears the Lambert sum; with the eye light, sets it to |n·d|.
void LanesNormals(LaneBlock* b, bool eyeLight) {
  const hn::ScalableTag<float> d;
  const size_t N = hn::Lanes(d);
  const auto zero = hn::Zero(d);
  for (size_t i = 0; i < b->lanes; i += N) {
    const RunLanes<decltype(d)> get(d, b->run, i);  // per-run values (common/run_lanes-inl.h)
    const auto dx = hn::Load(d, b->dirX + i), dy = hn::Load(d, b->dirY + i), dz = hn::Load(d, b->dirZ + i);
    hn::Vec<decltype(d)> nx, ny, nz;
    FacingNormal(d, b, get, i, hn::Load(d, b->b0 + i), hn::Load(d, b->b1 + i), hn::Load(d, b->b2 + i), dx, dy,
                 dz, &nx, &ny, &nz);
    hn::Store(nx, d, b->nX + i);
    hn::Store(ny, d, b->nY + i);
    hn::Store(nz, d, b->nZ + i);
    if (eyeLight) {
      // A light at the eye: albedo·|n·d|, no falloff, no shadows.
      const auto cosine = hn::Abs(hn::Add(hn::Add(hn::Mul(nx, dx), hn::Mul(ny, dy)), hn::Mul(nz, dz)));
      hn::Store(cosine, d, b->sumR + i);
      hn::Store(cosine, d, b->sumG + i);
      hn::Store(cosine, d, b->sumB + i);
    } else {
      hn::Store(zero, d, b->sumR + i);
      hn::Store(zero, d, b->sumG + i);
      hn::Store(zero, d, b->sumB + i);
    }
  }
}

// One light's E·cosθ for lanes i.. with lighting normal n (0 where it does
// not reach a lane): from the vector to the light vx/vy/vz + i (point, spot)
// or the light's direction (directional, where vx/vy/vz are not read). One
// function for both lane paths: their bits must agree.
template <class D>
HWY_INLINE hn::Vec<D> LightWeight(D d, const LaneLight& light, const float* vxs, const float* vys,
                                  const float* vzs, size_t i, hn::Vec<D> nx, hn::Vec<D> ny, hn::Vec<D> nz) {
  const auto zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  auto lx = hn::Set(d, light.dirX), ly = hn::Set(d, light.dirY), lz = hn::Set(d, light.dirZ);
  auto irradiance = hn::Set(d, light.intensity);
  auto reaches = hn::Eq(zero, zero);
  if (light.type != 2) {
    const auto vx = hn::Load(d, vxs + i), vy = hn::Load(d, vys + i), vz = hn::Load(d, vzs + i);
    const auto distance = hn::Sqrt(hn::Add(hn::Add(hn::Mul(vx, vx), hn::Mul(vy, vy)), hn::Mul(vz, vz)));
    reaches = hn::Gt(distance, zero);
    lx = hn::Div(vx, distance);
    ly = hn::Div(vy, distance);
    lz = hn::Div(vz, distance);
    // I / d², as two divisions: d² alone would overflow float sooner.
    irradiance = hn::Div(hn::Div(irradiance, distance), distance);
    if (light.range > 0.0f) {
      // glTF's range window: clamp(1 − (d / range)⁴, 0, 1).
      const auto r = hn::Div(distance, hn::Set(d, light.range));
      const auto r2 = hn::Mul(r, r);
      irradiance = hn::Mul(irradiance, hn::Min(hn::Max(hn::Sub(one, hn::Mul(r2, r2)), zero), one));
    }
    if (light.type == 1) {
      // The cone: cd = spot·(−l), t = clamp((cd − cos outer) / denominator, 0, 1), weight t².
      const auto cd =
          hn::Neg(hn::Add(hn::Add(hn::Mul(hn::Set(d, light.spotX), lx), hn::Mul(hn::Set(d, light.spotY), ly)),
                          hn::Mul(hn::Set(d, light.spotZ), lz)));
      const auto t = hn::Min(
          hn::Max(hn::Div(hn::Sub(cd, hn::Set(d, light.cosOuter)), hn::Set(d, light.coneDenominator)), zero),
          one);
      irradiance = hn::Mul(irradiance, hn::Mul(t, t));
    }
  }
  const auto cosine = hn::Add(hn::Add(hn::Mul(nx, lx), hn::Mul(ny, ly)), hn::Mul(nz, lz));
  reaches = hn::And(reaches, hn::And(hn::Gt(cosine, zero), hn::Gt(irradiance, zero)));
  return hn::IfThenElseZero(reaches, hn::Mul(irradiance, cosine));
}

// One light's E·cosθ per lane (0 where it does not reach the lane), from
// toLight* (point, spot: the vector from the surface to the light) or the
// light's direction (directional).
void LanesLightWeight(LaneBlock* b, const LaneLight& light) {
  const hn::ScalableTag<float> d;
  const size_t N = hn::Lanes(d);
  for (size_t i = 0; i < b->lanes; i += N) {
    const auto w = LightWeight(d, light, b->toLightX, b->toLightY, b->toLightZ, i, hn::Load(d, b->nX + i),
                               hn::Load(d, b->nY + i), hn::Load(d, b->nZ + i));
    hn::Store(w, d, b->weight + i);
  }
}

// sum += light colour · V · weight, per lane (V: visR/G/B when
// `visibility`, else 1).
void LanesAccumulate(LaneBlock* b, const LaneLight& light, bool visibility) {
  const hn::ScalableTag<float> d;
  const size_t N = hn::Lanes(d);
  const auto zero = hn::Zero(d);
  for (size_t i = 0; i < b->lanes; i += N) {
    const auto w = hn::Load(d, b->weight + i);
    const auto lit = hn::Gt(w, zero);
    auto r = hn::Set(d, light.colorR), g = hn::Set(d, light.colorG), bl = hn::Set(d, light.colorB);
    if (visibility) {
      r = hn::Mul(r, hn::Load(d, b->visR + i));
      g = hn::Mul(g, hn::Load(d, b->visG + i));
      bl = hn::Mul(bl, hn::Load(d, b->visB + i));
    }
    // Unlit lanes add nothing (not 0·V: V is not set there).
    hn::Store(hn::Add(hn::Load(d, b->sumR + i), hn::IfThenElseZero(lit, hn::Mul(r, w))), d, b->sumR + i);
    hn::Store(hn::Add(hn::Load(d, b->sumG + i), hn::IfThenElseZero(lit, hn::Mul(g, w))), d, b->sumG + i);
    hn::Store(hn::Add(hn::Load(d, b->sumB + i), hn::IfThenElseZero(lit, hn::Mul(bl, w))), d, b->sumB + i);
  }
}

// L = emission + (1 − w)(1 − t)·albedo·sum/π (the eye light: albedo·|n·d|),
// premultiplied by alpha.
void LanesFinish(LaneBlock* b, bool eyeLight) {
  const hn::ScalableTag<float> d;
  const size_t N = hn::Lanes(d);
  const auto zero = hn::Zero(d);
  const auto invPi = hn::Set(d, eyeLight ? 1.0f : float(0.31830988618379067154));
  for (size_t i = 0; i < b->lanes; i += N) {
    const RunLanes<decltype(d)> get(d, b->run, i);
    const auto diffuse = get(b->diffuseWeight);
    const auto hasDiffuse = hn::Gt(diffuse, zero);
    // The lane's own colours, or its run's (the same values).
    const bool perLane = b->colourPerLane;
    const auto read = [&](const float* lane, const float* run) {
      return perLane ? hn::Load(d, lane + i) : get(run);
    };
    const auto alpha = read(b->alpha, b->runAlpha);
    const auto channel = [&](const auto& albedo, const float* sum, const auto& e, float* out) {
      const auto direct = hn::Mul(albedo, hn::Mul(hn::Load(d, sum + i), invPi));
      const auto L = hn::IfThenElse(hasDiffuse, hn::Add(e, hn::Mul(diffuse, direct)), e);
      hn::Store(hn::Mul(L, alpha), d, out + i);
    };
    channel(read(b->albedoR, b->runAlbedoR), b->sumR, read(b->emitR, b->runEmitR), b->outR);
    channel(read(b->albedoG, b->runAlbedoG), b->sumG, read(b->emitG, b->runEmitG), b->outG);
    channel(read(b->albedoB, b->runAlbedoB), b->sumB, read(b->emitB, b->runEmitB), b->outB);
    hn::Store(alpha, d, b->outA + i);
  }
}

// The lanes above in two passes instead of five, for a block whose lights
// need no visibility callback (the eye light, or no LightVisibility): each
// lane's operations the same and in the same order (the same bits), with
// fewer intermediates through the block's arrays. The double pass
// (LanesSurfaceLights) is LanesSurface, with each lane's position kept in
// registers for LanesToLight of every point or spot light; the float pass
// (LanesLightsFinish) is LanesNormals, then per light LanesLightWeight and
// LanesAccumulate (V = 1), then LanesFinish.
void LanesSurfaceLights(LaneBlock* b, const LaneInputs* in, const LaneLight* lights, size_t lightCount,
                        bool eyeLight) {
  const hn::ScalableTag<double> d;
  const hn::Rebind<float, decltype(d)> df;
  const size_t N = hn::Lanes(d);
  const auto zero = hn::Zero(d), one = hn::Set(d, 1.0), minusOne = hn::Set(d, -1.0);
  for (size_t i = 0; i < b->lanes; i += N) {
    const RunLanes<decltype(d)> get(d, in->run64, i);
    const auto dx = hn::Load(d, in->dirX + i), dy = hn::Load(d, in->dirY + i), dz = hn::Load(d, in->dirZ + i);
    const auto dot =
        hn::Add(hn::Add(hn::Mul(dx, get(b->ngXd)), hn::Mul(dy, get(b->ngYd))), hn::Mul(dz, get(b->ngZd)));
    hn::Store(hn::DemoteTo(df, hn::IfThenElse(hn::Lt(dot, zero), one, minusOne)), df, b->side + i);
    hn::Store(hn::DemoteTo(df, dx), df, b->dirX + i);
    hn::Store(hn::DemoteTo(df, dy), df, b->dirY + i);
    hn::Store(hn::DemoteTo(df, dz), df, b->dirZ + i);
    const auto b1 = hn::PromoteTo(d, hn::Load(df, in->b1 + i)),
               b2 = hn::PromoteTo(d, hn::Load(df, in->b2 + i));
    const auto b0 = hn::Sub(hn::Sub(one, b1), b2);
    hn::Store(hn::DemoteTo(df, b0), df, b->b0 + i);
    if (eyeLight) continue;
    const auto corner = [&](const double* p0, const double* p1, const double* p2) RASTRAY_LAMBDA_INLINE {
      return hn::Add(hn::Add(hn::Mul(b0, get(p0)), hn::Mul(b1, get(p1))), hn::Mul(b2, get(p2)));
    };
    const auto posX = corner(b->p0X, b->p1X, b->p2X);
    const auto posY = corner(b->p0Y, b->p1Y, b->p2Y);
    const auto posZ = corner(b->p0Z, b->p1Z, b->p2Z);
    for (size_t l = 0; l < lightCount; ++l) {
      if (lights[l].type == 2) continue;
      hn::Store(hn::DemoteTo(df, hn::Sub(hn::Set(d, lights[l].posX), posX)), df, b->lightX[l] + i);
      hn::Store(hn::DemoteTo(df, hn::Sub(hn::Set(d, lights[l].posY), posY)), df, b->lightY[l] + i);
      hn::Store(hn::DemoteTo(df, hn::Sub(hn::Set(d, lights[l].posZ), posZ)), df, b->lightZ[l] + i);
    }
  }
}

void LanesLightsFinish(LaneBlock* b, const LaneInputs* in, const LaneLight* lights, size_t lightCount,
                       bool eyeLight) {
  const hn::ScalableTag<float> df;
  const size_t N = hn::Lanes(df);
  const auto zero = hn::Zero(df);
  const auto invPi = hn::Set(df, eyeLight ? 1.0f : float(0.31830988618379067154));
  const bool perLane = b->colourPerLane;
  for (size_t i = 0; i < b->lanes; i += N) {
    const RunLanes<decltype(df)> get(df, in->run, i);
    // LanesNormals.
    const auto dx = hn::Load(df, b->dirX + i), dy = hn::Load(df, b->dirY + i), dz = hn::Load(df, b->dirZ + i);
    hn::Vec<decltype(df)> nx, ny, nz;
    FacingNormal(df, b, get, i, hn::Load(df, b->b0 + i), hn::Load(df, in->b1 + i), hn::Load(df, in->b2 + i),
                 dx, dy, dz, &nx, &ny, &nz);
    hn::Vec<decltype(df)> sumR, sumG, sumB;
    if (eyeLight) {
      const auto cosine = hn::Abs(hn::Add(hn::Add(hn::Mul(nx, dx), hn::Mul(ny, dy)), hn::Mul(nz, dz)));
      sumR = sumG = sumB = cosine;
    } else {
      sumR = sumG = sumB = zero;
      for (size_t l = 0; l < lightCount; ++l) {
        const LaneLight& light = lights[l];
        // LanesLightWeight.
        const auto w = LightWeight(df, light, b->lightX[l], b->lightY[l], b->lightZ[l], i, nx, ny, nz);
        // LanesAccumulate without visibility.
        const auto lit = hn::Gt(w, zero);
        sumR = hn::Add(sumR, hn::IfThenElseZero(lit, hn::Mul(hn::Set(df, light.colorR), w)));
        sumG = hn::Add(sumG, hn::IfThenElseZero(lit, hn::Mul(hn::Set(df, light.colorG), w)));
        sumB = hn::Add(sumB, hn::IfThenElseZero(lit, hn::Mul(hn::Set(df, light.colorB), w)));
      }
    }
    // LanesFinish.
    const auto diffuse = get(b->diffuseWeight);
    const auto hasDiffuse = hn::Gt(diffuse, zero);
    const auto read = [&](const float* lane, const float* run) {
      return perLane ? hn::Load(df, lane + i) : get(run);
    };
    const auto alpha = read(b->alpha, b->runAlpha);
    const auto channel = [&](const auto& albedo, const auto& sum, const auto& e, float* out) {
      const auto direct = hn::Mul(albedo, hn::Mul(sum, invPi));
      const auto L = hn::IfThenElse(hasDiffuse, hn::Add(e, hn::Mul(diffuse, direct)), e);
      hn::Store(hn::Mul(L, alpha), df, out + i);
    };
    channel(read(b->albedoR, b->runAlbedoR), sumR, read(b->emitR, b->runEmitR), b->outR);
    channel(read(b->albedoG, b->runAlbedoG), sumG, read(b->emitG, b->runEmitG), b->outG);
    channel(read(b->albedoB, b->runAlbedoB), sumB, read(b->emitB, b->runEmitB), b->outB);
    hn::Store(alpha, df, b->outA + i);
  }
}

// Lanes [i0, i0 + n) of the block from one run of a PrimaryHitBlock:
// run index r, the hits' directions and barycentrics (BlockShader::addRun).
void LanesAppendRun(LaneBlock* b, size_t i0, size_t n, int32_t r, const double* dirX, const double* dirY,
                    const double* dirZ, const float* b1, const float* b2) {
  const hn::ScalableTag<double> d;
  const hn::RebindToSigned<decltype(d)> di;
  const hn::Rebind<int32_t, decltype(d)> di32;
  const hn::Rebind<float, decltype(d)> df;
  const size_t N = hn::Lanes(d);
  const auto run = hn::Set(di32, r);
  const auto run64 = hn::Set(di, int64_t(r));
  size_t k = 0;
  for (; k + N <= n; k += N) {
    const size_t o = i0 + k;
    hn::StoreU(run, di32, b->run + o);
    hn::StoreU(run64, di, b->run64 + o);
    hn::StoreU(hn::LoadU(d, dirX + k), d, b->dirXd + o);
    hn::StoreU(hn::LoadU(d, dirY + k), d, b->dirYd + o);
    hn::StoreU(hn::LoadU(d, dirZ + k), d, b->dirZd + o);
    hn::StoreU(hn::LoadU(df, b1 + k), df, b->b1 + o);
    hn::StoreU(hn::LoadU(df, b2 + k), df, b->b2 + o);
  }
  for (; k < n; ++k) {
    const size_t o = i0 + k;
    b->run[o] = r;
    b->run64[o] = int64_t(r);
    b->dirXd[o] = dirX[k];
    b->dirYd[o] = dirY[k];
    b->dirZd[o] = dirZ[k];
    b->b1[o] = b1[k];
    b->b2[o] = b2[k];
  }
}

// out[i] = (outR, outG, outB, outA)[i] for the block's used lanes: its
// colours to consecutive RGBA pixels.
void LanesStoreColors(const LaneBlock* b, float* out) {
  const hn::ScalableTag<float> d;
  const size_t N = hn::Lanes(d);
  size_t i = 0;
  for (; i + N <= b->used; i += N)
    hn::StoreInterleaved4(hn::Load(d, b->outR + i), hn::Load(d, b->outG + i), hn::Load(d, b->outB + i),
                          hn::Load(d, b->outA + i), d, out + 4 * i);
  for (; i < b->used; ++i) {
    out[4 * i] = b->outR[i];
    out[4 * i + 1] = b->outG[i];
    out[4 * i + 2] = b->outB[i];
    out[4 * i + 3] = b->outA[i];
  }
}

// Whether index[k] = index[0] + k (mod 2³²) for every k < n.
bool LanesConsecutive(const uint32_t* index, size_t n) {
  const hn::ScalableTag<uint32_t> du;
  const size_t N = hn::Lanes(du);
  const uint32_t first = index[0];
  size_t k = 0;
  for (; k + N <= n; k += N)
    if (!hn::AllTrue(du, hn::Eq(hn::LoadU(du, index + k), hn::Iota(du, first + uint32_t(k))))) return false;
  for (; k < n; ++k)
    if (index[k] != first + uint32_t(k)) return false;
  return true;
}

size_t RefineLanes() { return hn::Lanes(hn::ScalableTag<double>()); }

// intersectTrianglePlane then refinedBarycentrics (common/surface.{h,cpp})
// per lane: common/primary_refinement-inl.h, with s = origin − a,
// q = s × e1 and e2 · q computed per lane as the scalar memo computes them.
void LanesRefine(kernel_detail::RefineBlock* b) {
  const hn::ScalableTag<double> d;
  const size_t N = hn::Lanes(d);
  const auto one = hn::Set(d, 1.0);
  for (size_t i = 0; i < b->lanes; i += N) {
    RefinePlaneLanes<hn::Vec<decltype(d)>> pl;
    pl.e1x = hn::Load(d, b->e1x + i), pl.e1y = hn::Load(d, b->e1y + i), pl.e1z = hn::Load(d, b->e1z + i);
    pl.e2x = hn::Load(d, b->e2x + i), pl.e2y = hn::Load(d, b->e2y + i), pl.e2z = hn::Load(d, b->e2z + i);
    // s = origin − a, q = s × e1
    pl.sx = hn::Sub(hn::Load(d, b->ox + i), hn::Load(d, b->ax + i));
    pl.sy = hn::Sub(hn::Load(d, b->oy + i), hn::Load(d, b->ay + i));
    pl.sz = hn::Sub(hn::Load(d, b->oz + i), hn::Load(d, b->az + i));
    pl.qx = hn::Sub(hn::Mul(pl.sy, pl.e1z), hn::Mul(pl.e1y, pl.sz));
    pl.qy = hn::Sub(hn::Mul(pl.sz, pl.e1x), hn::Mul(pl.e1z, pl.sx));
    pl.qz = hn::Sub(hn::Mul(pl.sx, pl.e1y), hn::Mul(pl.e1x, pl.sy));
    pl.e2DotQ = hn::Add(hn::Add(hn::Mul(pl.e2x, pl.qx), hn::Mul(pl.e2y, pl.qy)), hn::Mul(pl.e2z, pl.qz));
    pl.slot1 = hn::Load(d, b->slot1 + i), pl.slot2 = hn::Load(d, b->slot2 + i);
    hn::Vec<decltype(d)> b1, b2;
    const auto ok = RefineOnPlane(d, hn::Load(d, b->dx + i), hn::Load(d, b->dy + i), hn::Load(d, b->dz + i),
                                  hn::Load(d, b->depthPerT + i), pl, &b1, &b2);
    hn::Store(b1, d, b->b1 + i);
    hn::Store(b2, d, b->b2 + i);
    hn::Store(hn::IfThenElseZero(ok, one), d, b->refined + i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <type_traits>

#include "common/optics.h"
#include "common/primary_refinement.h"
#include "common/shading.h"
#include "common/surface.h"
#include "common/triangle_plane.h"

namespace rastray {

HWY_EXPORT(KernelLanes);
HWY_EXPORT(LanesSurface);
HWY_EXPORT(LanesToLight);
HWY_EXPORT(LanesNormals);
HWY_EXPORT(LanesLightWeight);
HWY_EXPORT(LanesAccumulate);
HWY_EXPORT(LanesFinish);
HWY_EXPORT(LanesSurfaceLights);
HWY_EXPORT(LanesLightsFinish);
HWY_EXPORT(LanesAppendRun);
HWY_EXPORT(LanesStoreColors);
HWY_EXPORT(LanesConsecutive);
HWY_EXPORT(RefineLanes);
HWY_EXPORT(LanesRefine);

using kernel_detail::kBlock;
using kernel_detail::LaneBlock;
using kernel_detail::LaneInputs;
using kernel_detail::LaneLight;

ShadeHit refinePrimaryHit(const Scene& scene, const Ray& ray, const SampleHit& hit,
                          const glm::dvec2& footprintPosition) {
  ShadeHit s;
  s.instance = hit.instance;
  s.triangle = hit.triangle;
  s.b1 = hit.b1;
  s.b2 = hit.b2;
  s.direction = ray.direction;
  s.footprintPosition = footprintPosition;
  // surfacePointOnRay's refinement: kept when the plane is missed or behind.
  double t;
  glm::dvec2 b, clamped;
  if (intersectTrianglePlane(scene, hit.instance, hit.triangle, ray, &t, &b) &&
      refinedBarycentrics(ray, t, b, &clamped)) {
    s.b1 = float(clamped.x);
    s.b2 = float(clamped.y);
  }
  return s;
}

namespace {

std::atomic<bool> twoPassShading{true};

}  // namespace

void setTwoPassShadingForTest(bool enabled) { twoPassShading.store(enabled, std::memory_order_relaxed); }

namespace {

// The scalar double reference for one hit: exactly what a renderer did
// before the kernel (surfacePointOnRay's point, pixelFootprint, shade).

// Whether Shader::shade at depth 0 would trace a secondary ray from this
// material (or it is BLEND): such lanes take the scalar path, in every
// renderer alike.
bool needsScalarShade(const Shader& shader, const Material& m) {
  if (m.alphaMode == AlphaMode::Blend) return true;
  // Normal, occlusion and metallic-roughness maps: the lanes do not read
  // them (per-hit normal, mirror weight and occlusion), Shader::shade does.
  if (m.hasSurfaceMaps()) return true;
  const bool canTrace = shader.secondary() && 0 < shader.options().maxDepth;
  return canTrace && (m.mirrorWeight() > 0.0f || (1.0f - m.mirrorWeight()) * m.transmission > 0.0f);
}

bool samplesTexture(const Shader& shader, const Material& m) {
  if (shader.textures().empty()) return false;
  return m.baseColorTexture >= 0 || (m.emissiveTexture >= 0 && m.emissive != glm::vec3(0.0f)) ||
         m.hasSurfaceMaps();
}

// The colour the lanes give every hit on `instance` when it depends on
// nothing of the hit, else nothing. LanesFinish's L = e + diffuse ·
// (albedo · (sum/π)) on the lanes' path: without a diffuse term
// (diffuse ≤ 0 or NaN) L = e; with the eye light, sum = |n·d| is finite
// and ≥ 0 (n and d unit: the face normal of finite corners, the ray's
// direction), so on a black base colour albedo · (sum/π) is albedo's own
// zero for every hit, and the same operations with sum = 0 give L's bits.
// Lights' sums may be +inf (I/d² near a light): not constant there.
std::optional<glm::vec4> constantColour(const Shader& shader, uint32_t instance) {
  const Scene& scene = shader.scene();
  const Material& m = scene.materialOf(instance);
  if (needsScalarShade(shader, m) || samplesTexture(shader, m) || scene.instances[instance].hasColors)
    return std::nullopt;
  const float diffuse = (1.0f - m.mirrorWeight()) * (1.0f - m.transmission);  // enterRun's
  const glm::vec3 albedo(m.baseColorFactor);
  const bool eyeLight = shader.eyeLight();
  if (diffuse > 0.0f && !(eyeLight && albedo == glm::vec3(0.0f))) return std::nullopt;
  const float alpha = m.alphaMode == AlphaMode::Blend ? m.baseColorFactor.a : 1.0f;
  const float invPi = eyeLight ? 1.0f : float(0.31830988618379067154);
  const float sum = 0.0f;
  glm::vec4 colour(0.0f, 0.0f, 0.0f, alpha);
  for (int c = 0; c < 3; ++c) {
    const float direct = albedo[c] * (sum * invPi);
    const float L = diffuse > 0.0f ? m.emissive[c] + diffuse * direct : m.emissive[c];
    colour[c] = L * alpha;
  }
  return colour;
}

// The footprint only where a texture is sampled: elsewhere it is unused.
glm::vec4 shadeReference(const Shader& shader, const ShadeHit& h) {
  const SurfacePoint p =
      makeSurfacePoint(shader.scene(), SampleHit{h.instance, h.triangle, 0.0f, h.b1, h.b2});
  const TextureFootprint fp = samplesTexture(shader, *p.material)
                                  ? pixelFootprint(shader.scene(), shader.camera(), p, h.footprintPosition)
                                  : TextureFootprint{};
  return shader.shade(p, h.direction, fp, 0, h.throughput);
}

LaneLight laneLight(const Light& light) {
  LaneLight l{};
  l.type = light.type == LightType::Point ? 0 : light.type == LightType::Spot ? 1 : 2;
  l.colorR = light.color.r;
  l.colorG = light.color.g;
  l.colorB = light.color.b;
  l.intensity = light.intensity;
  l.range = light.range;
  l.spotX = float(light.direction.x);
  l.spotY = float(light.direction.y);
  l.spotZ = float(light.direction.z);
  const double cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
  l.cosOuter = float(cosOuter);
  l.coneDenominator = float(std::max(1e-6, cosInner - cosOuter));
  l.dirX = float(-light.direction.x);
  l.dirY = float(-light.direction.y);
  l.dirZ = float(-light.direction.z);
  l.posX = light.position.x;
  l.posY = light.position.y;
  l.posZ = light.position.z;
  return l;
}

// The host side of one block: the scalar per-lane work around the lanes.
class BlockShader {
 public:
  explicit BlockShader(const Shader& shader)
      : shader_(shader),
        scene_(shader.scene()),
        vectorLanes_(HWY_DYNAMIC_DISPATCH(KernelLanes)()),
        twoPass_(twoPassShading.load(std::memory_order_relaxed)),
        visible_(shader.visibility() && !shader.eyeLight() && !shader.scene().lights.empty()) {
    for (const Light& light : scene_.lights) lights_.push_back(laneLight(light));
    std::fill_n(runKeys_, size_t(1) << kRunCacheBits, ~uint64_t(0));
  }

  bool full() const { return block_.used == kBlock; }
  size_t used() const { return block_.used; }

  // Gathers hit `h` (to be written to `*out`) into the next lane.
  void add(const ShadeHit& h, const Material& m, glm::vec4* out) {
    LaneBlock& b = block_;
    colourPerLane();
    const size_t i = b.used++;
    if (i == 0) base_ = out;
    if (!contiguous_ || out != base_ + i) {
      noLongerContiguous(i);
      outputs_[i] = out;
    }
    // Consecutive hits mostly share a triangle: its data is looked up once
    // per run (the same values, so the lane does not depend on the run).
    enterRun(h.instance, h.triangle, m);
    b.run[i] = int32_t(b.runs - 1);
    b.run64[i] = int64_t(b.runs - 1);
    const Instance& inst = *run_.inst;
    const glm::uvec3 t = run_.corners;
    // The side, b0, the rounded direction and the position: LanesSurface.
    b.dirXd[i] = h.direction.x;
    b.dirYd[i] = h.direction.y;
    b.dirZd[i] = h.direction.z;
    b.b1[i] = h.b1;
    b.b2[i] = h.b2;

    // Base colour and emission: Shader::baseColor and emission's float
    // steps, here with the textures sampled through the pixel footprint.
    glm::vec4 base = m.baseColorFactor;
    glm::vec3 emit = m.emissive;
    if (&m != material_) {
      material_ = &m;
      textured_ = samplesTexture(shader_, m);
    }
    const bool textured = textured_;
    if (textured || visible_) {
      // The full surface point: the footprint and the visibility callback
      // take it (the same one Shader::shade would get).
      points_[i] = makeSurfacePoint(scene_, SampleHit{h.instance, h.triangle, 0.0f, h.b1, h.b2});
    }
    if (textured) {
      const TextureFootprint fp = pixelFootprint(scene_, shader_.camera(), points_[i], h.footprintPosition);
      base = shader_.baseColor(points_[i], fp);
      emit = shader_.emission(points_[i], fp);
    } else if (inst.hasColors) {
      const double b0 = 1.0 - double(h.b1) - double(h.b2);
      const glm::vec4 color =
          float(b0) * scene_.colors[t.x] + h.b1 * scene_.colors[t.y] + h.b2 * scene_.colors[t.z];
      base *= color;
    }
    b.albedoR[i] = base.r;
    b.albedoG[i] = base.g;
    b.albedoB[i] = base.b;
    b.emitR[i] = emit.r;
    b.emitG[i] = emit.g;
    b.emitB[i] = emit.b;
    b.alpha[i] = m.alphaMode == AlphaMode::Blend ? base.a : 1.0f;
  }

  // Gathers hits [first, end) of `h`, one run (one triangle, material
  // `m`), the colour of hit k to colors[h.colorIndex[k]]; the block has
  // room for them. The lanes get the values add() would give them; where
  // neither a texture, vertex colours nor a visibility callback needs the
  // hit's own surface, the base colour and emission are the run's.
  void addRun(const PrimaryHitBlock& h, size_t first, size_t end, const Material& m, glm::vec4* colors) {
    const uint32_t instance = h.runInstance[h.run[first]], triangle = h.runTriangle[h.run[first]];
    if (&m != material_) {
      material_ = &m;
      textured_ = samplesTexture(shader_, m);
    }
    if (textured_ || visible_ || scene_.instances[instance].hasColors) {
      for (size_t k = first; k < end; ++k) {
        ShadeHit s;
        s.instance = instance;
        s.triangle = triangle;
        s.b1 = h.b1[k];
        s.b2 = h.b2[k];
        s.direction = glm::dvec3(h.dirX[k], h.dirY[k], h.dirZ[k]);
        s.footprintPosition = glm::dvec2(h.footprintX[k], h.footprintY[k]);
        add(s, m, &colors[h.colorIndex[k]]);
      }
      return;
    }
    LaneBlock& b = block_;
    const int32_t hitRun = h.run[first];
    if (h.runCorners && h.runFaceNormal && h.runCorners[hitRun].x != kNoId)
      enterRun(instance, triangle, m, &h.runCorners[hitRun], &h.runFaceNormal[hitRun]);
    else
      enterRun(instance, triangle, m);
    const size_t i0 = b.used, n = end - first;
    b.used += n;
    const int32_t r = int32_t(b.runs - 1);
    if (n >= 16) {
      // A large triangle's run: in lanes.
      HWY_DYNAMIC_DISPATCH(LanesAppendRun)
      (&b, i0, n, r, h.dirX + first, h.dirY + first, h.dirZ + first, h.b1 + first, h.b2 + first);
    } else {
      std::fill_n(b.run + i0, n, r);
      std::fill_n(b.run64 + i0, n, int64_t(r));
      std::copy_n(h.dirX + first, n, b.dirXd + i0);
      std::copy_n(h.dirY + first, n, b.dirYd + i0);
      std::copy_n(h.dirZ + first, n, b.dirZd + i0);
      std::copy_n(h.b1 + first, n, b.b1 + i0);
      std::copy_n(h.b2 + first, n, b.b2 + i0);
    }
    if (b.colourPerLane) {
      std::fill_n(b.albedoR + i0, n, b.runAlbedoR[r]);
      std::fill_n(b.albedoG + i0, n, b.runAlbedoG[r]);
      std::fill_n(b.albedoB + i0, n, b.runAlbedoB[r]);
      std::fill_n(b.emitR + i0, n, b.runEmitR[r]);
      std::fill_n(b.emitG + i0, n, b.runEmitG[r]);
      std::fill_n(b.emitB + i0, n, b.runEmitB[r]);
      std::fill_n(b.alpha + i0, n, b.runAlpha[r]);
    }
    // The run's outputs: consecutive pixels continuing the block's are
    // not stored lane by lane (base_ + lane gives them).
    const uint32_t c0 = h.colorIndex[first];
    if (i0 == 0) base_ = &colors[c0];
    if (contiguous_ && &colors[c0] == base_ + i0 && consecutive(h.colorIndex + first, n)) return;
    noLongerContiguous(i0);
    for (size_t k = 0; k < n; ++k) outputs_[i0 + k] = &colors[h.colorIndex[first + k]];
  }

  // Whether index[k] = index[0] + k for k < n.
  static bool consecutive(const uint32_t* index, size_t n) {
    if (n >= 16) return HWY_DYNAMIC_DISPATCH(LanesConsecutive)(index, n);
    uint32_t apart = 0;  // nonzero when some index is not index[0] + k
    for (size_t k = 0; k < n; ++k) apart |= index[k] ^ (index[0] + uint32_t(k));
    return apart == 0;
  }

  // Shades the whole of `h` reading its per-hit inputs in place (no copy
  // into the block), when the two-pass lanes take it and no lane needs
  // anything of its own: every run on the lanes' path (no scalar-path
  // material), no texture, vertex colours or visibility callback, and
  // `h` offers its inputs (PrimaryHitBlock::run64, lanes, runFirst, 64-byte
  // aligned). The block's run table then has one entry per run of `h`
  // (the same values when two runs share a triangle), so `h`'s run
  // indices index it. Returns false, having done nothing, otherwise.
  bool shadeInPlace(const PrimaryHitBlock& h, glm::vec4* colors) {
    LaneBlock& b = block_;
    const bool eyeLight = shader_.eyeLight();
    if (!twoPass_ || b.used != 0 || h.count == 0 || !h.run64 || !h.runFirst) return false;
    if (!eyeLight && (shader_.visibility() || lights_.size() > kernel_detail::kTwoPassLights)) return false;
    const size_t lanes = (h.count + vectorLanes_ - 1) / vectorLanes_ * vectorLanes_;
    if (h.lanes < lanes || h.runs > kBlock) return false;
    const auto aligned = [](const void* p) { return reinterpret_cast<uintptr_t>(p) % 64 == 0; };
    if (!aligned(h.run) || !aligned(h.run64) || !aligned(h.dirX) || !aligned(h.dirY) || !aligned(h.dirZ) ||
        !aligned(h.b1) || !aligned(h.b2))
      return false;
    const Material* materials[kBlock];
    uint32_t instance = kNoId;
    for (size_t r = 0; r < h.runs; ++r) {
      if (h.runInstance[r] != instance) {
        instance = h.runInstance[r];
        const Material& m = scene_.materialOf(instance);
        if (needsScalarShade(shader_, m) || samplesTexture(shader_, m) ||
            scene_.instances[instance].hasColors)
          return false;
        materials[r] = &m;
      } else {
        materials[r] = materials[r - 1];
      }
    }
    for (size_t r = 0; r < h.runs; ++r) {
      if (h.runCorners && h.runFaceNormal && h.runCorners[r].x != kNoId)
        enterRun(h.runInstance[r], h.runTriangle[r], *materials[r], &h.runCorners[r], &h.runFaceNormal[r],
                 /*everyRun=*/true);
      else
        enterRun(h.runInstance[r], h.runTriangle[r], *materials[r], nullptr, nullptr, /*everyRun=*/true);
    }
    b.used = h.count;
    b.lanes = lanes;
    b.colourPerLane = false;
    const LaneInputs in{h.run, h.run64, h.dirX, h.dirY, h.dirZ, h.b1, h.b2};
    HWY_DYNAMIC_DISPATCH(LanesSurfaceLights)(&b, &in, lights_.data(), lights_.size(), eyeLight);
    HWY_DYNAMIC_DISPATCH(LanesLightsFinish)(&b, &in, lights_.data(), lights_.size(), eyeLight);
    if (consecutive(h.colorIndex, h.count)) {
      HWY_DYNAMIC_DISPATCH(LanesStoreColors)(&b, &colors[h.colorIndex[0]].x);
    } else {
      for (size_t i = 0; i < b.used; ++i)
        colors[h.colorIndex[i]] = glm::vec4(b.outR[i], b.outG[i], b.outB[i], b.outA[i]);
    }
    b.used = 0;
    b.runs = 0;
    return true;
  }

  // The block's outputs stop being consecutive at lane i: lanes [0, i)
  // get their outputs_ entries from base_ (kept consecutive until now).
  void noLongerContiguous(size_t i) {
    if (!contiguous_) return;
    for (size_t k = 0; k < i; ++k) outputs_[k] = base_ + k;
    contiguous_ = false;
  }

  // Shades the gathered lanes and writes their colours; empties the block.
  void run() {
    LaneBlock& b = block_;
    if (b.used == 0) return;
    const bool eyeLight = shader_.eyeLight();
    padLanes(vectorLanes_);
    if (twoPass_ &&
        (eyeLight || (!shader_.visibility() && lights_.size() <= kernel_detail::kTwoPassLights))) {
      // No visibility callback between the lights' weights and their
      // sums: the steps in two passes over the lanes.
      const LaneInputs in{b.run, b.run64, b.dirXd, b.dirYd, b.dirZd, b.b1, b.b2};
      HWY_DYNAMIC_DISPATCH(LanesSurfaceLights)(&b, &in, lights_.data(), lights_.size(), eyeLight);
      HWY_DYNAMIC_DISPATCH(LanesLightsFinish)(&b, &in, lights_.data(), lights_.size(), eyeLight);
      storeColors();
      return;
    }
    HWY_DYNAMIC_DISPATCH(LanesSurface)(&b, !eyeLight);
    HWY_DYNAMIC_DISPATCH(LanesNormals)(&b, eyeLight);
    if (!eyeLight) {
      const LightVisibility* visibility = shader_.visibility();
      for (size_t l = 0; l < lights_.size(); ++l) {
        const Light& light = scene_.lights[l];
        if (light.type != LightType::Directional) {
          // The vector to the light in double, rounded once.
          HWY_DYNAMIC_DISPATCH(LanesToLight)(&b, light.position.x, light.position.y, light.position.z);
        }
        HWY_DYNAMIC_DISPATCH(LanesLightWeight)(&b, lights_[l]);
        if (visibility) {
          // The lit lanes, asked in one batch (the ray caster traces them
          // in packets): Shader::directLight's direction and distance, in
          // double.
          size_t n = 0;
          for (size_t i = 0; i < b.used; ++i) {
            if (!(b.weight[i] > 0.0f)) continue;
            if (light.type == LightType::Directional) {
              litToLight_[n] = -light.direction;
              litDistance_[n] = std::numeric_limits<double>::infinity();
            } else {
              const glm::dvec3 v = light.position - points_[i].position;
              litDistance_[n] = glm::length(v);
              litToLight_[n] = v / litDistance_[n];
            }
            litPoints_[n] = &points_[i];
            litLanes_[n++] = uint32_t(i);
          }
          visibility->transmittances(int(l), n, litPoints_, litToLight_, litDistance_, litVisibility_);
          for (size_t k = 0; k < n; ++k) {
            const size_t i = litLanes_[k];
            b.visR[i] = litVisibility_[k].r;
            b.visG[i] = litVisibility_[k].g;
            b.visB[i] = litVisibility_[k].b;
          }
        }
        HWY_DYNAMIC_DISPATCH(LanesAccumulate)(&b, lights_[l], visibility != nullptr);
      }
    }
    HWY_DYNAMIC_DISPATCH(LanesFinish)(&b, eyeLight);
    storeColors();
  }

 private:
  // The block's colours to their outputs; empties the block.
  void storeColors() {
    LaneBlock& b = block_;
    if (contiguous_) {
      // The lanes' colours go to consecutive pixels (a run of samples
      // along a tile row): written interleaved in lanes.
      HWY_DYNAMIC_DISPATCH(LanesStoreColors)(&b, &base_->x);
    } else {
      for (size_t i = 0; i < b.used; ++i)
        *outputs_[i] = glm::vec4(b.outR[i], b.outG[i], b.outB[i], b.outA[i]);
    }
    contiguous_ = true;
    b.used = 0;
    b.runs = 0;
    b.colourPerLane = false;
  }

  // What every lane on one triangle reads: its instance, corner indices,
  // positions (double, exact), face normal (double and rounded) and
  // authored corner normals (zero when the instance has none).
  struct TriangleRun {  // trivially copyable (the run cache copies its bytes)
    uint32_t instance = kNoId, triangle = kNoId;
    const Instance* inst = nullptr;
    glm::uvec3 corners{0};
    glm::dvec3 p0{0.0}, p1{0.0}, p2{0.0};
    glm::dvec3 ng{0.0, 0.0, 1.0};
    glm::vec3 ngF{0.0f, 0.0f, 1.0f};
    bool authored = false;
    glm::vec3 n0{0.0f}, n1{0.0f}, n2{0.0f};
  };
  static_assert(std::is_trivially_copyable<TriangleRun>::value, "the run cache copies its bytes");

  // The lanes that follow are on (instance, triangle) with material `m`:
  // a new entry in the block's run table unless the last one is the same
  // triangle (the same values either way, so a lane does not depend on
  // its neighbours).
  // With `corners` and `faceNormal` (the caller's, PrimaryHitBlock), the
  // triangle's values are made from them instead of the run cache.
  // With `everyRun`, a new entry even on the same triangle.
  void enterRun(uint32_t instance, uint32_t triangle, const Material& m, const glm::uvec3* corners = nullptr,
                const glm::dvec3* faceNormal = nullptr, bool everyRun = false) {
    LaneBlock& b = block_;
    const bool newTriangle = instance != run_.instance || triangle != run_.triangle;
    if (newTriangle) {
      if (corners)
        makeRun(instance, triangle, *corners, *faceNormal);
      else
        startRun(instance, triangle);
    }
    if (!newTriangle && b.runs != 0 && !everyRun) return;
    const size_t r = b.runs++;
    b.ngX[r] = run_.ngF.x;
    b.ngY[r] = run_.ngF.y;
    b.ngZ[r] = run_.ngF.z;
    b.authored[r] = run_.authored ? 1.0f : 0.0f;
    b.n0X[r] = run_.n0.x, b.n0Y[r] = run_.n0.y, b.n0Z[r] = run_.n0.z;
    b.n1X[r] = run_.n1.x, b.n1Y[r] = run_.n1.y, b.n1Z[r] = run_.n1.z;
    b.n2X[r] = run_.n2.x, b.n2Y[r] = run_.n2.y, b.n2Z[r] = run_.n2.z;
    b.diffuseWeight[r] = (1.0f - m.mirrorWeight()) * (1.0f - m.transmission);
    b.ngXd[r] = run_.ng.x, b.ngYd[r] = run_.ng.y, b.ngZd[r] = run_.ng.z;
    b.p0X[r] = run_.p0.x, b.p0Y[r] = run_.p0.y, b.p0Z[r] = run_.p0.z;
    b.p1X[r] = run_.p1.x, b.p1Y[r] = run_.p1.y, b.p1Z[r] = run_.p1.z;
    b.p2X[r] = run_.p2.x, b.p2Y[r] = run_.p2.y, b.p2Z[r] = run_.p2.z;
    // Shader::baseColor and emission without texture or vertex colours.
    const glm::vec4 base = m.baseColorFactor;
    b.runAlbedoR[r] = base.r, b.runAlbedoG[r] = base.g, b.runAlbedoB[r] = base.b;
    b.runEmitR[r] = m.emissive.r, b.runEmitG[r] = m.emissive.g, b.runEmitB[r] = m.emissive.b;
    b.runAlpha[r] = m.alphaMode == AlphaMode::Blend ? base.a : 1.0f;
  }

  // From here on the block's lanes read their own colours: those gathered
  // so far get their run's.
  void colourPerLane() {
    LaneBlock& b = block_;
    if (b.colourPerLane) return;
    b.colourPerLane = true;
    for (size_t i = 0; i < b.used; ++i) {
      const int32_t r = b.run[i];
      b.albedoR[i] = b.runAlbedoR[r], b.albedoG[i] = b.runAlbedoG[r], b.albedoB[i] = b.runAlbedoB[r];
      b.emitR[i] = b.runEmitR[r], b.emitG[i] = b.runEmitG[r], b.emitB[i] = b.runEmitB[r];
      b.alpha[i] = b.runAlpha[r];
    }
  }

  // run_ for (instance, triangle): from the cache of recent triangles
  // (a function of the triangle alone: the same values), else computed.
  // Small triangles give runs of one or two samples, and a tile's next
  // row meets the same triangles again.
  void startRun(uint32_t instance, uint32_t triangle) {
    const size_t slot = (triangle * 2654435761u + instance * 40503u) >> (32 - kRunCacheBits);
    const uint64_t key = uint64_t(instance) << 32 | triangle;
    unsigned char* const cached = runCache_.get() + slot * sizeof(TriangleRun);
    if (runKeys_[slot] == key) {
      std::memcpy(static_cast<void*>(&run_), cached, sizeof(TriangleRun));
      return;
    }
    computeRun(instance, triangle);
    runKeys_[slot] = key;
    std::memcpy(cached, static_cast<const void*>(&run_), sizeof(TriangleRun));
  }

  void computeRun(uint32_t instance, uint32_t triangle) {
    makeRun(instance, triangle, scene_.triangle(instance, triangle),
            triangleFaceNormal(scene_, instance, triangle));
  }

  // run_ from the triangle's corner indices and face normal.
  void makeRun(uint32_t instance, uint32_t triangle, const glm::uvec3& corners,
               const glm::dvec3& faceNormal) {
    TriangleRun& r = run_;
    r.instance = instance;
    r.triangle = triangle;
    r.inst = &scene_.instances[instance];
    r.corners = corners;
    r.p0 = glm::dvec3(scene_.positions[r.corners.x]);
    r.p1 = glm::dvec3(scene_.positions[r.corners.y]);
    r.p2 = glm::dvec3(scene_.positions[r.corners.z]);
    r.ng = faceNormal;
    r.ngF = glm::vec3(r.ng);
    r.authored = r.inst->normals == NormalSource::Authored;
    r.n0 = r.authored ? scene_.normals[r.corners.x] : glm::vec3(0.0f);
    r.n1 = r.authored ? scene_.normals[r.corners.y] : glm::vec3(0.0f);
    r.n2 = r.authored ? scene_.normals[r.corners.z] : glm::vec3(0.0f);
  }

  // Fills the lanes from `used` to a whole number of vectors with a
  // harmless surface (the last run's normals and corners at b0 = 1, no
  // colour), never read back.
  void padLanes(size_t vectorLanes) {
    LaneBlock& b = block_;
    b.lanes = (b.used + vectorLanes - 1) / vectorLanes * vectorLanes;
    for (size_t i = b.used; i < b.lanes; ++i) {
      b.dirXd[i] = b.dirYd[i] = 0.0;
      b.dirZd[i] = -1.0;
      b.run[i] = int32_t(b.runs - 1);  // the last run's normals, corners (and colours, per run)
      b.run64[i] = int64_t(b.runs - 1);
      b.b1[i] = b.b2[i] = 0.0f;
      b.albedoR[i] = b.albedoG[i] = b.albedoB[i] = 0.0f;
      b.emitR[i] = b.emitG[i] = b.emitB[i] = 0.0f;
      b.alpha[i] = 1.0f;
      b.visR[i] = b.visG[i] = b.visB[i] = 1.0f;
    }
  }

  const Shader& shader_;
  const Scene& scene_;
  const size_t vectorLanes_;
  const bool twoPass_;  // the two-pass lanes where the lights allow it (setTwoPassShadingForTest)
  const bool visible_;  // lights with a visibility callback: lanes need their full surface point
  const Material* material_ = nullptr;  // the last lane's, and whether it samples a texture
  bool textured_ = false;
  std::vector<LaneLight> lights_;
  TriangleRun run_;
  static constexpr int kRunCacheBits = 7;
  // (instance << 32 | triangle) of each entry of runCache_; all ones: none
  // (built once per BlockShader: only the keys are set up front).
  uint64_t runKeys_[size_t(1) << kRunCacheBits];
  // The entries' bytes (TriangleRun is trivially copyable), not
  // constructed: only entries whose key is set are read.
  std::unique_ptr<unsigned char[]> runCache_{new unsigned char[sizeof(TriangleRun) << kRunCacheBits]};
  LaneBlock block_;
  // Where each lane's colour goes: base_ + i for every used lane i while
  // contiguous_ (outputs_ then unset), else outputs_[i].
  glm::vec4* outputs_[kBlock];
  glm::vec4* base_ = nullptr;
  bool contiguous_ = true;
  SurfacePoint points_[kBlock];  // set where textured or lit with a visibility callback
  // One light's lit lanes, for LightVisibility::transmittances.
  const SurfacePoint* litPoints_[kBlock];
  glm::dvec3 litToLight_[kBlock];
  double litDistance_[kBlock];
  glm::vec3 litVisibility_[kBlock];
  uint32_t litLanes_[kBlock];
};

}  // namespace

void shadePrimaryHits(const Shader& shader, const ShadeHit* hits, size_t count, glm::vec4* colors,
                      const uint32_t* colorIndex, ShadingPath path) {
  const auto out = [&](size_t i) -> glm::vec4& { return colors[colorIndex ? colorIndex[i] : i]; };
  if (path == ShadingPath::Reference || shader.options().referenceShading) {
    for (size_t i = 0; i < count; ++i) out(i) = shadeReference(shader, hits[i]);
    return;
  }
  // Built at the first lane: a batch of scalar-path hits (a BLEND layer)
  // needs none of it.
  std::optional<BlockShader> block;
  // The path is a function of the material: decided once per run of hits
  // on one instance.
  uint32_t runInstance = kNoId;
  const Material* material = nullptr;
  bool scalar = false;
  for (size_t i = 0; i < count; ++i) {
    const ShadeHit& h = hits[i];
    if (h.instance != runInstance) {
      runInstance = h.instance;
      material = &shader.scene().materialOf(h.instance);
      scalar = needsScalarShade(shader, *material);
    }
    if (scalar) {
      out(i) = shadeReference(shader, h);
      continue;
    }
    if (!block) block.emplace(shader);
    block->add(h, *material, &out(i));
    if (block->full()) block->run();
  }
  if (block) block->run();
}

struct PrimaryHitShader::Impl {
  Impl(const Shader& s, ShadingPath path)
      : shader(s), reference(path == ShadingPath::Reference || s.options().referenceShading) {}
  const Shader& shader;
  const bool reference;
  std::optional<BlockShader> block;  // built at the first lane, as in shadePrimaryHits
  uint32_t runInstance = kNoId;      // the path is a function of the material: decided once per instance
  const Material* material = nullptr;
  bool scalar = false;
  std::optional<glm::vec4> constant;  // constantColour's

  void enterInstance(uint32_t instance) {
    if (instance == runInstance) return;
    runInstance = instance;
    material = &shader.scene().materialOf(instance);
    scalar = needsScalarShade(shader, *material);
    constant = constantColour(shader, instance);
  }

  // Writes every hit's colour when each one's instance has a constant
  // colour; else returns false (the colours written so far are written
  // again by the other paths).
  bool shadeConstant(const PrimaryHitBlock& h, glm::vec4* colors) {
    for (size_t k = 0; k < h.count; ++k) {
      enterInstance(h.runInstance[h.run[k]]);
      if (!constant) return false;
      colors[h.colorIndex[k]] = *constant;
    }
    return true;
  }
};

bool PrimaryHitShader::needsHitInputs() const {
  if (impl_->reference) return true;
  const Scene& scene = impl_->shader.scene();
  for (uint32_t i = 0; i < scene.instances.size(); ++i)
    if (!constantColour(impl_->shader, i)) return true;
  return false;
}

PrimaryHitShader::PrimaryHitShader(const Shader& shader, ShadingPath path)
    : impl_(std::make_unique<Impl>(shader, path)) {}

PrimaryHitShader::~PrimaryHitShader() = default;

void PrimaryHitShader::shade(const PrimaryHitBlock& h, glm::vec4* colors) {
  Impl& s = *impl_;
  const auto shadeHit = [&](size_t k) {
    ShadeHit one;
    one.instance = h.runInstance[h.run[k]];
    one.triangle = h.runTriangle[h.run[k]];
    one.b1 = h.b1[k];
    one.b2 = h.b2[k];
    one.direction = glm::dvec3(h.dirX[k], h.dirY[k], h.dirZ[k]);
    one.footprintPosition = glm::dvec2(h.footprintX[k], h.footprintY[k]);
    colors[h.colorIndex[k]] = shadeReference(s.shader, one);
  };
  if (s.reference) {
    for (size_t k = 0; k < h.count; ++k) shadeHit(k);
    return;
  }
  if (s.shadeConstant(h, colors)) return;
  if (!h.dirX) throw std::logic_error("PrimaryHitShader: a block without hit inputs on a lit instance");
  if (h.run64 && h.runFirst) {
    if (!s.block) s.block.emplace(s.shader);
    if (s.block->shadeInPlace(h, colors)) return;
  }
  for (size_t first = 0, end = 0; first < h.count; first = end) {
    const int32_t run = h.run[first];
    if (h.runFirst) {
      end = h.runFirst[run + 1];
    } else {
      for (end = first + 1; end < h.count && h.run[end] == run; ++end) {
      }
    }
    s.enterInstance(h.runInstance[run]);
    if (s.scalar) {
      for (size_t k = first; k < end; ++k) shadeHit(k);
      continue;
    }
    if (!s.block) s.block.emplace(s.shader);
    if (s.block->used() + (end - first) > kBlock) s.block->run();  // more hits than a block: in pieces
    for (size_t piece = first; piece < end; piece += kBlock) {
      const size_t pieceEnd = std::min(end, piece + kBlock);
      if (piece > first) s.block->run();
      s.block->addRun(h, piece, pieceEnd, *s.material, colors);
    }
  }
  if (s.block) s.block->run();
}

void shadePrimaryHits(const Shader& shader, const ShadeHit* hits, size_t count, glm::vec4* colors,
                      ShadingPath path) {
  shadePrimaryHits(shader, hits, count, colors, nullptr, path);
}

void refinePrimaryHits(const Scene& scene, const Ray* rays, const SampleHit* hits,
                       const glm::dvec2* footprintPositions, size_t count, ShadeHit* out) {
  using kernel_detail::kRefineBlock;
  using kernel_detail::RefineBlock;
  RefineBlock b;
  const size_t vectorLanes = HWY_DYNAMIC_DISPATCH(RefineLanes)();
  uint32_t runInstance = kNoId, runTriangle = kNoId;
  TrianglePlane plane{};
  for (size_t first = 0; first < count; first += kRefineBlock) {
    const size_t used = std::min(kRefineBlock, count - first);
    for (size_t k = 0; k < used; ++k) {
      const SampleHit& hit = hits[first + k];
      const Ray& ray = rays[first + k];
      // A triangle's plane once per run of hits on it (the memo's values).
      if (hit.instance != runInstance || hit.triangle != runTriangle) {
        plane = trianglePlane(scene, hit.instance, hit.triangle);
        runInstance = hit.instance;
        runTriangle = hit.triangle;
      }
      b.ax[k] = plane.a.x, b.ay[k] = plane.a.y, b.az[k] = plane.a.z;
      b.e1x[k] = plane.e1.x, b.e1y[k] = plane.e1.y, b.e1z[k] = plane.e1.z;
      b.e2x[k] = plane.e2.x, b.e2y[k] = plane.e2.y, b.e2z[k] = plane.e2.z;
      b.slot1[k] = double(plane.slot1);
      b.slot2[k] = double(plane.slot2);
      b.ox[k] = ray.origin.x, b.oy[k] = ray.origin.y, b.oz[k] = ray.origin.z;
      b.dx[k] = ray.direction.x, b.dy[k] = ray.direction.y, b.dz[k] = ray.direction.z;
      b.depthPerT[k] = ray.depthPerT;
    }
    // Padding: a unit plane z = 0 seen from +z, never read back.
    b.lanes = (used + vectorLanes - 1) / vectorLanes * vectorLanes;
    for (size_t k = used; k < b.lanes; ++k) {
      b.ax[k] = b.ay[k] = b.az[k] = 0.0;
      b.e1x[k] = 1.0, b.e1y[k] = b.e1z[k] = 0.0;
      b.e2y[k] = 1.0, b.e2x[k] = b.e2z[k] = 0.0;
      b.slot1[k] = 1.0, b.slot2[k] = 2.0;
      b.ox[k] = b.oy[k] = 0.0, b.oz[k] = 1.0;
      b.dx[k] = b.dy[k] = 0.0, b.dz[k] = -1.0;
      b.depthPerT[k] = 1.0;
    }
    HWY_DYNAMIC_DISPATCH(LanesRefine)(&b);
    for (size_t k = 0; k < used; ++k) {
      const SampleHit& hit = hits[first + k];
      ShadeHit& s = out[first + k];
      s.instance = hit.instance;
      s.triangle = hit.triangle;
      const bool refined = b.refined[k] != 0.0;
      s.b1 = refined ? float(b.b1[k]) : hit.b1;
      s.b2 = refined ? float(b.b2[k]) : hit.b2;
      s.direction = rays[first + k].direction;
      s.footprintPosition = footprintPositions[first + k];
      s.throughput = 1.0f;
    }
  }
}

const char* shadingKernelTarget() {
  // The target HWY_DYNAMIC_DISPATCH picks: the best one compiled and supported.
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  return targets.empty() ? "none" : hwy::TargetName(targets.front());
}

}  // namespace rastray

#endif  // HWY_ONCE
