#include <geode/primal/interface.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <sstream>
#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

#include <geode/primal/boundary.hpp>
#include <geode/primal/detail/edge_thirds.hpp>
#include <geode/primal/detail/lowest_node_sort.hpp>
#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

namespace {

struct TetFaceUse {
  Index tet = kInvalidIndex;
  int face = -1;
  std::array<Index, 3> nodes{};  // outward of the tet
};

struct TriangleUses {
  std::array<TetFaceUse, 2> use;
  int count = 0;
};

// The tet part's triangles with a node of the hex part (`near`), with the tets using them,
// numbered in order of first use (tet by tet, face by face): the only ones the interface search
// reads (an interface triangle has hex-part nodes, and so does any boundary triangle the
// node-wise conformity test compares with a hex-part quad). The rest of the tet part is left to
// check_input (conform.hpp): pairing its 740,000 face uses was half the search on the n = 36
// bench. The face uses are sorted by their lowest node (detail/lowest_node_sort.hpp): a hash map
// of the half million triangles of a 126k-tet part cost 0.12 s in random probes.
class TetTriangles {
 public:
  TetTriangles(const Model& model, const std::vector<char>& near);

  // The triangle with this key (face_key of three nodes), or nullptr.
  const TriangleUses* find(const FaceKey& key) const {
    const auto first =
        rec_.begin() + static_cast<std::ptrdiff_t>(start_[index_cast<std::size_t>(key[0])]);
    const auto last =
        rec_.begin() + static_cast<std::ptrdiff_t>(start_[index_cast<std::size_t>(key[0]) + 1]);
    const auto it = std::lower_bound(first, last, Record{key[0], key[1], key[2], -1});
    if (it == last || it->b != key[1] || it->c != key[2]) return nullptr;
    return &tris[index_cast<std::size_t>(tri_of_rec_[index_cast<std::size_t>(it - rec_.begin())])];
  }

  std::vector<TriangleUses> tris;
  std::vector<Index> tet_face_tri;  // tris index of face f of tet t at 4 t + f (or invalid)

