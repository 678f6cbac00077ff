#include "common/render_output.h"

namespace rastray {

void CounterSet::set(const std::string& name, uint64_t value) {
  for (auto& [n, v] : values)
    if (n == name) {
      v = value;
      return;
    }
  values.emplace_back(name, value);
}

void CounterSet::add(const std::string& name, uint64_t value) {
  for (auto& [n, v] : values)
    if (n == name) {
      v += value;
      return;
    }
  values.emplace_back(name, value);
}

uint64_t CounterSet::get(const std::string& name) const {
  for (const auto& [n, v] : values)
    if (n == name) return v;
  return 0;
}

void CounterSet::merge(const CounterSet& other) {
  for (const auto& [n, v] : other.values) add(n, v);
}

}  // namespace rastray
