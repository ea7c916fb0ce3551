#include "io/gmsh.hpp"

#include "io/atomic_file.hpp"

#include <gmsh.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <string>
#include <unordered_map>

#include "primal/boundary.hpp"
#include "primal/errors.hpp"
#include "io/file_format.hpp"
#include "primal/topology.hpp"

namespace geode::io {

using namespace primal;

namespace {

constexpr int kGmshTri3 = 2;
constexpr int kGmshQuad4 = 3;
constexpr int kGmshTet4 = 4;
constexpr int kGmshHex8 = 5;
constexpr int kGmshPoint = 15;

std::string gmsh_type_name(int type) {
  std::string name;
  int dim = 0, order = 0, num_nodes = 0, num_primary = 0;
  std::vector<double> local;
  try {
    gmsh::model::mesh::getElementProperties(type, name, dim, order, num_nodes, local,
                                            num_primary);
  } catch (...) {
    name = "unknown";
  }
  return name + " (Gmsh type " + std::to_string(type) + ")";
}

// Gmsh reports errors by throwing std::string (4.8) or std::exception; turn any of them into
// a message.
template <class F>
void gmsh_call(const std::string& where, F&& f) {
  try {
    f();
  } catch (const std::string& s) {
    throw InvalidInput(where + ": " + s);
  } catch (const InvalidInput&) {
    throw;
  } catch (const std::exception& e) {
    throw InvalidInput(where + ": " + e.what());
  } catch (...) {
    std::string last;
    gmsh::logger::getLastError(last);
    throw InvalidInput(where + ": Gmsh error" + (last.empty() ? "" : ": " + last));
  }
}

}  // namespace

GmshSession::GmshSession() {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
}

GmshSession::~GmshSession() { gmsh::finalize(); }

Model model_from_gmsh(std::string_view source_view) {
  const std::string source(source_view);
  Model model;

  // Nodes, numbered by ascending tag.
  std::vector<std::size_t> node_tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(node_tags, coords, parametric, -1, -1, false, false);
  std::vector<std::size_t> order(node_tags.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return node_tags[a] < node_tags[b]; });
  std::unordered_map<std::size_t, Index> index_of;
  index_of.reserve(node_tags.size());
  model.points.reserve(node_tags.size());
  for (std::size_t i : order) {
    if (!index_of.emplace(node_tags[i], static_cast<Index>(model.points.size())).second)
      continue;  // the same node listed twice (shared entity boundary)
    model.points.emplace_back(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);
  }
  auto node = [&](std::size_t tag, const std::string& what) {
    auto it = index_of.find(tag);
    if (it == index_of.end())
      throw InvalidInput(source + ": " + what + " refers to node tag " + std::to_string(tag) +
                         ", which does not exist");
    return it->second;
  };

  // Volume entities grouped into blocks.
  gmsh::vectorpair volumes;
  gmsh::model::getEntities(volumes, 3);
  std::vector<std::pair<int, int>> block_entity;  // (block id, entity tag)
  for (const auto& [dim, tag] : volumes) {
    std::vector<int> physicals;
    gmsh::model::getPhysicalGroupsForEntity(dim, tag, physicals);
    int block = tag;
    if (!physicals.empty()) {
      block = *std::min_element(physicals.begin(), physicals.end());
      std::string name;
      gmsh::model::getPhysicalName(3, block, name);
      if (!name.empty()) model.block_names[block] = name;
    }
    if (block <= 0)
      throw InvalidInput(source + ": volume entity " + std::to_string(tag) +
                         ": block id " + std::to_string(block) + " is not positive");
    block_entity.emplace_back(block, tag);
  }
  std::stable_sort(block_entity.begin(), block_entity.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [block, entity] : block_entity) {
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> element_tags, element_nodes;
    gmsh::model::mesh::getElements(types, element_tags, element_nodes, 3, entity);
    for (std::size_t t = 0; t < types.size(); ++t) {
      const auto& tags = element_tags[t];
      const auto& nodes = element_nodes[t];
      const ElementKind* kind = gmsh_cell_kind(types[t]);
      if (!kind) {
        if (!tags.empty())
          throw InvalidInput(source + ": element " + std::to_string(tags.front()) + ": " + gmsh_type_name(types[t]) +
                             " is not supported; only linear cells are (4-node tetrahedra, 8-node hexahedra, "
                             "6-node prisms, 5-node pyramids)");
        continue;
      }
      const GmshCell& cell = kGmshCells[static_cast<std::size_t>(*kind)];
      const auto n = static_cast<std::size_t>(cell.corners);
      for (std::size_t e = 0; e < tags.size(); ++e) {
        const std::string what = "element " + std::to_string(tags[e]);
        std::array<Index, 8> c{};
        for (std::size_t k = 0; k < n; ++k) c[k] = node(nodes[n * e + static_cast<std::size_t>(cell.order[k])], what);
        add_element(model, *kind, c, block, static_cast<std::int64_t>(tags[e]));
      }
    }
  }

