#pragma once
// The demo models as a loadable module: `geode demo` opens it at run time (cli/demo_module.cpp)
// so that libgmsh, and the hundred-odd libraries it needs, are loaded by that command only and
// every other command starts without them (docs/developer-guide.md, "Startup"). The module is
// built from demo/module/demo_module.cpp over the geode_demo library; its one exported symbol,
// kDemoModuleEntry, returns this table.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::demo {

struct DemoModule {
  primal::Model (*model)(const std::string& name, int n);  // demo_model
  const std::vector<std::string>& (*names)();              // demo_model_names
  // corner_study_models: the models' builders run code of the module, which stays loaded.
  std::vector<std::pair<std::string, std::function<primal::Model()>>> (*corner_study_models)(int n);
};

inline constexpr const char* kDemoModuleEntry = "geode_demo_module";

}  // namespace geode::demo
