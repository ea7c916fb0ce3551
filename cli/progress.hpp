#pragma once
// Progress of long work on stderr, one utility for every command: on a terminal a bar redrawn
// in place (at most ten times a second), in a log (stderr not a terminal) a line every few
// seconds; both only once a step has run for about 2 s, so short steps stay silent. Stage
// lines ("interface: 12 quads") are printed as they come. --quiet makes all of it silent;
// errors and warnings do not go through here and are never silenced.
#include <chrono>
#include <cstddef>
#include <string>

namespace geode::cli {

class Progress {
 public:
  using Clock = std::chrono::steady_clock;
  // `terminal`: draw a bar; otherwise log lines. Progress::for_stderr(quiet) picks it.
  Progress(bool quiet, bool terminal);
  static Progress for_stderr(bool quiet);

  void stage(const std::string& line);
  // A stage that has ended: "LINE (S s)", S the seconds since the previous stage_done (or since
  // this Progress was made), for commands whose stages say nothing while they run.
  void stage_done(const std::string& line);
  // `done` of `total` units of `what` (e.g. "buffer hexes"); a new `what` starts a new step.
  void step(const std::string& what, std::size_t done, std::size_t total);
  // The same for work counted in units that mean nothing to a user (primal::ValidityProgress):
  // shown as a percentage, "40 % of the output verified".
  void share(const std::string& what, std::size_t done, std::size_t total);

  // How long to wait before showing a step, and between log lines.
  static constexpr std::chrono::milliseconds kDelay{2000}, kLogEvery{5000}, kRedraw{100};

 private:
  void end_bar();
  // step() and share(): `count` is how the step reads ("3 / 8 buffer hexes").
  void show(const std::string& what, std::size_t done, std::size_t total, const std::string& count);
  bool quiet_, terminal_;
  std::string what_;
  Clock::time_point started_{}, last_{}, stage_started_ = Clock::now();
  bool bar_drawn_ = false;
  bool finished_ = false;  // the step has been told it is done
};

}  // namespace geode::cli
