// Progress on stderr (cli/progress.hpp).
#include "cli/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <iostream>

#include "cli/conventions.hpp"

namespace geode::cli {

Progress::Progress(bool quiet, bool terminal) : quiet_(quiet), terminal_(terminal) {}

Progress Progress::for_stderr(bool quiet) { return Progress(quiet, ::isatty(STDERR_FILENO) == 1); }

void Progress::end_bar() {
  if (bar_drawn_) std::cerr << "\n";
  bar_drawn_ = false;
}

void Progress::stage(const std::string& line) {
  if (quiet_) return;
  end_bar();
  std::cerr << "geode: " << line << std::endl;
}

void Progress::stage_done(const std::string& line) {
  const auto now = Clock::now();
  const double seconds = std::chrono::duration<double>(now - stage_started_).count();
  stage_started_ = now;
  stage(stage_line(line, seconds));
}

void Progress::step(const std::string& what, std::size_t done, std::size_t total) {
  if (quiet_) return;
  show(what, done, total, std::to_string(done) + " / " + std::to_string(total) + " " + what);
}

void Progress::share(const std::string& what, std::size_t done, std::size_t total) {
  if (quiet_) return;
  const std::size_t percent = total ? 100 * std::min(done, total) / total : 100;
  show(what, done, total, std::to_string(percent) + " % " + what);
}

void Progress::show(const std::string& what, std::size_t done, std::size_t total,
                    const std::string& count) {
  const auto now = Clock::now();
  if (what != what_ || done == 0) {
    end_bar();
    what_ = what;
    started_ = now;
    last_ = now;
    finished_ = false;
  }
  const bool finished = done >= total;
  if (finished && finished_) return;  // its end said (or passed) once
  finished_ = finished;
  if (now - started_ < kDelay) return;  // short steps stay silent
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(now - started_).count();
  if (terminal_) {
    if (!finished && bar_drawn_ && now - last_ < kRedraw) return;
    const std::size_t width = 30, filled = total ? width * std::min(done, total) / total : width;
    std::cerr << "\rgeode: [" << std::string(filled, '#') << std::string(width - filled, '.')
              << "] " << count << " (" << seconds << " s)" << std::flush;
    bar_drawn_ = true;
    if (finished) end_bar();
  } else {
    if (!finished && now - last_ < kLogEvery) return;
    std::cerr << "geode: " << count << " (" << seconds << " s)" << std::endl;
  }
  last_ = now;
}

}  // namespace geode::cli
