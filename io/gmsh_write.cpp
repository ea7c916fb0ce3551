// Our own writer of Gmsh .msh 4.1 and 2.2, ASCII and binary (Gmsh reference manual, "MSH file
// format" and "Legacy formats"), so that no output depends on libgmsh and every write error
// (a full disk) is reported (file_sink.hpp). The layout is Gmsh's own with Mesh.SaveAll:
// - one volume entity per block (entity tag = block id) in the block's physical volume;
//   all nodes are listed on the first volume entity (elements of every entity use them);
// - one surface entity per side set holding its faces as triangles / quads, in the set's
//   physical surface, and one point entity per node set holding one point element per node,
//   in the set's physical point;
// - every entity's tag is its physical tag, so entity tags too are distinct across dimensions
//   (GetFEM 5.4 takes a .msh 4.1 element's region from its entity's tag);
// - $PhysicalNames for every named group, names made safe by io/names.hpp.
// Physical tags are distinct across dimensions (GetFEM, among others, keeps one region per tag
// and renumbers a tag used twice): blocks keep their ids; a side or node set whose id is
// already taken gets id + 10^k, 10^k the smallest power of ten above every id in the model
// (side sets first, then node sets, each in model order).
// Node tags are index + 1; element tags run from 1 over the blocks in ascending id (cell kinds
// in primal::kElementKinds order within a block: hexes, tets, pyramids, wedges), then the side
// sets' faces, then the node sets' points.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <set>
#include <span>
#include <string>
#include <vector>

#include <geode/io/atomic_file.hpp>
#include <geode/io/file_sink.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/names.hpp>
#include <geode/io/text_chunks.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::io {

using namespace primal;

namespace {

constexpr int kTri3 = 2, kQuad4 = 3, kPoint = 15;

// One entity block of $Elements: its entity and type, and each element's Gmsh node tags. A
// volume block names the model's elements of one kind and their tags are made as they are
// written (a copy of an all-hex output's connectivity in 8-byte tags would be the largest
// array of a conform run); side and node sets hold their tags.
struct ElementBlock {
  int dim = 0;
  int entity = 0;
  int physical = 0;
  int type = 0;
  std::size_t nodes_per_element = 0;
  std::vector<std::size_t> node_tags;  // nodes_per_element per element (dim < 3)
  std::size_t first_tag = 0;
  ElementKind kind = ElementKind::kHex;  // dim 3: the elements' kind
  std::vector<Index> elements;           // dim 3: into the kind's array
  std::size_t count() const {
    if (dim == 3) return elements.size();
    return nodes_per_element ? node_tags.size() / nodes_per_element : 0;
  }
  // Element e's Gmsh node tags, in Gmsh's corner order (gmsh.hpp's kGmshCells).
  void tags(const Model& model, std::size_t e, std::array<std::size_t, 8>& out) const {
    if (dim != 3) {
      std::copy_n(node_tags.begin() + static_cast<std::ptrdiff_t>(e * nodes_per_element),
                  nodes_per_element, out.begin());
      return;
    }
    const GmshCell& cell = kGmshCells[static_cast<std::size_t>(kind)];
    const auto c = element_corners(model, {kind, elements[e]});
    // gmsh_corner[order[i]] = model_corner[i]
    for (std::size_t v = 0; v < nodes_per_element; ++v)
      out[index_cast<std::size_t>(cell.order[v])] = index_cast<std::size_t>(c[v]) + 1;
  }
};

struct Entity {
  int dim = 0;
  int tag = 0;
  int physical = 0;
  Point low = Point::Zero(), high = Point::Zero();  // the bounding box; zero while empty
  bool empty = true;
  void extend(const Point& p) {
    low = empty ? p : low.cwiseMin(p);
    high = empty ? p : high.cwiseMax(p);
    empty = false;
  }
};

struct PhysicalName {
  int dim = 0;
  int tag = 0;
  std::string name;
};

// The model laid out as Gmsh entities, element blocks and physical groups.
class MshLayout {
 public:
  MshLayout(const Model& model, const std::string& target) : model(model), target(target) {
    volumes();
    assign_set_tags();
    side_sets();
    node_sets();
    std::size_t next = 1;
    for (ElementBlock& b : blocks) {
      b.first_tag = next;
      next += b.count();
    }
    elements = next - 1;
  }

