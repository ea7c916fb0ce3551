#pragma once
// The full validity check (validity.hpp) where a mesh can be wrong, not everywhere: around a
// region of hexes (say a transition and the hexes a smoother moved), the rest of the mesh being
// valid by construction (a dicing checked against its tables, dice_model.hpp's check_dicing).
// Costs what the region costs, plus one pass over every hex for the corner Jacobians.
#include <array>
#include <span>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/primal/validity.hpp>

namespace geode::primal {

struct RegionValidityOptions {
  // The checked nodes are those of the hexes within this many rings (hexes sharing a node) of
  // the seeds; the check reads every hex around them. Two rings reach the far end of a diced
  // edge from a node moved before dicing (a diced input edge is two hex edges long), whose
  // corner cones the move turned.
  int rings = 2;
  // Empty, or one per hex: nonzero where its corner Jacobians are known to be above 0 as the
  // mesh is now (its scaled Jacobian, quality.hpp's hex_scaled_jacobian over the corners and the
  // centre, above 0 says so; so does corner_jacobians_positive below). Such a hex is not measured
  // again; the others are.
  std::span<const char> positive;
};

// check_validity's findings at the checked nodes, on the faces and edges with a checked node,
// and over the whole mesh for what is per hex or per node (out-of-range and repeated nodes,
// non-finite coordinates, unused nodes, non-positive corner Jacobians). Nodes, faces and edges
// elsewhere are taken as valid. The counts (V, E, F, C, the Euler characteristic) are those of
// the checked region's hexes, the boundary quads those with a checked node; `boundary.closed` and
// `boundary.manifold` say that no checked vertex or edge is non-manifold (every vertex link a
// disk or a sphere makes the boundary a closed manifold surface). With every hex seeded and
// rings >= 0 the verdict (ok()) is check_validity's.
HexValidityReport check_validity_around(const HexMesh& mesh, std::span<const Index> seeds,
                                        const RegionValidityOptions& options = {});
// The same on a mesh's arrays held elsewhere (a primal::Model's points and hexes).
HexValidityReport check_validity_around(std::span<const Point> points,
                                        std::span<const std::array<Index, 8>> hexes,
                                        std::span<const Index> seeds,
                                        const RegionValidityOptions& options = {});

// Per hex, 1 where every corner Jacobian is above 0 (the measure check_validity_around takes;
// hexes in parallel), 0 where one is not or a corner is out of range: the `positive` of hexes
// measured ahead, e.g. by a rank while it waits for another's work.
std::vector<char> corner_jacobians_positive(std::span<const Point> points,
                                            std::span<const std::array<Index, 8>> hexes);

}  // namespace geode::primal
