#pragma once
// Dicing a whole mixed model (primal/model.hpp) over one node array: the hex part 8 per hex,
// the tet part 4 per tet (primal/dice.hpp), wedges 6 per wedge (one hex at each corner, its
// axes the corner's edges, topology::kWedgeCornerNeighbors), every diced node keeping its origin
// (the sorted input nodes it was made from), and the model's node and side sets carried onto the
// result.
//
// A diced edge or face node is made once per part by dice(); the two parts meet it twice only
// where every origin node is used by both parts (the hex/tet interface) or was marked
// `shareable` by the caller. Only those nodes go through a hash map (DicedModel::find), so
// merging costs a few probes per interface face instead of one per diced edge and face.
// Wedges meet both parts (their quads hexes, their triangles tets): every node of a wedge is
// shareable. Pyramids are not diced (conform splits them into tets first): InvalidInput.
#include <span>
#include <string>
#include <vector>

#include <geode/primal/boundary.hpp>
#include <geode/primal/key_map.hpp>
#include <geode/primal/model.hpp>

namespace geode::primal {

// The origin key of a node without origin (cell centres, nodes added by the caller).
inline constexpr FaceKey kNoOrigin{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};

// `key` sorted ascending with its kInvalidIndex padding last.
FaceKey normalized_origin(FaceKey key);

struct DicedModel {
  // The model's points first (same numbers, unused ones included), then new nodes.
  std::vector<Point> points;
  // Per node: its origin nodes, normalized (an input node v: {v, -1, -1, -1}; an edge
  // midpoint: its 2 nodes; a face centre: 3 or 4), kNoOrigin for cell centres and added nodes.
  std::vector<FaceKey> origin;
  // Children in global node numbers, each part in its parent's order (dice.hpp's corner order).
  std::vector<std::array<Index, 8>> hex_children, tet_children, wedge_children;
  std::vector<Index> hex_parent, tet_parent,
      wedge_parent;  // per child: index into Model::hexes / tets / wedges

  Index add_node(const Point& p, const FaceKey& origin_key = kNoOrigin);
  // The node made from the (unsorted) origin nodes `key`: an input node itself, else an edge or
  // face node whose origin nodes are all shareable; kInvalidIndex when there is none.
  Index find(const FaceKey& key) const;

  KeyMap<4> shared;  // normalized origin -> node, for nodes whose origin nodes are all shareable
};

// `shareable` (per model point, may be empty) marks nodes besides the interface whose diced
// edge and face nodes the caller will look up with find(). `tet_room`: capacity in
// tet_children for that many more hexes, which the caller puts beside them without copying
// them (conform inserts the hex children and its templates in front). `point_room`: capacity
// in points for that many more nodes, likewise (geode_mpi's zone rank adds the zone's).
// Throws InvalidInput from dice().
DicedModel dice_model(const Model& model, std::span<const char> shareable = {},
                      std::size_t tet_room = 0, std::size_t point_room = 0);

// A diced model read against the dicing tables (dice.hpp's hex_dicing_table and
// tet_dicing_table, the wedge rule of dice_model): every child corner is the node its table
// entry names (a corner of the parent itself; the node whose origin is the parent's edge or
// face; the parent's own centre, a node of no other parent), and no origin is given to two
// nodes. With a valid input model (faces shared by at most two cells, manifold, positive) the
// diced children then form a valid mesh by construction: each parent face is diced once and
// its sub-faces are shared, in opposite orders, by the children on both sides. Costs one pass
// over the children and one over the nodes, with no hashing (what a full check_validity of
// the diced part would cost several times over).
struct DicingCheck {
  // Children (index into hex_children / tet_children / wedge_children) that differ from what
  // their table makes of their parent.
  std::vector<Index> wrong_hex_children, wrong_tet_children, wrong_wedge_children;
  Index missing_children = 0;  // children the tables make that the diced model lacks
  // Nodes made from the same origin as another node (a crack), ascending.
  std::vector<Index> duplicated_nodes;
  bool ok() const;
  std::string summary() const;
};

DicingCheck check_dicing(const Model& model, const DicedModel& diced);

// The lowest scaled Jacobian of the 6 hexes each wedge dices into (as dice_model makes them),
// wedge by wedge: the wedges' part of the yardstick (dice.hpp's diced_min_scaled_jacobian for
// hexes and tets). 1 when empty.
double diced_wedge_min_scaled_jacobian(std::span<const Point> points,
                                       std::span<const std::array<Index, 6>> wedges);

// The model's node sets on the diced nodes: every input node of a set plus every diced node
// whose origin nodes are all in it. `renumber` maps a diced node to its output number
// (kInvalidIndex: dropped).
std::vector<NodeSet> diced_node_sets(const Model& model, const DicedModel& diced,
                                     std::span<const Index> renumber);

// The model's side sets on the diced hexes: each input side becomes the faces of its parent's
// children lying on it (4 per quad, 3 per triangle). Output hex numbers are hex_offset + child
// for hex children, tet_offset + child for tet children and wedge_offset + child for wedge
// children (kInvalidIndex: right after the tet children).
std::vector<SideSet> diced_side_sets(const Model& model, const DicedModel& diced, Index hex_offset,
                                     Index tet_offset, Index wedge_offset = kInvalidIndex);

}  // namespace geode::primal
