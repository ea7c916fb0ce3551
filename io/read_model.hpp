#pragma once
// One entry point for reading a whole model (hex part, tet part, blocks, sets) from any input
// format of the format table (formats.hpp), chosen by extension and checked against the
// content before any parser sees it. io::write_model (formats.hpp) is its counterpart.
#include <filesystem>

#include <geode/io/file_partition.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/model.hpp>

namespace geode::io {

// Throws InvalidInput naming the file: missing, unknown extension, content of another format,
// and whatever the format's reader refuses (gmsh.hpp, exodus.hpp, vtk.hpp, ...), then
// check_geometry unless options say otherwise, then (with check_geometry and check_covering) the
// covering check of primal/input_check.hpp: a folded model, overlapping parts, an interface with
// a gap are refused naming the elements. check_covering false is for callers that merge nodes
// after reading and run require_single_covering themselves; `covering` is its options (geode_mpi
// shares the check among its ranks, and with it the read of a single Exodus file:
// exodus.hpp read_exodus_shared).
//
// Partitioned inputs: a Nemesis set (nemesis_set.hpp: `path` one of its pieces IN.exo.N.r, or
// IN.exo when that file does not exist and its pieces do) is read joined; a partitioned .msh 4.1
// as the unpartitioned file (gmsh.hpp). With `partition` not null, the partition such a file
// carries goes there (parts 0 for every other input).
primal::Model read_model(const std::filesystem::path& path, const primal::ReadOptions& options = {},
                         bool check_covering = true, FilePartition* partition = nullptr,
                         const primal::InputCheckOptions& covering = {});

// Whether read_model(path) forks a child process to run a library in (isolated.hpp): an
// Exodus file or a Nemesis set. A caller must then have no thread of its own at work during the
// read: a lock such a thread holds at the fork stays held for ever in the child (seen with the
// sanitizers' allocator: the child hung, and was killed at its time limit). Throws as
// read_model does for a broken Nemesis set.
bool read_forks(const std::filesystem::path& path);

// A VTK grid as a model: hexes, tets, pyramids and wedges (triangles and quads, boundary
// annotations, are left out), VTK's 0-based point and cell ids (as ParaView shows them) as file
// ids, blocks from the first integer cell array named "block" (our writers), "gmsh:physical"
// (meshio), "CellEntityIds" or "mat_id" (SfePy's, meshio's material ids); without one, a
// block per cell kind (primal::default_block: hexes 1, tets 2, pyramids 3, wedges 4). Block
// names, node sets and side sets from the field arrays write_vtu stores (vtk.hpp), each entry
// checked. Other cell types are refused naming the cell.
primal::Model model_from_vtk(const VtkGrid& grid, const primal::ReadOptions& options = {});

// What a reader's std::bad_alloc becomes (read_model, read_plain_mesh): InvalidInput naming the
// file and its size, so that the one-line message says which input did not fit.
InvalidInput out_of_memory_reading(const std::filesystem::path& path);

}  // namespace geode::io
