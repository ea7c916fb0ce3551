#include <geode/primal/grid_model.hpp>

#include <algorithm>
#include <utility>

namespace geode::primal {

Model grid_model(std::array<int, 3> cells, double h,
                 const std::function<bool(int, int, int)>& is_tet) {
  // Plain variables, not a structured binding: clang 14 (the fuzz build) cannot capture those.
  const int nx = cells[0], ny = cells[1], nz = cells[2];
  Model model;
  auto id = [&](int i, int j, int k) { return index_cast(i + (nx + 1) * (j + (ny + 1) * k)); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) model.points.emplace_back(i * h, j * h, k * h);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        if (!is_tet(i, j, k)) {
          model.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                                 id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                                 id(i, j + 1, k + 1)});
          model.hex_block.push_back(1);
          continue;
        }
        // Kuhn split: one tet per order in which the three axes are stepped from the lowest
        // corner to the highest.
        std::array<int, 3> axes{0, 1, 2};
        do {
          std::array<int, 3> at{i, j, k};
          std::array<Index, 4> tet{};
          tet[0] = id(at[0], at[1], at[2]);
          for (int s = 0; s < 3; ++s) {
            ++at[index_cast<std::size_t>(axes[index_cast<std::size_t>(s)])];
            tet[index_cast<std::size_t>(s + 1)] = id(at[0], at[1], at[2]);
          }
          const auto& p = model.points;
          if (tet_volume(p[index_cast<std::size_t>(tet[0])], p[index_cast<std::size_t>(tet[1])],
                         p[index_cast<std::size_t>(tet[2])],
                         p[index_cast<std::size_t>(tet[3])]) < 0)
            std::swap(tet[1], tet[2]);
          model.tets.push_back(tet);
          model.tet_block.push_back(2);
        } while (std::next_permutation(axes.begin(), axes.end()));
      }
  return model;
}

}  // namespace geode::primal
