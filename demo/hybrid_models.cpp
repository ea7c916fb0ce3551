#include <geode/demo/demo_models.hpp>

#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <geode/demo/detail/model_building.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/unfold.hpp>

namespace geode::demo {

using namespace primal;
using namespace io;
using namespace detail;

// ---- Hybrid models as a user meshes them: one geometry, one generate(3) --------------------
// Hex volumes transfinite (or swept) and recombined, tet volumes Delaunay, wedges extruded in
// layers, all meshed together, so Gmsh itself puts a pyramid on every quad a tet volume meets.

namespace {

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

// Gmsh 4.8's hybrid meshes hold, at some sizes, elements folded over their neighbours near the
// pyramids it puts on quads (positive tets whose neighbours lie on their own side of a shared
// face, a pyramid inside out): of n = 4, 6, ..., 24, hexdominant, hybrid and layer-interface at
// 14, 16 and 24 (and hexdominant at 29, 30, 31, 33), hybrid-cylinder at every n from 10,
// layer-mixed at all but 20 from 12, layer-side at 16. The read-time check refuses them, as it
// would a user's file; a user would mesh again at another size. So does the demo: the tet
// sizes scaled by these factors in turn (Mesh.MeshSizeFactor; the transfinite and swept hexes
// keep their node counts), the first mesh that passes the check kept. That mends all of them
// but hybrid-cylinder from n = 14 to 24. The cause (Gmsh 4.8's meshGRegion.cpp): after building
// the pyramids, RelocateVerticesOfPyramids moves the nodes of the tets within two rings of their
// apexes judging each move by the node's tets inside the rings only, and the closing
// setAllVolumesPositive reorders a tet a move turned over; no meshing option mends every size
// (docs/whole-models.md).
constexpr double kRemeshFactors[] = {1.0, 0.99, 1.01, 0.98, 1.02};

// One Gmsh model meshed in one generate(3), each volume its own named block; elements Gmsh hands
// back inverted re-oriented (orient_positively, with pyramids and wedges).
template <class F>
Model hybrid_gmsh(const std::string& name, F&& build) {
  return run_gmsh(name, [&] {
    gmsh::model::add(name);
    build();
    std::string refused;
    std::optional<Model> first;  // the first mesh refused, kept for unfold
    for (const double factor : kRemeshFactors) {
      gmsh::option::setNumber("Mesh.MeshSizeFactor", factor);
      gmsh::model::mesh::clear();
      try {
        gmsh::model::mesh::generate(3);
      } catch (const std::string& s) {  // Gmsh 4.8's errors: another size may mesh
        refused = "Gmsh failed to mesh " + name + ": " + s;
        continue;
      } catch (const std::exception& e) {
        refused = "Gmsh failed to mesh " + name + ": " + e.what();
        continue;
      }
      Model m = without_file_ids(model_from_gmsh(name));
      auto pt = [&](Index v) -> const Point& { return m.points[index_cast<std::size_t>(v)]; };
      orient_positively(m);
      for (auto& p : m.pyramids)
        if (tet_volume(pt(p[0]), pt(p[1]), pt(p[2]), pt(p[4])) < 0) std::swap(p[1], p[3]);
      for (auto& w : m.wedges)
        if (tet_volume(pt(w[0]), pt(w[1]), pt(w[2]), pt(w[3])) < 0)
          std::swap(w[1], w[2]), std::swap(w[4], w[5]);
      try {
        require_single_covering(m, "Gmsh's mesh of " + name);
        return m;
      } catch (const InvalidInput& e) {
        refused = e.what();
        if (!first) first = std::move(m);
      }
    }
    // Folded at every size: the first mesh's folds turned back, as conform --unfold does.
    if (first && unfold(*first).unfolded()) return std::move(*first);
    throw InvalidInput(refused + " (with the tet sizes 0.98 to 1.02 times the model's too)");
  });
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

}  // namespace geode::demo
