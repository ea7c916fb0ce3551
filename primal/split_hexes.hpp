#pragma once
// Hexes as tets: what conform makes of a thin hex layer that wedges go through from tets on one
// side to tets on the other (a curved surface recombined with a few triangles left, extruded in
// a few thin cells between tet volumes). Split, the wedges leave holes through the layer whose
// walls are interface quads as high as the layer's cells, so no buffer layer fits there (its
// hexes inverted or flat, or two layer hexes meeting along an edge only between two holes);
// as tets, the whole layer is diced with the tets around it and needs no buffer layer.
//
// A quad face takes the diagonal the tets already on it have (a split wedge's, the tet part's),
// unless they are two tets sharing their fourth node (a pyramid: Gmsh's on a layer, split first,
// or two of a split wedge's), which may as well be split along the other one where neither is
// then inverted and no side set names the face; the others are chosen run by
// run of hexes through opposite faces (a layer's columns and rows), for the best lowest then
// total quality of the run's hexes' splits and its end pyramids' tets, starting from the
// diagonals through their lowest nodes, so the tets conform. Each hex then takes the
// triangulation of the cube by its corners (74: two of 5 tets, the rest of 6) that has those
// diagonals and whose tets dice best. By the lowest-node rule alone one always has them (the cone
// from the hex's lowest corner: Dompierre, Labbe, Vallet, Camarero, "How to subdivide pyramids,
// prisms and hexahedra into tetrahedra", IMR 1999), but the tets on its faces can force others:
// 18 of the 64 choices of six diagonals have none, and where a thin cell's faces are warped
// about as much as it is high (a curved layer in 3 cells, the extruded surface's nodes numbered
// before the cells' inner ones), a top diagonal crossing the bottom one the wrong way leaves a
// tet flat or inverted, so a column's free faces must follow the diagonals its ends are given,
// and where both ends are given (pyramids on both sides of a layer 0.01 high on a radius of
// 0.4), one end's pyramid must follow the other. A hex none fits, or whose best has an inverted
// tet, gets its centre as a node of its own, coned over its faces' triangles: 12 tets.

#include <array>
#include <span>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

// The hexes and wedges of the pieces of hexes and wedges (joined through the faces they share)
// that hold `wedges`, ascending.
struct CellPieces {
  std::vector<Index> hexes, wedges;
};
CellPieces cell_pieces(const Model& model, std::span<const Index> wedges);

// The tets of the wedge columns through `wedges` (wedges stacked on their triangles): whether
// some column of them ends on a tet at both of its triangles, and the mean over such columns of
// their cells' height (the distance between the end triangles' centroids over the column's
// wedges) over their end triangles' mean edge: a layer through which wedges join tets on its
// two sides, and how thin its cells are.
struct WedgeColumns {
  bool through = false;
  double height_ratio = 0.0;  // over the columns through; 0 when none is
};
WedgeColumns wedge_columns(const Model& model, std::span<const Index> wedges);

// `model` with `hexes` (ascending) as 5, 6 or 12 tets each: its tets first (a re-split
// pyramid's two in their places, the sides on its side triangles moved with them), then each split
// hex's in hex order, in the hex's block with its file id; its other hexes kept in order; a
// centre node appended for each hex split around one (the next file id); side sets on a split
// hex's faces moved to its tets' faces on them (two on a quad). Throws TopologyError naming a hex
// no split of which into positive tets has the diagonals its neighbours give it, or one with a
// face under four tet triangles around a node (which no split of it follows).
Model split_hexes(const Model& model, std::span<const Index> hexes);

}  // namespace geode::primal
