#include <geode/demo/demo_models.hpp>

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include <geode/demo/detail/model_building.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>

namespace geode::demo {

using namespace primal;
using namespace io;
using namespace detail;

// ---- Demo models meshed with the Gmsh API ----------------------------------------------------

namespace {

// A model meshed by `build` in a new Gmsh session (volumes meshed separately, coincident nodes
// merged), positively oriented.
template <class F>
Model with_gmsh(const std::string& name, F&& build) {
  return run_gmsh(name, [&] {
    gmsh::model::add(name);
    build();
    gmsh::model::mesh::generate(3);
    Model m = without_file_ids(model_from_gmsh(name));
    // The separately meshed volumes meet at coincident nodes: merge them.
    merge_coincident_nodes(m, 1e-9);
    orient_positively(m);
    return m;
  });
}

// Transfinite curves with cells of size h (by the curve's bounding box length).
void transfinite_curves(double h) {
  gmsh::vectorpair curves;
  gmsh::model::getEntities(curves, 1);
  for (const auto& [dim, tag] : curves) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(dim, tag, x0, y0, z0, x1, y1, z1);
    const double length = std::max({x1 - x0, y1 - y0, z1 - z0});
    const int cells = std::max(1, static_cast<int>(std::lround(length / h)));
    gmsh::model::mesh::setTransfiniteCurve(tag, cells + 1);
  }
}

// The unit cube at `corner` as structured hexes of size h (block 1 named `name`).
Model structured_unit_cube(const Point& corner, double h, const std::string& name) {
  return hex_part_from_gmsh(name, [&] {
    const int box = gmsh::model::occ::addBox(corner.x(), corner.y(), corner.z(), 1, 1, 1);
    gmsh::model::occ::synchronize();
    transfinite_box(box, h);
    gmsh::model::addPhysicalGroup(3, {box}, 1);
    gmsh::model::setPhysicalName(3, 1, name);
  });
}

// The blocks (i, j, k) of the 3 x 3 x 3 split of [-2,2]^3 around the nugget [-1,1]^3 (block
// (1, 1, 1)) for which keep(i, j, k) holds, as OCC boxes fragmented so that neighbours share faces.
template <class Keep>
gmsh::vectorpair split_box_blocks(Keep keep) {
  const double edges[4] = {-2, -1, 1, 2};
  gmsh::vectorpair blocks;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        if (keep(i, j, k))
          blocks.push_back(
              {3, gmsh::model::occ::addBox(edges[i], edges[j], edges[k], edges[i + 1] - edges[i],
                                           edges[j + 1] - edges[j], edges[k + 1] - edges[k])});
  gmsh::vectorpair fragments;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::fragment(blocks, {}, fragments, map);
  return fragments;
}

// Side set 1 "outside": the hex quads on the boundary of the box [-2,2]^3 around a nugget.
void add_outside_side_set(Model& m) {
  SideSet outside{1, "outside", {}};
  for (const BoundaryQuad& q : boundary_quads(hex_part(m))) {
    Point c = Point::Zero();
    for (Index v : q.nodes) c += m.points[index_cast<std::size_t>(v)] / 4.0;
    if (c.cwiseAbs().maxCoeff() > 2.0 - 1e-9)
      outside.sides.push_back({{ElementKind::kHex, q.hex}, q.local_face});
  }
  m.side_sets.push_back(std::move(outside));
}

}  // namespace

Model demo_half_block(int n) {
  if (n < 1) throw InvalidInput("demo_half_block: n = " + std::to_string(n) + " must be >= 1");
  return with_gmsh("demo_half_block", [n] {
    const int hex = gmsh::model::occ::addBox(0, 0, 0, 1, 1, 1);
    const int tet = gmsh::model::occ::addBox(1, 0, 0, 1, 1, 1);
    gmsh::model::occ::synchronize();
    transfinite_curves(1.0 / n);
    for (int volume : {hex, tet})
      for (int s : boundary_surfaces(volume)) {
        gmsh::model::mesh::setTransfiniteSurface(s);
        if (volume == hex) gmsh::model::mesh::setRecombine(2, s);
      }
    gmsh::model::mesh::setTransfiniteVolume(hex);
    gmsh::model::mesh::setTransfiniteVolume(tet);
    gmsh::model::mesh::setRecombine(3, hex);
    gmsh::model::addPhysicalGroup(3, {hex}, 1);
    gmsh::model::setPhysicalName(3, 1, "hex");
    gmsh::model::addPhysicalGroup(3, {tet}, 2);
    gmsh::model::setPhysicalName(3, 2, "tet");
  });
}