  const Model& model;
  const std::string& target;
  std::vector<Entity> entities;  // in dimension order 0, 1, 2, 3 once sorted
  std::vector<ElementBlock> blocks;
  std::vector<PhysicalName> names;
  std::size_t elements = 0;
  int node_entity = 1;

 private:
  std::vector<int> side_tags_, node_tags_;

  Entity bounded(int dim, int tag, int physical, const std::vector<std::size_t>& nodes) const {
    Entity e{dim, tag, physical, Point::Zero(), Point::Zero(), true};
    for (std::size_t n : nodes) e.extend(model.points[n - 1]);
    return e;
  }

  void volumes() {
    // Every cell kind of the model through gmsh.hpp's table (kGmshCells: the Gmsh type and
    // corner order per primal::ElementKind), in its order within a block.
    std::map<int, std::vector<ElementBlock>> by_block;
    for (ElementKind kind : kElementKinds) {
      const GmshCell& cell = kGmshCells[static_cast<std::size_t>(kind)];
      const auto corners = index_cast<std::size_t>(cell.corners);
      for (std::size_t i = 0; i < element_count(model, kind); ++i) {
        const ElementRef ref{kind, index_cast(i)};
        const int block = block_of(model, ref);
        auto& list = by_block[block];
        if (list.empty() || list.back().type != cell.type)
          list.push_back({3, block, block, cell.type, corners, {}, 0, kind, {}});
        list.back().elements.push_back(ref.index);
      }
    }
    const bool finite = std::all_of(model.points.begin(), model.points.end(),
                                    [](const Point& p) { return p.allFinite(); });
    for (auto& [block, list] : by_block) {
      Entity e{3, block, block, Point::Zero(), Point::Zero(), true};
      for (ElementBlock& b : list) {
        extend_by_elements(e, b, finite);
        blocks.push_back(std::move(b));
      }
      entities.push_back(e);
      if (auto it = model.block_names.find(block);
          it != model.block_names.end() && !sanitize_name(it->second).empty())
        names.push_back({3, block, sanitize_name(it->second)});
    }
    if (by_block.empty()) {
      // Nodes need an entity even without elements.
      std::vector<std::size_t> all(model.points.size());
      for (std::size_t i = 0; i < all.size(); ++i) all[i] = i + 1;
      entities.push_back(bounded(3, 1, 0, all));
    }
    node_entity = entities.front().tag;
  }

