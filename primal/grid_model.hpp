#pragma once
// Small synthetic mixed hex + tet models on a grid (tests, benches, examples).
#include <array>
#include <functional>

#include <geode/primal/model.hpp>

namespace geode::primal {

// A grid of cells * h on [0, cells.x*h] x ...; node (i,j,k) is number
// i + (nx+1) * (j + (ny+1) * k). Cell (i,j,k) is a hex (block 1) unless is_tet(i,j,k), then it
// is split into 6 positive tets (block 2) around its diagonal from its lowest to its highest
// corner (Kuhn / Freudenthal). Every cell face is then split along the diagonal joining its
// lowest and highest corners, so the tets conform to each other and to the hex faces they touch
// (each such quad is two tet triangles). No node sets or side sets.
Model grid_model(std::array<int, 3> cells, double h,
                 const std::function<bool(int, int, int)>& is_tet);

}  // namespace geode::primal
