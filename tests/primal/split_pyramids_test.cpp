// split_pyramids' choice of diagonal is the model's, not its units' or position's.
#include <doctest/doctest.h>

#include <vector>

#include <geode/primal/model.hpp>
#include <geode/primal/split_pyramids.hpp>

using namespace geode;
using namespace geode::primal;

TEST_CASE("split_pyramids: a symmetric pyramid's diagonal does not change with scale or offset") {
  // Over a square its two diagonals' tets are equal but for rounding, which changes with the
  // units and the position: compared exactly, the same model in millimetres or far from the
  // origin got the other diagonal, so another mesh (found by a fault hunt).
  const std::vector<Point> unit = {{0, 0, 0},
                                   {1, 0, 0},
                                   {1, 1, 0},
                                   {0, 1, 0},
                                   {0.5, 0.5, 0.7},
                                   // a second pyramid, rotated a little, beside the first
                                   {2, 0, 0},
                                   {2.8, 0.6, 0},
                                   {2.2, 1.4, 0},
                                   {1.4, 0.8, 0},
                                   {1.8, 0.7, 0.9}};
  const auto diagonals = [&](double scale, const Point& offset) {
    Model m;
    for (const Point& p : unit) m.points.push_back(scale * p + offset);
    m.pyramids = {{0, 1, 2, 3, 4}, {5, 6, 7, 8, 9}};
    return split_pyramids(m).diagonal;
  };
  const std::vector<int> first = diagonals(1.0, Point::Zero());
  for (const double scale : {1e-12, 1e-9, 1e-6, 1e-3, 0.1, 3.0, 1e3, 1e6, 1e9, 1e12})
    for (const Point& offset :
         {Point(0, 0, 0), Point(5e5, 4e6, 0), Point(-3.3, 7.1, 2.9), Point(1e-3, 0, 0)}) {
      CAPTURE(scale);
      CAPTURE(offset.transpose());
      CHECK(diagonals(scale, scale * offset) == first);
    }
}
