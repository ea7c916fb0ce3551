#include <geode/primal/pillow.hpp>

#include <string>

#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

PillowResult pillow(const HexMesh& mesh, std::span<const Index> shrink_set,
                    const PillowOptions& options) {
  if (shrink_set.empty()) throw InvalidInput("pillow: the shrink set is empty");
  if (!(options.shrink > 0 && options.shrink < 1))
    throw InvalidInput("pillow: the shrink fraction must be in (0, 1)");
  const auto hexes = index_cast(mesh.hexes.size());
  std::vector<char> in_set(mesh.hexes.size(), 0);
  for (Index h : shrink_set) {
    if (h < 0 || h >= hexes)
      throw InvalidInput("pillow: hex " + std::to_string(h) + " of the shrink set is out of range");
    if (in_set[index_cast<std::size_t>(h)])
      throw InvalidInput("pillow: hex " + std::to_string(h) + " is twice in the shrink set");
    in_set[index_cast<std::size_t>(h)] = 1;
  }

  // The set's boundary faces: used by one set hex and by no other set hex.
  std::vector<HexFaceUse> surface;
  for (const auto& f : unique_faces(mesh)) {
    int uses_in_set = 0;
    for (const auto& u : f.uses) uses_in_set += in_set[index_cast<std::size_t>(u.hex)];
    if (uses_in_set == 1)
      for (const auto& u : f.uses)
        if (in_set[index_cast<std::size_t>(u.hex)]) surface.push_back(u);
  }

  PillowResult r;
  r.mesh = mesh;
  const std::size_t old_nodes = mesh.points.size();
  std::vector<Index> copy(old_nodes, kInvalidIndex);
  for (const auto& u : surface)
    for (int c : topology::kHexFaceCorners[index_cast<std::size_t>(u.local_face)]) {
      const Index n = mesh.hexes[index_cast<std::size_t>(u.hex)][index_cast<std::size_t>(c)];
      if (copy[index_cast<std::size_t>(n)] != kInvalidIndex) continue;
      copy[index_cast<std::size_t>(n)] = index_cast(old_nodes + r.copy_of.size());
      r.copy_of.push_back(n);
    }

  // First-guess positions: towards the centroids of the set's hexes around each copied node.
  std::vector<Point> towards(r.copy_of.size(), Point::Zero());
  std::vector<int> count(r.copy_of.size(), 0);
  for (Index h : shrink_set) {
    const auto& hex = mesh.hexes[index_cast<std::size_t>(h)];
    Point centroid = Point::Zero();
    for (Index n : hex) centroid += mesh.points[index_cast<std::size_t>(n)] / 8.0;
    for (Index n : hex)
      if (const Index c = copy[index_cast<std::size_t>(n)]; c != kInvalidIndex) {
        towards[index_cast<std::size_t>(c) - old_nodes] += centroid;
        ++count[index_cast<std::size_t>(c) - old_nodes];
      }
  }
  for (std::size_t i = 0; i < r.copy_of.size(); ++i) {
    const Point& p = mesh.points[index_cast<std::size_t>(r.copy_of[i])];
    r.mesh.points.push_back(p + options.shrink * (towards[i] / count[i] - p));
  }

  // The set's hexes move onto the copies; each boundary face of the set becomes a hex whose
  // bottom is the copied face and top the face itself. kHexFaceCorners runs outward of the
  // set hex, i.e. into the new hex, as a hex's bottom face 0-1-2-3 does.
  for (Index h : shrink_set)
    for (Index& n : r.mesh.hexes[index_cast<std::size_t>(h)])
      if (copy[index_cast<std::size_t>(n)] != kInvalidIndex) n = copy[index_cast<std::size_t>(n)];
  for (const auto& u : surface) {
    const auto& hex = mesh.hexes[index_cast<std::size_t>(u.hex)];
    const auto& face = topology::kHexFaceCorners[index_cast<std::size_t>(u.local_face)];
    std::array<Index, 8> layer{};
    for (int i = 0; i < 4; ++i) {
      const Index n = hex[index_cast<std::size_t>(face[index_cast<std::size_t>(i)])];
      layer[index_cast<std::size_t>(i)] = copy[index_cast<std::size_t>(n)];
      layer[index_cast<std::size_t>(i) + 4] = n;
    }
    r.layer.push_back(index_cast(r.mesh.hexes.size()));
    r.mesh.hexes.push_back(layer);
    if (!mesh.block.empty()) r.mesh.block.push_back(mesh.block[index_cast<std::size_t>(u.hex)]);
  }
  return r;
}

}  // namespace geode::primal
