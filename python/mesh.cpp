// geode.check, geode.quality, geode.dual, geode.smooth and geode.isomorphism: any hex mesh (or
// planar quad mesh) given as arrays, as `geode check` and `geode dual` take files
// (cli/check_command.cpp, cli/dual_command.cpp). Every id in and out is 0-based.
#include <algorithm>
#include <nlohmann/json.hpp>
#include <optional>
#include <tuple>

#include <geode/primal/boundary.hpp>
#include <geode/primal/isomorphism.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/quality_report.hpp>
#include <geode/primal/realizability.hpp>
#include <geode/primal/smooth.hpp>
#include <geode/primal/validity.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include <geode/stc/mesh_dual.hpp>
#include <geode/stc/mesh_fields.hpp>
#include "python/arrays.hpp"

namespace geode::python {
namespace {

primal::HexMesh hex_mesh(const py::handle& points, const py::handle& cells) {
  primal::HexMesh m;
  m.points = to_points(points, "points");
  m.hexes = to_cells<8>(cells, "cells");
  return m;
}

primal::QuadMesh quad_mesh(const py::handle& points, const py::handle& cells) {
  primal::QuadMesh m;
  m.points = to_points(points, "points");
  m.quads = to_cells<4>(cells, "cells");
  return m;
}

py::list face_keys(const std::vector<primal::FaceKey>& keys) {
  py::list l;
  for (const auto& k : keys) {
    py::list nodes;
    for (Index n : k)
      if (n != primal::kInvalidIndex) nodes.append(n);
    l.append(py::tuple(nodes));
  }
  return l;
}

py::list edge_keys(const std::vector<primal::EdgeKey>& keys) {
  py::list l;
  for (const auto& k : keys) l.append(py::make_tuple(k[0], k[1]));
  return l;
}

py::list coverage(const std::vector<primal::NodeCoverage>& nodes) {
  py::list l;
  for (const auto& c : nodes)
    l.append(py::dict(py::arg("node") = c.node, py::arg("angle") = c.angle,
                      py::arg("expected") = c.expected));
  return l;
}

// {"valid", "validity" (the report's text), "report": {what each check found}, "quality",
// "obstructions"}: `geode check --format json` with 0-based ids.
py::dict check(const py::handle& points, const py::handle& cells, double planar_angle) {
  if (!(planar_angle >= 0.0 && planar_angle <= 90.0))  // as `geode check --planar-angle`
    throw InvalidInput("check: planar_angle must lie in [0, 90] degrees");
  primal::RealizabilityOptions options;
  options.planar_angle_degrees = planar_angle;
  py::dict d;
  if (cell_width(cells, "cells") == 8) {
    const primal::HexMesh mesh = hex_mesh(points, cells);
    primal::HexValidityReport v;
    {
      py::gil_scoped_release free;
      v = primal::check_validity(mesh);
    }
    d["dimension"] = 3;
    d["valid"] = v.ok();
    d["validity"] = v.summary();
    py::dict r;
    r["out_of_range_hexes"] = v.out_of_range_hexes;
    r["non_finite_nodes"] = v.non_finite_nodes;
    r["repeated_node_hexes"] = v.repeated_node_hexes;
    r["unused_nodes"] = v.unused_nodes;
    r["overshared_faces"] = face_keys(v.overshared_faces);
    r["misoriented_faces"] = face_keys(v.misoriented_faces);
    r["nonmanifold_edges"] = edge_keys(v.nonmanifold_edges);
    r["nonmanifold_vertices"] = v.nonmanifold_vertices;
    r["euler"] = v.euler;
    r["boundary_closed"] = v.boundary.closed;
    r["boundary_manifold"] = v.boundary.manifold;
    r["boundary_euler"] = v.boundary.euler;
    r["inverted_hexes"] = v.inverted_hexes;
    r["overlapping_nodes"] = coverage(v.overlapping_nodes);
    d["report"] = r;
    const bool analysable =
        v.out_of_range_hexes.empty() && v.repeated_node_hexes.empty() && !mesh.hexes.empty();
    d["quality"] = py::none();
    d["obstructions"] = py::none();
    if (analysable) {
      primal::QualityReport q;
      std::vector<primal::Obstruction> obstructions;
      {
        py::gil_scoped_release free;
        q = primal::hex_quality_report(mesh);
        obstructions = primal::find_obstructions(mesh, options);
      }
      d["quality"] = to_python(primal::quality_report_json(q));
      d["obstructions"] = to_python(primal::obstructions_json(obstructions, 0));
    }
    return d;
  }
  const primal::QuadMesh mesh = quad_mesh(points, cells);
  const primal::QuadValidityReport v = primal::check_validity(mesh);
  d["dimension"] = 2;
  d["valid"] = v.ok();
  d["validity"] = v.summary();
  py::dict r;
  r["out_of_range_quads"] = v.out_of_range_quads;
  r["non_finite_nodes"] = v.non_finite_nodes;
  r["repeated_node_quads"] = v.repeated_node_quads;
  r["unused_nodes"] = v.unused_nodes;
  r["planar"] = v.planar;
  r["overshared_edges"] = edge_keys(v.overshared_edges);
  r["misoriented_edges"] = edge_keys(v.misoriented_edges);
  r["nonmanifold_vertices"] = v.nonmanifold_vertices;
  r["euler"] = v.euler;
  r["boundary_loops"] = v.boundary_loops;
  r["inverted_quads"] = v.inverted_quads;
  r["overlapping_nodes"] = coverage(v.overlapping_nodes);
  d["report"] = r;
  d["quality"] = py::none();
  d["obstructions"] = py::none();
  if (v.out_of_range_quads.empty() && v.repeated_node_quads.empty() && !mesh.quads.empty()) {
    double lo = 1e300, hi = -1e300;
    Index at = 0;
    for (std::size_t q = 0; q < mesh.quads.size(); ++q) {
      const double s = primal::quad_scaled_jacobian(
          primal::quad_corners(mesh, primal::index_cast(q)), Point::UnitZ());
      if (s < lo) lo = s, at = primal::index_cast(q);
      hi = std::max(hi, s);
    }
    d["quality"] = to_python({{"num_quads", mesh.quads.size()},
                              {"scaled_jacobian", {{"min", lo}, {"max", hi}, {"min_quad", at}}}});
    d["obstructions"] =
        to_python(primal::obstructions_json(primal::find_obstructions(mesh, options), 0));
  }
  return d;
}

py::dict quality(const py::handle& points, const py::handle& hexes, bool per_hex) {
  const primal::HexMesh mesh = hex_mesh(points, hexes);
  primal::QualityReport q;
  {
    py::gil_scoped_release free;
    q = primal::hex_quality_report(mesh);
  }
  py::dict d(to_python(primal::quality_report_json(q)));
  d["table"] = primal::format_quality_table(q);
  if (per_hex) {
    py::dict values;
    for (const auto& info : primal::hex_metrics()) {
      std::vector<double> v(mesh.hexes.size());
      for (std::size_t h = 0; h < v.size(); ++h)
        v[h] = info.evaluate(primal::hex_corners(mesh, primal::index_cast(h)));
      values[py::str(std::string(info.key))] = double_array(std::move(v));
    }
    d["per_hex"] = values;
  }
  return d;
}

template <class Dual>
py::dict dual_dict(const Dual& dual, std::size_t nodes, std::size_t cells) {
  py::dict d;
  d["nodes"] = nodes;
  d["cells"] = cells;
  py::list sheets;
  for (std::size_t s = 0; s < dual.sheets.size(); ++s) {
    const auto& sh = dual.sheets[s];
    int closed = 0;
    for (const auto& t : sh.trace) closed += t.closed;
    py::dict x;
    x["sheet"] = s;
    x["edges"] = sh.edges.size();
    x["crossings"] = sh.cells.size();
    x["cells"] = sh.cells;
    x["self_intersecting"] = sh.self_intersecting;
    x["trace_pieces"] = sh.trace.size();
    x["closed_trace_pieces"] = closed;
    py::list trace;  // the boundary trace: each piece's boundary edges (ids into "edges") in order
    for (const auto& t : sh.trace)
      trace.append(py::dict(py::arg("edges") = t.edges, py::arg("closed") = t.closed));
    x["trace"] = trace;
    sheets.append(x);
  }
  d["sheets"] = sheets;
  py::list triples;
  for (const auto& [tuple, count] : dual.intersections)
    triples.append(py::dict(py::arg("sheets") = std::vector<Index>(tuple.begin(), tuple.end()),
                            py::arg("cells") = count));
  d["intersections"] = triples;
  std::vector<std::array<Index, 2>> edges = dual.edges;
  std::vector<Index> edge_sheet = dual.edge_sheet;
  std::vector<Index> cell_sheets;
  for (const auto& c : dual.cell_sheets) cell_sheets.insert(cell_sheets.end(), c.begin(), c.end());
  d["edges"] = py::array(py::cast(edges));
  d["edge_sheet"] = index_array(std::move(edge_sheet));
  constexpr py::ssize_t kDim = std::tuple_size_v<typename decltype(dual.cell_sheets)::value_type>;
  d["cell_sheets"] = index_array(std::move(cell_sheets))
                         .reshape({static_cast<py::ssize_t>(dual.cell_sheets.size()), kDim});
  return d;
}

// The sheets (chords) of a mesh, and with rebuild=True the mesh rebuilt from them through the
// arrangement engine (stc::sheet_fields, compute_arrangement, dualize), as `geode dual --rebuild`.
py::dict dual(const py::handle& points, const py::handle& cells, bool rebuild) {
  const bool hexes = cell_width(cells, "cells") == 8;
  primal::HexMesh hex;
  primal::QuadMesh quad;
  if (hexes)
    hex = hex_mesh(points, cells);
  else
    quad = quad_mesh(points, cells);
  py::dict d;
  stc::DualMesh D;
  {
    std::optional<stc::HexDual> hd;
    std::optional<stc::QuadDual> qd;
    {
      py::gil_scoped_release free;
      if (hexes)
        hd = stc::mesh_dual(hex);
      else
        qd = stc::mesh_dual(quad);
    }
    d = hexes ? dual_dict(*hd, hex.points.size(), hex.hexes.size())
              : dual_dict(*qd, quad.points.size(), quad.quads.size());
  }
  d["dimension"] = hexes ? 3 : 2;
  if (!rebuild) return d;
  {
    py::gil_scoped_release free;
    const stc::MeshArrangementInput fields =
        hexes ? stc::sheet_fields(hex) : stc::sheet_fields(quad);
    D = stc::dualize(stc::compute_arrangement(fields.sheets, fields.domain));
  }
  py::dict r;
  if (hexes) {
    r["points"] = points_array(std::move(D.hex.points));
    r["cells"] = cells_array<8>(std::move(D.hex.hexes));
  } else {
    r["points"] = points_array(std::move(D.quad.points));
    r["cells"] = cells_array<4>(std::move(D.quad.quads));
  }
  r["element_sheets"] = D.element_sheets;
  d["rebuild"] = r;
  return d;
}

// Which nodes may move: "fixed" boundary (default), "free", or "box": nodes on the faces of the
// bounding box slide in them (along box edges, box corners fixed); `fixed` nodes never move.
template <class Mesh>
std::vector<primal::NodeConstraint> constraints(const Mesh& mesh,
                                                const std::vector<Index>& boundary_nodes,
                                                const std::string& boundary,
                                                const std::vector<Index>& fixed) {
  std::vector<primal::NodeConstraint> c(mesh.points.size(), primal::NodeConstraint::free());
  if (boundary == "box") {
    Eigen::AlignedBox3d box;
    for (const auto& p : mesh.points) box.extend(p);
    const double tol = 1e-9 * std::max(box.diagonal().norm(), 1.0);
    c = primal::box_constraints(mesh.points, box.min(), box.max(), {}, tol);
  } else if (boundary == "fixed") {
    for (Index n : boundary_nodes)
      c[primal::index_cast<std::size_t>(n)] = primal::NodeConstraint::fixed();
  } else if (boundary != "free") {
    throw InvalidInput("smooth: boundary must be 'fixed', 'free' or 'box'");
  }
  for (Index n : fixed) {
    if (n < 0 || primal::index_cast<std::size_t>(n) >= c.size())
      throw InvalidInput("smooth: fixed node " + std::to_string(n) + " is out of range");
    c[primal::index_cast<std::size_t>(n)] = primal::NodeConstraint::fixed();
  }
  return c;
}

py::dict smooth(const py::handle& points, const py::handle& cells, const std::string& boundary,
                const std::vector<Index>& fixed, int max_iterations) {
  primal::SmoothOptions options;
  if (max_iterations < 1) throw InvalidInput("smooth: max_iterations must be at least 1");
  options.max_iterations = max_iterations;
  primal::SmoothResult r;
  py::dict d;
  if (cell_width(cells, "cells") == 8) {
    primal::HexMesh mesh = hex_mesh(points, cells);
    {
      py::gil_scoped_release free;
      std::vector<Index> b;
      if (boundary == "fixed") b = primal::boundary_nodes(mesh);
      const auto c = constraints(mesh, b, boundary, fixed);
      r = primal::smooth_hex_mesh(mesh, c, options);
    }
    d["points"] = points_array(std::move(mesh.points));
  } else {
    primal::QuadMesh mesh = quad_mesh(points, cells);
    {
      py::gil_scoped_release free;
      std::vector<Index> b;
      if (boundary == "fixed") {
        const auto v = primal::check_validity(mesh);
        for (const auto& loop : v.boundary_loops) b.insert(b.end(), loop.begin(), loop.end());
      }
      const auto c = constraints(mesh, b, boundary, fixed);
      r = primal::smooth_quad_mesh(mesh, Point::UnitZ(), c, options);
    }
    d["points"] = points_array(std::move(mesh.points));
  }
  d["untangled"] = r.untangled;
  d["iterations"] = r.iterations;
  d["initial_min_scaled_jacobian"] = r.initial_min_scaled_jacobian;
  d["final_min_scaled_jacobian"] = r.final_min_scaled_jacobian;
  d["final_max_scaled_jacobian"] = r.final_max_scaled_jacobian;
  d["initial_min_jacobian"] = r.initial_min_jacobian;
  d["final_min_jacobian"] = r.final_min_jacobian;
  d["seconds"] = r.seconds;
  return d;
}

py::object isomorphism(const py::handle& a, const py::handle& b, const py::object& labels) {
  primal::NodeLabels l;
  if (!labels.is_none()) {
    std::pair<std::vector<int>, std::vector<int>> pair;
    try {
      pair = labels.cast<std::pair<std::vector<int>, std::vector<int>>>();
    } catch (const py::cast_error&) {
      throw InvalidInput("isomorphism: labels must be two sequences of integers, one per node");
    }
    l.first = pair.first, l.second = pair.second;
  }
  const int k = cell_width(a, "a");
  if (cell_width(b, "b") != k)
    throw InvalidInput("isomorphism: a and b must both be hexes or both quads");
  std::optional<primal::MeshMapping> map;
  auto nodes = [](const auto& cells) {
    Index n = 0;
    for (const auto& c : cells)
      for (Index v : c) n = std::max(n, v + 1);
    return n;
  };
  if (k == 8) {
    primal::HexMesh x, y;
    x.hexes = to_cells<8>(a, "a"), y.hexes = to_cells<8>(b, "b");
    x.points.resize(primal::index_cast<std::size_t>(nodes(x.hexes))),
        y.points.resize(primal::index_cast<std::size_t>(nodes(y.hexes)));
    py::gil_scoped_release free;
    map = primal::find_isomorphism(x, y, l);
  } else {
    primal::QuadMesh x, y;
    x.quads = to_cells<4>(a, "a"), y.quads = to_cells<4>(b, "b");
    x.points.resize(primal::index_cast<std::size_t>(nodes(x.quads))),
        y.points.resize(primal::index_cast<std::size_t>(nodes(y.quads)));
    py::gil_scoped_release free;
    map = primal::find_isomorphism(x, y, l);
  }
  if (!map) return py::none();
  py::dict d;
  d["node_map"] = index_array(std::move(map->node_map));
  d["cell_map"] = index_array(std::move(map->cell_map));
  return d;
}

}  // namespace

void bind_mesh(py::module_& m) {
  m.def("check", &check, py::arg("points"), py::arg("cells"), py::arg("planar_angle") = 1.0,
        "Validity (faces shared by two hexes, manifold, closed boundary, positive Jacobians, "
        "covering), quality and "
        "the combinatorial obstructions to untangling of a hex (M x 8) or planar quad (M x 4, z = "
        "0) mesh; ids 0-based.");
  m.def("quality", &quality, py::arg("points"), py::arg("hexes"), py::arg("per_hex") = false,
        "The paper's Table 1 metrics (Verdict definitions) over the hexes: {'metrics': [...], "
        "'table': text}, and with "
        "per_hex=True {'per_hex': {key: array}}.");
  m.def("dual", &dual, py::arg("points"), py::arg("cells"), py::arg("rebuild") = false,
        "The mesh's sheets (chords in 2D), their crossings and traces, and the cells per sheet "
        "triple; rebuild=True also "
        "rebuilds the mesh from those sheets through the arrangement engine ({'rebuild': "
        "{'points', 'cells'}}).");
  m.def("smooth", &smooth, py::arg("points"), py::arg("cells"), py::arg("boundary") = "fixed",
        py::arg("fixed") = std::vector<Index>{}, py::arg("max_iterations") = 3000,
        "Untangle, then maximise the minimum scaled Jacobian (primal/smooth.hpp). boundary: "
        "'fixed' (default), 'free', "
        "or 'box' (nodes slide in the faces of the bounding box); `fixed` nodes stay. Returns "
        "{'points', ...}.");
  m.def("isomorphism", &isomorphism, py::arg("a"), py::arg("b"), py::arg("labels") = py::none(),
        "A combinatorial isomorphism between two hex (or quad) meshes given by their cells, each "
        "cell mapped as the "
        "same cube: {'node_map', 'cell_map'} (a -> b), or None. labels=(first, second): nodes keep "
        "their label.");
}

}  // namespace geode::python