Model demo_nugget(int n) {
  if (n < 2 || n % 2 != 0)
    throw InvalidInput("demo_nugget: n = " + std::to_string(n) + " must be even and >= 2");
  Model m = with_gmsh("demo_nugget", [n] {
    // Shared faces between the hex blocks (not with the nugget: its faces carry triangles).
    const gmsh::vectorpair fragments =
        split_box_blocks([](int i, int j, int k) { return i != 1 || j != 1 || k != 1; });
    const int nugget = gmsh::model::occ::addBox(-1, -1, -1, 2, 2, 2);
    gmsh::model::occ::synchronize();
    transfinite_curves(2.0 / n);
    std::vector<int> hex_volumes;
    for (const auto& [dim, tag] : fragments) {
      hex_volumes.push_back(tag);
      for (int s : boundary_surfaces(tag)) {
        gmsh::model::mesh::setTransfiniteSurface(s);
        gmsh::model::mesh::setRecombine(2, s);
      }
      gmsh::model::mesh::setTransfiniteVolume(tag);
      gmsh::model::mesh::setRecombine(3, tag);
    }
    for (int s : boundary_surfaces(nugget)) gmsh::model::mesh::setTransfiniteSurface(s);
    gmsh::model::addPhysicalGroup(3, hex_volumes, 1);
    gmsh::model::setPhysicalName(3, 1, "hex blocks");
    gmsh::model::addPhysicalGroup(3, {nugget}, 2);
    gmsh::model::setPhysicalName(3, 2, "tet nugget");
  });
  add_outside_side_set(m);
  return m;
}

Model demo_delaunay_block(int n, DemoDiagonals diagonals, bool four_triangles) {
  if (n < 1) throw InvalidInput("demo_delaunay_block: n = " + std::to_string(n) + " must be >= 1");
  const double h = 1.0 / n;
  return run_gmsh("demo_delaunay_block", [&] {
    Model hexes = structured_unit_cube(Point(0, 0, 0), h, "hex");
    Shell shell;
    append_solid_boundary(
        shell, h, [] { gmsh::model::occ::addBox(1, 0, 0, 1, 1, 1); },
        [](const Box& b) { return b[3] < 1 + kEps; }, [](const Box& b) { return b[3] > 1 + kEps; });
    append_interface_triangles(
        shell, hexes, [](const Point& c) { return c.x() > 1 - kEps; },
        diagonal_chooser(diagonals, h), four_chooser(four_triangles));
    return join(std::move(hexes), tet_fill(shell, {}, 2, "tet"));
  });
}

Model demo_cylinder(int n, bool four_triangles) {
  if (n < 2) throw InvalidInput("demo_cylinder: n = " + std::to_string(n) + " must be >= 2");
  const double h = 1.0 / n;
  return run_gmsh("demo_cylinder", [&] {
    Model hexes = hex_part_from_gmsh("cylinder", [n, h] {
      const int disk = gmsh::model::occ::addDisk(0, 0, -0.5, 0.5, 0.5);
      gmsh::vectorpair out;
      gmsh::model::occ::extrude({{2, disk}}, 0, 0, 1, out, {n}, {}, true);
      gmsh::model::occ::synchronize();
      gmsh::option::setNumber("Mesh.MeshSizeMax", h);
      gmsh::model::mesh::setRecombine(2, disk);
      for (const auto& [dim, tag] : out)
        if (dim == 3) {
          gmsh::model::addPhysicalGroup(3, {tag}, 1);
          gmsh::model::setPhysicalName(3, 1, "hex cylinder");
        }
    });
    gmsh::option::setNumber("Mesh.MeshSizeMax", 1e22);
    Shell outer, inner;
    append_solid_boundary(
        outer, 2 * h, [] { gmsh::model::occ::addBox(-1, -1, -1, 2, 2, 2); },
        [](const Box&) { return false; }, [](const Box&) { return true; });
    append_interface_triangles(
        inner, hexes, [](const Point&) { return true; },
        diagonal_chooser(DemoDiagonals::kRandom, h), four_chooser(four_triangles));
    return join(std::move(hexes), tet_fill(outer, {inner}, 2, "tet box"));
  });
}