 private:
  // A face use: its nodes ascending, and 4 t + f.
  struct Record {
    Index a, b, c, use;
    bool operator<(const Record& o) const {
      return std::tie(a, b, c, use) < std::tie(o.a, o.b, o.c, o.use);
    }
  };
  std::vector<std::size_t> start_;  // per node, its first record; the record count at the end
  std::vector<Record> rec_;         // the face uses, by their nodes, then by use
  std::vector<Index> tri_of_rec_;   // at a triangle's first record, its tris index
};

TetTriangles::TetTriangles(const Model& model, const std::vector<char>& near)
    : tet_face_tri(4 * model.tets.size(), kInvalidIndex) {
  auto face_use = [&](Index use) {
    const auto t = index_cast<std::size_t>(use / 4);
    const auto f = index_cast<std::size_t>(use % 4);
    TetFaceUse u{index_cast(t), static_cast<int>(f), {}};
    for (std::size_t i = 0; i < 3; ++i)
      u.nodes[i] = model.tets[t][index_cast<std::size_t>(topology::kTetFaceCorners[f][i])];
    return u;
  };
  auto is_near = [&](Index v) { return near[index_cast<std::size_t>(v)] != 0; };
  // visit(t, f, key) for every face with a near node.
  auto each_face = [&](auto&& visit) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, model.tets.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t t = r.begin(); t != r.end(); ++t) {
                          const auto& tet = model.tets[t];
                          if (std::none_of(tet.begin(), tet.end(), is_near)) continue;
                          for (Index f = 0; f < 4; ++f) {
                            const TetFaceUse u = face_use(index_cast(4 * t) + f);
                            if (std::any_of(u.nodes.begin(), u.nodes.end(), is_near))
                              visit(index_cast(4 * t) + f, face_key(u.nodes));
                          }
                        }
                      });
  };
  auto each_use = [&](auto&& visit) {
    each_face([&](Index use, const FaceKey& k) { visit(Record{k[0], k[1], k[2], use}); });
  };
  auto each_lowest = [&](auto&& visit) {
    each_face([&](Index, const FaceKey& k) { visit(k[0]); });
  };
  rec_ = detail::sort_by_lowest_node<Record>(
      model.points.size(), each_lowest, each_use, [](const Record& r) { return r.a; }, start_);
  // Each triangle's uses are a run of rec_, its first use first; runs within a node's records,
  // nodes in parallel (each run writes its own slots).
  auto same = [&](std::size_t i, std::size_t j) {
    return rec_[i].a == rec_[j].a && rec_[i].b == rec_[j].b && rec_[i].c == rec_[j].c;
  };
  auto for_each_run = [&](auto&& f) { detail::for_each_run(start_, same, f); };
  // Numbered in order of first use: the first uses flagged, then counted in use order.
  {
    std::vector<char> first(tet_face_tri.size(), 0);
    for_each_run(
        [&](std::size_t b, std::size_t) { first[index_cast<std::size_t>(rec_[b].use)] = 1; });
    Index count = 0;
    for (std::size_t u = 0; u < first.size(); ++u)
      if (first[u]) tet_face_tri[u] = count++;
    tris.resize(index_cast<std::size_t>(count));
  }
  tri_of_rec_.assign(rec_.size(), kInvalidIndex);
  // A triangle of three tets or more: reported at the third use that comes first in tet order.
  std::atomic<Index> third = std::numeric_limits<Index>::max();
  for_each_run([&](std::size_t b, std::size_t e) {
    const Index id = tet_face_tri[index_cast<std::size_t>(rec_[b].use)];
    tri_of_rec_[b] = id;
    TriangleUses& at = tris[index_cast<std::size_t>(id)];
    for (std::size_t k = b; k < e; ++k) {
      tet_face_tri[index_cast<std::size_t>(rec_[k].use)] = id;
      if (k - b < 2) at.use[k - b] = face_use(rec_[k].use);
    }
    at.count = static_cast<int>(std::min<std::size_t>(e - b, 2));
    if (e - b > 2) {
      const Index u = rec_[b + 2].use;
      Index seen = third.load();
      while (u < seen && !third.compare_exchange_weak(seen, u)) {}
    }
  });
  if (const Index u = third.load(); u != std::numeric_limits<Index>::max()) {
    const TriangleUses& at =
        tris[index_cast<std::size_t>(tet_face_tri[index_cast<std::size_t>(u)])];
    throw TopologyError("find_interface: triangle (nodes " + node_list(model, face_use(u).nodes) +
                        ") is a face of more than two tets (" +
                        describe_element(model, {ElementKind::kTet, at.use[0].tet}) + ", " +
                        describe_element(model, {ElementKind::kTet, at.use[1].tet}) + ", " +
                        describe_element(model, {ElementKind::kTet, u / 4}) + ")");
  }
}

// A boundary quad of the hex part: a hex's, or a wedge's quad face used by no other cell of
// the hex part.
struct PartQuad {
  ElementRef cell;
  int face = -1;
  std::array<Index, 4> nodes{};  // outward of the cell
};

// Messages speak in the file's ids (model.hpp: describe_element, node_list).
std::string quad_name(const Model& model, ElementRef cell, const std::array<Index, 4>& corners) {
  return describe_element(model, cell) + " face (nodes " + node_list(model, corners) + ")";
}

std::string tet_face_name(const Model& model, const TetFaceUse& use) {
  return describe_element(model, {ElementKind::kTet, use.tet}) + " face (nodes " +
         node_list(model, use.nodes) + ")";
}

// Whether p lies on triangle (a, b, c), edges and corners included, within tol * longest edge.
bool on_triangle(const Point& p, const Point& a, const Point& b, const Point& c, double tol) {
  const Point n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  const double h = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  if (n2 <= 0.0 || h <= 0.0) return false;
  if (std::abs((p - a).dot(n)) / std::sqrt(n2) > tol * h) return false;
  const double la = (b - p).cross(c - p).dot(n) / n2;
  const double lb = (c - p).cross(a - p).dot(n) / n2;
  const double lc = (a - p).cross(b - p).dot(n) / n2;
  return la >= -tol && lb >= -tol && lc >= -tol;
}