  // Extends `e` by the corners of b's elements: min and max are exact, so any order gives the
  // one loop's box, unless a coordinate is not finite, whose comparisons depend on the order
  // (then the one loop). A block with more corners than the model has points has the nodes it
  // uses marked, then the marked points read in order, both in parallel: reading a point per
  // corner, 8 random reads a hex, was 2 % of a conform run writing .msh. A smaller one (a model
  // of many blocks) reads its corners, so that no block costs more than its corners twice.
  void extend_by_elements(Entity& e, const ElementBlock& b, bool finite) const {
    auto extend = [&](Entity& box, std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        for (Index v : element_corners(model, {b.kind, b.elements[i]}))
          box.extend(model.points[index_cast<std::size_t>(v)]);
    };
    if (!finite || b.elements.size() * b.nodes_per_element < model.points.size())
      return extend(e, 0, b.elements.size());
    std::vector<char> used(model.points.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, b.elements.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                          for (Index v : element_corners(model, {b.kind, b.elements[i]}))
                            std::atomic_ref<char>(used[index_cast<std::size_t>(v)])
                                .store(1, std::memory_order_relaxed);
                      });
    const Entity box = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, used.size(), 8192), Entity{},
        [&](const tbb::blocked_range<std::size_t>& r, Entity box) {
          for (std::size_t v = r.begin(); v != r.end(); ++v)
            if (used[v]) box.extend(model.points[v]);
          return box;
        },
        [](Entity a, const Entity& c) {
          if (!c.empty) a.extend(c.low), a.extend(c.high);
          return a;
        });
    if (!box.empty) e.extend(box.low), e.extend(box.high);
  }

  void assign_set_tags() {
    std::set<int> used;
    long long largest = 0;
    for (const auto& [block, list] : model.block_names)
      largest = std::max<long long>(largest, block);
    for (const Entity& e : entities) {
      if (e.physical) used.insert(e.physical);
      largest = std::max<long long>(largest, e.physical);
    }
    for (const SideSet& s : model.side_sets) largest = std::max<long long>(largest, s.id);
    for (const NodeSet& s : model.node_sets) largest = std::max<long long>(largest, s.id);
    long long offset = 10;
    while (offset <= largest) offset *= 10;
    auto tag_for = [&](int id, const std::string& what) {
      long long tag = id;
      while (used.count(static_cast<int>(tag))) {
        tag += offset;
        if (tag > INT32_MAX)
          throw InvalidInput(target + ": " + what + " " + std::to_string(id) +
                             ": no distinct physical tag is left for it");
      }
      used.insert(static_cast<int>(tag));
      return static_cast<int>(tag);
    };
    for (const SideSet& s : model.side_sets) side_tags_.push_back(tag_for(s.id, "side set"));
    for (const NodeSet& s : model.node_sets) node_tags_.push_back(tag_for(s.id, "node set"));
  }

  void side_sets() {
    for (std::size_t s = 0; s < model.side_sets.size(); ++s) {
      const SideSet& set = model.side_sets[s];
      const int physical = side_tags_[s], entity = physical;
      ElementBlock tri{2, entity, physical, kTri3, 3, {}, 0, ElementKind::kHex, {}},
          quad{2, entity, physical, kQuad4, 4, {}, 0, ElementKind::kHex, {}};
      for (const Side& side : set.sides) {
        const std::vector<Index> face = element_face(model, side);
        for (Index v : face)
          (face.size() == 4 ? quad : tri).node_tags.push_back(index_cast<std::size_t>(v) + 1);
      }
      std::vector<std::size_t> all = tri.node_tags;
      all.insert(all.end(), quad.node_tags.begin(), quad.node_tags.end());
      entities.push_back(bounded(2, entity, physical, all));
      if (!tri.node_tags.empty()) blocks.push_back(std::move(tri));
      if (!quad.node_tags.empty()) blocks.push_back(std::move(quad));
      if (const std::string name = sanitize_name(set.name); !name.empty())
        names.push_back({2, physical, name});
    }
  }

  void node_sets() {
    for (std::size_t s = 0; s < model.node_sets.size(); ++s) {
      const NodeSet& set = model.node_sets[s];
      const int physical = node_tags_[s], entity = physical;
      ElementBlock points{0, entity, physical, kPoint, 1, {}, 0, ElementKind::kHex, {}};
      for (Index v : set.nodes) points.node_tags.push_back(index_cast<std::size_t>(v) + 1);
      entities.push_back(bounded(0, entity, physical, points.node_tags));
      if (!points.node_tags.empty()) blocks.push_back(std::move(points));
      if (const std::string name = sanitize_name(set.name); !name.empty())
        names.push_back({0, physical, name});
    }
  }
};

class MshWriter {
 public:
  MshWriter(const MshLayout& layout, FileSink& out, bool binary, GmshVersion version)
      : l_(layout), out_(out), binary_(binary), v41_(version == GmshVersion::k41) {}

  void write() {
    out_.text("$MeshFormat\n");
    out_.text(v41_ ? "4.1 " : "2.2 ");
    out_.text(binary_ ? "1 8\n" : "0 8\n");
    if (binary_) {
      out_.raw<std::int32_t>(1);
      out_.ch('\n');
    }
    out_.text("$EndMeshFormat\n");
    physical_names();
    if (v41_) {
      entities41();
      nodes41();
      elements41();
    } else {
      nodes22();
      elements22();
    }
  }

 private:
  const MshLayout& l_;
  FileSink& out_;
  bool binary_;
  bool v41_;

