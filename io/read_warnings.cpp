#include <geode/io/read_warnings.hpp>

#include <iostream>

namespace geode::io {

namespace {
thread_local ReadWarnings* collector = nullptr;
}

ReadWarnings::ReadWarnings() : previous_(collector) { collector = this; }
ReadWarnings::~ReadWarnings() { collector = previous_; }

void read_warning(const std::string& message) {
  if (collector) {
    collector->messages_.push_back(message);
    return;
  }
  std::cerr << "geode: warning: " << message << "\n";
}

}  // namespace geode::io
