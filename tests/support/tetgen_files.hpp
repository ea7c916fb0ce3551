#pragma once
// TetGen's output files as tests read them (its .node and .ele formats: a header line, then one
// numbered line per item; the .poly the test wrote numbers from 0 or 1, and TetGen keeps that
// first index). Tests that mesh realistic tet parts with the tetgen command use these.
#include <doctest/doctest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/primal/model.hpp>

namespace geode::test {

// The points of a .node file, in order.
inline std::vector<primal::Point> read_tetgen_nodes(const std::filesystem::path& path) {
  std::ifstream f(path);
  REQUIRE(f);
  std::size_t n = 0;
  int dim = 0, attrs = 0, markers = 0;
  f >> n >> dim >> attrs >> markers;
  std::vector<primal::Point> points(n);
  for (primal::Point& p : points) {
    long id = 0;
    std::string rest;
    f >> id >> p.x() >> p.y() >> p.z();
    std::getline(f, rest);
  }
  REQUIRE(f);
  return points;
}

// The tets of a .ele file, their nodes less `first` (the .poly's first index): positions in
// `points`, read_tetgen_nodes' list, each tet oriented to a positive volume there (TetGen's
// orientation follows its input's facets).
inline std::vector<std::array<primal::Index, 4>> read_tetgen_tets(
    const std::filesystem::path& path, primal::Index first,
    const std::vector<primal::Point>& points) {
  std::ifstream f(path);
  REQUIRE(f);
  std::size_t n = 0;
  int per = 0, attrs = 0;
  f >> n >> per >> attrs;
  std::vector<std::array<primal::Index, 4>> tets(n);
  for (auto& t : tets) {
    long id = 0;
    std::string rest;  // region attributes, if any
    f >> id >> t[0] >> t[1] >> t[2] >> t[3];
    std::getline(f, rest);
    for (primal::Index& v : t) {
      v -= first;
      if (v < 0 || primal::index_cast<std::size_t>(v) >= points.size()) {
        FAIL("a tet node outside the .node file: " << v + first);
      }
    }
    auto at = [&](std::size_t k) -> const primal::Point& {
      return points[primal::index_cast<std::size_t>(t[k])];
    };
    if (primal::tet_volume(at(0), at(1), at(2), at(3)) < 0.0) std::swap(t[1], t[2]);
  }
  REQUIRE(f);
  return tets;
}

}  // namespace geode::test
