#pragma once
// What the demo models (demo_models.cpp: hex parts in Delaunay tets; hybrid_models.cpp: hybrid
// meshes as a user makes them) build with: Gmsh models turned into geode models, closed
// triangle shells filled with Gmsh's tets, hex and tet parts joined. Not part of the API. Those
// that call the Gmsh API expect a Gmsh session open (run_gmsh opens one).
#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <geode/demo/demo_models.hpp>
#include <geode/demo/gmsh_session.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/model.hpp>

namespace geode::demo::detail {

// The templates below read as the demo models do, primal's and io's names unqualified.
using namespace primal;
using namespace io;

// A demo model's elements are numbered as its writers number them (index + 1), not by the tags
// of the Gmsh model it was built in: the parts are joined and re-oriented after meshing.
Model without_file_ids(Model m);

// The surfaces bounding a volume of Gmsh's current model (tags, unsigned).
std::vector<int> boundary_surfaces(int volume);

// Gmsh may hand back elements with negative orientation; flip those (mirror the hex, swap two
// tet corners) so that the model follows the VTK convention.
void orient_positively(Model& m);

// A closed triangulated surface being assembled for tet_fill: points merged by position.
struct Shell {
  std::vector<Point> points;
  std::vector<std::array<Index, 3>> tris;
  std::map<std::array<long long, 3>, Index> by_position;

