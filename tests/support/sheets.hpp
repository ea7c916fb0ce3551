#pragma once
// Sheets the stc tests build arrangements of: planes and spheres, each the zero set of its field.
#include <string>

#include <geode/stc/arrangement.hpp>

namespace geode::test {

// The plane through `p` with normal `n` (zero on it, positive on n's side).
inline stc::Sheet plane(const stc::Point& p, const stc::Point& n, const std::string& name) {
  return {name, [p, n](const stc::Point& x) { return (x - p).dot(n); }, "plane"};
}

// The sphere of centre `c` and radius `r` (negative inside).
inline stc::Sheet sphere(const stc::Point& c, double r, const std::string& name) {
  return {name, [c, r](const stc::Point& x) { return (x - c).norm() - r; }, "sphere"};
}

}  // namespace geode::test