  // ASCII lines of items [0, n), made in parallel chunks (text_chunks.hpp): `line(i, at)`
  // writes item i's line, at most `room` characters, at `at` and returns its end.
  template <class Line>
  void text_chunks(std::size_t n, std::size_t room, Line&& line) {
    constexpr std::size_t kLines = 2048;
    write_in_chunks(
        n, kLines,
        [&](std::size_t begin, std::size_t end, std::string& text) {
          text.resize((end - begin) * room);
          char* at = text.data();
          for (std::size_t i = begin; i < end; ++i) at = line(i, at);
          text.resize(index_cast<std::size_t>(at - text.data()));
        },
        [this](std::string_view bytes) { out_.text(bytes); });
  }

  // ASCII fields separated by spaces, each line ended by the caller.
  void num(std::int64_t x) { out_.integer(x); }
  void sp() { out_.ch(' '); }
  void nl() { out_.ch('\n'); }
  // 4.1 binary: int is 4 bytes, size_t 8.
  void int_field(int x, bool last = false) {
    if (binary_) return out_.raw<std::int32_t>(x);
    num(x);
    last ? nl() : sp();
  }
  void size_field(std::size_t x, bool last = false) {
    if (binary_) return out_.raw<std::uint64_t>(x);
    num(static_cast<std::int64_t>(x));
    last ? nl() : sp();
  }
  void real_field(double x, bool last = false) {
    if (binary_) return out_.raw<double>(x);
    out_.real(x);
    last ? nl() : sp();
  }

  void physical_names() {
    if (l_.names.empty()) return;
    out_.text("$PhysicalNames\n");
    num(index_cast<std::int64_t>(l_.names.size()));
    nl();
    for (const PhysicalName& p : l_.names) {
      num(p.dim);
      sp();
      num(p.tag);
      out_.text(" \"");
      out_.text(p.name);
      out_.text("\"\n");
    }
    out_.text("$EndPhysicalNames\n");
  }

  void entities41() {
    std::array<std::vector<const Entity*>, 4> by_dim;
    for (const Entity& e : l_.entities) by_dim[index_cast<std::size_t>(e.dim)].push_back(&e);
    out_.text("$Entities\n");
    for (std::size_t d = 0; d < 4; ++d) size_field(by_dim[d].size(), d == 3);
    for (std::size_t d = 0; d < 4; ++d)
      for (const Entity* e : by_dim[d]) {
        int_field(e->tag);
        for (int k = 0; k < 3; ++k) real_field(e->low[k]);
        if (d > 0)
          for (int k = 0; k < 3; ++k) real_field(e->high[k]);
        size_field(e->physical ? 1 : 0, d == 0 && !e->physical);
        if (e->physical) int_field(e->physical, d == 0);
        if (d > 0) size_field(0, true);  // no bounding entities: a discrete model
      }
    if (binary_) nl();
    out_.text("$EndEntities\n");
  }

  void nodes41() {
    const auto& pts = l_.model.points;
    out_.text("$Nodes\n");
    size_field(1);
    size_field(pts.size());
    size_field(pts.empty() ? 0 : 1);
    size_field(pts.size(), true);
    int_field(3);
    int_field(l_.node_entity);
    int_field(0);
    size_field(pts.size(), true);
    if (binary_) {
      for (std::size_t i = 0; i < pts.size(); ++i) size_field(i + 1, true);
      for (const Point& p : pts) {
        real_field(p.x());
        real_field(p.y());
        real_field(p.z(), true);
      }
      nl();
    } else {
      text_chunks(pts.size(), kIntegerText + 1, [](std::size_t i, char* at) {
        at = put_number(at, index_cast<std::int64_t>(i + 1));
        *at++ = '\n';
        return at;
      });
      text_chunks(pts.size(), 3 * (kRealText + 1), [&pts](std::size_t i, char* at) {
        for (int k = 0; k < 3; ++k) {
          at = put_number(at, pts[i][k]);
          *at++ = k < 2 ? ' ' : '\n';
        }
        return at;
      });
    }
    out_.text("$EndNodes\n");
  }

