#pragma once
// Wedges as tets: what conform makes of a wedge layer that joins the two sides of the hex/tet
// interface (find_interface refuses it: where a layer of hexes and wedges side by side lies
// under tets, as an extruded boundary layer whose surface was only partly recombined is, the
// interface over its hexes ends inside the mesh at the wedges, and no buffer layer can end
// there). Each wedge of the pieces that do becomes three tets, and the hexes' quads the wedges
// covered are interface quads as any other.
//
// A quad face takes the diagonal the tets already on it have (a split pyramid's), else the one
// through its lowest node number, so two split wedges sharing it take the same one and the
// tets conform (Dompierre, Labbe, Vallet, Camarero, "How to subdivide pyramids, prisms and
// hexahedra into tetrahedra", IMR 1999: by that rule the three diagonals never go round the
// wedge, which no three tets could follow).
#include <array>
#include <span>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

// The three tets of a wedge (corner order of topology.hpp), positive for a positive wedge, whose
// edges split its quad faces (cell_topology(kWedge) order) along `diagonal[q]`: 0, the first and
// third corners of face q; 1, the second and fourth. Throws TopologyError naming the wedge when
// the three diagonals go round it.
std::array<std::array<Index, 4>, 3> wedge_tets(const Model& model, Index wedge,
                                               const std::array<int, 3>& diagonal);

// The wedges joined to `seeds` through the faces wedges share (whole pieces), ascending.
std::vector<Index> wedge_pieces(const Model& model, std::span<const Index> seeds);

// `model` with `wedges` (ascending) as three tets each: its tets first, then each split wedge's
// three in wedge order, in the wedge's block with its file id; its other wedges kept in order;
// side sets on a split wedge's faces moved to its tets' faces on them (two on a quad). Throws
// TopologyError naming a wedge whose forced diagonals (tets already on its quads) go round it.
Model split_wedges(const Model& model, std::span<const Index> wedges);

}  // namespace geode::primal