// Two elements of one kind on the same nodes (a duplicated element, or one block read twice)
// hide the faces between them, so that the interface would seem to vanish there; name them
// instead. First pair in element order. Given `near` (per node), only the elements with a node
// there: the tets at the hex part (TetTriangles).
template <std::size_t N>
void refuse_duplicates(const Model& model, const std::vector<std::array<Index, N>>& cells,
                       ElementKind kind, const std::vector<char>* near = nullptr) {
  auto skipped = [&](std::size_t e) {
    return near && std::none_of(cells[e].begin(), cells[e].end(),
                                [&](Index v) { return (*near)[index_cast<std::size_t>(v)] != 0; });
  };
  // Each element's sorted nodes, sorted by the smallest (detail::sort_by_lowest_node, in
  // parallel): duplicates sit together. The first pair in element order is the one whose later
  // element comes first.
  using Use = detail::KeyedUse<N>;
  std::vector<std::size_t> start;
  auto each_lowest = [&](auto&& visit) {  // counted by their lowest node alone
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t e = r.begin(); e != r.end(); ++e)
                          if (!skipped(e))
                            visit(*std::min_element(cells[e].begin(), cells[e].end()));
                      });
  };
  const std::vector<Use> uses = detail::sort_by_lowest_node<Use>(
      model.points.size(), each_lowest,
      [&](auto&& visit) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 4096),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                            for (std::size_t e = r.begin(); e != r.end(); ++e) {
                              if (skipped(e)) continue;
                              Use u{cells[e], e};
                              std::sort(u.key.begin(), u.key.end());
                              visit(u);
                            }
                          });
      },
      [](const Use& u) { return u.key[0]; }, start);
  std::size_t later = cells.size(), earlier = 0;
  for (std::size_t k = 1; k < uses.size(); ++k)
    if (uses[k].key == uses[k - 1].key && uses[k].at < later &&
        (k < 2 || uses[k - 2].key != uses[k].key))
      later = uses[k].at, earlier = uses[k - 1].at;
  if (later < cells.size())
    throw TopologyError("find_interface: " + describe_element(model, {kind, index_cast(later)}) +
                        " has the same nodes as " +
                        describe_element(model, {kind, index_cast(earlier)}) + " (nodes " +
                        node_list(model, cells[later]) +
                        "): a duplicated element (an element or a block given twice?)");
}

// How far (relative to its mean edge) a four-triangle split's centre node may lie off the plane
// through the quad's centre point: enough for a centre put on a curved surface the quad
// approximates (the sag of a quad spanning 30 degrees is 0.03 of its edge), far less than a
// gap or an overlap between the parts.
constexpr double kFanCentreOffset = 0.05;

}  // namespace