  Index node(const Point& p) {
    // Positions from different Gmsh models agree to rounding error; 1e-8 cells merge them.
    const std::array<long long, 3> key{std::llround(p.x() * 1e8), std::llround(p.y() * 1e8),
                                       std::llround(p.z() * 1e8)};
    auto [it, inserted] = by_position.try_emplace(key, index_cast(points.size()));
    if (inserted) points.push_back(p);
    return it->second;
  }
};

// Triangles of the surfaces of Gmsh's current model (meshed) for which keep(tag) holds.
template <class Keep>
void append_gmsh_triangles(Shell& shell, Keep keep) {
  std::vector<std::size_t> tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(tags, coords, parametric, -1, -1, true, false);
  std::map<std::size_t, Point> node;
  for (std::size_t i = 0; i < tags.size(); ++i)
    node[tags[i]] = Point(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);
  gmsh::vectorpair surfaces;
  gmsh::model::getEntities(surfaces, 2);
  for (const auto& [dim, tag] : surfaces) {
    if (!keep(tag)) continue;
    std::vector<std::size_t> elements, nodes;
    gmsh::model::mesh::getElementsByType(2, elements, nodes, tag);
    for (std::size_t e = 0; e + 2 < nodes.size(); e += 3)
      shell.tris.push_back({shell.node(node.at(nodes[e])), shell.node(node.at(nodes[e + 1])),
                            shell.node(node.at(nodes[e + 2]))});
  }
}

// The boundary quads of the hex part for which on_interface(centre) holds, each split into two
// triangles: along corners 0-2 when split(quad number, centre) is false, 1-3 otherwise (the
// other diagonal where that one would fold the quad); or, where four(centre) holds and they do
// not fold, into four triangles around a new node at the mean of its corners.
template <class OnInterface, class Split, class Four>
void append_interface_triangles(Shell& shell, const Model& hexes, OnInterface on_interface,
                                Split split, Four four) {
  int count = 0;
  for (const BoundaryQuad& q : boundary_quads(hex_part(hexes))) {
    Point c = Point::Zero();
    for (Index v : q.nodes) c += hexes.points[index_cast<std::size_t>(v)] / 4.0;
    if (!on_interface(c)) continue;
    std::array<Index, 4> n{};
    std::array<Point, 4> p;
    for (int k = 0; k < 4; ++k) {
      p[k] = hexes.points[index_cast<std::size_t>(q.nodes[k])];
      n[k] = shell.node(p[k]);
    }
    // A split folding a non-convex quad (a triangle facing away from the quad) is not taken.
    const Point normal = (p[2] - p[0]).cross(p[3] - p[1]);
    auto folds = [&](int a, int b, int d) {
      return (p[b] - p[a]).cross(p[d] - p[a]).dot(normal) <= 0;
    };
    const bool folds02 = folds(0, 1, 2) || folds(0, 2, 3),
               folds13 = folds(0, 1, 3) || folds(1, 2, 3);
    bool along13 = split(count++, c);
    bool four_folds = false;  // a triangle around the centre facing away (non-convex quad)
    for (int k = 0; k < 4; ++k)
      four_folds |= (p[(k + 1) % 4] - p[k]).cross(c - p[k]).dot(normal) <= 0;
    if (four(c) && !four_folds) {
      const Index m = shell.node(c);
      for (int k = 0; k < 4; ++k) shell.tris.push_back({n[k], n[(k + 1) % 4], m});
      continue;
    }
    if (along13 ? folds13 : folds02) along13 = !along13;
    if (along13) {
      shell.tris.push_back({n[0], n[1], n[3]});
      shell.tris.push_back({n[1], n[2], n[3]});
    } else {
      shell.tris.push_back({n[0], n[1], n[2]});
      shell.tris.push_back({n[0], n[2], n[3]});
    }
  }
}

// Gmsh's Delaunay tets inside the closed surface `shell` (whose nodes it keeps), as a new
// Gmsh model; `holes` are closed surfaces inside it bounding regions left empty (further
// surface loops of the volume).
Model tet_fill(const Shell& shell, const std::vector<Shell>& holes, int block,
               const std::string& block_name);

// hexes + tets as one model, coincident nodes merged, every element positively oriented.
Model join(Model hexes, const Model& tets);

// The hex part meshed by `build` in a new Gmsh model (volumes meshed separately, coincident
// nodes merged), positively oriented.
template <class F>
Model hex_part_from_gmsh(const std::string& name, F&& build) {
  gmsh::model::add(name);
  build();
  gmsh::model::mesh::generate(3);
  Model m = without_file_ids(model_from_gmsh(name));
  m.tets.clear(), m.tet_block.clear();
  merge_coincident_nodes(m, 1e-9);
  orient_positively(m);
  gmsh::model::remove();
  return m;
}

// An entity's bounding box: x, y, z low, then x, y, z high.
using Box = std::array<double, 6>;
Box bounding_box(int dim, int tag);

// The boundary of an OCC solid made by `build` (returns its volume tag), meshed in 2D with
// cells of size h, the curves for which `fixed_curve(bounding box)` holds transfinite with cells
// of size h, as a Shell of the surfaces for which keep(bounding box) holds.
template <class Build, class FixedCurve, class Keep>
void append_solid_boundary(Shell& shell, double h, Build build, FixedCurve fixed_curve, Keep keep) {
  gmsh::model::add("outer");
  build();
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", h);
  gmsh::option::setNumber("Mesh.MeshSizeMin", 0.5 * h);
  gmsh::vectorpair curves;
  gmsh::model::getEntities(curves, 1);
  for (const auto& [dim, tag] : curves) {
    const Box b = bounding_box(dim, tag);
    if (!fixed_curve(b)) continue;
    const double length = std::max({b[3] - b[0], b[4] - b[1], b[5] - b[2]});
    gmsh::model::mesh::setTransfiniteCurve(
        tag, std::max(1, static_cast<int>(std::lround(length / h))) + 1);
  }
  gmsh::model::mesh::generate(2);
  append_gmsh_triangles(shell, [&](int tag) { return keep(bounding_box(2, tag)); });
  gmsh::model::remove();
  gmsh::option::setNumber("Mesh.MeshSizeMax", 1e22);
  gmsh::option::setNumber("Mesh.MeshSizeMin", 0);
}

// Split chooser: alternate by the quad centre's grid cell parity, or random (fixed seed).
std::function<bool(int, const Point&)> diagonal_chooser(DemoDiagonals d, double h);

// Four-triangle chooser: when `on`, half the quads (at random, fixed seed) in four triangles,
// the first always so that every model has one; none otherwise.
std::function<bool(const Point&)> four_chooser(bool on);

// Gmsh's OCC bounding boxes are enlarged by a tolerance; entity tests on them allow for it.
inline constexpr double kEps = 1e-4;

// A box volume transfinite and recombined: structured hexes of size about h (each curve by its
// own length, boxes may be tilted).
void transfinite_box(int volume, double h);

// build() in a Gmsh session of its own; Gmsh's errors (thrown as strings) become
// std::runtime_error naming the model.
Model run_gmsh(const std::string& name, const std::function<Model()>& build);

}  // namespace geode::demo::detail
