#include "conform/demo_models.hpp"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "primal/boundary.hpp"
#include "primal/errors.hpp"
#include "primal/io_gmsh.hpp"
#include "primal/quality.hpp"

namespace geode::conform {

using namespace primal;

// ---- Demo models meshed with the Gmsh API ----------------------------------------------------

namespace {

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
    if (tet_volume(p[static_cast<std::size_t>(t[0])], p[static_cast<std::size_t>(t[1])],
                   p[static_cast<std::size_t>(t[2])], p[static_cast<std::size_t>(t[3])]) < 0)
      std::swap(t[1], t[2]);
  }
  for (auto& h : m.hexes) {
    HexCorners c;
    for (std::size_t i = 0; i < 8; ++i) c[i] = m.points[static_cast<std::size_t>(h[i])];
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
    Model m = model_from_gmsh(name);
    // The separately meshed volumes meet at coincident nodes: merge them.
    merge_coincident_nodes(m, 1e-9);
    orient_positively(m);
    return m;
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
  if (n < 2 || n % 2 != 0) throw InvalidInput("demo_nugget: n = " + std::to_string(n) + " must be even and >= 2");
  Model m = with_gmsh("demo_nugget", [n] {
    const double edges[4] = {-2, -1, 1, 2};
    gmsh::vectorpair blocks;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) {
          if (i == 1 && j == 1 && k == 1) continue;
          const int tag = gmsh::model::occ::addBox(edges[i], edges[j], edges[k], edges[i + 1] - edges[i],
                                                   edges[j + 1] - edges[j], edges[k + 1] - edges[k]);
          blocks.push_back({3, tag});
        }
    // Shared faces between the hex blocks (not with the nugget: its faces carry triangles).
    gmsh::vectorpair fragments;
    std::vector<gmsh::vectorpair> map;
    gmsh::model::occ::fragment(blocks, {}, fragments, map);
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
  // Side set: the outer boundary quads of the hex blocks.
  SideSet outside{1, "outside", {}};
  for (const BoundaryQuad& q : boundary_quads(hex_part(m))) {
    Point c = Point::Zero();
    for (Index v : q.nodes) c += m.points[static_cast<std::size_t>(v)] / 4.0;
    if (c.cwiseAbs().maxCoeff() > 2.0 - 1e-9) outside.sides.push_back({{ElementKind::Hex, q.hex}, q.local_face});
  }
  m.side_sets.push_back(std::move(outside));
  return m;
}

}  // namespace geode::conform
