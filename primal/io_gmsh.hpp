#pragma once
// Gmsh .msh (v4.1, ASCII or binary) input and output of a mixed hex + tet model through the
// Gmsh C++ API.
//
// Mapping between a Model and Gmsh's entities:
// - element blocks  <-> volume entities; the block id is the entity's first physical group
//   of dimension 3 (its name is the block name) or, without one, the entity tag;
// - side sets       <-> physical groups of dimension 2: each triangle / quad element is
//   matched to the hex or tet face with the same nodes (hexes searched first, lowest index);
// - node sets       <-> physical groups of dimension 0 or 1 (all nodes of their elements;
//   the writer stores one point element per node in one point entity per set).
// Entries of node sets come back sorted by node number, those of side sets sorted (hex sides
// first, by element and face), since Gmsh groups elements by type. Nodes are numbered by ascending Gmsh
// tag; the writer uses tag = index + 1, so models round-trip.
// Node order: Gmsh's 4-node tetrahedron (type 4) and 8-node hexahedron (type 5) use the same
// corner order as VTK/Exodus (Gmsh reference manual, "Node ordering"); the tables
// kGmshHexToVtk / kGmshTetToVtk below carry that fact as data and the tests check it on a
// hand-written file.
#include <array>
#include <filesystem>
#include <string_view>

#include "primal/model.hpp"

namespace geode::primal {

// vtk_corner[i] = gmsh_corner[kGmsh*ToVtk[i]].
inline constexpr std::array<int, 8> kGmshHexToVtk{0, 1, 2, 3, 4, 5, 6, 7};
inline constexpr std::array<int, 4> kGmshTetToVtk{0, 1, 2, 3};

enum class GmshFormat { Ascii, Binary };
// MSH 4.1 (Gmsh 4's own) or 2.2 (what older solvers' readers and converters still expect).
enum class GmshVersion { k41, k22 };

// Reads a .msh file (any version Gmsh reads; 4.1 is what we write). Throws InvalidInput naming
// the file, the element or entry and the reason: missing or unreadable file, a file Gmsh
// cannot parse (e.g. truncated), a volume element that is not a linear hex or tet, a node tag
// out of range, a side-set face that is no face of a hex or tet.
Model read_gmsh(const std::filesystem::path& path);

// Writes .msh (v4.1 or 2.2) atomically (a temporary file in the same directory, then rename).
// Block ids must be positive; a block may hold both hexes and tets. Blocks become physical
// volumes, side sets physical surfaces (their faces as triangles / quads), node sets physical
// points, each with its id and name.
void write_gmsh(const Model& model, const std::filesystem::path& path,
                GmshFormat format = GmshFormat::Ascii, GmshVersion version = GmshVersion::k41);

// RAII: initializes the Gmsh API (no config files, General.Terminal = 0) and finalizes it on
// destruction. Gmsh's state is global: do not nest sessions or use them from several threads.
class GmshSession {
 public:
  GmshSession();
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

// Converts Gmsh's current model (inside a GmshSession) to a Model, as read_gmsh does after
// opening; `source` names it in error messages. Lets builders that mesh with the Gmsh API
// (conform/demo_models.hpp) share the reader's conversion.
Model model_from_gmsh(std::string_view source);

}  // namespace geode::primal