  // Physical groups of lower dimension: side sets (dim 2) and node sets (dim 0, 1).
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  FaceOwners face_owner;
  bool faces_built = false;
  auto build_faces = [&] {
    if (faces_built) return;
    faces_built = true;
    face_owner = FaceOwners(model);
  };
  for (const auto& [dim, ptag] : groups) {
    if (dim == 3) continue;
    std::string name;
    gmsh::model::getPhysicalName(dim, ptag, name);
    if (dim == 2) {
      build_faces();
      SideSet set{ptag, name, {}};
      const std::string where = source + ": side set " + std::to_string(ptag) + " '" + name + "'";
      std::vector<int> entities;
      gmsh::model::getEntitiesForPhysicalGroup(dim, ptag, entities);
      for (int entity : entities) {
        std::vector<int> types;
        std::vector<std::vector<std::size_t>> element_tags, element_nodes;
        gmsh::model::mesh::getElements(types, element_tags, element_nodes, 2, entity);
        for (std::size_t t = 0; t < types.size(); ++t) {
          const std::size_t n = types[t] == kGmshTri3 ? 3 : types[t] == kGmshQuad4 ? 4 : 0;
          if (n == 0) {
            if (!element_tags[t].empty())
              throw InvalidInput(where + ": element " + std::to_string(element_tags[t].front()) +
                                 ": " + gmsh_type_name(types[t]) +
                                 " is not supported; only 3-node triangles and 4-node quads are");
            continue;
          }
          for (std::size_t e = 0; e < element_tags[t].size(); ++e) {
            const std::string what = "element " + std::to_string(element_tags[t][e]);
            std::vector<Index> face;
            for (std::size_t i = 0; i < n; ++i)
              face.push_back(node(element_nodes[t][n * e + i], where + ": " + what));
            const Side* owner = face_owner.find(face);
            if (!owner) throw InvalidInput(where + ": " + what + " is not a face of any volume element");
            set.sides.push_back(*owner);
          }
        }
      }
      std::sort(set.sides.begin(), set.sides.end());  // Gmsh groups elements by type
      model.side_sets.push_back(std::move(set));
    } else {
      std::vector<std::size_t> tags;
      std::vector<double> xyz;
      gmsh::model::mesh::getNodesForPhysicalGroup(dim, ptag, tags, xyz);
      NodeSet set{ptag, name, {}};
      const std::string where = source + ": node set " + std::to_string(ptag) + " '" + name + "'";
      for (std::size_t tag : tags) set.nodes.push_back(node(tag, where));
      std::sort(set.nodes.begin(), set.nodes.end());
      set.nodes.erase(std::unique(set.nodes.begin(), set.nodes.end()), set.nodes.end());
      model.node_sets.push_back(std::move(set));
    }
  }
  validate(model, source);
  return model;
}

Model read_gmsh(const std::filesystem::path& path, const ReadOptions& options) {
  check_mesh_format(path, MeshFileFormat::kGmsh);
  return parse_gmsh(read_file_bytes(path), path.string(), options);
}