Model demo_l_shape(int n) {
  if (n < 1) throw InvalidInput("demo_l_shape: n = " + std::to_string(n) + " must be >= 1");
  const double h = 1.0 / n;
  auto in_notch = [](const Box& b) { return b[0] > 1 - kEps && b[1] > 1 - kEps; };
  return run_gmsh("demo_l_shape", [&] {
    Model hexes = structured_unit_cube(Point(1, 1, 0), h, "hex notch");
    Shell shell;
    append_solid_boundary(
        shell, h,
        [] {
          gmsh::vectorpair out;
          std::vector<gmsh::vectorpair> map;
          gmsh::model::occ::cut({{3, gmsh::model::occ::addBox(0, 0, 0, 2, 2, 1)}},
                                {{3, gmsh::model::occ::addBox(1, 1, 0, 1, 1, 1)}}, out, map);
        },
        in_notch, [&](const Box& b) { return !in_notch(b); });
    append_interface_triangles(
        shell, hexes, [](const Point& c) { return c.x() < 1 + kEps || c.y() < 1 + kEps; },
        diagonal_chooser(DemoDiagonals::kRandom, h), four_chooser(false));
    return join(std::move(hexes), tet_fill(shell, {}, 2, "tet L"));
  });
}

namespace {

// An all-quad mesh of the square [-1,1]^2 (z = 0) with the circle of radius r about its centre
// imprinted (the circle is a chain of quad edges), n uniform segments per side so that it meets
// structured n x n faces. Blossom recombination leaves triangles on some inputs; the next 2D
// algorithm (Frontal-Delaunay, Delaunay, MeshAdapt) or a circle with two more segments (the
// circle and the annulus both need an even number of boundary segments) is tried until the
// quads alone tile the square.
struct SquareQuads {
  std::vector<Point> points;
  std::vector<std::array<Index, 4>> quads;
};

// Every quad strictly convex and counter-clockwise, their areas summing to the square's: the
// quads tile it without a fold, an overlap or a hole.
bool tiles_square(const SquareQuads& f) {
  double area = 0;
  for (const auto& q : f.quads) {
    for (std::size_t k = 0; k < 4; ++k) {
      const Point& a = f.points[index_cast<std::size_t>(q[(k + 3) % 4])];
      const Point& b = f.points[index_cast<std::size_t>(q[k])];
      const Point& c = f.points[index_cast<std::size_t>(q[(k + 1) % 4])];
      if ((c - b).cross(a - b).z() <= 0) return false;
      area += 0.5 * b.head<2>().homogeneous().cross(c.head<2>().homogeneous()).z();
    }
  }
  return !f.quads.empty() && std::abs(area - 4.0) < 1e-9;
}

// One attempt; no quads when the result does not tile the square.
SquareQuads mesh_imprinted_square(int n, double r, int algorithm, int circle_segments) {
  gmsh::model::add("imprinted face");
  gmsh::vectorpair pieces;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::fragment({{2, gmsh::model::occ::addRectangle(-1, -1, 0, 2, 2)}},
                             {{2, gmsh::model::occ::addDisk(0, 0, 0, r, r)}}, pieces, map);
  gmsh::model::occ::synchronize();
  gmsh::vectorpair curves, surfaces;
  gmsh::model::getEntities(curves, 1);
  for (const auto& [dim, tag] : curves) {
    const Box b = bounding_box(dim, tag);
    const bool side = b[3] - b[0] < kEps || b[4] - b[1] < kEps;
    gmsh::model::mesh::setTransfiniteCurve(tag, (side ? n : circle_segments) + 1);
  }
  gmsh::model::getEntities(surfaces, 2);
  for (const auto& [dim, tag] : surfaces) gmsh::model::mesh::setRecombine(dim, tag);
  gmsh::option::setNumber("Mesh.MeshSizeMax", 2.0 / n);
  gmsh::option::setNumber("Mesh.Algorithm", algorithm);
  gmsh::model::mesh::generate(2);
  gmsh::option::setNumber("Mesh.MeshSizeMax", 1e22);
  gmsh::option::setNumber("Mesh.Algorithm", 6);

  SquareQuads f;
  std::vector<std::size_t> tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(tags, coords, parametric, -1, -1, true, false);
  std::map<std::size_t, Index> index;
  for (std::size_t i = 0; i < tags.size(); ++i)
    if (index.try_emplace(tags[i], index_cast(f.points.size())).second)
      f.points.emplace_back(coords[3 * i], coords[3 * i + 1], 0.0);
  // Fresh output vectors per call: Gmsh takes non-empty ones as preallocated.
  std::vector<std::size_t> quads, quad_nodes, triangles, triangle_nodes;
  gmsh::model::mesh::getElementsByType(3, quads, quad_nodes);
  gmsh::model::mesh::getElementsByType(2, triangles, triangle_nodes);
  gmsh::model::remove();
  for (std::size_t e = 0; e + 3 < quad_nodes.size(); e += 4)
    f.quads.push_back({index.at(quad_nodes[e]), index.at(quad_nodes[e + 1]),
                       index.at(quad_nodes[e + 2]), index.at(quad_nodes[e + 3])});
  if (!triangles.empty() || !tiles_square(f)) f.quads.clear();
  return f;
}

SquareQuads imprinted_square(int n, double r) {
  // About the cell size 2/n along the circle, even, at least 8.
  const int segments = std::max(8, 2 * static_cast<int>(std::lround(std::numbers::pi * r * n / 2)));
  for (int extra : {0, 2, 4})
    for (int algorithm : {6, 5, 1}) {
      SquareQuads f = mesh_imprinted_square(n, r, algorithm, segments + extra);
      if (!f.quads.empty()) return f;
    }
  throw std::runtime_error(
      "demo_fulcher: Gmsh's quads do not tile the face with a circle of radius " +
      std::to_string(r) + " at n = " + std::to_string(n) + " (triangles left or quads folded)");
}

// The face quads swept along `axis` from the nugget face (coordinate 1) to the box (2) in
// `layers` equal layers, the face's (u, v) on the two other axes in cyclic order; block 1.
void append_swept_slab(Model& m, const SquareQuads& face, int axis, int layers) {
  const Index base = index_cast(m.points.size());
  const Index count = index_cast(face.points.size());
  for (int k = 0; k <= layers; ++k)
    for (const Point& p : face.points) {
      Point q;
      q[axis] = 1.0 + static_cast<double>(k) / layers;
      q[(axis + 1) % 3] = p.x();
      q[(axis + 2) % 3] = p.y();
      m.points.push_back(q);
    }
  for (int k = 0; k < layers; ++k)
    for (const auto& quad : face.quads) {
      std::array<Index, 8> h{};
      for (std::size_t c = 0; c < 4; ++c) {
        h[c] = base + k * count + quad[c];
        h[c + 4] = base + (k + 1) * count + quad[c];
      }
      m.hexes.push_back(h);
      m.hex_block.push_back(1);
    }
}

}  // namespace

