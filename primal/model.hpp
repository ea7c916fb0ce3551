#pragma once
// A mixed model of linear cells (hexes, tets, pyramids, wedges) as read from an input file
// (Exodus II, Gmsh, VTK): one point array shared by every part, element blocks, named node sets
// and side sets. This is the input of the
// whole-model geode pipeline (interface detection, buffer layer, dicing, templates).
//
// Conventions:
// - Element connectivity is in VTK/Exodus order (primal/topology.hpp); readers convert.
// - Element order after reading is block by block (Gmsh: ascending block id; Exodus: file
//   order), each kind in its own array; writers emit blocks in ascending id, so a
//   model whose elements are already grouped by ascending block round-trips exactly.
// - A side is (element, local face) with the face numbered as in topology.hpp
//   (kCellKinds[kind].face), which is the Exodus side number minus one.
// - Per kind, generic code reads topology::kCellKinds[kind] (corners, faces, edges) and the
//   accessors below (element_count, element_corners, block_of, element_id) instead of naming
//   the arrays.
#include <compare>
#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include <geode/primal/mesh.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

// The index into topology::kCellKinds.
enum class ElementKind : std::uint8_t { kHex, kTet, kPyramid, kWedge };
inline constexpr std::array<ElementKind, 4> kElementKinds{
    ElementKind::kHex, ElementKind::kTet, ElementKind::kPyramid, ElementKind::kWedge};

struct ElementRef {
  ElementKind kind = ElementKind::kHex;
  Index index = kInvalidIndex;  // into the kind's array (Model::hexes, tets, pyramids, wedges)
  auto operator<=>(const ElementRef&) const = default;
};

struct Side {
  ElementRef element;
  int face = 0;  // 0-based local face (topology.hpp order == Exodus side - 1)
  auto operator<=>(const Side&) const = default;
};

struct NodeSet {
  int id = 0;  // > 0
  std::string name;
  std::vector<Index> nodes;
  // Optional: the points, edges and faces the set was given as (a .msh physical point or
  // curve: each element's nodes). Dicing then adds a new node only when every node it is made
  // from lies in one piece, so that a set on two parallel edges does not grow onto the face
  // between them; without pieces (or with single points only), when every such node is in the set.
  std::vector<std::vector<Index>> pieces = {};
};

struct SideSet {
  int id = 0;  // > 0
  std::string name;
  std::vector<Side> sides;
};

struct Model {
  std::vector<Point> points;
  std::vector<std::array<Index, 8>> hexes;     // VTK/Exodus HEX8 order
  std::vector<std::array<Index, 4>> tets;      // VTK/Exodus TETRA4 order
  std::vector<std::array<Index, 5>> pyramids;  // VTK/Exodus PYRAMID5 order
  std::vector<std::array<Index, 6>>
      wedges;  // Exodus WEDGE6 order (topology.hpp; VTK's is mirrored)
  // Element block id (> 0) per element. Empty means "all in one block": 1 for hexes, 2 for
  // tets, 3 for pyramids, 4 for wedges (default_block).
  std::vector<int> hex_block;
  std::vector<int> tet_block;
  std::vector<int> pyramid_block;
  std::vector<int> wedge_block;
  std::map<int, std::string> block_names;  // optional
  std::vector<NodeSet> node_sets;
  std::vector<SideSet> side_sets;
  // The file's own ids, for messages (Gmsh node and element tags, Exodus 1-based numbers, VTK
  // 0-based ids as ParaView shows them). Empty means index + 1, the ids a writer gives.
  std::vector<std::int64_t> node_ids;
  std::vector<std::int64_t> hex_ids;
  std::vector<std::int64_t> tet_ids;
  std::vector<std::int64_t> pyramid_ids;
  std::vector<std::int64_t> wedge_ids;
};

