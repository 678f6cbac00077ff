// How much memory a command may use, and estimates of what a load or a
// render will need, checked before the big allocations: a request above
// the budget is refused with exit status 2 and a line naming what would
// take the memory, never left to the kernel's out-of-memory killer.
//
// Estimates are upper bounds of the process's peak resident set (RSS),
// built from the sizes of the structures the renderers allocate; their
// accuracy against measured peaks is tested (tests/app/memory_test.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace rastray {

struct MemoryBudget {
  uint64_t bytes = 0;
  // Where the limit came from, for messages: "--max-memory 4G" or
  // "the default --max-memory, 80% of 23.4 GiB physical memory".
  std::string origin;

  // 80 % of the machine's physical memory, or of the cgroup's memory.max
  // when that is lower (containers): the rest is left to the system.
  static MemoryBudget machineDefault();
  // "--max-memory" values: bytes, or a number with K, M, G or T (powers of
  // 1024; "GiB" and "GB" read the same). Throws InputError("command line",
  // "--max-memory", ...) for anything else, zero or beyond 2^63.
  static MemoryBudget parse(const std::string& text);
};

// Parts of an estimate, each named for the message that refuses it.
class MemoryEstimate {
 public:
  void add(const std::string& part, uint64_t bytes);  // adds to a part of the same name
  uint64_t total() const;
  const std::vector<std::pair<std::string, uint64_t>>& parts() const { return parts_; }
  // The largest parts, largest first: "deep samples 31.2 GiB, frame 120 MiB".
  std::string largest(size_t count) const;

 private:
  std::vector<std::pair<std::string, uint64_t>> parts_;
};

// "512 B", "12.0 MiB", "3.50 GiB".
std::string formatBytes(uint64_t bytes);

// This process's resident set now (/proc/self/statm) and its peak so far
// (getrusage); 0 when unknown.
uint64_t currentRssBytes();
uint64_t peakRssBytes();
// Physical memory (sysconf), lowered to the cgroup v2/v1 limit when set.
uint64_t physicalMemoryBytes();

// Throws InputError(file, element, "<what> needs about X (largest parts)
// above the memory limit Y (<origin>)") when the estimate exceeds the
// budget. `what` names the work: "rendering 1920x1080 at 64 spp".
void checkMemory(const MemoryEstimate& estimate, const MemoryBudget& budget, const std::string& file,
                 const std::string& element, const std::string& what);

// Saturating arithmetic for estimates: an absurd request must give a huge
// estimate, never a wrapped small one.
inline uint64_t mulSat(uint64_t a, uint64_t b) {
  uint64_t r;
  return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
}
inline uint64_t addSat(uint64_t a, uint64_t b) {
  uint64_t r;
  return __builtin_add_overflow(a, b, &r) ? UINT64_MAX : r;
}

}  // namespace rastray
