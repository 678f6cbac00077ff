#include "bench/peers/obj_export.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "common/error.h"

namespace rastray::peers {

namespace {

// FNV-1a, 64 bit: a cache key, not a security measure.
uint64_t fnv1a(const std::string& bytes) {
  uint64_t h = 1469598103934665603ull;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

std::string cachedObjPath(const std::string& scenePath, const glm::dvec3& origin,
                          const std::string& workDir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path canonical = fs::canonical(scenePath, ec);
  if (ec) throw InputError(scenePath, "", "cannot open: " + ec.message());
  const auto size = fs::file_size(canonical, ec);
  const auto mtime = fs::last_write_time(canonical, ec).time_since_epoch().count();
  if (ec) throw InputError(scenePath, "", "cannot read its size and time: " + ec.message());
  std::string key = canonical.string() + '\n' + std::to_string(size) + '\n' + std::to_string(mtime) + '\n';
  for (int i = 0; i < 3; ++i) {
    uint64_t bits;
    std::memcpy(&bits, &origin[i], sizeof bits);
    key += std::to_string(bits) + ' ';
  }
  char name[32];
  std::snprintf(name, sizeof name, "-%016llx.obj", static_cast<unsigned long long>(fnv1a(key)));
  return (fs::path(workDir) / (canonical.stem().string() + name)).string();
}

void writeObj(const Scene& scene, const std::string& path) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  FILE* f = std::fopen(tmp.c_str(), "w");
  if (!f) throw InputError(path, "", std::string("cannot write: ") + std::strerror(errno));
  std::fprintf(f, "# rastray flattened scene %s, rebased on (%.17g, %.17g, %.17g)\n", scene.path.c_str(),
               scene.origin.x, scene.origin.y, scene.origin.z);
  for (const glm::vec3& p : scene.positions) std::fprintf(f, "v %.9g %.9g %.9g\n", p.x, p.y, p.z);
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    std::fprintf(f, "g instance_%zu\n", i);
    for (uint32_t t = 0; t < inst.triangleCount; ++t) {
      const glm::uvec3& tri = scene.triangles[inst.firstTriangle + t];
      std::fprintf(f, "f %u %u %u\n", tri.x + 1, tri.y + 1, tri.z + 1);  // OBJ counts from 1
    }
  }
  const bool ok = std::ferror(f) == 0;
  if (std::fclose(f) != 0 || !ok) {
    std::remove(tmp.c_str());
    throw InputError(path, "", "writing failed");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError(path, "", std::string("cannot rename into place: ") + std::strerror(errno));
  }
}

}  // namespace rastray::peers