// Per kind (kElementKinds): the table, the element count and corners, the block and file-id
// vectors. element_corners is empty for an element that does not exist.
const topology::CellKindTopology& cell_topology(ElementKind kind);
const char* element_kind_name(ElementKind kind);  // "hex", "tet", "pyramid", "wedge"
int default_block(ElementKind kind);              // 1, 2, 3, 4
std::size_t element_count(const Model& model, ElementKind kind);
std::size_t element_count(const Model& model);  // every kind
std::span<const Index> element_corners(const Model& model, ElementRef element);
const std::vector<int>& element_blocks(const Model& model, ElementKind kind);
std::vector<int>& element_blocks(Model& model, ElementKind kind);
const std::vector<std::int64_t>& element_ids(const Model& model, ElementKind kind);
std::vector<std::int64_t>& element_ids(Model& model, ElementKind kind);
// f(cells) with the typed element array of `kind` (model.hexes, .tets, .pyramids or .wedges),
// for loops that need the corner count at compile time; `Model` may be const.
template <class M, class F>
void with_cells(M& model, ElementKind kind, F&& f) {
  switch (kind) {
    case ElementKind::kHex:
      return f(model.hexes);
    case ElementKind::kTet:
      return f(model.tets);
    case ElementKind::kPyramid:
      return f(model.pyramids);
    case ElementKind::kWedge:
      return f(model.wedges);
  }
}
// The nodes of local face `face` of the element (topology order: outward), 3 or 4 of them.
std::vector<Index> element_face(const Model& model, const Side& side);
// The faces of tets [first, first + count) of `model` whose corners all lie on `face`: the sides
// a side on a cell becomes where the cell is split into those tets (a pyramid, a wedge).
std::vector<Side> tet_sides_on(const Model& model, Index first, Index count,
                               std::span<const Index> face);
// Rewrites every side set of `model`: each side becomes the sides `map` appends for it (the
// side itself, renumbered, or the sides of the cells its element was split into); each set is
// then sorted.
void rewrite_sides(Model& model, const std::function<void(const Side&, std::vector<Side>&)>& map);
// Appends an element of `kind` (its first cell_topology(kind).corners corners), pushing its
// block and file id onto the kind's vectors (readers fill them for every element).
void add_element(Model& model, ElementKind kind, std::span<const Index> corners, int block,
                 std::int64_t file_id);

// Every face of every element by its node set -> its first side (kinds in kElementKinds order,
// elements ascending): what readers match a side set given as faces (Gmsh, VTK) against.
class FaceOwners {
 public:
  explicit FaceOwners(const Model& model);
  FaceOwners() = default;
  const Side* find(std::span<const Index> nodes) const;  // 3 or 4 nodes, any order

 private:
  struct Hash {
    std::size_t operator()(const std::array<Index, 4>& k) const;
  };
  std::unordered_map<std::array<Index, 4>, Side, Hash> owner_;
};

// The points, lines or faces of one group a file tags (a Gmsh physical point, curve or surface
// as Gmsh's .vtk and meshio give them, cells with a tag): each cell's nodes, and its id in the
// file for messages.
struct TaggedCells {
  int dim = 0;  // 0 points, 1 lines, 2 faces
  int id = 0;   // the group's tag, the set's id
  std::string name;
  std::vector<std::vector<Index>> cells;
  std::vector<std::int64_t> cell_ids;
};
// The sets the .msh reader makes of such groups, added to the model: points and lines a node
// set (each cell a piece), faces a side set of the elements they are faces of. InvalidInput
// naming `source`, the set and the cell by its file id (`cell_word`: how the file names one,
// "cell", "element") for a face of no element.
void add_tagged_sets(Model& model, std::span<const TaggedCells> groups, const std::string& source,
                     const std::string& cell_word);
// Gmsh's tags are per dimension while node sets share one range of ids: a physical curve may
// have a physical point's tag. Such a group of lines takes tag + 10^k, 10^k the smallest power
// of ten above every point and line tag (as the .msh writer moves a set's id off a taken one);
// returns, per group moved, its index and the tag it had. InvalidInput naming `source` where no
// such id fits in an int.
struct MovedGroup {
  std::size_t group = 0;
  int was = 0;
};
std::vector<MovedGroup> separate_node_set_ids(std::span<TaggedCells> groups,
                                              const std::string& source);

// What readers check beyond the file's structure.
struct ReadOptions {
  // check_geometry below (else check_points only): off for tools that read connectivity
  // alone (a mesh's dual).
  bool check_geometry = true;
  // Appended to check_geometry's refusal of an inverted or flat tet or pyramid: what the command
  // offers for one (conform's --unfold).
  std::string inverted_hint;
};

