// geode.conform's core and the demo models: a hex + tet model given as arrays (the package's
// geode.conform converts a meshio.Mesh to them and back), conformed as `geode conform` does
// (cli/conform_command.cpp) with the same options, messages and verdict (conform/report.hpp).
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include <geode/conform/conform.hpp>
#include <geode/conform/report.hpp>
#include <geode/demo/demo_models.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/model.hpp>
#include "python/arrays.hpp"

namespace geode::python {
namespace {

std::vector<int> to_blocks(const py::handle& blocks, std::size_t n, const std::string& what) {
  if (blocks.is_none()) return {};
  auto b = blocks.cast<std::vector<int>>();
  if (b.size() != n)
    throw InvalidInput(what + ": " + std::to_string(b.size()) + " block ids for " +
                       std::to_string(n) + " elements");
  return b;
}

py::dict model_dict(primal::Model&& model) {
  // The module hands out hexes and tets only so far: refuse rather than drop the other kinds.
  for (primal::ElementKind kind : {primal::ElementKind::kPyramid, primal::ElementKind::kWedge})
    if (const std::size_t n = primal::element_count(model, kind))
      throw InvalidInput(
          "the model holds " + std::to_string(n) + " " + primal::element_kind_name(kind) +
          "s, which the Python module does not hand out yet (the command writes them: "
          "geode demo --save-input)");
  py::dict d;
  const std::size_t nh = model.hexes.size(), nt = model.tets.size();
  std::vector<int> hb = model.hex_block, tb = model.tet_block;
  if (hb.empty()) hb.assign(nh, 1);
  if (tb.empty()) tb.assign(nt, 2);
  d["points"] = points_array(std::move(model.points));
  d["hexes"] = cells_array<8>(std::move(model.hexes));
  d["tets"] = cells_array<4>(std::move(model.tets));
  d["hex_block"] = py::array(py::cast(hb));
  d["tet_block"] = py::array(py::cast(tb));
  d["block_names"] = model.block_names;
  py::list node_sets, side_sets;
  for (auto& s : model.node_sets)
    node_sets.append(py::dict(py::arg("id") = s.id, py::arg("name") = s.name,
                              py::arg("nodes") = index_array(std::move(s.nodes))));
  for (const auto& s : model.side_sets) {
    std::vector<Index> sides;  // (element, local face) pairs: hexes in conform's all-hex output
    for (const auto& side : s.sides) {
      sides.push_back(side.element.index);
      sides.push_back(side.face);
    }
    auto a = index_array(std::move(sides))
                 .reshape({static_cast<py::ssize_t>(s.sides.size()), py::ssize_t{2}});
    side_sets.append(
        py::dict(py::arg("id") = s.id, py::arg("name") = s.name, py::arg("sides") = a));
  }
  d["node_sets"] = node_sets;
  d["side_sets"] = side_sets;
  return d;
}

// The model as arrays; conform's options by name, as `geode conform` spells them (with _).
py::dict conform_arrays(const py::handle& points, const py::handle& hexes,
                        const py::handle& hex_block, const py::handle& tets,
                        const py::handle& tet_block, const std::map<int, std::string>& block_names,
                        const py::list& node_sets, const std::string& source,
                        const std::string& smooth, const std::string& quality,
                        const std::string& geode_block, const std::string& buffer_side,
                        double buffer_thickness, double smooth_target,
                        const py::object& template_box, const py::object& merge_tolerance,
                        const std::string& relax) {
  primal::Model model;
  model.points = to_points(points, source + ": points");
  model.hexes = to_cells<8>(hexes, source + ": hexes");
  model.tets = to_cells<4>(tets, source + ": tets");
  model.hex_block = to_blocks(hex_block, model.hexes.size(), source + ": hex blocks");
  model.tet_block = to_blocks(tet_block, model.tets.size(), source + ": tet blocks");
  model.block_names = block_names;
  for (const auto& s : node_sets) {
    const auto d = s.cast<py::dict>();
    primal::NodeSet set;
    set.id = d["id"].cast<int>();
    set.name = d.contains("name") ? d["name"].cast<std::string>() : std::string();
    set.nodes = d["nodes"].cast<std::vector<Index>>();
    model.node_sets.push_back(std::move(set));
  }
  // What the readers check of a file, here of the arrays (ids are 0-based indices + 1, as
  // written; messages name the source).
  primal::validate(model, source);
  primal::check_geometry(model, source);

  conform::ConformOptions opts;
  opts.smooth = conform::parse_conform_smooth(smooth);
  opts.quality = conform::parse_conform_quality(quality);
  opts.geode_block = geode_block;
  opts.relax = conform::parse_conform_relax(relax);
  opts.buffer.side = conform::parse_buffer_side(buffer_side);
  if (!(buffer_thickness >= 0) ||
      buffer_thickness > conform::max_buffer_thickness(opts.buffer.side)) {
    std::ostringstream m;
    m << "buffer_thickness " << buffer_thickness << " with buffer_side " << buffer_side
      << ": at most " << conform::max_buffer_thickness(opts.buffer.side);
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
  {
    py::gil_scoped_release free;
    if (merge) merged = primal::merge_coincident_nodes(model, *merge);
    // The read-time check of a file (after merging: duplicated nodes look like a gap), which
    // local verification, the default, takes as given; its messages name the source.
    primal::require_single_covering(model, source);
    try {
      r = conform::conform(model, opts);
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
  d["model"] = model_dict(std::move(r.model));
  return d;
}

}  // namespace

void bind_conform(py::module_& m) {
  m.def("_conform", &conform_arrays, py::arg("points"), py::arg("hexes"), py::arg("hex_block"),
        py::arg("tets"), py::arg("tet_block"), py::arg("block_names"), py::arg("node_sets"),
        py::arg("source"), py::arg("smooth"), py::arg("quality"), py::arg("geode_block"),
        py::arg("buffer_side"), py::arg("buffer_thickness"), py::arg("smooth_target"),
        py::arg("template_box"), py::arg("merge_tolerance"), py::arg("relax"));
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
