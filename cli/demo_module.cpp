// The demo models, loaded on first use (demo/demo_module.hpp): from next to the executable (the
// build tree) or from the library directory beside its bin/ (an installed tree).
#include "cli/demo_module.hpp"

#include <dlfcn.h>

#include <filesystem>
#include <string>
#include <vector>

#include <geode/primal/errors.hpp>

namespace geode::cli {

namespace fs = std::filesystem;

const demo::DemoModule& demo_module() {
  static const demo::DemoModule* module = [] {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    const std::vector<fs::path> candidates{
        exe.parent_path() / GEODE_DEMO_MODULE,
        exe.parent_path() / GEODE_DEMO_MODULE_LIBDIR / GEODE_DEMO_MODULE};
    std::string errors;
    for (const fs::path& path : candidates) {
      void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!handle) {
        errors += std::string(errors.empty() ? "" : "; ") + dlerror();
        continue;
      }
      using Entry = const demo::DemoModule* (*)();
      if (auto entry = reinterpret_cast<Entry>(dlsym(handle, demo::kDemoModuleEntry)))
        return entry();
      errors += std::string(errors.empty() ? "" : "; ") + path.string() + ": no " +
                demo::kDemoModuleEntry;
    }
    throw InvalidInput("geode demo: the demo models cannot be loaded (" + errors + ")");
  }();
  return *module;
}

}  // namespace geode::cli
