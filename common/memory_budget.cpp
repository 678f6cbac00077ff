#include "common/memory_budget.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "common/error.h"

namespace rastray {

namespace {

// The budget leaves a fifth of the machine to the system and other work.
constexpr double kDefaultFraction = 0.8;

// A cgroup limit in bytes from a file holding a number ("max": none).
uint64_t cgroupLimit(const char* path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text) || text.empty() || !std::isdigit(static_cast<unsigned char>(text[0]))) return 0;
  try {
    return std::stoull(text);
  } catch (const std::exception&) {
    return 0;
  }
}

}  // namespace

uint64_t physicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGESIZE);
  uint64_t bytes = pages > 0 && pageSize > 0 ? mulSat(uint64_t(pages), uint64_t(pageSize)) : 0;
  // cgroup v2, then v1 (whose "no limit" is a huge number, beyond RAM).
  for (const char* path : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    const uint64_t limit = cgroupLimit(path);
    if (limit > 0 && (bytes == 0 || limit < bytes)) bytes = limit;
  }
  return bytes;
}

MemoryBudget MemoryBudget::machineDefault() {
  const uint64_t physical = physicalMemoryBytes();
  MemoryBudget b;
  if (physical == 0) {
    b.bytes = UINT64_MAX;
    b.origin = "no default --max-memory: physical memory unknown";
    return b;
  }
  b.bytes = uint64_t(double(physical) * kDefaultFraction);
  b.origin = "the default --max-memory, 80% of " + formatBytes(physical) + " physical memory";
  return b;
}

MemoryBudget MemoryBudget::parse(const std::string& text) {
  const auto bad = [&](const std::string& why) -> MemoryBudget {
    throw InputError("command line", "--max-memory", "'" + text + "' " + why);
  };
  size_t end = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &end);
  } catch (const std::exception&) {
    return bad("is not a size (e.g. 512M, 4G, 1.5T)");
  }
  std::string unit = text.substr(end);
  for (char& c : unit) c = char(std::toupper(static_cast<unsigned char>(c)));
  if (unit.size() == 3 && unit.substr(1) == "IB") unit.resize(1);
  if (unit.size() == 2 && unit[1] == 'B') unit.resize(1);
  double scale = 1.0;
  if (unit == "K")
    scale = 1024.0;
  else if (unit == "M")
    scale = 1024.0 * 1024.0;
  else if (unit == "G")
    scale = 1024.0 * 1024.0 * 1024.0;
  else if (unit == "T")
    scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  else if (!unit.empty() && unit != "B")
    return bad("has an unknown unit (use K, M, G or T)");
  const double bytes = value * scale;
  if (!(bytes >= 1.0) || !(bytes < 9.2e18)) return bad("must lie between 1 byte and 8 EiB");
  MemoryBudget b;
  b.bytes = uint64_t(bytes);
  b.origin = "--max-memory " + text;
  return b;
}

void MemoryEstimate::add(const std::string& part, uint64_t bytes) {
  for (auto& [name, value] : parts_)
    if (name == part) {
      value = addSat(value, bytes);
      return;
    }
  parts_.emplace_back(part, bytes);
}

uint64_t MemoryEstimate::total() const {
  uint64_t sum = 0;
  for (const auto& part : parts_) sum = addSat(sum, part.second);
  return sum;
}

std::string MemoryEstimate::largest(size_t count) const {
  std::vector<std::pair<std::string, uint64_t>> sorted = parts_;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string out;
  for (size_t i = 0; i < sorted.size() && i < count; ++i)
    out += (i ? ", " : "") + sorted[i].first + " " + formatBytes(sorted[i].second);
  return out;
}

std::string formatBytes(uint64_t bytes) {
  if (bytes == UINT64_MAX) return "more than 16 EiB";
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double v = double(bytes);
  int u = 0;
  while (v >= 1024.0 && u < 6) {
    v /= 1024.0;
    ++u;
  }
  char buf[32];
  if (u == 0)
    std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  else
    std::snprintf(buf, sizeof buf, v < 10.0 ? "%.2f %s" : "%.1f %s", v, units[u]);
  return buf;
}

uint64_t currentRssBytes() {
  std::ifstream in("/proc/self/statm");
  uint64_t size = 0, resident = 0;
  if (!(in >> size >> resident)) return 0;
  return resident * uint64_t(sysconf(_SC_PAGESIZE));
}

uint64_t peakRssBytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return uint64_t(usage.ru_maxrss) * 1024;  // Linux reports KiB
}

void checkMemory(const MemoryEstimate& estimate, const MemoryBudget& budget, const std::string& file,
                 const std::string& element, const std::string& what) {
  if (estimate.total() <= budget.bytes) return;
  throw InputError(file, element,
                   what + " needs about " + formatBytes(estimate.total()) + " (" + estimate.largest(3) +
                       "), above the memory limit of " + formatBytes(budget.bytes) + " (" + budget.origin +
                       ")");
}

}  // namespace rastray
