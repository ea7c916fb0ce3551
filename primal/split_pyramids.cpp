#include <geode/primal/split_pyramids.hpp>

#include <algorithm>
#include <map>

#include <geode/primal/dice.hpp>

namespace geode::primal {

std::array<std::array<Index, 4>, 2> pyramid_tets(const std::array<Index, 5>& p, int diagonal) {
  if (diagonal == 0) return {{{p[0], p[1], p[2], p[4]}, {p[0], p[2], p[3], p[4]}}};
  return {{{p[0], p[1], p[3], p[4]}, {p[1], p[2], p[3], p[4]}}};
}

PyramidSplit split_pyramids(const Model& model) {
  PyramidSplit out;
  out.model = model;
  Model& m = out.model;
  m.pyramids.clear(), m.pyramid_block.clear(), m.pyramid_ids.clear();
  const std::size_t np = model.pyramids.size();
  out.diagonal.assign(np, 0);
  out.tet_pyramid.assign(model.tets.size(), kInvalidIndex);
  if (np == 0) return out;

  // Per pyramid and diagonal: the least scaled Jacobian of its two tets diced.
  std::vector<std::array<double, 2>> quality(np);
  for (std::size_t p = 0; p < np; ++p)
    for (int d = 0; d < 2; ++d) {
      const auto tets = pyramid_tets(model.pyramids[p], d);
      quality[p][index_cast<std::size_t>(d)] = diced_min_scaled_jacobian(model.points, tets);
    }
  // Pyramids by base quad (its sorted nodes); a diagonal as its sorted node pair.
  std::map<std::array<Index, 4>, std::vector<std::size_t>> by_base;
  for (std::size_t p = 0; p < np; ++p) {
    std::array<Index, 4> key{model.pyramids[p][0], model.pyramids[p][1], model.pyramids[p][2],
                             model.pyramids[p][3]};
    std::sort(key.begin(), key.end());
    by_base[key].push_back(p);
  }
  auto pair_of = [&](std::size_t p, int d) {
    const auto& c = model.pyramids[p];
    const Index a = c[index_cast<std::size_t>(d)], b = c[index_cast<std::size_t>(d + 2)];
    return std::pair<Index, Index>{std::min(a, b), std::max(a, b)};
  };
  for (const auto& [key, members] : by_base) {
    double best = -2.0;
    std::pair<Index, Index> chosen{};
    for (int d = 0; d < 2; ++d) {
      const auto diagonal = pair_of(members.front(), d);
      double worst = 2.0;
      for (std::size_t p : members)
        worst = std::min(worst, quality[p][pair_of(p, 0) == diagonal ? 0 : 1]);
      if (worst > best) best = worst, chosen = diagonal;
    }
    for (std::size_t p : members) out.diagonal[p] = pair_of(p, 0) == chosen ? 0 : 1;
  }

  const bool blocks =
      !model.tet_block.empty() || !model.pyramid_block.empty() || !model.tets.empty() || np > 0;
  if (blocks && m.tet_block.empty())
    m.tet_block.assign(model.tets.size(), default_block(ElementKind::kTet));
  if (m.tet_ids.empty())
    for (std::size_t t = 0; t < model.tets.size(); ++t)
      m.tet_ids.push_back(static_cast<std::int64_t>(t) + 1);
  std::vector<Index> first_tet(np);
  for (std::size_t p = 0; p < np; ++p) {
    first_tet[p] = index_cast(m.tets.size());
    const ElementRef ref{ElementKind::kPyramid, index_cast(p)};
    for (const auto& t : pyramid_tets(model.pyramids[p], out.diagonal[p])) {
      m.tets.push_back(t);
      m.tet_block.push_back(block_of(model, ref));
      m.tet_ids.push_back(element_id(model, ref));
      out.tet_pyramid.push_back(index_cast(p));
    }
  }
  // Sides of pyramids: the faces of its two tets whose nodes are all on the pyramid's face.
  rewrite_sides(m, [&](const Side& s, std::vector<Side>& sides) {
    if (s.element.kind != ElementKind::kPyramid) {
      sides.push_back(s);
      return;
    }
    const auto on = tet_sides_on(m, first_tet[index_cast<std::size_t>(s.element.index)], 2,
                                 element_face(model, s));
    sides.insert(sides.end(), on.begin(), on.end());
  });
  return out;
}

}  // namespace geode::primal
