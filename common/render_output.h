// What every renderer hands back: the image and AOVs, optionally every
// sample and layer, and the work it did (SPEC §6, §8).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "common/image.h"

namespace rastray {

// Named work counters in a fixed order (printed by --stats, written by
// --json). Renderers count per thread and add the totals here.
struct CounterSet {
  std::vector<std::pair<std::string, uint64_t>> values;

  void set(const std::string& name, uint64_t value);
  void add(const std::string& name, uint64_t value);
  uint64_t get(const std::string& name) const;  // 0 when absent
  void merge(const CounterSet& other);          // adds, keeping first-seen order
};

struct RenderOutput {
  FlatImage image;
  // Every sample of every pixel and every transparency layer, front to
  // back (DeepImage order); filled only when a caller asks for it (deep
  // EXR output, cross-validation).
  DeepImage samples;
  bool hasSamples = false;
  CounterSet counters;
  std::vector<std::pair<std::string, double>> timings;  // stage, seconds
  std::vector<std::string> passesRun;
  std::vector<std::string> passesLeftOut;  // each with its reason
};

}  // namespace rastray
