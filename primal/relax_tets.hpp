#pragma once
// Relaxing a tet mesher's nodes before dicing: each free node moves to where the lowest
// scaled Jacobian of the hexes its tets dice into (primal/dice.hpp, the yardstick's measure)
// is highest. Tet meshers leave poor tets beside a hex part: Gmsh's pyramids on the quads it
// shares with a hex part have their apex as low as 7 % of the base edge (the hexdominant demo,
// n = 8), so their two tets are nearly flat, and the buffer layer above them is as thin. The
// search is a compass search (six axis directions, the step halved when none improves), node
// by node, the worst node first (ties by node number): a node moves only when the lowest of
// its own tets rises, so no tet's diced minimum falls below where the lowest of its
// neighbourhood started, and no tet inverts. Nodes on the boundary, between blocks or used by
// other cells are the caller's to exclude (tet_nodes_to_relax).
#include <span>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

struct RelaxTetsOptions {
  int sweeps = 2;              // passes over the free nodes, worst first in each
  int halvings = 5;            // a node's step halved at most this often
  double initial_step = 0.25;  // x the node's shortest tet edge
  double good = 1.0;           // a node whose tets all dice at least this well stays
};

struct RelaxTetsResult {
  Index nodes_moved = 0;  // free nodes that moved at all
  // The lowest diced scaled Jacobian over the tets at the free nodes, before and after.
  double min_before = 1.0, min_after = 1.0;
  double seconds = 0.0;
};

// Moves `free_nodes` of `points` (each at most once in the list) among `tets` (positively
// oriented). Deterministic: the order depends on qualities and node numbers only.
RelaxTetsResult relax_tet_nodes(std::vector<Point>& points,
                                std::span<const std::array<Index, 4>> tets,
                                std::span<const Index> free_nodes,
                                const RelaxTetsOptions& options = {});

// The tet nodes of `model` within `rings` rings of tets from the quads of its hexes and wedges
// that tets cover (all four corners tet nodes: the tets sharing a node with such a quad, then
// the tets sharing a node with those, ...) that may move without
// changing the model's shape or its materials: used by tets only, all of one block, on no
// boundary face (a face of one element; a quad's two triangles count as faces too), in no
// node set and on no face of a side set (a surface embedded in the tets). Sorted ascending.
// `seeds`: nodes the rings also start from (the corners of cells conform split into tets,
// primal/split_hexes.hpp, where a hex layer was).
std::vector<Index> tet_nodes_to_relax(const Model& model, int rings,
                                      std::span<const Index> seeds = {});

}  // namespace geode::primal