Model demo_fulcher(int n) {
  if (n < 2 || n % 2 != 0)
    throw InvalidInput("demo_fulcher: n = " + std::to_string(n) + " must be even and >= 2");
  // Circle radii on the nugget faces x = 1, y = 1, z = 1.
  constexpr std::array<double, 3> kRadii{0.3, 0.5, 0.7};
  return run_gmsh("demo_fulcher", [&] {
    Model hexes = hex_part_from_gmsh("fulcher blocks", [n] {
      // The nugget and the three swept slabs (added below) are not structured blocks.
      const gmsh::vectorpair fragments = split_box_blocks(
          [](int i, int j, int k) { return (i == 1) + (j == 1) + (k == 1) < 2 || i + j + k < 3; });
      gmsh::model::occ::synchronize();
      std::vector<int> volumes;
      for (const auto& [dim, tag] : fragments) {
        transfinite_box(tag, 2.0 / n);
        volumes.push_back(tag);
      }
      gmsh::model::addPhysicalGroup(3, volumes, 1);
      gmsh::model::setPhysicalName(3, 1, "hex blocks");
    });
    for (int axis = 0; axis < 3; ++axis)
      append_swept_slab(hexes, imprinted_square(n, kRadii[index_cast<std::size_t>(axis)]), axis,
                        n / 2);
    merge_coincident_nodes(hexes, 1e-9);
    orient_positively(hexes);
    // The whole nugget boundary is interface: its triangles are the hex quads split in two.
    Shell shell;
    append_interface_triangles(
        shell, hexes, [](const Point& c) { return c.cwiseAbs().maxCoeff() < 1 + kEps; },
        diagonal_chooser(DemoDiagonals::kRandom, 2.0 / n), four_chooser(false));
    Model m = join(std::move(hexes), tet_fill(shell, {}, 2, "tet nugget"));
    add_outside_side_set(m);
    return m;
  });
}

