#include <geode/io/read_warnings.hpp>

#include <iostream>

#include <geode/io/names.hpp>

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

void warn_moved_node_sets(std::span<const primal::TaggedCells> groups,
                          std::span<const primal::MovedGroup> moved, const std::string& source,
                          const std::string& line_word, const std::string& point_word) {
  const auto named = [](const std::string& name) {
    return name.empty() ? std::string() : " '" + sanitize_name(name) + "'";
  };
  for (const primal::MovedGroup& m : moved) {
    const primal::TaggedCells& line = groups[m.group];
    std::string point_name;
    for (const primal::TaggedCells& g : groups)
      if (g.dim == 0 && g.id == m.was) point_name = g.name;
    read_warning(source + ": " + line_word + " " + std::to_string(m.was) + named(line.name) +
                 " and " + point_word + " " + std::to_string(m.was) + named(point_name) +
                 " would both be node set " + std::to_string(m.was) + ": the lines are node set " +
                 std::to_string(line.id));
  }
}

}  // namespace geode::io
