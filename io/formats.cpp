// The format table (io/formats.hpp) and the dispatch that reads it.
#include <geode/io/formats.hpp>

#include <algorithm>
#include <cctype>
#include <new>
#include <stdexcept>

#include <geode/io/exodus.hpp>
#include <geode/io/file_format.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/nemesis_set.hpp>
#include <geode/io/read_model.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/errors.hpp>

namespace geode::io {

namespace fs = std::filesystem;

namespace {

// The grid's volume cells and their cell arrays, the points as they are.
VtkGrid without_boundary_cells(VtkGrid g) {
  std::vector<std::size_t> keep;
  for (std::size_t c = 0; c < g.cells.size(); ++c)
    if (!vtk_boundary_cell(g.cell_types[c])) keep.push_back(c);
  const auto kept = [&keep](auto values) {
    decltype(values) out;
    out.reserve(keep.size());
    for (std::size_t c : keep) out.push_back(std::move(values[c]));
    return out;
  };
  g.cells = kept(std::move(g.cells));
  g.cell_types = kept(std::move(g.cell_types));
  for (auto& [name, values] : g.cell_data.doubles) values = kept(std::move(values));
  for (auto& [name, values] : g.cell_data.ints) values = kept(std::move(values));
  return g;
}

// A VTK file's cells as given: all quads (a planar quad mesh), or hexes (vertices, lines,
// triangles and quads beside them annotate the volume, vtk_boundary_cell, and are left out); a
// file with tets, pyramids or wedges as a model from the same parse, its cells unchecked
// (PlainMesh::model: read_plain_mesh says whether the caller takes one).
std::optional<PlainMesh> read_vtk_plain(const fs::path& path) {
  VtkGrid g = read_vtk_file(path);
  PlainMesh m;
  if (std::any_of(g.cell_types.begin(), g.cell_types.end(),
                  [](int t) { return t == kVtkTetra || t == kVtkPyramid || t == kVtkWedge; })) {
    primal::ReadOptions plain;
    plain.check_geometry = false;
    m.model = model_from_vtk(g, plain);
    return m;
  }
  const bool quads = !g.cell_types.empty() && std::all_of(g.cell_types.begin(), g.cell_types.end(),
                                                          [](int t) { return t == kVtkQuad; });
  if (quads) {
    m.dim = 2;
    m.quad = to_quad_mesh(g);
    return m;
  }
  if (std::any_of(g.cell_types.begin(), g.cell_types.end(), vtk_boundary_cell) &&
      std::any_of(g.cell_types.begin(), g.cell_types.end(),
                  [](int t) { return t == kVtkHexahedron; }))
    g = without_boundary_cells(std::move(g));
  m.hex = to_hex_mesh(g);  // names the first cell that is not a hex
  return m;
}

constexpr FormatCarries kExodusCarries{Carried::kYes, Carried::kYes, Carried::kYes,
                                       Carried::kYes, Carried::kYes, "hex, tet, pyramid, wedge"};
constexpr FormatCarries kGmshCarries{Carried::kYes, Carried::kYes, Carried::kYes,
                                     Carried::kYes, Carried::kYes, "hex, tet, pyramid, wedge"};
constexpr std::string_view kGmshHint =
    "it does not start with $MeshFormat; Gmsh scripts are not read";

// The table. One entry per format; the reader and writer live in the format's own file. Fields
// left out keep their defaults (GCC's -Wextra would ask for every field of a designated
// initializer).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const std::vector<MeshFormat>& table() {
  static const std::vector<MeshFormat> formats{
      {.name = "exo",
       .title = "Exodus II",
       .extensions = {".exo", ".e"},
       .signature = looks_like_exodus,
       .signature_hint = "no netCDF or HDF5 signature",
       .read = read_exodus,
       .write = [](const primal::Model& m, const fs::path& p,
                   const WriteOptions&) { write_exodus(m, p); },
       .reads_in_child = true,
       .carries = kExodusCarries,
       .read_variants =
           "netCDF classic, 64-bit, CDF-5 or netCDF-4/HDF5, as Cubit, SEACAS and meshio write it",
       .written_as = "netCDF, with coordinate names x y z"},
      {.name = "msh",
       .title = "Gmsh .msh",
       .extensions = {".msh"},
       .signature = looks_like_gmsh,
       .signature_hint = kGmshHint,
       .read = read_gmsh,
       .write = [](const primal::Model& m, const fs::path& p,
                   const WriteOptions& o) { write_gmsh(m, p, o.msh_encoding); },
       .carries = kGmshCarries,
       .read_variants = "2.2 and 4.1, ASCII and binary",
       .written_as = "4.1 ASCII (`--msh-encoding binary`: binary)"},
      {.name = "msh22",
       .title = "Gmsh .msh 2.2",
       .extensions = {".msh"},
       .signature = looks_like_gmsh,
       .signature_hint = kGmshHint,
       .write = [](const primal::Model& m, const fs::path& p,
                   const WriteOptions& o) { write_gmsh(m, p, o.msh_encoding, GmshVersion::k22); },
       .carries = kGmshCarries,
       .written_as = "2.2 ASCII (`--format msh22`; `--msh-encoding binary`: binary)"},
      {.name = "vtu",
       .title = "VTK XML .vtu",
       .extensions = {".vtu"},
       .signature = looks_like_vtu,
       .read = [](const fs::path& p,
                  const primal::ReadOptions& o) { return model_from_vtk(read_vtu(p), o); },
       .write =
           [](const primal::Model& m, const fs::path& p, const WriteOptions& o) {
             write_vtu(p, m, {}, o.vtk_encoding, o.scaled_jacobians);
           },
       .write_quads = [](const primal::QuadMesh& m, const fs::path& p,
                         const WriteOptions& o) { write_vtu(p, m, {}, o.vtk_encoding); },
       .read_plain = read_vtk_plain,
       .writes_scaled_jacobians = true,
       .index_base = 0,
       .element_order = primal::ElementOrder::kAsGiven,
       .carries = {Carried::kYes, Carried::kYes, Carried::kYes, Carried::kYes, Carried::kYes,
                   "hex, tet, pyramid, wedge; planar quad"},
       .read_variants = "ascii, binary (base64), appended (raw and base64), zlib-compressed, "
                        "UInt32 or UInt64 headers",
       .written_as = "binary (base64; `--vtk-encoding ascii`); cell arrays `block`, `mat_id` (the "
                     "block again, for Python solvers), `scaled_jacobian`, "
                     "block names and sets as field data `block:NAME`, `node_set:ID:NAME`, "
                     "`side_set:ID:NAME`"},
      {.name = "vtk",
       .title = "legacy VTK .vtk",
       .extensions = {".vtk"},
       .signature = looks_like_vtk,
       .read = [](const fs::path& p,
                  const primal::ReadOptions& o) { return model_from_vtk(read_vtk(p), o); },
       .write =
           [](const primal::Model& m, const fs::path& p, const WriteOptions& o) {
             write_vtk(p, m, {}, o.vtk_encoding, o.scaled_jacobians);
           },
       .write_quads = [](const primal::QuadMesh& m, const fs::path& p,
                         const WriteOptions& o) { write_vtk(p, m, {}, o.vtk_encoding); },
       .read_plain = read_vtk_plain,
       .writes_scaled_jacobians = true,
       .index_base = 0,
       .element_order = primal::ElementOrder::kAsGiven,
       .carries = {Carried::kYes, Carried::kYes, Carried::kYes, Carried::kYes, Carried::kYes,
                   "hex, tet, pyramid, wedge; planar quad"},
       .read_variants = "ASCII and BINARY, classic and 5.1 cell layouts",
       .written_as = "4.2 BINARY (`--vtk-encoding ascii`: ASCII); cell arrays `block`, "
                     "`scaled_jacobian`; block names and sets as dataset field data, named as in "
                     ".vtu"},
  };
  return formats;
}
#pragma GCC diagnostic pop

std::string lower_extension(const fs::path& path) {
  std::string e = path.extension().string();
  std::transform(e.begin(), e.end(), e.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

bool has_extension(const MeshFormat& f, std::string_view e) {
  return std::find(f.extensions.begin(), f.extensions.end(), e) != f.extensions.end();
}

bool plays(const MeshFormat& f, FormatRole role) {
  switch (role) {
    case FormatRole::kRead:
      return f.read != nullptr;
    case FormatRole::kReadQuads:
      return f.read_plain != nullptr;
    case FormatRole::kWrite:
      return f.write != nullptr;
    case FormatRole::kWriteQuads:
      return f.write_quads != nullptr;
  }
  return false;
}

const MeshFormat& resolve(const fs::path& path, std::string_view format, FormatRole role) {
  const MeshFormat* f = format.empty() ? writer_for(path) : find_mesh_format(format);
  if (!f && format.empty())
    throw InvalidInput(path.string() + ": unknown output format '" + lower_extension(path) +
                       "' (expected " + extension_list(role) + ")");
  if (!f || !plays(*f, role))
    throw InvalidInput(path.string() + ": '" + std::string(format) + "' is not a mesh format" +
                       (role == FormatRole::kWriteQuads ? " for quad meshes" : "") + " (expected " +
                       [&] {
                         std::string s;
                         for (const auto& n : format_names(role)) s += (s.empty() ? "" : ", ") + n;
                         return s;
                       }() +
                       ")");
  return *f;
}

const char* carried_text(Carried c) {
  switch (c) {
    case Carried::kNo:
      return "no";
    case Carried::kWritten:
      return "written";
    case Carried::kYes:
      return "yes";
  }
  return "no";
}

}  // namespace

std::span<const MeshFormat> mesh_formats() { return table(); }

const MeshFormat* find_mesh_format(std::string_view name) {
  for (const MeshFormat& f : table())
    if (f.name == name) return &f;
  return nullptr;
}

const MeshFormat* reader_for(const fs::path& path) {
  const std::string e = lower_extension(path);
  for (const MeshFormat& f : table())
    if (f.read && has_extension(f, e)) return &f;
  return nullptr;
}

const MeshFormat* writer_for(const fs::path& path) {
  const std::string e = lower_extension(path);
  for (const MeshFormat& f : table())
    if (f.write && has_extension(f, e)) return &f;
  return nullptr;
}

std::string extension_list(FormatRole role, std::string_view separator,
                           std::string_view last_separator) {
  std::vector<std::string_view> all;
  for (const MeshFormat& f : table())
    if (plays(f, role))
      for (std::string_view e : f.extensions)
        if (std::find(all.begin(), all.end(), e) == all.end()) all.push_back(e);
  std::string s;
  for (std::size_t i = 0; i < all.size(); ++i)
    s += (i == 0                ? ""
          : i + 1 == all.size() ? std::string(last_separator)
                                : std::string(separator)) +
         std::string(all[i]);
  return s;
}

std::vector<std::string> format_names(FormatRole role) {
  std::vector<std::string> names;
  for (const MeshFormat& f : table())
    if (plays(f, role)) names.emplace_back(f.name);
  return names;
}

void check_signature(const fs::path& path, const MeshFormat& format) {
  const std::string head = read_file_head(path);
  if (format.signature(head)) return;
  std::string what = path.string() + ": not in " + std::string(format.title) + " format";
  const MeshFormat* found = nullptr;
  for (const MeshFormat& f : table())
    if (f.read && f.signature(head)) {
      found = &f;
      break;
    }
  if (head.empty())
    what += " (the file is empty)";
  else if (found)
    what += " (its content is " + std::string(found->title) + ")";
  else if (!format.signature_hint.empty())
    what += " (" + std::string(format.signature_hint) + ")";
  throw InvalidInput(what);
}

PlainMesh read_plain_mesh(const fs::path& path, const MeshFormat** format, bool other_cells) {
  // A Nemesis set (geode_mpi's pieces without --join, named by a piece or by the joined name):
  // an Exodus model, which read_model joins.
  const std::optional<NemesisSet> set = find_nemesis_set(path);
  const MeshFormat* f = reader_for(set ? set->base : path);
  if (!f) {
    (void)read_file_head(path);  // a missing file is named as such first
    throw InvalidInput(path.string() + ": unknown input format '" + lower_extension(path) +
                       "' (expected " + extension_list(FormatRole::kRead) + ")");
  }
  if (format) *format = f;
  if (!set) check_signature(path, *f);  // each piece's is read_model's
  // A model with other cells than hexes goes to a caller that takes one, whichever reader made
  // it; to the others it is refused naming what it holds.
  auto other = [&](primal::Model model) {
    if (other_cells) {
      PlainMesh m;
      m.model = std::move(model);
      return m;
    }
    for (primal::ElementKind kind :
         {primal::ElementKind::kTet, primal::ElementKind::kPyramid, primal::ElementKind::kWedge})
      if (const std::size_t n = primal::element_count(model, kind))
        throw InvalidInput(path.string() + ": holds " + std::to_string(n) + " " +
                           primal::element_kind_name(kind) +
                           "s; expected an all-hex mesh (use `geode conform` first)");
    throw std::logic_error("read_plain_mesh: a model without other cells");
  };
  if (f->read_plain && !set) try {
      if (auto m = f->read_plain(path))
        return m->model ? other(std::move(*m->model)) : std::move(*m);
    } catch (const std::bad_alloc&) {
      throw out_of_memory_reading(path);
    }
  // The cells as the file gives them, as read_plain does: judging them (inverted, folded,
  // overshared) is the caller's (geode check reports an invalid mesh; it refused an .exo or
  // .msh one at the read, exit 2, where it reported a .vtu one).
  primal::ReadOptions plain;
  plain.check_geometry = false;
  primal::Model model = read_model(path, plain, /*check_covering=*/false);
  if (primal::element_count(model) > model.hexes.size()) return other(std::move(model));
  if (model.hexes.empty())  // surfaces only (a 2D Gmsh mesh), or nothing: no mesh to judge
    throw InvalidInput(path.string() +
                       ": holds no hexes (no volume element at all); expected an "
                       "all-hex mesh");
  PlainMesh m;
  m.hex = primal::hex_part(model);
  return m;
}

const MeshFormat& output_format(const fs::path& path, std::string_view format) {
  return resolve(path, format, FormatRole::kWrite);
}

primal::ElementNumbering element_numbering(const MeshFormat& format) {
  return {format.element_order, format.index_base};
}

void write_model(const primal::Model& model, const fs::path& path, std::string_view format,
                 const WriteOptions& options) {
  output_format(path, format).write(model, path, options);
}

void write_quad_mesh(const primal::QuadMesh& mesh, const fs::path& path, std::string_view format,
                     const WriteOptions& options) {
  resolve(path, format, FormatRole::kWriteQuads).write_quads(mesh, path, options);
}

std::string format_matrix_markdown() {
  std::string s =
      "| extension | format (`--format`) | read | written | cells | blocks | block names | node "
      "sets | side sets "
      "| set names |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const MeshFormat& f : table()) {
    std::string ext;
    for (std::string_view e : f.extensions)
      ext += (ext.empty() ? "`" : ", `") + std::string(e) + "`";
    const FormatCarries& c = f.carries;
    s += "| " + ext + " | " + std::string(f.title) + " (`" + std::string(f.name) + "`) | " +
         (f.read ? std::string(f.read_variants) : std::string("by `msh`")) + " | " +
         (f.write ? std::string(f.written_as) : std::string("no")) + " | " + std::string(c.cells) +
         " | " + carried_text(c.blocks) + " | " + carried_text(c.block_names) + " | " +
         carried_text(c.node_sets) + " | " + carried_text(c.side_sets) + " | " +
         carried_text(c.set_names) + " |\n";
  }
  return s;
}

}  // namespace geode::io
