#pragma once
// Gmsh .msh input and output of a mixed model (hexes, tets, pyramids, prisms). Reading is our own
// (gmsh_read.cpp: versions 2.2 and 4.1, ASCII and binary), so that a user's file never reaches
// libgmsh, which would run any text that is not a mesh as a Gmsh script. Writing is our own too
// (gmsh_write.cpp: 4.1 and 2.2, ASCII and binary, every write error reported); io never calls
// libgmsh: only the demo models use the Gmsh C++ API (demo/gmsh_session.hpp).
//
// Mapping between a Model and Gmsh's entities:
// - element blocks  <-> volume entities; the block id is the entity's physical group of
//   dimension 3 (its name is the block name; in several: the one over the fewest entities, with
//   a warning for a group left empty) or, without one, the entity tag; in a partitioned file,
//   the partitioned entity's groups, else its parent's, else the parent's tag;
// - side sets       <-> physical groups of dimension 2: each triangle / quad element is
//   matched to the hex or tet face with the same nodes (hexes searched first, lowest index);
// - node sets       <-> physical groups of dimension 0 or 1 (all nodes of their elements, and
//   the elements as the set's pieces, model.hpp; the writer stores one point element per node
//   in one point entity per set).
// Written physical tags are distinct across dimensions (gmsh_write.cpp: a set whose id is a
// block's, or another set's, is moved by a power of ten). Names go through io/names.hpp.
// Entries of node sets come back sorted by node number, those of side sets sorted (hex sides
// first, by element and face), since Gmsh groups elements by type. Nodes are numbered by ascending
// Gmsh tag; the writer uses tag = index + 1, so models round-trip. Node order: Gmsh's 4-node
// tetrahedron (type 4) and 8-node hexahedron (type 5) use the same corner order as VTK/Exodus (Gmsh
// reference manual, "Node ordering"); the tables kGmshHexToVtk / kGmshTetToVtk below carry that
// fact as data and the tests check it on a hand-written file.
#include <array>
#include <filesystem>
#include <string_view>

#include <geode/io/file_partition.hpp>
#include <geode/primal/model.hpp>

namespace geode::io {

// vtk_corner[i] = gmsh_corner[kGmsh*ToVtk[i]].
inline constexpr std::array<int, 8> kGmshHexToVtk{0, 1, 2, 3, 4, 5, 6, 7};
inline constexpr std::array<int, 4> kGmshTetToVtk{0, 1, 2, 3};

// The volume cells per primal::ElementKind (hex, tet, pyramid, wedge): the Gmsh element type
// and model_corner[i] = gmsh_corner[order[i]]. Gmsh's 5-node pyramid (type 7) is in VTK/Exodus
// order, its 6-node prism (type 6) in Exodus WEDGE6 order, the model's (reference manual,
// "Node ordering": prism 0-1-2 at the bottom counter-clockwise seen from 3-4-5 above).
struct GmshCell {
  int type;
  int corners;
  std::array<int, 8> order;
};
inline constexpr std::array<GmshCell, 4> kGmshCells{{{5, 8, {0, 1, 2, 3, 4, 5, 6, 7}},
                                                     {4, 4, {0, 1, 2, 3}},
                                                     {7, 5, {0, 1, 2, 3, 4}},
                                                     {6, 6, {0, 1, 2, 3, 4, 5}}}};
// The kind of a Gmsh volume type, or nullptr when it is not a linear cell the model holds.
inline const primal::ElementKind* gmsh_cell_kind(long long type) {
  for (std::size_t k = 0; k < kGmshCells.size(); ++k)
    if (kGmshCells[k].type == type) return &primal::kElementKinds[k];
  return nullptr;
}

enum class GmshFormat { kAscii, kBinary };
// MSH 4.1 (Gmsh 4's own) or 2.2 (what older solvers' readers and converters still expect).
enum class GmshVersion { k41, k22 };

// Reads a .msh file, version 2.2 or 4.1, ASCII or binary. Node and element tags become the
// model's file ids. Throws InvalidInput naming the file, the line (byte in binary files) or
// the element / node tag and the reason: missing or unreadable file, a file that does not
// start with $MeshFormat (a script, another format), another version, a truncated section or
// one without its $End line, a volume element that is not a linear hex, tet, pyramid or prism, an
// element referring to a node not in $Nodes, a node given twice at two places, a side-set face that
// is no face of a hex or tet; then check_geometry (model.hpp) unless options say otherwise.
primal::Model read_gmsh(const std::filesystem::path& path, const primal::ReadOptions& options = {});
// A partitioned 4.1 file ($PartitionedEntities, as gmsh.model.mesh.partition writes it): the
// model is the unpartitioned file's (the elements Gmsh adds on the boundaries between
// partitions are left out; elements of a block by ascending tag, the order partitioning
// regroups), and `partition` gets each volume element's partition (Gmsh's tag
// - 1). A file of Gmsh's Mesh.PartitionSplitMeshFiles=1 set (one partition's elements) is
// refused. A file without partitions, or one that does not give every volume element one,
// gives partition->parts == 0.
primal::Model read_gmsh_partitioned(const std::filesystem::path& path,
                                    const primal::ReadOptions& options, FilePartition* partition);
// The same on a file's content; `source` names it in messages.
primal::Model parse_gmsh(std::string_view content, const std::string& source,
                         const primal::ReadOptions& options = {},
                         FilePartition* partition = nullptr);

// Writes .msh (v4.1 or 2.2) atomically (a temporary file in the same directory, then rename).
// Block ids must be positive; a block may hold both hexes and tets. Blocks become physical
// volumes, side sets physical surfaces (their faces as triangles / quads), node sets physical
// points, each with its id and name.
void write_gmsh(const primal::Model& model, const std::filesystem::path& path,
                GmshFormat format = GmshFormat::kAscii, GmshVersion version = GmshVersion::k41);

}  // namespace geode::io
