#include "common/sampling.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace rastray {

namespace {

// Direct3D 11 standard sample patterns, in 1/16 pixel from the centre.
constexpr int kPattern2[][2] = {{4, 4}, {-4, -4}};
constexpr int kPattern4[][2] = {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}};
constexpr int kPattern8[][2] = {{1, -3}, {-1, 3}, {5, 1}, {-3, -5}, {-5, 5}, {-7, -1}, {3, 7}, {7, -7}};
constexpr int kPattern16[][2] = {{1, 1},  {-1, -3}, {-3, 2},  {4, -1}, {-5, -2}, {2, 5},  {5, 3}, {3, -5},
                                 {-2, 6}, {0, -7},  {-4, -6}, {-6, 4}, {-8, 0},  {7, -4}, {6, 7}, {-7, -8}};

template <size_t N>
std::vector<glm::dvec2> fromPattern(const int (&pattern)[N][2]) {
  std::vector<glm::dvec2> out;
  for (const auto& p : pattern) out.emplace_back(0.5 + p[0] / 16.0, 0.5 + p[1] / 16.0);
  return out;
}

int gridSide(int spp) {
  if (spp <= 0 || spp > kMaxGridSide * kMaxGridSide) return 0;
  int n = static_cast<int>(std::lround(std::sqrt(static_cast<double>(spp))));
  return (n > 4 && n * n == spp) ? n : 0;
}

}  // namespace

bool isSupportedSampleCount(int spp) {
  return spp == 1 || spp == 2 || spp == 4 || spp == 8 || spp == 16 || gridSide(spp) > 0;
}

std::string supportedSampleCounts() {
  return "1, 2, 4, 8, 16 or n*n for 4 < n <= " + std::to_string(kMaxGridSide) + ", at most " +
         std::to_string(kMaxGridSide * kMaxGridSide);
}

std::vector<glm::dvec2> samplePositions(int spp) {
  switch (spp) {
    case 1:
      return {glm::dvec2(0.5, 0.5)};
    case 2:
      return fromPattern(kPattern2);
    case 4:
      return fromPattern(kPattern4);
    case 8:
      return fromPattern(kPattern8);
    case 16:
      return fromPattern(kPattern16);
    default:
      break;
  }
  const int n = gridSide(spp);
  if (n == 0)
    throw std::invalid_argument("unsupported sample count " + std::to_string(spp) + " (use " +
                                supportedSampleCounts() + ")");
  std::vector<glm::dvec2> out;
  out.reserve(static_cast<size_t>(spp));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) out.emplace_back((i + 0.5) / n, (j + 0.5) / n);
  return out;
}

int centreSampleIndex(int spp) {
  const auto positions = samplePositions(spp);
  int best = 0;
  double bestDistance = std::numeric_limits<double>::infinity();
  for (int i = 0; i < static_cast<int>(positions.size()); ++i) {
    const glm::dvec2 d = positions[static_cast<size_t>(i)] - glm::dvec2(0.5);
    const double distance = glm::dot(d, d);
    if (distance < bestDistance) {  // strict: ties keep the lowest index
      bestDistance = distance;
      best = i;
    }
  }
  return best;
}

}  // namespace rastray
