#include <geode/demo/detail/model_building.hpp>

#include <memory>
#include <random>

#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>

namespace geode::demo::detail {

Model without_file_ids(Model m) {
  for (ElementKind kind : kElementKinds) element_ids(m, kind).clear();
  m.node_ids.clear();
  return m;
}

std::vector<int> boundary_surfaces(int volume) {
  gmsh::vectorpair faces;
  gmsh::model::getBoundary({{3, volume}}, faces, false, false, false);
  std::vector<int> tags;
  for (const auto& [dim, tag] : faces) tags.push_back(std::abs(tag));
  return tags;
}

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

using Box = std::array<double, 6>;
Box bounding_box(int dim, int tag) {
  Box b;
  gmsh::model::getBoundingBox(dim, tag, b[0], b[1], b[2], b[3], b[4], b[5]);
  return b;
}

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

Model run_gmsh(const std::string& name, const std::function<Model()>& build) {
  GmshSession session;
  try {
    return build();
  } catch (const std::string& s) {
    throw std::runtime_error(name + ": Gmsh failed: " + s);
  }
}

}  // namespace geode::demo::detail
