#pragma once
// The interface between the hex part and the tet part of a Model: the boundary quads of the
// hex part (its hexes and the quad faces of its wedges, which are diced in place as hexes are)
// whose two triangles (split along one diagonal), or four triangles (around a centre node of
// the tet part, the paper's Section 5 variant), are boundary faces of the tet part.
// Both parts must share the interface nodes (conform node-wise); merge coincident nodes first
// (merge_coincident_nodes) if the input keeps the parts apart.
#include <array>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

struct InterfaceQuad {
  // The cell owning the quad: a hex, or a wedge (a quad face of it meeting two tet triangles,
  // as a split pyramid on a wedge leaves it); `hex` indexes Model::hexes or Model::wedges.
  ElementKind kind = ElementKind::kHex;
  Index hex = kInvalidIndex;
  int face = -1;  // its local face (cell_topology(kind).face: kHexFaceCorners for a hex)
  ElementRef owner() const { return {kind, hex}; }
  // The face's corners in topology order: counter-clockwise seen from outside the cell, i.e.
  // from the tet side.
  std::array<Index, 4> corners{};
  // Which diagonal the tets split the quad along: 0 joins corners[0]-corners[2], 1 joins
  // corners[1]-corners[3]. Triangle i is then (c0 c1 c2), (c0 c2 c3) for diagonal 0 and
  // (c0 c1 c3), (c1 c2 c3) for diagonal 1.
  int diagonal = 0;
  // Four-triangle split: the tet-part node the four triangles share (kInvalidIndex for two
  // triangles; `diagonal` is then not used). Triangle i is (c_i, c_i+1, centre).
  Index centre = kInvalidIndex;
  // Tet owning triangle i (the first 2, or all 4 with a centre) and its local face
  // (kTetFaceCorners).
  std::array<Index, 4> tets{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  std::array<int, 4> tet_faces{-1, -1, -1, -1};
  int triangle_count() const { return centre == kInvalidIndex ? 2 : 4; }
};

// The buffer layer duplicates every interface node: the hex-side cells around it keep the
// node, the tet-side ones take the copy. Which side a cell at an interface node is on is read
// from the cells around the node, joined across the faces they share there (never across the
// interface, whose quads and triangles are different faces): the cells joined to a hex or to
// an interface quad's owner are on the hex side, those joined to an interface triangle's tet on
// the tet side; a cell joined to neither (it touches the node only by an edge or a corner)
// is loose, and may take either copy.
enum class InterfaceSide : std::uint8_t { kHex, kTet, kLoose };

struct InterfaceNodeUse {
  ElementRef cell;             // a tet or a wedge (a hex is always on the hex side)
  Index node = kInvalidIndex;  // an interface node of it
  InterfaceSide side = InterfaceSide::kTet;
};

struct Interface {
  std::vector<InterfaceQuad> quads;    // the hex part's boundary quads in order, then the wedges'
  std::vector<Index> nodes;            // every interface node, ascending
  std::vector<InterfaceNodeUse> uses;  // every tet and wedge at an interface node, by node
};

// The two or four triangles of an interface quad, as node triples in the quad's orientation.
std::vector<std::array<Index, 3>> interface_triangles(const InterfaceQuad& quad);

// Finds the interface. Throws TopologyError naming the hex face (hex and nodes) or node, in the
// model's file ids with coordinates (model.hpp: describe_element, describe_node), when the parts
// do not conform:
// - a boundary quad of the hex part matched by only one triangle of the tet part (or by
//   triangles of both diagonals);
// - a four-triangle centre node that is a node of the hex part too, lies more than 0.05 of the
//   quad's mean edge off the plane through the quad's centre point (a gap between the parts
//   when outside the hex, an overlap when inside), or outside the quad (a triangle folds);
// - two hexes, wedges or tets on the same nodes (a duplicated element; tets where they touch
//   the hex part: the tet part away from it is check_input's, conform.hpp);
// - a node of one side lying on a boundary face of the other side without being one of its
//   corners (hanging node, different refinement, unmerged duplicate node);
// - a node used by both parts that is on no interface quad (the parts touch along an edge
//   or at a point only);
// - a tet on the hex side of the interface quad it touches (the parts overlap);
// - a face with a node of the hex part shared by more than two tets;
// - a cell joining the two sides around an interface node (see InterfaceSide: a wedge sharing
//   faces there with a hex and with a tet of the interface, as where a wedge layer over the
//   tet part meets a hex layer over the hex part): the interface ends inside the mesh there,
//   where no buffer layer can end, and the message names that cell (a wedge) and the node;
//   given `joining`, every such wedge is put there instead, ascending (the interface's uses
//   then leave the cells joined to both sides out: the caller splits those wedges and starts
//   again, primal/split_wedges.hpp).
// `tolerance` is relative to the local edge length (used by the hanging-node test).
Interface find_interface(const Model& model, double tolerance = 1e-6,
                         std::vector<Index>* joining = nullptr);

}  // namespace geode::primal
