#pragma once
// Pieces for node sets given as nodes only (Exodus node sets), so that dicing does not grow
// them into the model. Dicing adds a node to a set without pieces when every node it is made
// from is in the set (primal/dice_model.hpp diced_node_sets): right for a set on one plane, but
// a set on the model's boundary that turns a corner (a boundary condition on two faces, or on
// the whole skin) then took in the centres of faces and the midpoints of edges inside the
// model whose corners lie on the set (a tet beside an edge of the model, with a node on each
// face): a boundary condition on interior nodes.
#include <geode/primal/model.hpp>

namespace geode::primal {

// For each node set with no piece of two nodes or more whose every node lies on the model's
// boundary (a node of a face that one element alone uses): its pieces become the boundary
// faces whose nodes are all in the set, and each of its nodes on no such face as a point, so
// that dicing adds to it only nodes on those faces. Other sets (with pieces, or with a node
// inside the model: a surface embedded in a block, where faces inside the model belong to the
// set) are left as they are.
void infer_boundary_node_set_pieces(Model& model);

}  // namespace geode::primal
