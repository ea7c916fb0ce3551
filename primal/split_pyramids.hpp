#pragma once
// Pyramids as tets: what conform makes of a pyramid before dicing (the option (a), the
// default `--pyramids split`; a pyramid template would be the other option). Each pyramid is
// split along the base diagonal whose two tets are the better ones: the larger least scaled
// Jacobian of the hexes dicing those tets gives (primal/dice.hpp, the measure of the
// yardstick), so a pyramid's yardstick is its better two tets. Where two pyramids share a base
// quad, one diagonal serves both (the better of the two for the worse of the pyramids), so the
// tets conform across it. The base quad itself then meets the hex or wedge under it as any
// interface quad split into two triangles does, and gets the geode transition.
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

struct PyramidSplit {
  // The input without pyramids: its own tets first, then two per pyramid (in pyramid order),
  // each in the pyramid's block with the pyramid's file id; side sets on pyramid faces moved to
  // the tets' faces on them (a base: the two tets' faces).
  Model model;
  std::vector<Index> tet_pyramid;  // per tet of model: the pyramid it came from or kInvalidIndex
  std::vector<int> diagonal;       // per pyramid: 0 (corners 0-2) or 1 (corners 1-3)
};

// The two tets of pyramid `p` split along `diagonal` (0: corners 0-2, 1: corners 1-3), both
// positively oriented for a pyramid whose base is counter-clockwise seen from the apex.
std::array<std::array<Index, 4>, 2> pyramid_tets(const std::array<Index, 5>& p, int diagonal);

PyramidSplit split_pyramids(const Model& model);

}  // namespace geode::primal