void write_gmsh(const Model& model, const std::filesystem::path& path, GmshFormat format,
                GmshVersion version) {
  const std::string target = path.string();
  validate(model, target);
  GmshSession session;
  // Gmsh picks the format from the extension, so the temporary file keeps ".msh".
  write_path_atomically(path, ".msh", [&](const std::filesystem::path& temp) {
    gmsh_call(target, [&] {
      gmsh::model::add("geode");
      std::vector<int> blocks;
      for (ElementKind kind : kElementKinds)
        for (std::size_t e = 0; e < element_count(model, kind); ++e) blocks.push_back(block_of(model, {kind, static_cast<Index>(e)}));
      std::sort(blocks.begin(), blocks.end());
      blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
      // Nodes live on the first volume entity; elements of other entities may use them.
      const int node_entity = blocks.empty() ? 1 : blocks.front();
      if (blocks.empty()) gmsh::model::addDiscreteEntity(3, node_entity);
      for (int b : blocks) gmsh::model::addDiscreteEntity(3, b);
      std::vector<std::size_t> node_tags(model.points.size());
      std::vector<double> coords;
      coords.reserve(3 * model.points.size());
      for (std::size_t i = 0; i < model.points.size(); ++i) {
        node_tags[i] = i + 1;
        coords.insert(coords.end(), {model.points[i].x(), model.points[i].y(), model.points[i].z()});
      }
      if (!node_tags.empty()) gmsh::model::mesh::addNodes(3, node_entity, node_tags, coords);

      std::size_t next_element = 1;
      for (int b : blocks) {
        std::vector<int> types;
        std::vector<std::vector<std::size_t>> tags, nodes;
        for (ElementKind kind : kElementKinds) {
          const GmshCell& cell = kGmshCells[static_cast<std::size_t>(kind)];
          std::vector<std::size_t> kind_tags, kind_nodes;
          for (std::size_t e = 0; e < element_count(model, kind); ++e) {
            const ElementRef ref{kind, static_cast<Index>(e)};
            if (block_of(model, ref) != b) continue;
            kind_tags.push_back(next_element++);
            // gmsh_corner[order[i]] = model_corner[i]
            const auto corners = element_corners(model, ref);
            std::array<std::size_t, 8> g{};
            for (std::size_t c = 0; c < static_cast<std::size_t>(cell.corners); ++c)
              g[static_cast<std::size_t>(cell.order[c])] = static_cast<std::size_t>(corners[c]) + 1;
            kind_nodes.insert(kind_nodes.end(), g.begin(), g.begin() + cell.corners);
          }
          if (kind_tags.empty()) continue;
          types.push_back(cell.type);
          tags.push_back(std::move(kind_tags));
          nodes.push_back(std::move(kind_nodes));
        }
        gmsh::model::mesh::addElements(3, b, types, tags, nodes);
        gmsh::model::addPhysicalGroup(3, {b}, b);
        if (auto it = model.block_names.find(b); it != model.block_names.end())
          gmsh::model::setPhysicalName(3, b, it->second);
      }

      int surface = 0;
      for (const SideSet& set : model.side_sets) {
        gmsh::model::addDiscreteEntity(2, ++surface);
        std::vector<std::size_t> tri_tags, tri_nodes, quad_tags, quad_nodes;
        for (const Side& s : set.sides) {
          const std::vector<Index> face = element_face(model, s);
          (face.size() == 4 ? quad_tags : tri_tags).push_back(next_element++);
          for (Index v : face) (face.size() == 4 ? quad_nodes : tri_nodes).push_back(static_cast<std::size_t>(v) + 1);
        }
        std::vector<int> types;
        std::vector<std::vector<std::size_t>> tags, nodes;
        if (!tri_tags.empty()) {
          types.push_back(kGmshTri3);
          tags.push_back(tri_tags);
          nodes.push_back(tri_nodes);
        }
        if (!quad_tags.empty()) {
          types.push_back(kGmshQuad4);
          tags.push_back(quad_tags);
          nodes.push_back(quad_nodes);
        }
        gmsh::model::mesh::addElements(2, surface, types, tags, nodes);
        gmsh::model::addPhysicalGroup(2, {surface}, set.id);
        gmsh::model::setPhysicalName(2, set.id, set.name);
      }

      int point_entity = 0;
      for (const NodeSet& set : model.node_sets) {
        gmsh::model::addDiscreteEntity(0, ++point_entity);
        std::vector<std::size_t> tags, nodes;
        for (Index v : set.nodes) {
          tags.push_back(next_element++);
          nodes.push_back(static_cast<std::size_t>(v) + 1);
        }
        gmsh::model::mesh::addElements(0, point_entity, {kGmshPoint}, {tags}, {nodes});
        gmsh::model::addPhysicalGroup(0, {point_entity}, set.id);
        gmsh::model::setPhysicalName(0, set.id, set.name);
      }

      gmsh::option::setNumber("Mesh.MshFileVersion", version == GmshVersion::k22 ? 2.2 : 4.1);
      gmsh::option::setNumber("Mesh.Binary", format == GmshFormat::Binary ? 1 : 0);
      gmsh::option::setNumber("Mesh.SaveAll", 1);
      gmsh::write(temp.string());
    });
  });
}

}  // namespace geode::io
