#pragma once
// The demo models for `geode demo`, loaded at run time (demo/demo_module.hpp); InvalidInput
// naming what failed when the module cannot be found or opened.
#include <geode/demo/demo_module.hpp>

namespace geode::cli {

const demo::DemoModule& demo_module();

}  // namespace geode::cli
