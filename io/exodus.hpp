#pragma once
// Exodus II input and output of a mixed model (libexodusII): coordinates, element blocks
// 'HEX8' / 'TETRA4' / 'PYRAMID5' / 'WEDGE6', named node sets and side sets, block names.
//
// Node order: Exodus HEX8 and TETRA4 number their corners as VTK does (Exodus II manual,
// "Element Types"; primal/topology.hpp), so kExodusHexToVtk / kExodusTetToVtk are the identity;
// they are kept as data so that the conversion is visible. Side numbers are 1-based in the
// file and 0-based (topology.hpp face order, which is Exodus's side order) in the Model.
// Elements are numbered globally in block order in the file; the reader keeps the blocks in
// file order, the writer writes them in ascending id. An Exodus block holds one element type:
// a model block of several kinds (Gmsh's tet volume with its pyramids) is written as one block
// per kind, the first kind (hex, tet, pyramid, wedge order) keeping the id, each other one a new
// id above every model id, named "<block name> <kind>s".
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include <geode/primal/model.hpp>
#include <geode/primal/shares.hpp>

namespace geode::io {

// vtk_corner[i] = exodus_corner[kExodus*ToVtk[i]].
inline constexpr std::array<int, 8> kExodusHexToVtk{0, 1, 2, 3, 4, 5, 6, 7};
inline constexpr std::array<int, 4> kExodusTetToVtk{0, 1, 2, 3};

// The element types per primal::ElementKind (hex, tet, pyramid, wedge): the name the writer
// gives, the names the reader accepts with that node count (aliases Cubit, SEACAS and meshio
// write), and model_corner[i] = exodus_corner[order[i]] (the identity: the model's corner
// order is Exodus's for all four, topology.hpp).
struct ExodusCell {
  const char* name;
  int corners;
  std::array<const char*, 4> aliases;  // nullptr-padded
  std::array<int, 8> order;
};
inline constexpr std::array<ExodusCell, 4> kExodusCells{{
    {"HEX8", 8, {"HEX8", "HEX", "HEXAHEDRON", nullptr}, {0, 1, 2, 3, 4, 5, 6, 7}},
    {"TETRA4", 4, {"TETRA4", "TETRA", "TET4", "TET"}, {0, 1, 2, 3}},
    {"PYRAMID5", 5, {"PYRAMID5", "PYRAMID", nullptr, nullptr}, {0, 1, 2, 3, 4}},
    {"WEDGE6", 6, {"WEDGE6", "WEDGE", nullptr, nullptr}, {0, 1, 2, 3, 4, 5}},
}};

// The file is checked for the netCDF / HDF5 signature (file_format.hpp) and screened
// (netcdf_screen.hpp: a classic header parsed whole and bounded by the file's size, an HDF5
// superblock checked) before libexodusII opens it, and libexodusII then reads it in a child
// process under memory and CPU limits (isolated.hpp), so that a crash of libhdf5 or of
// libexodusII on a corrupt file is a refusal, not ours. Node and element number maps, when present
// (Cubit writes them), are the model's file ids; otherwise 1-based numbers. Block ids are the
// file's; a file with a block id <= 0 (meshio numbers blocks from 0) gets its blocks numbered 1, 2,
// ... in file order. Throws InvalidInput naming the file, the block / element / set entry and the
// reason: missing or unreadable file, not an Exodus file (e.g. truncated), an element type other
// than those of kExodusCells with their node counts, a node or element number out of range, a side
// number out of range; then check_geometry (model.hpp) unless options say otherwise.
primal::Model read_exodus(const std::filesystem::path& path,
                          const primal::ReadOptions& options = {});

// read_exodus with the reading shared among processes (primal/shares.hpp; geode_mpi's ranks):
// each reads, in its own child, the header, the block headers and names, and its run of the
// nodes (coordinates, node map) and of each block's elements (connectivity, element map), the
// first also the sets; the exchange gives every process all the runs, joined in share order
// into what read_exodus reads, then checked as it checks them. Collective: each returns the
// model read_exodus returns, or throws what it throws for the file (the first share's reason,
// in share order, when several fail).
primal::Model read_exodus_shared(const std::filesystem::path& path,
                                 const primal::ReadOptions& options, const primal::Shares& shares);

// A piece of a Nemesis set (nemesis_set.hpp) carries, beside its model, Nemesis I's processor
// count and global counts; processors 0 when the file has none.
struct NemesisInfo {
  int processors = 0;
  std::int64_t global_nodes = 0, global_elements = 0;
};
// read_exodus, and the file's Nemesis I counts in `nemesis` when not null.
primal::Model read_exodus_piece(const std::filesystem::path& path,
                                const primal::ReadOptions& options, NemesisInfo* nemesis);

// Writes atomically (a temporary file in the same directory, then rename). The header is given
// room for every definition, all made before the bulk data: netCDF's classic format moves the
// whole data region whenever a definition outgrows the header. `define`, when given, is called
// with the libexodusII file id once the model's variables are defined, to define more (Nemesis:
// parallel/nemesis.cpp); `write_more` after the model's own data, to write the rest. Data
// written early would leave a hole before it that netCDF reads, block by block, as the model's
// data fills it.
void write_exodus(const primal::Model& model, const std::filesystem::path& path,
                  const std::function<void(int exo)>& define = {},
                  const std::function<void(int exo)>& write_more = {});

// Why the last libexodusII call failed, in words ("No space left on device (the disk is full)",
// a netCDF error), for callers of its API beside write_exodus (the Nemesis maps' writer).
std::string exodus_error_cause();

}  // namespace geode::io
