#include <geode/parallel/partition.hpp>

#include <metis.h>

#include <cstdint>
#include <stdexcept>
#include <string>

#include <geode/primal/submodel.hpp>

namespace geode::parallel {

std::vector<int> partition_elements(const primal::Model& model, int parts) {
  const auto offsets = primal::element_offsets(model);
  const std::size_t n = offsets.back();
  std::vector<int> part(n, 0);
  if (parts <= 1 || n == 0) return part;
  std::vector<idx_t> eptr{0}, eind, weight;
  eptr.reserve(n + 1);
  eind.reserve(n * 8);
  weight.reserve(n);
  for (primal::ElementKind kind : primal::kElementKinds)
    for (std::size_t e = 0; e < primal::element_count(model, kind); ++e) {
      const auto corners = primal::element_corners(model, {kind, primal::index_cast(e)});
      for (primal::Index v : corners) eind.push_back(v);
      eptr.push_back(static_cast<idx_t>(eind.size()));
      // The hexes it dices into (8, 4, 6; a pyramid as its two tets): the parts' output balanced.
      weight.push_back(kind == primal::ElementKind::kPyramid ? 8
                                                             : static_cast<idx_t>(corners.size()));
    }
  idx_t ne = static_cast<idx_t>(n), nn = static_cast<idx_t>(model.points.size()), ncommon = 3,
        np = parts, objval = 0;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;
  std::vector<idx_t> epart(n), npart(model.points.size());
  const int status =
      METIS_PartMeshDual(&ne, &nn, eptr.data(), eind.data(), weight.data(), nullptr, &ncommon, &np,
                         nullptr, options, &objval, epart.data(), npart.data());
  if (status != METIS_OK)
    throw std::runtime_error("METIS_PartMeshDual failed (status " + std::to_string(status) + ")");
  for (std::size_t e = 0; e < n; ++e) part[e] = static_cast<int>(epart[e]);
  return part;
}

std::vector<int> ranks_of_parts(const std::vector<int>& part, int parts, int ranks) {
  if (parts < ranks || ranks < 1) return {};
  std::vector<int> rank(part.size());
  for (std::size_t e = 0; e < part.size(); ++e)
    rank[e] = static_cast<int>(static_cast<std::int64_t>(part[e]) * ranks / parts);
  return rank;
}

}  // namespace geode::parallel
