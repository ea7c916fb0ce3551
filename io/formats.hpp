#pragma once
// The format table: every mesh file format geode reads or writes, one entry each (extensions,
// signature, reader, writer, what it carries). read_model, write_model, every command's format
// choices and help texts, and the format matrix of docs/formats.md (`geode formats`) are read
// off it, so a new format is its reader and writer in a file of their own plus one entry in
// formats.cpp (docs/developer-guide.md, "A file format").
//
// Signatures are checked before any reader sees a byte (file_format.hpp); an entry's reader
// must also refuse content that is not its format, whoever calls it.
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <geode/io/gmsh.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/element_numbers.hpp>
#include <geode/primal/mesh.hpp>
#include <geode/primal/model.hpp>

namespace geode::io {

// How much of one kind of model data survives a format.
enum class Carried {
  kNo,       // dropped when written, absent when read
  kWritten,  // written (for other tools), not read back
  kYes,      // written and read back
};

// What a format keeps of a primal::Model.
struct FormatCarries {
  Carried blocks = Carried::kNo;       // element block (material) ids
  Carried block_names = Carried::kNo;  // Model::block_names
  Carried node_sets = Carried::kNo;    // ids and nodes
  Carried side_sets = Carried::kNo;    // ids and element sides
  Carried set_names = Carried::kNo;    // names of node and side sets
  std::string_view cells;              // the cell kinds it reads and writes, for people
};

// Options a writer may use; others ignore them.
struct WriteOptions {
  VtkEncoding vtk_encoding = VtkEncoding::kBinary;  // .vtu DataArrays, legacy .vtk data
  // .msh 4.1 and 2.2: ASCII unless asked, as Gmsh saves by default, since some solvers' readers
  // take text only (GetFEM's import fails on binary .msh of either version).
  GmshFormat msh_encoding = GmshFormat::kAscii;
  // Each element's scaled Jacobian (hexes, tets, pyramids, wedges in turn; primal/quality.hpp's
  // per kind), for the formats that write them (MeshFormat::writes_scaled_jacobians), from a
  // caller that has them already (conform measures every output hex); empty: computed.
  std::span<const double> scaled_jacobians;
};

// A hex or planar quad mesh as the file gives it, without the geometry checks of a Model's
// readers: for tools that diagnose tangled meshes (`geode check`, `geode dual`, `geode view`).
struct PlainMesh {
  int dim = 3;  // 3: hex, 2: quad
  primal::HexMesh hex;
  primal::QuadMesh quad;
  // With read_plain_mesh's `other_cells`: a file holding tets, pyramids or wedges (a hybrid
  // mesh) as read_model reads it, its cells unchecked (dim 3, hex empty).
  std::optional<primal::Model> model;
};

using ModelReader = primal::Model (*)(const std::filesystem::path& path,
                                      const primal::ReadOptions& options);
using ModelWriter = void (*)(const primal::Model& model, const std::filesystem::path& path,
                             const WriteOptions& options);
using QuadWriter = void (*)(const primal::QuadMesh& mesh, const std::filesystem::path& path,
                            const WriteOptions& options);
// The file's cells as they are when it holds only hexes or only quads; nothing for other
// content (which then goes through `read`).
using PlainReader = std::optional<PlainMesh> (*)(const std::filesystem::path& path);
// Whether a file's first bytes (up to 4 KiB) look like the format.
using Signature = bool (*)(std::string_view head);

struct MeshFormat {
  std::string_view name;   // --format name: exo, msh, msh22, vtu, vtk
  std::string_view title;  // "Exodus II", for messages and the docs
  std::vector<std::string_view>
      extensions;  // lower case, with the dot; several entries may share one
  Signature signature = nullptr;
  std::string_view signature_hint;   // said when a file lacks the signature
  ModelReader read = nullptr;        // nullptr: written only (read by another entry)
  ModelWriter write = nullptr;       // nullptr: read only
  QuadWriter write_quads = nullptr;  // planar quad meshes; nullptr: none
  PlainReader read_plain = nullptr;  // nullptr: read through `read`
  // Its reader runs a library in a forked child process (isolated.hpp): see read_forks.
  bool reads_in_child = false;
  // Writes each cell's scaled Jacobian (WriteOptions::scaled_jacobians).
  bool writes_scaled_jacobians = false;
  primal::Index index_base = 1;  // how the file numbers nodes and elements (messages)
  // The order its writer numbers an all-hex model's elements in (element_numbers.hpp).
  primal::ElementOrder element_order = primal::ElementOrder::kByBlock;
  FormatCarries carries;
  std::string_view read_variants;  // versions and encodings read
  std::string_view written_as;     // the version and encoding written
};

// Every entry, in the order the docs list them and --format choices name them.
std::span<const MeshFormat> mesh_formats();

// The entry named `name` (a --format name), or nullptr.
const MeshFormat* find_mesh_format(std::string_view name);

// The entry that reads `path`, by its extension (any case); nullptr when none does.
const MeshFormat* reader_for(const std::filesystem::path& path);
// The entry that writes `path`: the first writer with its extension, or nullptr.
const MeshFormat* writer_for(const std::filesystem::path& path);
// The entry write_model uses for `path`: `format` by name, else by the path's extension;
// InvalidInput naming the path when neither gives a model writer.
const MeshFormat& output_format(const std::filesystem::path& path, std::string_view format);

// How the file `format` writes numbers an all-hex model's hexes (messages, reports).
primal::ElementNumbering element_numbering(const MeshFormat& format);

// Lists for messages and help texts: ".exo, .e, .msh, .vtu or .vtk" (each extension once, in
// table order), of the formats that read (or read planar quad meshes, write, write planar quad
// meshes).
enum class FormatRole { kRead, kReadQuads, kWrite, kWriteQuads };
std::string extension_list(FormatRole role, std::string_view separator = ", ",
                           std::string_view last_separator = " or ");
// --format names of the formats that write (or write quad meshes): {"exo", "msh", ...}.
std::vector<std::string> format_names(FormatRole role);

// The file's content starts like `format`; InvalidInput naming the file otherwise (what it
// looks like instead, by the other entries' signatures; empty files; the entry's hint).
void check_signature(const std::filesystem::path& path, const MeshFormat& format);

// Reads `path` with the hex or quad cells as the file gives them (PlainMesh) where the entry
// can, else through read_model with its points checked but not its cells (their geometry and
// covering are for the caller to judge, as with the entries that read plain meshes);
// InvalidInput naming the file otherwise, and for a file with other cells than hexes unless
// `other_cells` (PlainMesh::model).
PlainMesh read_plain_mesh(const std::filesystem::path& path, const MeshFormat** format = nullptr,
                          bool other_cells = false);

// Writes a model in the format `format` names, or, when empty, the one the extension names
// (.msh: Gmsh 4.1). InvalidInput naming the file for an unknown format or extension, and
// whatever the writer refuses. Writes are atomic (no half-written file).
void write_model(const primal::Model& model, const std::filesystem::path& path,
                 std::string_view format = {}, const WriteOptions& options = {});
// The same for a planar quad mesh (formats with write_quads).
void write_quad_mesh(const primal::QuadMesh& mesh, const std::filesystem::path& path,
                     std::string_view format = {}, const WriteOptions& options = {});

// The format matrix of docs/formats.md, as Markdown (one row per entry).
std::string format_matrix_markdown();

}  // namespace geode::io
