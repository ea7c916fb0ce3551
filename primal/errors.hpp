#pragma once
// Exceptions for what a user can cause. Internal invariants use assert instead.
#include <stdexcept>
#include <string>
#include <string_view>

namespace geode {

namespace detail {
// The message as one line of valid UTF-8: control characters (a newline or a NUL read from a
// file) and bytes that are not UTF-8 become \xHH, so that what a file holds, quoted in a
// message, cannot break the one-line message, a terminal or Python's str of it.
std::string one_line(std::string_view message);
}  // namespace detail

// Bad input: a malformed file, an out-of-range index, an unknown option value. The message
// names the file (or argument), the line or element, and the reason.
struct InvalidInput : std::runtime_error {
  explicit InvalidInput(std::string_view message) : std::runtime_error(detail::one_line(message)) {}
};

// Input that is well-formed but topologically unusable: a non-conforming interface, an
// arrangement that is not in general position, a cell that is not a ball.
struct TopologyError : std::runtime_error {
  explicit TopologyError(std::string_view message)
      : std::runtime_error(detail::one_line(message)) {}
};

// Work stopped because its caller no longer needs it: long loops (the smoother's) end when the
// TBB task group they run in is cancelled, by its owner (conform's reference templates, built
// while the input is read, when the input is refused) or by another task's exception. Never
// shown to a user: whoever cancelled the group discards it.
struct Cancelled : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace geode
