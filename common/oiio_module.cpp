#include "common/oiio_module.h"

#include <dlfcn.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/memory_budget.h"

namespace rastray {

namespace {

constexpr const char* kModuleName = "rastray_oiio.so";

std::atomic<bool> loaded{false};

// Where to look, in order: beside the running program, one folder up (the
// test, bench and fuzz programs sit in subfolders of the build), beside the
// shared object holding this code when that is not the program (the Python
// module, python/, installed with the module beside it), then the path the
// build wrote it to (a program run from elsewhere).
std::vector<std::string> candidatePaths() {
  std::vector<std::string> paths;
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    paths.push_back((self.parent_path() / kModuleName).string());
    paths.push_back((self.parent_path().parent_path() / kModuleName).string());
  }
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&candidatePaths), &info) && info.dli_fname && info.dli_fname[0] == '/') {
    const std::filesystem::path object(info.dli_fname);
    if (object != self) paths.push_back((object.parent_path() / kModuleName).string());
  }
#ifdef RASTRAY_OIIO_MODULE_PATH
  paths.push_back(RASTRAY_OIIO_MODULE_PATH);
#endif
  return paths;
}

const OiioFunctions* load() {
  static const OiioHost host = {kOiioModuleVersion, &checkExrHeaders, &checkFailed, &formatBytes};
  std::string tried;
  for (const std::string& path : candidatePaths()) {
    if (access(path.c_str(), F_OK) != 0) {
      tried += "\n  " + path + ": not there";
      continue;
    }
    // RTLD_LOCAL: OpenImageIO's symbols stay the module's; the module is
    // never closed (its functions are kept in a static table).
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      tried += "\n  " + path + ": " + dlerror();
      continue;
    }
    using Entry = const OiioFunctions* (*)(const OiioHost*);
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, "rastray_oiio_module"));
    const OiioFunctions* functions = entry ? entry(&host) : nullptr;
    if (functions && functions->version == kOiioModuleVersion) {
      loaded = true;
      return functions;
    }
    tried += "\n  " + path + ": not a module of this build (interface version " +
             std::to_string(kOiioModuleVersion) + " expected)";
  }
  throw std::runtime_error(std::string("cannot load ") + kModuleName +
                           " (rastray's OpenImageIO module, built beside the rastray program):" + tried);
}

}  // namespace

const OiioFunctions& oiioModule() {
  static const OiioFunctions* functions = load();
  return *functions;
}

bool oiioModuleLoaded() { return loaded; }

}  // namespace rastray