// The file id of a node or element (see Model::node_ids).
std::int64_t node_id(const Model& model, Index node);
std::int64_t element_id(const Model& model, ElementRef element);
// For messages, in file ids with coordinates: "node 14 (0.5, 1, 0)", "hex 97 (centre (0.5,
// 0.5, 0.5))", and a list of nodes "4 5 9 8".
std::string describe_node(const Model& model, Index node);
std::string describe_element(const Model& model, ElementRef element);
std::string node_list(const Model& model, std::span<const Index> nodes);
// Shortest text that reads back to the same double; a point as "(x, y, z)".
std::string number_text(double x);
std::string point_text(const Point& p);

// Block id of an element, applying the empty-vector defaults above.
int block_of(const Model& model, ElementRef element);

// Puts every element of blocks `ids` (two or more) into the first, which keeps its name; the
// others' names go. For blocks a file had to keep apart that are one material: an Exodus block
// holds one element type, so Cubit writes a volume's tets and its pyramids as two blocks, and
// apart they are two materials whose shared faces smoothing must keep. Throws InvalidInput
// naming `source` for an id no element has or one listed twice.
void join_blocks(Model& model, std::span<const int> ids, std::string_view source);

// Throws InvalidInput naming `source` and the offending element / set entry when a node index
// is out of range, a block or file-id vector has the wrong size, an id is not positive, or a
// side's face number is out of range. Readers call it before returning; writers before writing.
void validate(const Model& model, std::string_view source);

// A node with a NaN or infinite coordinate (every node, used or not): InvalidInput naming
// `source` and the node by its file id, with its coordinates. Readers always check it.
void check_points(const Model& model, std::string_view source);
// What readers refuse beyond structure (validate): check_points, then a tet of signed volume
// <= 0, a hex or wedge with a corner Jacobian <= 0 (topology.hpp's corner frames: inverted,
// flat or folded), a pyramid that splits along neither base diagonal into two positive tets, a
// node set's node that no element uses. Throws InvalidInput naming `source` and the node or
// element by its file id, with coordinates; `inverted_hint` appended where a tet or pyramid is
// at fault (ReadOptions::inverted_hint).
void check_geometry(const Model& model, std::string_view source,
                    std::string_view inverted_hint = {});
// What check_geometry refuses (but check_points), every element and node at most once, up to
// max_findings of them, in its order: each text names the element or node by its file id,
// without the source. `geode check` lists them all where a reader stops at the first.
std::vector<std::string> geometry_findings(const Model& model, std::size_t max_findings,
                                           std::string_view inverted_hint = {});

// The two parts over the model's whole point array (unused points included), so that node
// numbers agree between the parts and the model. Every element carries its block (block_of).
HexMesh hex_part(const Model& model);
TetMesh tet_part(const Model& model);

// Signed volume of tet (a, b, c, d): positive when a-b-c is counter-clockwise seen from d.
double tet_volume(const Point& a, const Point& b, const Point& c, const Point& d);

// The signed volumes of a pyramid's corner tets, in base corner order: at corner k, (k - 1, k,
// k + 1, apex). The pyramid splits into two positive tets (split_pyramids.hpp pyramid_tets)
// along its diagonal 0-2 when those at corners 1 and 3 are positive, along 1-3 when those at 0
// and 2 are (what conform makes of it, and what check_geometry asks of one of the two).
std::array<double, 4> pyramid_corner_volumes(const Model& model,
                                             const std::array<Index, 5>& pyramid);
bool splits_positive(const std::array<double, 4>& corner_volumes);

// The distance under which two of the model's nodes count as one place (duplicated nodes): 1e-9
// of its bounding box's diagonal (0 for no points). The hints naming duplicated nodes use it,
// and offer it to --merge-tolerance.
double coincident_tolerance(const Model& model);

// Merges points closer than `tolerance` (keeps the lowest index, renumbers everything, drops
// the merged points). Returns how many points were removed. Spatial hashing, O(n).
Index merge_coincident_nodes(Model& model, double tolerance);

// A tolerance as long as an element's edge merges that element's own nodes: throws
// InvalidInput naming the shortest edge's element (every kind) unless `tolerance` is below it,
// so that the caller refuses it instead of reporting the collapsed elements it would leave.
// `option` is how the caller's user gave it ("--merge-tolerance", "merge_tolerance=").
void check_merge_tolerance(const Model& model, double tolerance, const std::string& option);

}  // namespace geode::primal