namespace {

// The two triangles a quad splits into along diagonal 0 (corners 0-2) or 1 (corners 1-3).
std::array<std::array<Index, 3>, 2> split(const std::array<Index, 4>& c, int diagonal) {
  if (diagonal == 0) return {{{c[0], c[1], c[2]}, {c[0], c[2], c[3]}}};
  return {{{c[0], c[1], c[3]}, {c[1], c[2], c[3]}}};
}

// The hex part's boundary quads with a node of the tet part (`near`): the hexes' (in
// boundary_quads' order: hex by hex, faces in table order), then the wedges' quad faces that no
// hex or other wedge shares, in wedge order. A quad without such a node neither matches tet
// triangles nor shares a node with one (the node-wise conformity test), and every cell using a
// quad with such a node has it: the uses of those quads are counted among those cells only
// (all 280,000 hex faces of the n = 36 bench were sorted, and the hex part copied, before).
std::vector<PartQuad> part_quads(const Model& model, const std::vector<char>& near) {
  auto is_near = [&](Index v) { return near[index_cast<std::size_t>(v)] != 0; };
  struct Use {
    FaceKey key;
    PartQuad quad;
  };
  std::vector<Use> hex_uses, wedge_uses;
  auto gather = [&](ElementKind kind, const auto& cells, std::vector<Use>& uses) {
    const auto& faces = cell_topology(kind).face;
    for (std::size_t e = 0; e < cells.size(); ++e) {
      if (std::none_of(cells[e].begin(), cells[e].end(), is_near)) continue;
      for (std::size_t f = 0; f < faces.size(); ++f) {
        if (faces[f].size != 4) continue;
        std::array<Index, 4> c{};
        for (std::size_t i = 0; i < 4; ++i)
          c[i] = cells[e][index_cast<std::size_t>(faces[f].corners[i])];
        if (std::any_of(c.begin(), c.end(), is_near))
          uses.push_back({face_key(c), {{kind, index_cast(e)}, static_cast<int>(f), c}});
      }
    }
  };
  gather(ElementKind::kHex, model.hexes, hex_uses);
  gather(ElementKind::kWedge, model.wedges, wedge_uses);
  // How many uses each key has among `uses` (and `also`, counted on top when given).
  auto counts = [](const std::vector<Use>& uses, const std::vector<Use>* also) {
    std::vector<FaceKey> keys;
    for (const Use& u : uses) keys.push_back(u.key);
    if (also)
      for (const Use& u : *also) keys.push_back(u.key);
    std::sort(keys.begin(), keys.end());
    std::vector<int> n(uses.size());
    for (std::size_t i = 0; i < uses.size(); ++i) {
      const auto [lo, hi] = std::equal_range(keys.begin(), keys.end(), uses[i].key);
      n[i] = static_cast<int>(hi - lo);
    }
    return n;
  };
  std::vector<PartQuad> out;
  const std::vector<int> hex_count = counts(hex_uses, nullptr);
  std::vector<Use> hex_boundary;
  for (std::size_t i = 0; i < hex_uses.size(); ++i)
    if (hex_count[i] == 1) out.push_back(hex_uses[i].quad), hex_boundary.push_back(hex_uses[i]);
  if (wedge_uses.empty()) return out;
  const std::vector<int> wedge_count = counts(wedge_uses, &hex_boundary);
  for (std::size_t i = 0; i < wedge_uses.size(); ++i)
    if (wedge_count[i] == 1) out.push_back(wedge_uses[i].quad);
  return out;
}

// Which copy of each interface node the tets and wedges around it take (InterfaceSide): per
// node, its cells joined across the faces they share at the node; refuses a set of cells
// joined to both sides, naming a wedge of it (only a wedge, sharing quads with the hex part
// and triangles with the tet part, can join them), or, given `joining`, adds that wedge to it
// and goes on.
std::vector<InterfaceNodeUse> node_uses(const Model& model, const Interface& itf,
                                        std::vector<Index>* joining) {
  std::vector<InterfaceNodeUse> out;
  if (itf.nodes.empty()) return out;
  std::vector<Index> slot(model.points.size(), kInvalidIndex);
  for (std::size_t k = 0; k < itf.nodes.size(); ++k)
    slot[index_cast<std::size_t>(itf.nodes[k])] = index_cast(k);
  // Per node: its cells (every kind but pyramids, which conform splits first), and the owners
  // of its interface quads (the hex side) and triangles (the tet side).
  std::vector<std::vector<ElementRef>> cells(itf.nodes.size()), hex_side(itf.nodes.size()),
      tet_side(itf.nodes.size());
  for (ElementKind kind : {ElementKind::kHex, ElementKind::kTet, ElementKind::kWedge})
    for (std::size_t e = 0; e < element_count(model, kind); ++e) {
      const ElementRef ref{kind, index_cast(e)};
      for (Index v : element_corners(model, ref))
        if (const Index k = slot[index_cast<std::size_t>(v)]; k != kInvalidIndex)
          cells[index_cast<std::size_t>(k)].push_back(ref);
    }
  for (const InterfaceQuad& q : itf.quads) {
    for (Index v : q.corners)
      hex_side[index_cast<std::size_t>(slot[index_cast<std::size_t>(v)])].push_back(q.owner());
    const auto triangles = interface_triangles(q);
    for (std::size_t i = 0; i < triangles.size(); ++i)
      for (Index v : triangles[i])
        if (const Index k = slot[index_cast<std::size_t>(v)]; k != kInvalidIndex)
          tet_side[index_cast<std::size_t>(k)].push_back({ElementKind::kTet, q.tets[i]});
  }
  DisjointSets sets;
  std::vector<std::pair<FaceKey, Index>> faces;  // a face at the node -> its first cell
  for (std::size_t k = 0; k < itf.nodes.size(); ++k) {
    const Index v = itf.nodes[k];
    const auto& at = cells[k];
    sets.reset(at.size());
    faces.clear();
    for (std::size_t c = 0; c < at.size(); ++c) {
      const auto corners = element_corners(model, at[c]);
      for (const auto& f : cell_topology(at[c].kind).face) {
        if (f.size == 0) continue;
        std::array<Index, 4> nodes{};
        bool has = false;
        for (int i = 0; i < f.size; ++i) {
          nodes[index_cast<std::size_t>(i)] =
              corners[index_cast<std::size_t>(f.corners[index_cast<std::size_t>(i)])];
          has |= nodes[index_cast<std::size_t>(i)] == v;
        }
        if (!has) continue;
        const FaceKey key = face_key(std::span<const Index>(nodes.data(), f.size));
        const auto it =
            std::find_if(faces.begin(), faces.end(), [&](const auto& e) { return e.first == key; });
        if (it == faces.end())
          faces.emplace_back(key, index_cast(c));
        else
          sets.unite(it->second, index_cast(c));
      }
    }
    // Per set (its root): a hex-side cell and a tet-side cell in it, if any.
    std::vector<const ElementRef*> hex_in(at.size(), nullptr), tet_in(at.size(), nullptr);
    auto root_of = [&](const ElementRef& e) {
      return index_cast<std::size_t>(
          sets.find(index_cast(std::find(at.begin(), at.end(), e) - at.begin())));
    };
    for (const ElementRef& e : hex_side[k]) hex_in[root_of(e)] = &e;
    for (std::size_t c = 0; c < at.size(); ++c)
      if (at[c].kind == ElementKind::kHex) hex_in[root_of(at[c])] = &at[c];
    for (const ElementRef& e : tet_side[k]) tet_in[root_of(e)] = &e;
    for (std::size_t c = 0; c < at.size(); ++c) {
      const std::size_t r = root_of(at[c]);
      if (hex_in[r] && tet_in[r]) {
        const auto wedge = std::find_if(at.begin(), at.end(), [&](const ElementRef& e) {
          return e.kind == ElementKind::kWedge && root_of(e) == r;
        });
        if (joining && wedge != at.end()) {
          joining->push_back(wedge->index);
          continue;
        }
        throw TopologyError(
            "find_interface: " + describe_element(model, wedge != at.end() ? *wedge : at[c]) +
            " joins the two sides of the hex/tet interface at " + describe_node(model, v) +
            ": through the faces the cells share at that node it connects " +
            describe_element(model, *hex_in[r]) + " on the interface's quad side to " +
            describe_element(model, *tet_in[r]) +
            " on its triangle side, so the interface ends inside the mesh there, and no buffer "
            "layer can end at that node (one ends only where the interface meets the model "
            "boundary)");
      }
      if (at[c].kind == ElementKind::kHex) continue;
      out.push_back({at[c], v,
                     hex_in[r]   ? InterfaceSide::kHex
                     : tet_in[r] ? InterfaceSide::kTet
                                 : InterfaceSide::kLoose});
    }
  }
  return out;
}

}  // namespace

