#pragma once
// Warnings of the readers: what a file holds that a Model cannot carry as given (an entity in
// several physical volumes), one line each naming the file. Printed to stderr as
// "geode: warning: ..." unless a ReadWarnings object on the same thread collects them.
#include <string>
#include <vector>

namespace geode::io {

void read_warning(const std::string& message);

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
