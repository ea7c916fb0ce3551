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

#include <geode/demo/gmsh_session.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>

namespace geode::demo {

using namespace primal;
using namespace io;

// ---- Demo models meshed with the Gmsh API ----------------------------------------------------

namespace {

// A demo model's elements are numbered as its writers number them (index + 1), not by the tags
// of the Gmsh model it was built in: the parts are joined and re-oriented after meshing.
Model without_file_ids(Model m) {
  for (ElementKind kind : kElementKinds) element_ids(m, kind).clear();
  m.node_ids.clear();
  return m;
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

std::vector<int> boundary_surfaces(int volume) {
  gmsh::vectorpair faces;
  gmsh::model::getBoundary({{3, volume}}, faces, false, false, false);
  std::vector<int> tags;
  for (const auto& [dim, tag] : faces) tags.push_back(std::abs(tag));
  return tags;
}

// Gmsh may hand back elements with negative orientation; flip those (mirror the hex, swap two
// tet corners) so that the model follows the VTK convention.
void orient_positively(Model& m) {
  for (auto& t : m.tets) {
    const auto& p = m.points;
    if (tet_volume(p[index_cast<std::size_t>(t[0])], p[index_cast<std::size_t>(t[1])],
                   p[index_cast<std::size_t>(t[2])], p[index_cast<std::size_t>(t[3])]) < 0)
      std::swap(t[1], t[2]);
  }
  for (auto& h : m.hexes) {
    HexCorners c;
    for (std::size_t i = 0; i < 8; ++i) c[i] = m.points[index_cast<std::size_t>(h[i])];
    if (hex_volume(c) < 0) h = {h[4], h[5], h[6], h[7], h[0], h[1], h[2], h[3]};
  }
}

template <class F>
Model with_gmsh(const std::string& name, F&& build) {
  GmshSession session;
  try {
    gmsh::model::add(name);
    build();
    gmsh::model::mesh::generate(3);
    Model m = without_file_ids(model_from_gmsh(name));
    // The separately meshed volumes meet at coincident nodes: merge them.
    merge_coincident_nodes(m, 1e-9);
    orient_positively(m);
    return m;
  } catch (const std::string& s) {
    throw std::runtime_error(name + ": Gmsh failed: " + s);
  }
}

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
               const std::string& block_name) {
  gmsh::model::add("tet_fill");
  std::size_t next_node = 1;
  auto add_surface = [&](const Shell& s) {
    const int tag = gmsh::model::addDiscreteEntity(2);
    std::vector<std::size_t> node_tags;
    std::vector<double> coords;
    for (const Point& p : s.points) {
      node_tags.push_back(next_node++);
      coords.insert(coords.end(), {p.x(), p.y(), p.z()});
    }
    std::vector<std::size_t> tri_nodes;
    for (const auto& t : s.tris)
      for (Index v : t) tri_nodes.push_back(node_tags[index_cast<std::size_t>(v)]);
    gmsh::model::mesh::addNodes(2, tag, node_tags, coords);
    gmsh::model::mesh::addElementsByType(tag, 2, {}, tri_nodes);
    return tag;
  };
  std::vector<int> loops{gmsh::model::geo::addSurfaceLoop({add_surface(shell)})};
  for (const Shell& h : holes) loops.push_back(gmsh::model::geo::addSurfaceLoop({add_surface(h)}));
  const int volume = gmsh::model::geo::addVolume(loops);
  gmsh::model::geo::synchronize();
  gmsh::model::addPhysicalGroup(3, {volume}, block);
  gmsh::model::setPhysicalName(3, block, block_name);
  gmsh::model::mesh::generate(3);
  Model m = without_file_ids(model_from_gmsh("tet_fill"));
  gmsh::model::remove();
  return m;
}

// hexes + tets as one model, coincident nodes merged, every element positively oriented.
Model join(Model hexes, const Model& tets) {
  const Index offset = index_cast(hexes.points.size());
  hexes.points.insert(hexes.points.end(), tets.points.begin(), tets.points.end());
  for (auto t : tets.tets) {
    for (Index& v : t) v += offset;
    hexes.tets.push_back(t);
  }
  if (!tets.tet_block.empty()) hexes.tet_block = tets.tet_block;
  for (const auto& [id, name] : tets.block_names) hexes.block_names[id] = name;
  if (hexes.hex_block.empty()) hexes.hex_block.assign(hexes.hexes.size(), 1);
  merge_coincident_nodes(hexes, 1e-9);
  orient_positively(hexes);
  // Drop points no element uses (Gmsh's geometry points).
  std::vector<Index> renum(hexes.points.size(), kInvalidIndex);
  std::vector<Point> points;
  auto use = [&](Index& v) {
    if (renum[index_cast<std::size_t>(v)] == kInvalidIndex) {
      renum[index_cast<std::size_t>(v)] = index_cast(points.size());
      points.push_back(hexes.points[index_cast<std::size_t>(v)]);
    }
    v = renum[index_cast<std::size_t>(v)];
  };
  for (auto& h : hexes.hexes)
    for (Index& v : h) use(v);
  for (auto& t : hexes.tets)
    for (Index& v : t) use(v);
  for (auto& ns : hexes.node_sets)
    for (Index& v : ns.nodes) use(v);
  hexes.points = std::move(points);
  return hexes;
}

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

// The boundary of an OCC solid made by `build` (returns its volume tag), meshed in 2D with
// cells of size h, the curves for which `fixed_curve(bounding box)` holds transfinite with cells
// of size h, as a Shell of the surfaces for which keep(bounding box) holds.
using Box = std::array<double, 6>;
Box bounding_box(int dim, int tag) {
  Box b;
  gmsh::model::getBoundingBox(dim, tag, b[0], b[1], b[2], b[3], b[4], b[5]);
  return b;
}

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
std::function<bool(int, const Point&)> diagonal_chooser(DemoDiagonals d, double h) {
  if (d == DemoDiagonals::kAlternate)
    return [h](int, const Point& c) {
      const long long s = std::llround(std::floor(c.x() / h)) +
                          std::llround(std::floor(c.y() / h)) + std::llround(std::floor(c.z() / h));
      return (s & 1) != 0;
    };
  auto rng = std::make_shared<std::mt19937>(12345u);
  return [rng](int, const Point&) { return ((*rng)() & 1u) != 0; };
}

// Four-triangle chooser: when `on`, half the quads (at random, fixed seed) in four triangles,
// the first always so that every model has one; none otherwise.
std::function<bool(const Point&)> four_chooser(bool on) {
  if (!on) return [](const Point&) { return false; };
  auto rng = std::make_shared<std::mt19937>(2024u);
  auto first = std::make_shared<bool>(true);
  return [rng, first](const Point&) {
    const bool four = *first || ((*rng)() & 1u) != 0;
    *first = false;
    return four;
  };
}

// Gmsh's OCC bounding boxes are enlarged by a tolerance; entity tests on them allow for it.
constexpr double kEps = 1e-4;

// A boundary layer as an analyst grows one on a wall: 3 graded layers of wedges (at 0.2, 0.5
// and 1 of `thickness`) extruded `thickness` up off the top face of `volume` (the face at the
// volume's highest z); the extrusion's entities, its volume among them.
gmsh::vectorpair wedge_layer_on_top(int volume, double thickness) {
  const double z = bounding_box(3, volume)[5];
  int top = 0;
  for (int s : boundary_surfaces(volume))
    if (bounding_box(2, s)[2] > z - kEps) top = s;
  gmsh::vectorpair layer;
  gmsh::model::occ::extrude({{2, top}}, 0, 0, thickness, layer, {1, 1, 1}, {0.2, 0.5, 1.0}, true);
  gmsh::model::occ::synchronize();
  return layer;
}

void transfinite_box(int volume, double h) {
  gmsh::vectorpair surfaces, curves;
  for (int s : boundary_surfaces(volume)) surfaces.push_back({2, s});
  gmsh::model::getBoundary(surfaces, curves, false, false, false);
  for (const auto& [dim, tag] : curves) {
    double length = 0.0;  // the curve's own length: boxes may be tilted
    gmsh::model::occ::getMass(1, std::abs(tag), length);
    gmsh::model::mesh::setTransfiniteCurve(
        std::abs(tag), std::max(1, static_cast<int>(std::lround(length / h))) + 1);
  }
  for (int s : boundary_surfaces(volume)) {
    gmsh::model::mesh::setTransfiniteSurface(s);
    gmsh::model::mesh::setRecombine(2, s);
  }
  gmsh::model::mesh::setTransfiniteVolume(volume);
  gmsh::model::mesh::setRecombine(3, volume);
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

Model run_gmsh(const std::string& name, const std::function<Model()>& build) {
  GmshSession session;
  try {
    return build();
  } catch (const std::string& s) {
    throw std::runtime_error(name + ": Gmsh failed: " + s);
  }
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

}  // namespace geode::demo

namespace geode::demo {

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

// ---- Hybrid models as a user meshes them: one geometry, one generate(3) --------------------
// Hex volumes transfinite (or swept) and recombined, tet volumes Delaunay, wedges extruded in
// layers, all meshed together, so Gmsh itself puts a pyramid on every quad a tet volume meets.

namespace {

// One Gmsh model meshed in one generate(3), each volume its own named block; elements Gmsh hands
// back inverted re-oriented (orient_positively, with pyramids and wedges).
template <class F>
Model hybrid_gmsh(const std::string& name, F&& build) {
  GmshSession session;
  try {
    gmsh::model::add(name);
    build();
    gmsh::model::mesh::generate(3);
    Model m = without_file_ids(model_from_gmsh(name));
    auto pt = [&](Index v) -> const Point& { return m.points[index_cast<std::size_t>(v)]; };
    orient_positively(m);
    for (auto& p : m.pyramids)
      if (tet_volume(pt(p[0]), pt(p[1]), pt(p[2]), pt(p[4])) < 0) std::swap(p[1], p[3]);
    for (auto& w : m.wedges)
      if (tet_volume(pt(w[0]), pt(w[1]), pt(w[2]), pt(w[3])) < 0)
        std::swap(w[1], w[2]), std::swap(w[4], w[5]);
    return m;
  } catch (const std::string& s) {
    throw std::runtime_error(name + ": Gmsh failed: " + s);
  }
}

void name_volume(int volume, int block, const std::string& name) {
  gmsh::model::addPhysicalGroup(3, {volume}, block);
  gmsh::model::setPhysicalName(3, block, name);
}

// OCC boxes fragmented so that neighbours share their faces; returns the volumes in input order.
std::vector<int> shared_boxes(const std::vector<std::array<double, 6>>& boxes) {
  gmsh::vectorpair in;
  for (const auto& b : boxes)
    in.push_back({3, gmsh::model::occ::addBox(b[0], b[1], b[2], b[3], b[4], b[5])});
  gmsh::vectorpair fragments;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::fragment(in, {}, fragments, map);
  gmsh::model::occ::synchronize();
  std::vector<int> volumes;
  for (const auto& m : map) volumes.push_back(m.front().second);
  return volumes;
}

}  // namespace

Model demo_hybrid(int n) {
  if (n < 1) throw InvalidInput("demo_hybrid: n = " + std::to_string(n) + " must be >= 1");
  const double h = 1.0 / n;
  return hybrid_gmsh("demo_hybrid", [&] {
    const auto v = shared_boxes({{0, 0, 0, 1, 1, 1}, {1, 0, 0, 1, 1, 1}});
    transfinite_box(v[0], h);
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    name_volume(v[0], 1, "hex");
    name_volume(v[1], 2, "tet");
  });
}

Model demo_hybrid_cylinder(int n) {
  if (n < 2) throw InvalidInput("demo_hybrid_cylinder: n = " + std::to_string(n) + " must be >= 2");
  const double h = 1.0 / n;
  return hybrid_gmsh("demo_hybrid_cylinder", [&] {
    // A disk of recombined quads swept in n layers (the hex cylinder) inside a Delaunay box:
    // the box is cut by the cylinder, sharing its surfaces.
    const int disk = gmsh::model::occ::addDisk(0, 0, -0.5, 0.5, 0.5);
    gmsh::vectorpair swept;
    gmsh::model::occ::extrude({{2, disk}}, 0, 0, 1, swept, {n}, {}, true);
    int cylinder = 0;
    for (const auto& [dim, tag] : swept)
      if (dim == 3) cylinder = tag;
    const int box = gmsh::model::occ::addBox(-1, -1, -1, 2, 2, 2);
    gmsh::vectorpair fragments;
    std::vector<gmsh::vectorpair> map;
    gmsh::model::occ::fragment({{3, box}}, {{3, cylinder}}, fragments, map);
    gmsh::model::occ::synchronize();
    int potting = 0;
    for (const auto& [dim, tag] : map[0])
      if (tag != cylinder) potting = tag;
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    gmsh::option::setNumber("Mesh.RecombinationAlgorithm",
                            3);  // blossom full-quad: no triangle left
    gmsh::model::mesh::setRecombine(2, disk);
    name_volume(cylinder, 1, "hex cylinder");
    name_volume(potting, 2, "tet box");
  });
}

Model demo_boundary_layer(int n) {
  if (n < 1) throw InvalidInput("demo_boundary_layer: n = " + std::to_string(n) + " must be >= 1");
  const double h = 1.0 / n;
  return hybrid_gmsh("demo_boundary_layer", [&] {
    // A Delaunay tet box with a boundary layer of wedges extruded from its top in 3 layers
    // (0.1 thick, graded), as an analyst grows one on a wall.
    const int box = gmsh::model::occ::addBox(0, 0, 0, 1, 1, 1);
    gmsh::model::occ::synchronize();
    const gmsh::vectorpair layer = wedge_layer_on_top(box, 0.1);
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    name_volume(box, 2, "tet");
    for (const auto& [dim, tag] : layer)
      if (dim == 3) name_volume(tag, 4, "boundary layer");
  });
}

Model demo_layer_side(int n) {
  if (n < 1) throw InvalidInput("demo_layer_side: n = " + std::to_string(n) + " must be >= 1");
  const double h = 1.0 / n;
  return hybrid_gmsh("demo_layer_side", [&] {
    // A Delaunay tet box [0,1]^3 with 3 graded layers of wedges extruded 0.2 off its top, and a
    // Delaunay slab swept off the layer's side x = 1 (0.5 long, no layers): the slab's tets meet
    // the layer's side quads, so Gmsh puts a pyramid on each, as beside a boundary layer that
    // ends inside the domain.
    const int box = gmsh::model::occ::addBox(0, 0, 0, 1, 1, 1);
    gmsh::model::occ::synchronize();
    const gmsh::vectorpair layer = wedge_layer_on_top(box, 0.2);
    int wedges = 0;
    for (const auto& [dim, tag] : layer)
      if (dim == 3) wedges = tag;
    int side = 0;
    for (int s : boundary_surfaces(wedges)) {
      const Box b = bounding_box(2, s);
      if (b[0] > 1.0 - kEps && b[3] < 1.0 + kEps) side = s;
    }
    gmsh::vectorpair slab;
    gmsh::model::occ::extrude({{2, side}}, 0.5, 0, 0, slab);
    gmsh::model::occ::synchronize();
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    name_volume(box, 2, "tet");
    name_volume(wedges, 4, "boundary layer");
    for (const auto& [dim, tag] : slab)
      if (dim == 3) name_volume(tag, 5, "tet slab");
  });
}

Model demo_layer_interface(int n) {
  if (n < 1) throw InvalidInput("demo_layer_interface: n = " + std::to_string(n) + " must be >= 1");
  const double h = 1.0 / n;
  return hybrid_gmsh("demo_layer_interface", [&] {
    // A transfinite hex box [0,1]^3 beside a Delaunay tet box [1,2] x [0,1]^2 (pyramids on the
    // shared face), and 3 graded layers of wedges extruded 0.2 off the tet box's top: the
    // layer's edge x = 1 lies on the hex/tet interface's top edge.
    const auto v = shared_boxes({{0, 0, 0, 1, 1, 1}, {1, 0, 0, 1, 1, 1}});
    transfinite_box(v[0], h);
    const gmsh::vectorpair layer = wedge_layer_on_top(v[1], 0.2);
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    name_volume(v[0], 1, "hex");
    name_volume(v[1], 2, "tet");
    for (const auto& [dim, tag] : layer)
      if (dim == 3) name_volume(tag, 4, "boundary layer");
  });
}

Model demo_layer_mixed(int n) {
  if (n < 1) throw InvalidInput("demo_layer_mixed: n = " + std::to_string(n) + " must be >= 1");
  const double h = 1.0 / n;
  return hybrid_gmsh("demo_layer_mixed", [&] {
    // Two Delaunay tet boxes [0,1]^3 and [1,2] x [0,1]^2 side by side, and 3 graded layers
    // extruded 0.2 off their tops, the left top recombined into quads: a layer of hexes beside
    // a layer of wedges, as an extrusion off a surface recombined only in part gives. Gmsh puts
    // a pyramid on every hex quad the tets meet; the wedges meet the tets by their triangles.
    const auto v = shared_boxes({{0, 0, 0, 1, 1, 1}, {1, 0, 0, 1, 1, 1}});
    std::array<int, 2> top{};
    for (std::size_t i = 0; i < 2; ++i)
      for (int s : boundary_surfaces(v[i]))
        if (bounding_box(2, s)[2] > 1.0 - kEps) top[i] = s;
    gmsh::model::mesh::setRecombine(2, top[0]);
    // Both tops in one extrusion, so that the wall over their shared edge is one surface.
    gmsh::vectorpair layer;
    gmsh::model::occ::extrude({{2, top[0]}, {2, top[1]}}, 0, 0, 0.2, layer, {1, 1, 1},
                              {0.2, 0.5, 1.0}, true);
    gmsh::model::occ::synchronize();
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    gmsh::model::addPhysicalGroup(3, {v[0], v[1]}, 2);
    gmsh::model::setPhysicalName(3, 2, "tet");
    for (const auto& [dim, tag] : layer)
      if (dim == 3)
        name_volume(tag, bounding_box(3, tag)[3] < 1.0 + kEps ? 1 : 4,
                    bounding_box(3, tag)[3] < 1.0 + kEps ? "hex layer" : "wedge layer");
  });
}

Model demo_hexdominant(int n) {
  if (n < 1) throw InvalidInput("demo_hexdominant: n = " + std::to_string(n) + " must be >= 1");
  const double h = 1.0 / n;
  return hybrid_gmsh("demo_hexdominant", [&] {
    // An L of a transfinite hex block [0,1]^3 and a Delaunay tet block [1,2] x [0,1]^2 (pyramids
    // on their shared face), a layer of wedges extruded off the tet block's far face x = 2, and a
    // second hex block [0,1] x [1,2] x [0,1] on the first one's back face: all four cell kinds
    // side by side, hexes meeting wedges' neighbours, tets meeting pyramids and wedges.
    const auto v = shared_boxes({{0, 0, 0, 1, 1, 1}, {1, 0, 0, 1, 1, 1}, {0, 1, 0, 1, 1, 1}});
    transfinite_box(v[0], h);
    transfinite_box(v[2], h);
    int far = 0;
    for (int s : boundary_surfaces(v[1]))
      if (bounding_box(2, s)[0] > 2.0 - kEps) far = s;
    gmsh::vectorpair layer;
    gmsh::model::occ::extrude({{2, far}}, 0.15, 0, 0, layer, {2}, {}, true);
    gmsh::model::occ::synchronize();
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    name_volume(v[0], 1, "hex");
    name_volume(v[2], 3, "hex back");
    name_volume(v[1], 2, "tet");
    for (const auto& [dim, tag] : layer)
      if (dim == 3) name_volume(tag, 4, "wedge layer");
  });
}

namespace {

// One part of the potting model: `build` adds its OCC volumes (fragmented where they touch) and
// sets their meshing; they become block `id` named `name`.
Model potting_part(int id, const std::string& name,
                   const std::function<gmsh::vectorpair()>& build) {
  return hex_part_from_gmsh(name, [&] {
    const gmsh::vectorpair volumes = build();
    std::vector<int> tags;
    for (const auto& [dim, tag] : volumes) tags.push_back(tag);
    gmsh::model::addPhysicalGroup(3, tags, id);
    gmsh::model::setPhysicalName(3, id, name);
  });
}

// Structured boxes (each {x0, y0, z0, x1, y1, z1}; touching ones must meet in whole faces, so
// that each stays a six-faced transfinite block), fragmented so that they share those faces,
// optionally rotated by `angle` about the axis through `centre`.
gmsh::vectorpair structured_boxes(const std::vector<Box>& boxes, double h,
                                  const Point& centre = Point::Zero(),
                                  const Point& axis = Point::UnitZ(), double angle = 0.0) {
  gmsh::vectorpair volumes, fragments;
  for (const Box& b : boxes)
    volumes.push_back(
        {3, gmsh::model::occ::addBox(b[0], b[1], b[2], b[3] - b[0], b[4] - b[1], b[5] - b[2])});
  std::vector<gmsh::vectorpair> map;
  if (volumes.size() > 1)
    gmsh::model::occ::fragment(volumes, {}, fragments, map);
  else
    fragments = volumes;
  if (angle != 0.0)
    gmsh::model::occ::rotate(fragments, centre.x(), centre.y(), centre.z(), axis.x(), axis.y(),
                             axis.z(), angle);
  gmsh::model::occ::synchronize();
  for (const auto& [dim, tag] : fragments) transfinite_box(tag, h);
  return fragments;
}

// A disk of radius r about `centre` in the plane normal to `axis` (x or z), its unstructured
// recombined quads swept along the axis over `length` in layers of about h.
gmsh::vectorpair swept_cylinder(const Point& centre, double r, int axis, double length, double h) {
  const int disk = gmsh::model::occ::addDisk(centre.x(), centre.y(), centre.z(), r, r);
  if (axis == 0)
    gmsh::model::occ::rotate({{2, disk}}, centre.x(), centre.y(), centre.z(), 0, 1, 0,
                             std::numbers::pi / 2);
  gmsh::vectorpair out, volumes;
  const Point along = length * (axis == 0 ? Point::UnitX() : Point::UnitZ());
  gmsh::model::occ::extrude({{2, disk}}, along.x(), along.y(), along.z(), out,
                            {std::max(1, static_cast<int>(std::lround(length / h)))}, {}, true);
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", h);
  gmsh::model::mesh::setRecombine(2, disk);
  for (const auto& dt : out)
    if (dt.first == 3) volumes.push_back(dt);
  return volumes;
}

}  // namespace

Model demo_potting(int n) {
  if (n < 2) throw InvalidInput("demo_potting: n = " + std::to_string(n) + " must be >= 2");
  const double h = 1.0 / n;
  return run_gmsh("demo_potting", [&] {
    std::vector<Model> parts;
    parts.push_back(potting_part(1, "block_a", [&] {
      return structured_boxes({{0.5, 0.5, 0.6, 1.5, 1.5, 1.6}}, h);
    }));
    parts.push_back(potting_part(2, "slab_b", [&] {
      return structured_boxes({{2.2, 0.5, 0.5, 4.2, 1.1, 1.5}}, h);
    }));
    parts.push_back(potting_part(
        3, "pin_z", [&] { return swept_cylinder(Point(1.0, 3.0, 0.5), 0.4, 2, 1.4, h); }));
    parts.push_back(potting_part(
        4, "pin_x", [&] { return swept_cylinder(Point(2.2, 3.5, 1.3), 0.3, 0, 2.1, h); }));
    parts.push_back(potting_part(5, "tilted", [&] {
      return structured_boxes({{2.8, 1.8, 0.8, 3.6, 2.6, 1.6}}, h, Point(3.2, 2.2, 1.2),
                              Point(1, 1, 0), 0.5);
    }));
    // An L-shaped bracket: a concave edge and saddle corners where it meets its convex ones.
    parts.push_back(potting_part(6, "bracket", [&] {
      return structured_boxes({{4.7, 0.5, 0.6, 5.2, 1.0, 1.6},
                               {5.2, 0.5, 0.6, 5.7, 1.0, 1.6},
                               {4.7, 1.0, 0.6, 5.2, 2.0, 1.6}},
                              h);
    }));
    gmsh::option::setNumber("Mesh.MeshSizeMax", 1e22);
    Shell outer;
    append_solid_boundary(
        outer, 1.5 * h, [] { gmsh::model::occ::addBox(0, 0, 0, 6.2, 4.4, 2.2); },
        [](const Box&) { return false; }, [](const Box&) { return true; });
    std::vector<Shell> holes(parts.size());
    Model hexes;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      append_interface_triangles(
          holes[i], parts[i], [](const Point&) { return true; },
          diagonal_chooser(DemoDiagonals::kRandom, h), four_chooser(false));
      const Index offset = index_cast(hexes.points.size());
      hexes.points.insert(hexes.points.end(), parts[i].points.begin(), parts[i].points.end());
      for (auto hex : parts[i].hexes) {
        for (Index& v : hex) v += offset;
        hexes.hexes.push_back(hex);
      }
      hexes.hex_block.insert(hexes.hex_block.end(), parts[i].hex_block.begin(),
                             parts[i].hex_block.end());
      hexes.block_names.insert(parts[i].block_names.begin(), parts[i].block_names.end());
    }
    return join(std::move(hexes), tet_fill(outer, holes, 7, "potting"));
  });
}

Model demo_wedge(int n, double angle) {
  if (n < 2) throw InvalidInput("demo_wedge: n = " + std::to_string(n) + " must be >= 2");
  if (!(angle >= 30.0 && angle <= 330.0))
    throw InvalidInput("demo_wedge: angle " + std::to_string(angle) +
                       " must be in [30, 330] degrees");
  const double h = 1.0 / n;  // the tet box's boundary cells: 1.5 h
  // k kites around the origin, each spanning angle / k there, right angles where its sides meet
  // the rays at distance 1.
  const int k = static_cast<int>(std::ceil(angle / 120.0));
  const double span = angle / k * std::numbers::pi / 180.0;
  return run_gmsh("demo_wedge", [&] {
    Model hexes = hex_part_from_gmsh("wedge", [&] {
      auto ray = [](double a, double r) {
        return gmsh::model::occ::addPoint(r * std::cos(a), r * std::sin(a), 0.0);
      };
      const int o = gmsh::model::occ::addPoint(0, 0, 0);
      std::vector<int> rim;
      for (int i = 0; i <= k; ++i) rim.push_back(ray(i * span, 1.0));
      gmsh::vectorpair kites;
      for (int i = 0; i < k; ++i) {
        const int tip = ray((i + 0.5) * span, 1.0 / std::cos(span / 2));
        const std::vector<int> corners{o, rim[index_cast<std::size_t>(i)], tip,
                                       rim[index_cast<std::size_t>(i + 1)]};
        std::vector<int> lines;
        for (std::size_t c = 0; c < 4; ++c)
          lines.push_back(gmsh::model::occ::addLine(corners[c], corners[(c + 1) % 4]));
        kites.push_back(
            {2, gmsh::model::occ::addPlaneSurface({gmsh::model::occ::addCurveLoop(lines)})});
      }
      gmsh::vectorpair faces, out, volumes;
      std::vector<gmsh::vectorpair> map;
      if (k > 1)
        gmsh::model::occ::fragment(kites, {}, faces, map);
      else
        faces = kites;
      gmsh::model::occ::extrude(faces, 0, 0, 1, out, {n}, {}, true);
      gmsh::model::occ::synchronize();
      // Opposite sides of a transfinite kite have equal counts, and neighbours share rays: n
      // cells on every side (the rim sides, tan(span / 2) long, get cells of their own size).
      gmsh::vectorpair curves;
      gmsh::model::getBoundary(faces, curves, false, false, false);
      for (const auto& [dim, tag] : curves)
        gmsh::model::mesh::setTransfiniteCurve(std::abs(tag), n + 1);
      for (const auto& [dim, tag] : faces) {
        gmsh::model::mesh::setTransfiniteSurface(tag);
        gmsh::model::mesh::setRecombine(2, tag);
      }
      std::vector<int> tags;
      for (const auto& [dim, tag] : out)
        if (dim == 3) tags.push_back(tag);
      gmsh::model::addPhysicalGroup(3, tags, 1);
      gmsh::model::setPhysicalName(3, 1, "wedge");
    });
    Box box{1e9, 1e9, 1e9, -1e9, -1e9, -1e9};
    for (const Point& p : hexes.points)
      for (int a = 0; a < 3; ++a)
        box[a] = std::min(box[a], p[a]), box[a + 3] = std::max(box[a + 3], p[a]);
    Shell outer, inner;
    append_solid_boundary(
        outer, 1.5 * h,
        [&] {
          gmsh::model::occ::addBox(box[0] - 1, box[1] - 1, box[2] - 1, box[3] - box[0] + 2,
                                   box[4] - box[1] + 2, box[5] - box[2] + 2);
        },
        [](const Box&) { return false; }, [](const Box&) { return true; });
    append_interface_triangles(
        inner, hexes, [](const Point&) { return true; },
        diagonal_chooser(DemoDiagonals::kRandom, h), four_chooser(false));
    return join(std::move(hexes), tet_fill(outer, {inner}, 2, "tet"));
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
