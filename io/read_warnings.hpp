#pragma once
// Warnings of the readers: what a file holds that a Model cannot carry as given (an entity in
// several physical volumes), one line each naming the file. Printed to stderr as
// "geode: warning: ..." unless a ReadWarnings object on the same thread collects them.
#include <span>
#include <string>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::io {

void read_warning(const std::string& message);

// Says of each group primal::separate_node_set_ids moved which node set it became: "`source`:
// `line_word` 5 'edge' and `point_word` 5 'corner' would both be node set 5: the lines are node
// set 15".
void warn_moved_node_sets(std::span<const primal::TaggedCells> groups,
                          std::span<const primal::MovedGroup> moved, const std::string& source,
                          const std::string& line_word, const std::string& point_word);

// While alive, collects this thread's read warnings instead of printing them.
class ReadWarnings {
 public:
  ReadWarnings();
  ~ReadWarnings();
  ReadWarnings(const ReadWarnings&) = delete;
  ReadWarnings& operator=(const ReadWarnings&) = delete;
  const std::vector<std::string>& messages() const { return messages_; }

 private:
  friend void read_warning(const std::string& message);
  std::vector<std::string> messages_;
  ReadWarnings* previous_ = nullptr;
};

}  // namespace geode::io