std::vector<std::array<Index, 3>> interface_triangles(const InterfaceQuad& q) {
  if (q.centre == kInvalidIndex) {
    const auto two = split(q.corners, q.diagonal);
    return {two.begin(), two.end()};
  }
  std::vector<std::array<Index, 3>> four;
  for (std::size_t i = 0; i < 4; ++i)
    four.push_back({q.corners[i], q.corners[(i + 1) % 4], q.centre});
  return four;
}

Interface find_interface(const Model& model, double tol, std::vector<Index>* joining) {
  validate(model, "find_interface");
  const auto& P = model.points;
  auto pt = [&](Index v) -> const Point& { return P[index_cast<std::size_t>(v)]; };
  // Per node: kInHex for a hex's node, kInWedge for a wedge's (either: the hex part's).
  constexpr char kInHex = 1, kInWedge = 2;
  std::vector<char> in_part(P.size(), 0);
  for (const auto& h : model.hexes)
    for (Index v : h) in_part[index_cast<std::size_t>(v)] |= kInHex;
  for (const auto& w : model.wedges)
    for (Index v : w) in_part[index_cast<std::size_t>(v)] |= kInWedge;
  auto in_hex = [&](Index v) { return (in_part[index_cast<std::size_t>(v)] & kInHex) != 0; };
  refuse_duplicates(model, model.hexes, ElementKind::kHex);
  refuse_duplicates(model, model.tets, ElementKind::kTet, &in_part);
  refuse_duplicates(model, model.wedges, ElementKind::kWedge);

  // Triangles of the tet part at the hex part with the tets using them (boundary triangles: one
  // use).
  const TetTriangles triangles_of(model, in_part);
  const std::vector<TriangleUses>& tris = triangles_of.tris;
  // The boundary triangle with this key, or nullptr.
  auto boundary_triangle = [&](const FaceKey& key) -> const TetFaceUse* {
    const TriangleUses* uses = triangles_of.find(key);
    return uses && uses->count == 1 ? &uses->use[0] : nullptr;
  };

  // Per boundary-triangle edge, the third nodes of the boundary triangles on it: the candidate
  // centres of a four-triangle split.
  detail::EdgeThirds thirds;
  for (const TriangleUses& uses : tris)
    if (uses.count == 1)
      thirds.add(uses.use[0].nodes[0], uses.use[0].nodes[1], uses.use[0].nodes[2]);
  thirds.sort();
  // The node x for which (c_i, c_i+1, x) are boundary triangles for all four sides of the quad;
  // of several (a single tet layer's outer faces can fan around the quad too) the nearest to the
  // quad's middle.
  auto four_split_centre = [&](const std::array<Index, 4>& c) -> Index {
    const auto on = thirds.on(c[0], c[1]);
    if (on.empty()) return kInvalidIndex;
    const Point middle = (pt(c[0]) + pt(c[1]) + pt(c[2]) + pt(c[3])) / 4.0;
    Index best = kInvalidIndex;
    for (const auto& [edge, x] : on) {
      bool all = true;
      for (std::size_t i = 1; i < 4 && all; ++i)
        all = boundary_triangle(face_key(std::array<Index, 3>{c[i], c[(i + 1) % 4], x})) != nullptr;
      if (all && (best == kInvalidIndex || (pt(x) - middle).norm() < (pt(best) - middle).norm()))
        best = x;
    }
    return best;
  };

  std::vector<char> in_tet(P.size(), 0);
  for (const auto& t : model.tets)
    for (Index v : t) in_tet[index_cast<std::size_t>(v)] = 1;
  const std::vector<PartQuad> quads = part_quads(model, in_tet);
  std::vector<char> matched(tris.size(), 0);  // one of the two triangles of an interface quad
  Interface out;
  std::vector<const PartQuad*> unmatched_quads;
  for (const PartQuad& bq : quads) {
    const auto& c = bq.nodes;
    const std::array<std::array<std::array<Index, 3>, 2>, 2> splits{split(c, 0), split(c, 1)};
    std::array<std::array<const TetFaceUse*, 2>, 2> found{};
    int count = 0;
    for (int d = 0; d < 2; ++d)
      for (int i = 0; i < 2; ++i) {
        if (const TetFaceUse* u = boundary_triangle(
                face_key(splits[index_cast<std::size_t>(d)][index_cast<std::size_t>(i)]))) {
          found[index_cast<std::size_t>(d)][index_cast<std::size_t>(i)] = u;
          ++count;
        }
      }
    const Index centre = count == 0 ? four_split_centre(c) : kInvalidIndex;
    if (count == 0 && centre == kInvalidIndex) {
      unmatched_quads.push_back(&bq);
      continue;
    }
    const std::string name = quad_name(model, bq.cell, c);
    if (centre != kInvalidIndex && in_hex(centre))
      throw TopologyError("find_interface: " + name + " is split into four triangles around " +
                          describe_node(model, centre) + ", a node of the hex part too");
    if (centre != kInvalidIndex) {
      // The four triangles must cover the quad as its two triangles would: the centre near the
      // quad's surface (off it is a gap between the parts, or an overlap) and every triangle
      // facing the way the quad does (else the centre lies outside the quad).
      const Point normal = (pt(c[2]) - pt(c[0])).cross(pt(c[3]) - pt(c[1])).normalized();
      const Point middle = (pt(c[0]) + pt(c[1]) + pt(c[2]) + pt(c[3])) / 4.0;
      double edge = 0;
      for (std::size_t i = 0; i < 4; ++i) edge += (pt(c[(i + 1) % 4]) - pt(c[i])).norm() / 4.0;
      const double off = (pt(centre) - middle).dot(normal);
      if (std::abs(off) > kFanCentreOffset * edge) {
        std::ostringstream m;
        m << "find_interface: " << name << " is split into four triangles around "
          << describe_node(model, centre) << ", which lies " << std::abs(off) << " "
          << (off > 0 ? "outside the hex face (a gap between the parts)"
                      : "inside the hex (the parts overlap)")
          << "; at most " << kFanCentreOffset << " x the quad's mean edge (" << edge
          << ") off its centre " << point_text(middle);
        throw TopologyError(m.str());
      }
      for (std::size_t i = 0; i < 4; ++i)
        if ((pt(c[(i + 1) % 4]) - pt(c[i])).cross(pt(centre) - pt(c[i])).dot(normal) <= 0)
          throw TopologyError("find_interface: " + name + " is split into four triangles around " +
                              describe_node(model, centre) +
                              ", which lies outside the quad (the triangle on nodes " +
                              node_list(model, std::array<Index, 3>{c[i], c[(i + 1) % 4], centre}) +
                              " folds over)");
    }
    const bool d0 = found[0][0] && found[0][1], d1 = found[1][0] && found[1][1];
    if (centre == kInvalidIndex && (count != 2 || !(d0 || d1))) {
      std::string detail;
      for (int d = 0; d < 2; ++d)
        for (int i = 0; i < 2; ++i)
          if (const TetFaceUse* u = found[index_cast<std::size_t>(d)][index_cast<std::size_t>(i)])
            detail += (detail.empty() ? "" : ", ") + tet_face_name(model, *u);
      throw TopologyError("find_interface: " + name + " is matched by " +
                          (count == 1
                               ? std::string("only one triangle of the tet part")
                               : std::to_string(count) + " triangles not forming one split") +
                          ": " + detail);
    }
    InterfaceQuad q;
    q.kind = bq.cell.kind;
    q.hex = bq.cell.index;
    q.face = bq.face;
    q.corners = c;
    q.diagonal = d0 ? 0 : 1;
    q.centre = centre;
    // The quad's normal points into the tet side; each tet's apex must lie there.
    const Point normal = (pt(c[2]) - pt(c[0])).cross(pt(c[3]) - pt(c[1]));
    const Point middle = (pt(c[0]) + pt(c[1]) + pt(c[2]) + pt(c[3])) / 4.0;
    const auto triangles = interface_triangles(q);
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      const TetFaceUse& u = centre == kInvalidIndex ? *found[index_cast<std::size_t>(q.diagonal)][i]
                                                    : *boundary_triangle(face_key(triangles[i]));
      q.tets[i] = u.tet;
      q.tet_faces[i] = u.face;
      matched[index_cast<std::size_t>(triangles_of.tet_face_tri[4 * index_cast<std::size_t>(u.tet) +
                                                                index_cast<std::size_t>(u.face)])] =
          1;
      const auto& tet = model.tets[index_cast<std::size_t>(u.tet)];
      Index apex = kInvalidIndex;
      for (Index v : tet)
        if (std::find(u.nodes.begin(), u.nodes.end(), v) == u.nodes.end()) apex = v;
      if ((pt(apex) - middle).dot(normal) <= 0.0)
        throw TopologyError(
            "find_interface: " + describe_element(model, {ElementKind::kTet, u.tet}) + " on " +
            name + " lies on the hex side of it (the parts overlap or are inverted)");
    }
    out.quads.push_back(q);
  }

  // Node-wise conformity: a node of one side must not lie on a face of the other side that
  // does not have it as a corner. Candidates are unmatched boundary faces sharing a node.
  std::unordered_map<Index, std::vector<const PartQuad*>> quads_at;
  for (const PartQuad* bq : unmatched_quads)
    for (Index v : bq->nodes) quads_at[v].push_back(bq);
  // In tet order, so that the first offence reported does not depend on hashing.
  for (std::size_t t = 0; t < model.tets.size(); ++t)
    for (std::size_t f = 0; f < 4; ++f) {
      const Index id = triangles_of.tet_face_tri[4 * t + f];
      // No hex-part node: it shares none with a quad (only those are compared below).
      if (id == kInvalidIndex) continue;
      const TriangleUses& uses = tris[index_cast<std::size_t>(id)];
      if (uses.count != 1 || matched[index_cast<std::size_t>(id)]) continue;
      const TetFaceUse& tri = uses.use[0];
      std::unordered_set<const PartQuad*> seen;
      for (Index v : tri.nodes) {
        auto it = quads_at.find(v);
        if (it == quads_at.end()) continue;
        for (const PartQuad* bq : it->second) {
          if (!seen.insert(bq).second) continue;
          const auto& c = bq->nodes;
          auto has = [](auto& arr, Index x) {
            return std::find(arr.begin(), arr.end(), x) != arr.end();
          };
          for (Index p : tri.nodes) {
            if (has(c, p)) continue;
            if (on_triangle(pt(p), pt(c[0]), pt(c[1]), pt(c[2]), tol) ||
                on_triangle(pt(p), pt(c[0]), pt(c[2]), pt(c[3]), tol) ||
                on_triangle(pt(p), pt(c[0]), pt(c[1]), pt(c[3]), tol) ||
                on_triangle(pt(p), pt(c[1]), pt(c[2]), pt(c[3]), tol))
              throw TopologyError(
                  "find_interface: " + describe_node(model, p) + " of the tet part (" +
                  describe_element(model, {ElementKind::kTet, tri.tet}) + ") lies on " +
                  quad_name(model, bq->cell, c) +
                  " but is not one of its corners: the parts do not conform node-wise");
          }
          for (Index p : c) {
            if (has(tri.nodes, p)) continue;
            if (on_triangle(pt(p), pt(tri.nodes[0]), pt(tri.nodes[1]), pt(tri.nodes[2]), tol))
              throw TopologyError(
                  "find_interface: " + describe_node(model, p) + " of the hex part (" +
                  describe_element(model, bq->cell) + ") lies on " + tet_face_name(model, tri) +
                  " but is not one of its corners: the parts do not conform node-wise");
          }
        }
      }
    }

  for (const InterfaceQuad& q : out.quads)
    out.nodes.insert(out.nodes.end(), q.corners.begin(), q.corners.end());
  std::sort(out.nodes.begin(), out.nodes.end());
  out.nodes.erase(std::unique(out.nodes.begin(), out.nodes.end()), out.nodes.end());

  // Nodes shared by both parts must be interface nodes, the buffer layer's start; without an
  // interface quad (the parts joined through wedges, say) each part is diced alone, and dicing
  // conforms along the edges and at the points they share.
  for (std::size_t v = 0; v < P.size() && !out.quads.empty(); ++v)
    if (in_hex(index_cast(v)) && in_tet[v] &&
        !std::binary_search(out.nodes.begin(), out.nodes.end(), index_cast(v)))
      throw TopologyError("find_interface: " + describe_node(model, index_cast(v)) +
                          " is used by both the hex and the tet part but lies on no interface quad "
                          "(the parts touch there along an edge or at a point: the buffer layer "
                          "starts from the interface quads' nodes)");
  out.uses = node_uses(model, out, joining);
  if (joining) {
    std::sort(joining->begin(), joining->end());
    joining->erase(std::unique(joining->begin(), joining->end()), joining->end());
  }
  return out;
}

}  // namespace geode::primal
