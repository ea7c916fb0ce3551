#pragma once
// Running the built `geode` command from a test (GEODE_CLI_PATH, set by CMake for the test
// programs); scratch files come from support/temp_dir.hpp. Header-only: the path is known where the
// tests are compiled, not in the fixtures library.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stdlib.h>

#include <cstdio>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "support/temp_dir.hpp"

namespace geode::test {

struct CliRun {
  int code = -1;
  std::string out;
};

// Runs `geode <args>` through the shell, capturing standard output, and standard error with it
// when `with_stderr` (dropped otherwise).
inline CliRun geode_cli(const std::string& args, bool with_stderr = false) {
  CliRun r;
  const std::string cmd =
      std::string(GEODE_CLI_PATH) + " " + args + (with_stderr ? " 2>&1" : " 2>/dev/null");
  FILE* p = ::popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = ::pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// The progress a command printed on stderr (`err`: its standard error alone, e.g. its report
// sent to a file with -o) is its stage lines (cli/progress.hpp Progress::stage_done), one per
// stage as it ends, in order: "geode: " + a line starting with starts[i] + " (S.S s)". A run
// this short shows no progress step (steps wait 2 s before they show).
inline void check_stage_lines(const std::string& err, const std::vector<std::string>& starts) {
  INFO(err);
  std::vector<std::string> lines;
  std::istringstream in(err);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  REQUIRE(lines.size() == starts.size());
  const std::regex timed(R"(geode: .* \([0-9]+\.[0-9] s\))");
  for (std::size_t i = 0; i < lines.size(); ++i) {
    CHECK(lines[i].rfind("geode: " + starts[i], 0) == 0);
    CHECK(std::regex_match(lines[i], timed));
  }
}

// An environment variable for one scope (the commands run as children inherit it).
struct ScopedEnv {
  const char* name;
  ScopedEnv(const char* n, const std::string& value) : name(n) { ::setenv(n, value.c_str(), 1); }
  ~ScopedEnv() { ::unsetenv(name); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;
};

}  // namespace geode::test