const std::vector<std::string>& demo_model_names() {
  static const std::vector<std::string> names{"half",        "delaunay",        "delaunay-random",
                                              "cylinder",    "lshape",          "nugget",
                                              "fulcher",     "fourtri",         "fourtri-cylinder",
                                              "hybrid",      "hybrid-cylinder", "boundary-layer",
                                              "hexdominant", "layer-side",      "layer-interface",
                                              "layer-mixed", "potting"};
  return names;
}

Model demo_model(const std::string& name, int n) {
  if (name == "half") return demo_half_block(n);
  if (name == "delaunay") return demo_delaunay_block(n, DemoDiagonals::kAlternate);
  if (name == "delaunay-random") return demo_delaunay_block(n, DemoDiagonals::kRandom);
  if (name == "cylinder") return demo_cylinder(n);
  if (name == "lshape") return demo_l_shape(n);
  if (name == "nugget") return demo_nugget(n % 2 ? n + 1 : n);
  if (name == "fulcher") return demo_fulcher(n % 2 ? n + 1 : n);
  if (name == "fourtri") return demo_delaunay_block(n, DemoDiagonals::kRandom, true);
  if (name == "fourtri-cylinder") return demo_cylinder(n, true);
  if (name == "hybrid") return demo_hybrid(n);
  if (name == "hybrid-cylinder") return demo_hybrid_cylinder(n);
  if (name == "boundary-layer") return demo_boundary_layer(n);
  if (name == "hexdominant") return demo_hexdominant(n);
  if (name == "layer-side") return demo_layer_side(n);
  if (name == "layer-interface") return demo_layer_interface(n);
  if (name == "layer-mixed") return demo_layer_mixed(n);
  if (name == "potting") return demo_potting(n);
  std::string names;
  for (const std::string& known : demo_model_names()) names += (names.empty() ? "" : ", ") + known;
  throw InvalidInput("demo model '" + name + "': expected one of " + names);
}

std::vector<std::pair<std::string, std::function<Model()>>> corner_study_models(int n) {
  std::vector<std::pair<std::string, std::function<Model()>>> models;
  for (const char* name : {"nugget", "lshape", "potting", "cylinder"})
    models.emplace_back(name, [name, n] { return demo_model(name, n); });
  for (double a : {60.0, 90.0, 120.0, 150.0, 210.0, 240.0, 270.0, 300.0})
    models.emplace_back("wedge-" + std::to_string(static_cast<int>(a)),
                        [a, n] { return demo_wedge(n, a); });
  return models;
}

}  // namespace geode::demo