  void elements41() {
    out_.text("$Elements\n");
    size_field(l_.blocks.size());
    size_field(l_.elements);
    size_field(l_.elements ? 1 : 0);
    size_field(l_.elements, true);
    for (const ElementBlock& b : l_.blocks) {
      int_field(b.dim);
      int_field(b.entity);
      int_field(b.type);
      size_field(b.count(), true);
      if (!binary_) {
        text_chunks(b.count(), (1 + b.nodes_per_element) * (kIntegerText + 1),
                    [&](std::size_t e, char* at) {
                      std::array<std::size_t, 8> nodes{};
                      b.tags(l_.model, e, nodes);
                      at = put_number(at, index_cast<std::int64_t>(b.first_tag + e));
                      for (std::size_t k = 0; k < b.nodes_per_element; ++k) {
                        *at++ = ' ';
                        at = put_number(at, index_cast<std::int64_t>(nodes[k]));
                      }
                      *at++ = '\n';
                      return at;
                    });
        continue;
      }
      std::array<std::size_t, 8> nodes{};
      for (std::size_t e = 0; e < b.count(); ++e) {
        size_field(b.first_tag + e);
        b.tags(l_.model, e, nodes);
        for (std::size_t k = 0; k < b.nodes_per_element; ++k)
          size_field(nodes[k], k + 1 == b.nodes_per_element);
      }
    }
    if (binary_) nl();
    out_.text("$EndElements\n");
  }

  // 2.2: counts as text lines; binary records are 4-byte ints and 8-byte doubles.
  void nodes22() {
    const auto& pts = l_.model.points;
    out_.text("$Nodes\n");
    num(index_cast<std::int64_t>(pts.size()));
    nl();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (binary_) {
        out_.raw<std::int32_t>(static_cast<std::int32_t>(i + 1));
        out_.raw<double>(pts[i].x());
        out_.raw<double>(pts[i].y());
        out_.raw<double>(pts[i].z());
      } else {
        num(static_cast<std::int64_t>(i + 1));
        sp();
        real_field(pts[i].x());
        real_field(pts[i].y());
        real_field(pts[i].z(), true);
      }
    }
    if (binary_) nl();
    out_.text("$EndNodes\n");
  }

  void elements22() {
    out_.text("$Elements\n");
    num(static_cast<std::int64_t>(l_.elements));
    nl();
    for (const ElementBlock& b : l_.blocks) {
      if (binary_ && b.count() > 0) {
        out_.raw<std::int32_t>(b.type);
        out_.raw<std::int32_t>(index_cast<std::int32_t>(b.count()));
        out_.raw<std::int32_t>(2);  // tags: physical, elementary entity
      }
      std::array<std::size_t, 8> nodes{};
      for (std::size_t e = 0; e < b.count(); ++e) {
        b.tags(l_.model, e, nodes);
        if (binary_) {
          out_.raw<std::int32_t>(static_cast<std::int32_t>(b.first_tag + e));
          out_.raw<std::int32_t>(b.physical);
          out_.raw<std::int32_t>(b.entity);
          for (std::size_t k = 0; k < b.nodes_per_element; ++k)
            out_.raw<std::int32_t>(static_cast<std::int32_t>(nodes[k]));
        } else {
          num(static_cast<std::int64_t>(b.first_tag + e));
          sp();
          num(b.type);
          out_.text(" 2 ");
          num(b.physical);
          sp();
          num(b.entity);
          for (std::size_t k = 0; k < b.nodes_per_element; ++k) {
            sp();
            num(static_cast<std::int64_t>(nodes[k]));
          }
          nl();
        }
      }
    }
    if (binary_) nl();
    out_.text("$EndElements\n");
  }
};

}  // namespace

void write_gmsh(const Model& model, const std::filesystem::path& path, GmshFormat format,
                GmshVersion version) {
  const std::string target = path.string();
  validate(model, target);
  const MshLayout layout(model, target);
  if (version == GmshVersion::k22 &&
      (model.points.size() >= INT32_MAX || layout.elements >= INT32_MAX))
    throw InvalidInput(
        target + ": more nodes or elements than .msh 2.2's 32-bit tags can number; write .msh 4.1");
  write_path_atomically(path, ".msh", [&](const std::filesystem::path& temp) {
    FileSink out(temp, target);
    MshWriter(layout, out, format == GmshFormat::kBinary, version).write();
    out.close();
  });
}

}  // namespace geode::io
