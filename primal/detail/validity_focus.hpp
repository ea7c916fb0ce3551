#pragma once
// check_validity (validity.hpp) where only some nodes' findings are wanted: the local check
// (validity_local.hpp) runs it on a region whose outer nodes lack part of their hexes, so what
// the full check finds there is the region's cut, not the mesh's.
#include <span>

#include <geode/primal/mesh.hpp>
#include <geode/primal/validity.hpp>

namespace geode::primal::detail {

// `focus`: empty (check_validity itself), or one flag per node. Then the findings at a node, and
// on the faces and edges through it, are check_validity's where the node or an edge's other
// end is flagged: elsewhere its link, its covering and its edges are not examined. Corner
// Jacobians and the probe are taken at flagged corners only (inverted_hexes: a non-positive
// one there), and the boundary surface is made of the boundary quads with a flagged node. The
// counts (V, E, F, C and the Euler characteristic) are the whole mesh's either way.
HexValidityReport check_validity(const HexMesh& mesh, std::span<const char> focus,
                                 const ValidityProgress& progress = {});

}  // namespace geode::primal::detail
