// geode.conform's core and the demo models: a model of hexes, tets, pyramids and wedges given as
// arrays (the package's geode.conform converts a meshio.Mesh to them and back), conformed as
// `geode conform` does (cli/conform_command.cpp) with the same options, messages and verdict
// (conform/report.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>

#include <geode/conform/conform.hpp>
#include <geode/conform/report.hpp>
#include <geode/demo/demo_models.hpp>
#include <geode/io/read_warnings.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/unfold.hpp>
#include "python/arrays.hpp"

namespace geode::python {
namespace {

// Each cell kind's entries in the dicts of arrays geode.conform passes in and the module hands
// out (python/geode/__init__.py), in primal::kElementKinds order: M x corners node numbers in
// the model's corner order (meshio's for all four: its linear wedge is Gmsh's prism), M block
// ids, and on the way in M file ids for messages.
struct KindKeys {
  primal::ElementKind kind;
  const char* cells;
  const char* block;
  const char* ids;
};
constexpr std::array<KindKeys, 4> kKindKeys{{
    {primal::ElementKind::kHex, "hexes", "hex_block", "hex_ids"},
    {primal::ElementKind::kTet, "tets", "tet_block", "tet_ids"},
    {primal::ElementKind::kPyramid, "pyramids", "pyramid_block", "pyramid_ids"},
    {primal::ElementKind::kWedge, "wedges", "wedge_block", "wedge_ids"},
}};

// A block id the files' 32-bit ids can hold; non-positive ones are refused by primal::validate,
// naming the element the same way.
void check_block_id(std::int64_t id, const std::string& where) {
  if (id < std::numeric_limits<int>::min() || id > std::numeric_limits<int>::max())
    throw InvalidInput(where + ": block id " + std::to_string(id) + " is out of range [1, " +
                       std::to_string(std::numeric_limits<int>::max()) + "]");
}

// One kind's arrays appended to the model, each element with its block and file id.
void add_cells(primal::Model& model, const KindKeys& keys, const py::dict& arrays,
               const std::string& source) {
  const std::string what = source + ": " + keys.cells;
  // Block ids as 64-bit, so that one too large for the files' 32-bit ids is refused naming the
  // element, as a reader does, rather than by pybind's cast error.
  const auto blocks = py::object(arrays[keys.block]).cast<std::vector<std::int64_t>>();
  const auto ids = py::object(arrays[keys.ids]).cast<std::vector<std::int64_t>>();
  auto add = [&](const auto& cells) {
    if (blocks.size() != cells.size() || ids.size() != cells.size())
      throw InvalidInput(what + ": " + std::to_string(blocks.size()) + " block ids and " +
                         std::to_string(ids.size()) + " element ids for " +
                         std::to_string(cells.size()) + " elements");
    for (std::size_t i = 0; i < cells.size(); ++i) {
      check_block_id(blocks[i], source + ": " + primal::element_kind_name(keys.kind) + " " +
                                    std::to_string(ids[i]));
      primal::add_element(model, keys.kind, cells[i], primal::index_cast<int>(blocks[i]), ids[i]);
    }
  };
  const py::object cells = arrays[keys.cells];
  // A cell by its id, as the checks after name it ("mesh: tet 30").
  const auto cell = [&](std::size_t i) {
    return source + ": " + primal::element_kind_name(keys.kind) + " " +
           (i < ids.size() ? std::to_string(ids[i]) : std::to_string(i + 1));
  };
  switch (primal::cell_topology(keys.kind).corners) {
    case 4:
      add(to_cells<4>(cells, what, cell));
      break;
    case 5:
      add(to_cells<5>(cells, what, cell));
      break;
    case 6:
      add(to_cells<6>(cells, what, cell));
      break;
    default:
      add(to_cells<8>(cells, what, cell));
  }
}

// Every kind's cells and blocks (a kind's default block where the model leaves them implicit),
// block names, node sets and side sets.
py::dict model_dict(primal::Model&& model) {
  py::dict d;
  for (const KindKeys& keys : kKindKeys) {
    std::vector<int> blocks = primal::element_blocks(model, keys.kind);
    if (blocks.empty())
      blocks.assign(primal::element_count(model, keys.kind), primal::default_block(keys.kind));
    d[keys.block] = py::array_t<int>(static_cast<py::ssize_t>(blocks.size()), blocks.data());
  }
  d["points"] = points_array(std::move(model.points));
  d["hexes"] = cells_array<8>(std::move(model.hexes));
  d["tets"] = cells_array<4>(std::move(model.tets));
  d["pyramids"] = cells_array<5>(std::move(model.pyramids));
  d["wedges"] = cells_array<6>(std::move(model.wedges));
  d["block_names"] = model.block_names;
  py::list node_sets, side_sets;
  for (auto& s : model.node_sets)
    node_sets.append(py::dict(py::arg("id") = s.id, py::arg("name") = s.name,
                              py::arg("nodes") = index_array(std::move(s.nodes))));
  for (const auto& s : model.side_sets) {
    // (element, local face) pairs, the element an index into its kind's array; the kinds as
    // primal::ElementKind numbers (conform's all-hex output: every one 0).
    std::vector<Index> sides, kinds;
    for (const auto& side : s.sides) {
      sides.push_back(side.element.index);
      sides.push_back(side.face);
      kinds.push_back(static_cast<Index>(side.element.kind));
    }
    auto a = index_array(std::move(sides))
                 .reshape({static_cast<py::ssize_t>(s.sides.size()), py::ssize_t{2}});
    side_sets.append(py::dict(py::arg("id") = s.id, py::arg("name") = s.name, py::arg("sides") = a,
                              py::arg("kinds") = index_array(std::move(kinds))));
  }
  d["node_sets"] = node_sets;
  d["side_sets"] = side_sets;
  return d;
}

// The model as arrays; conform's options by name, as `geode conform` spells them (with _).
py::dict conform_arrays(const py::handle& points, const py::dict& cells,
                        const std::map<std::int64_t, std::string>& block_names,
                        const py::list& node_sets, const py::list& tagged,
                        const std::string& source, const std::string& smooth,
                        const std::string& quality, const std::string& geode_block,
                        const std::string& buffer_side, double buffer_thickness,
                        double smooth_target, const py::object& template_box,
                        const py::object& merge_tolerance, const std::string& relax, bool unfold) {
  primal::Model model;
  model.points = to_points(points, source + ": points", false);
  for (const KindKeys& keys : kKindKeys) add_cells(model, keys, cells, source);
  for (const auto& [id, name] : block_names) {
    check_block_id(id, source + ": block name '" + name + "'");
    model.block_names[primal::index_cast<int>(id)] = name;
  }
  for (const auto& s : node_sets) {
    const auto d = s.cast<py::dict>();
    primal::NodeSet set;
    set.id = d["id"].cast<int>();
    set.name = d.contains("name") ? d["name"].cast<std::string>() : std::string();
    set.nodes = d["nodes"].cast<std::vector<Index>>();
    model.node_sets.push_back(std::move(set));
  }
  // Gmsh's physical points, curves and surfaces as meshio gives them (cells with their tag):
  // the sets a file's reader makes of them.
  std::vector<primal::TaggedCells> groups;
  for (const auto& t : tagged) {
    const auto d = t.cast<py::dict>();
    primal::TaggedCells g;
    g.dim = d["dim"].cast<int>();
    g.cell_ids = d["ids"].cast<std::vector<std::int64_t>>();
    try {  // a tag or a node number past 32 bits: the file's own refusal, not a cast error
      g.id = d["id"].cast<int>();
      g.name = d["name"].cast<std::string>();
      g.cells = d["cells"].cast<std::vector<std::vector<Index>>>();
    } catch (const py::cast_error&) {
      throw InvalidInput(source + ": the points, lines or faces of one tag, cell " +
                         (g.cell_ids.empty() ? std::string("?") : std::to_string(g.cell_ids[0])) +
                         " the first: their gmsh:physical tag or a node number lies outside the "
                         "32-bit range");
    }
    for (std::size_t c = 0; c < g.cells.size(); ++c)
      for (Index v : g.cells[c])
        if (v < 0 || primal::index_cast<std::size_t>(v) >= model.points.size())
          throw InvalidInput(source + ": cell " + std::to_string(g.cell_ids[c]) +
                             " refers to node " + std::to_string(v) + ", out of range [0, " +
                             std::to_string(model.points.size()) + ")");
    groups.push_back(std::move(g));
  }
  std::vector<std::string> read_warnings;  // as a file's reader says them
  {
    const io::ReadWarnings collected;
    const auto moved_sets = primal::separate_node_set_ids(groups, source);
    io::warn_moved_node_sets(groups, moved_sets, source, "line cells tagged",
                             "vertex cells tagged");
    read_warnings = collected.messages();
  }
  primal::add_tagged_sets(model, groups, source, "cell");
  // What the readers check of a file, here of the arrays: a wedge or pyramid in another corner
  // order is inverted, and refused as a file's is (the element ids are the package's: each
  // cell's 1-based position among the mesh's cells, a .msh file's element tag when meshio or
  // geode wrote it; messages name the source).
  primal::validate(model, source);
  if (!unfold)  // with unfold: after it (its inverted cells)
    primal::check_geometry(model, source, primal::inverted_hint("unfold=True"));

  conform::ConformOptions opts;
  // Hexes named as the returned mesh holds them: grouped by block in ascending id, from 0.
  opts.output_numbering = {primal::ElementOrder::kByBlock, 0};
  opts.smooth = conform::parse_conform_smooth(smooth);
  opts.quality = conform::parse_conform_quality(quality);
  opts.geode_block = geode_block;
  opts.relax = conform::parse_conform_relax(relax);
  conform::set_buffer_side(opts, buffer_side);  // "": automatic
  if (!(buffer_thickness >= 0) ||
      buffer_thickness > conform::max_buffer_thickness(opts.buffer.side)) {
    std::ostringstream m;
    m << "buffer_thickness " << buffer_thickness << " with buffer_side "
      << conform::buffer_side_name(opts.buffer.side) << ": at most "
      << conform::max_buffer_thickness(opts.buffer.side);
    throw InvalidInput(m.str());
  }
  opts.buffer.thickness = buffer_thickness;
  if (!(smooth_target >= 0 && smooth_target <= 1))
    throw InvalidInput("smooth_target must lie in [0, 1]");
  opts.smooth_target = smooth_target;
  if (!template_box.is_none()) {
    const auto b = template_box.cast<std::vector<double>>();
    if (b.size() != 3 ||
        !std::all_of(b.begin(), b.end(), [](double x) { return std::isfinite(x) && x > 0; }))
      throw InvalidInput("template_box must be three positive numbers");
    opts.template_box = {b[0], b[1], b[2]};
  }
  std::optional<double> merge;
  if (!merge_tolerance.is_none()) {
    merge = merge_tolerance.cast<double>();
    if (!(*merge >= 0)) throw InvalidInput("merge_tolerance must be >= 0");
  }
  conform::ConformResult r;
  Index merged = 0;
  std::vector<Index> moved;  // by unfold
  Index unfolded_cells = 0;  // turned back or read inverted, mended
  {
    py::gil_scoped_release free;
    if (merge) {
      try {
        primal::check_merge_tolerance(model, *merge, "merge_tolerance=");
      } catch (const InvalidInput& e) {
        throw InvalidInput(source + ": " + e.what());
      }
      merged = primal::merge_coincident_nodes(model, *merge);
    }
    primal::UnfoldResult unfolded;
    if (unfold) {  // as --unfold
      unfolded = primal::unfold(model);
      primal::check_geometry(model, source);
    }
    // The read-time check of a file (after merging: duplicated nodes look like a gap), which
    // local verification, the default, takes as given; its messages name the source.
    primal::InputCheckOptions checked;
    if (!unfold) checked.fold_hint = primal::fold_hint("unfold=True");
    if (!unfolded.covered_once) primal::require_single_covering(model, source, checked);
    moved = std::move(unfolded.moved);
    unfolded_cells = primal::index_cast(unfolded.turned.size() + unfolded.inverted.size());
    try {
      r = conform::conform(std::move(model), opts);  // the hints below read what is left
    } catch (const InvalidInput& e) {
      throw InvalidInput(source + ": " + e.what() +
                         conform::duplicate_node_hint(model, "merge_tolerance="));
    } catch (const TopologyError& e) {
      throw TopologyError(source + ": " + e.what() +
                          conform::duplicate_node_hint(model, "merge_tolerance="));
    }
  }
  py::dict d;
  d["valid"] = conform::result_valid(r);
  d["invalid_reason"] =
      d["valid"].cast<bool>() ? std::string() : source + ": " + conform::invalid_reason(r);
  d["report"] = to_python(conform::report_json(r));
  d["merged_nodes"] = merged;
  d["unfolded_nodes"] = moved;
  d["unfolded_cells"] = unfolded_cells;
  d["read_warnings"] = read_warnings;
  d["model"] = model_dict(std::move(r.model));
  return d;
}

}  // namespace

void bind_conform(py::module_& m) {
  m.def("_conform", &conform_arrays, py::arg("points"), py::arg("cells"), py::arg("block_names"),
        py::arg("node_sets"), py::arg("tagged"), py::arg("source"), py::arg("smooth"),
        py::arg("quality"), py::arg("geode_block"), py::arg("buffer_side"),
        py::arg("buffer_thickness"), py::arg("smooth_target"), py::arg("template_box"),
        py::arg("merge_tolerance"), py::arg("relax"), py::arg("unfold"));
  m.def(
      "_demo_model",
      [](const std::string& name, int n) {
        if (n < 1 || n > 64) throw InvalidInput("demo_model: n must lie in [1, 64]");
        primal::Model model;
        {
          py::gil_scoped_release free;
          model = demo::demo_model(name, n);
        }
        return model_dict(std::move(model));
      },
      py::arg("name"), py::arg("n"));
  m.def(
      "demo_model_names", [] { return demo::demo_model_names(); },
      "The demo models (meshed with the Gmsh API), as `geode demo --model` names them.");
}

}  // namespace geode::python
