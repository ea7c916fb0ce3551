// The entry point of the demo-model module (demo/demo_module.hpp).
#include <geode/demo/demo_models.hpp>
#include <geode/demo/demo_module.hpp>

extern "C" __attribute__((visibility("default"))) const geode::demo::DemoModule*
geode_demo_module() {
  static const geode::demo::DemoModule module{
      &geode::demo::demo_model, &geode::demo::demo_model_names, &geode::demo::corner_study_models};
  return &module;
}
