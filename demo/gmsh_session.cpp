// The Gmsh API session and the conversion of Gmsh's current model (demo/gmsh_session.hpp): the
// only code that calls libgmsh, so that only the demo models load it.
#include <geode/demo/gmsh_session.hpp>

#include <gmsh.h>

#include <algorithm>
#include <string>
#include <unordered_map>
#include <vector>

#include <geode/io/gmsh.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>

namespace geode::demo {

using namespace primal;
using io::gmsh_cell_kind;
using io::GmshCell;
using io::kGmshCells;

namespace {

constexpr int kGmshTri3 = 2;
constexpr int kGmshQuad4 = 3;

std::string gmsh_type_name(int type) {
  std::string name;
  int dim = 0, order = 0, num_nodes = 0, num_primary = 0;
  std::vector<double> local;
  try {
    gmsh::model::mesh::getElementProperties(type, name, dim, order, num_nodes, local, num_primary);
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

// Every option a session here sets (demo/, tests/, bench/), or that Gmsh sets as a side effect
// of what they call (partitioning sets Mesh.NbPartitions), with Gmsh's default, read once.
constexpr const char* kSessionOptions[] = {"General.NumThreads",
                                           "General.Terminal",
                                           "Mesh.Algorithm",
                                           "Mesh.Binary",
                                           "Mesh.MeshSizeFactor",
                                           "Mesh.MeshSizeMax",
                                           "Mesh.MeshSizeMin",
                                           "Mesh.MshFileVersion",
                                           "Mesh.NbPartitions",
                                           "Mesh.PartitionSplitMeshFiles",
                                           "Mesh.RecombinationAlgorithm",
                                           "Mesh.SaveAll",
                                           "Mesh.SubdivisionAlgorithm"};
std::vector<double>* g_defaults = nullptr;  // set by the first session; never freed
}  // namespace

GmshSession::GmshSession() {
  if (!g_defaults) {
    gmsh::initialize(0, nullptr, false);
    g_defaults = new std::vector<double>;
    for (const char* name : kSessionOptions) {
      double value = 0.0;
      gmsh::option::getNumber(name, value);
      g_defaults->push_back(value);
    }
  } else {
    gmsh::clear();
    for (std::size_t k = 0; k < std::size(kSessionOptions); ++k)
      gmsh::option::setNumber(kSessionOptions[k], (*g_defaults)[k]);
  }
  gmsh::option::setNumber("General.Terminal", 0);
}

GmshSession::~GmshSession() { gmsh::clear(); }

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
    if (!index_of.emplace(node_tags[i], index_cast(model.points.size())).second)
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
      throw InvalidInput(source + ": volume entity " + std::to_string(tag) + ": block id " +
                         std::to_string(block) + " is not positive");
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
          throw InvalidInput(
              source + ": element " + std::to_string(tags.front()) + ": " +
              gmsh_type_name(types[t]) +
              " is not supported; only linear cells are (4-node tetrahedra, 8-node hexahedra, "
              "6-node prisms, 5-node pyramids)");
        continue;
      }
      const GmshCell& cell = kGmshCells[static_cast<std::size_t>(*kind)];
      const auto n = index_cast<std::size_t>(cell.corners);
      for (std::size_t e = 0; e < tags.size(); ++e) {
        const std::string what = "element " + std::to_string(tags[e]);
        std::array<Index, 8> c{};
        for (std::size_t k = 0; k < n; ++k)
          c[k] = node(nodes[n * e + index_cast<std::size_t>(cell.order[k])], what);
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
            if (!owner)
              throw InvalidInput(where + ": " + what + " is not a face of any volume element");
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

}  // namespace geode::demo
