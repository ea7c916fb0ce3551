#include <geode/primal/dice_model.hpp>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cassert>
#include <cstdint>
#include <set>
#include <sstream>
#include <tuple>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <geode/primal/dice.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

namespace topo = topology;

FaceKey normalized_origin(FaceKey k) {
  // A sorting network of the four as unsigned numbers, branch-free (it is called for every edge
  // and face node that dicing makes and its check reads): kInvalidIndex (-1) is then the
  // largest, after every node number.
  std::array<std::uint32_t, 4> u;
  for (std::size_t i = 0; i < 4; ++i) u[i] = static_cast<std::uint32_t>(k[i]);
  const auto order = [&u](std::size_t a, std::size_t b) {
    const std::uint32_t lo = std::min(u[a], u[b]), hi = std::max(u[a], u[b]);
    u[a] = lo, u[b] = hi;
  };
  order(0, 1), order(2, 3), order(0, 2), order(1, 3), order(1, 2);
  for (std::size_t i = 0; i < 4; ++i) k[i] = static_cast<Index>(u[i]);
  return k;
}

Index DicedModel::add_node(const Point& p, const FaceKey& origin_key) {
  points.push_back(p);
  origin.push_back(origin_key);
  return index_cast(points.size() - 1);
}

Index DicedModel::find(const FaceKey& key) const {
  const FaceKey k = normalized_origin(key);
  if (k[0] == kInvalidIndex) return kInvalidIndex;
  if (k[1] == kInvalidIndex) return k[0];
  const Index* id = shared.find(k);
  return id ? *id : kInvalidIndex;
}

namespace {

// Wedges, one hex per corner c with axes along its edges (r, s, t) = kWedgeCornerNeighbors[c]:
// corners c, mid(c r), centre(c r s), mid(c s), mid(c t), centre(c r t), cell centre,
// centre(c s t) in VTK hex order, a right-handed hex for a positive wedge. Every edge and
// face node goes through the shared map (each of its nodes is shareable), at the centroid of
// its origin nodes, as dice() places those of hexes and tets.
void dice_wedges(const Model& model, DicedModel& out) {
  const auto& topo = cell_topology(ElementKind::kWedge);
  out.wedge_children.reserve(6 * model.wedges.size());
  out.wedge_parent.reserve(6 * model.wedges.size());
  for (std::size_t w = 0; w < model.wedges.size(); ++w) {
    const auto& c = model.wedges[w];
    auto node_of = [&](std::initializer_list<int> local) {
      FaceKey key = kNoOrigin;
      Point p = Point::Zero();
      std::size_t k = 0;
      for (int l : local) {
        key[k++] = c[index_cast<std::size_t>(l)];
        p += model.points[index_cast<std::size_t>(c[index_cast<std::size_t>(l)])];
      }
      key = normalized_origin(key);
      auto [id, inserted] = out.shared.try_emplace(key, kInvalidIndex);
      if (inserted) *id = out.add_node(p / static_cast<double>(local.size()), key);
      return *id;
    };
    // The face through corners a, b, d of this wedge (each pair of edges at a corner spans one).
    auto face_of = [&](int a, int b, int d) {
      for (int f = 0; f < topo.faces; ++f) {
        const auto& face = topo.face[index_cast<std::size_t>(f)];
        auto has = [&](int x) {
          return std::find(face.corners.begin(), face.corners.begin() + face.size, x) !=
                 face.corners.begin() + face.size;
        };
        if (has(a) && has(b) && has(d)) {
          if (face.size == 3) return node_of({face.corners[0], face.corners[1], face.corners[2]});
          return node_of({face.corners[0], face.corners[1], face.corners[2], face.corners[3]});
        }
      }
      return kInvalidIndex;
    };
    Point centre = Point::Zero();
    for (Index v : c) centre += model.points[index_cast<std::size_t>(v)] / 6.0;
    const Index mid = out.add_node(centre);
    for (int k = 0; k < 6; ++k) {
      const auto& n = topology::kWedgeCornerNeighbors[index_cast<std::size_t>(k)];
      out.wedge_children.push_back({c[index_cast<std::size_t>(k)], node_of({k, n[0]}),
                                    face_of(k, n[0], n[1]), node_of({k, n[1]}), node_of({k, n[2]}),
                                    face_of(k, n[0], n[2]), mid, face_of(k, n[1], n[2])});
      out.wedge_parent.push_back(index_cast(w));
    }
  }
}

// The wedge rule of dice_wedges as a dicing table: child k's corners as masks over the wedge's
// corners (k, its edges to n0, n1, n2, the faces spanned by two of them, the centre).
std::array<std::array<unsigned, 8>, 6> wedge_dicing_table() {
  const auto& topo = cell_topology(ElementKind::kWedge);
  auto face_of = [&](int a, int b, int d) {
    for (int f = 0; f < topo.faces; ++f) {
      const auto& face = topo.face[index_cast<std::size_t>(f)];
      unsigned m = 0;
      for (int i = 0; i < face.size; ++i) m |= 1u << face.corners[index_cast<std::size_t>(i)];
      if ((m >> a & 1) && (m >> b & 1) && (m >> d & 1)) return m;
    }
    return 0u;
  };
  std::array<std::array<unsigned, 8>, 6> t{};
  for (int k = 0; k < 6; ++k) {
    const auto& n = topology::kWedgeCornerNeighbors[index_cast<std::size_t>(k)];
    const unsigned c = 1u << k;
    t[index_cast<std::size_t>(k)] = {c,
                                     c | 1u << n[0],
                                     face_of(k, n[0], n[1]),
                                     c | 1u << n[1],
                                     c | 1u << n[2],
                                     face_of(k, n[0], n[2]),
                                     (1u << 6) - 1,
                                     face_of(k, n[1], n[2])};
  }
  return t;
}

// Entry by entry: std::array's operator== is a call of memcmp (1.4 % of a conform run here).
bool same_key(const FaceKey& a, const FaceKey& b) {
  return a[0] == b[0] && a[1] == b[1] && a[2] == b[2] && a[3] == b[3];
}

// One part's children against its table, parents in parallel (TBB), each writing its own
// children's flags; `centre` receives each parent's centre node (kInvalidIndex when its
// children do not agree on one).
template <std::size_t NP, std::size_t NChildren>
std::vector<Index> wrong_children(const std::vector<std::array<Index, NP>>& parents,
                                  const std::array<std::array<unsigned, 8>, NChildren>& table,
                                  const std::vector<std::array<Index, 8>>& children,
                                  const std::vector<Index>& parent_of,
                                  const std::vector<FaceKey>& origin, Index num_input_nodes,
                                  std::vector<Index>& centre) {
  constexpr unsigned kAll = (1u << NP) - 1;
  // Per table entry, read once: a parent corner (its index), the centre (-1), or an edge or
  // face (-2: its corners in `of`, and `support`, its number among the parent's edges and faces:
  // several children name each one, whose node is read off `origin` once per parent). The
  // table is read once (std::popcount is a library call on the baseline x86-64).
  struct Entry {
    int corner = -2;
    std::array<std::size_t, 4> of{};
    std::size_t size = 0, support = 0;
  };
  std::array<std::array<Entry, 8>, NChildren> entries{};
  std::vector<unsigned> supports;
  for (std::size_t ch = 0; ch < NChildren; ++ch)
    for (std::size_t k = 0; k < 8; ++k) {
      const unsigned s = table[ch][k];
      Entry& x = entries[ch][k];
      if (std::popcount(s) == 1) {
        x.corner = std::countr_zero(s);
      } else if (s == kAll) {
        x.corner = -1;
      } else {
        for (std::size_t q = 0; q < NP; ++q)
          if (s >> q & 1) x.of[x.size++] = q;
        x.support = static_cast<std::size_t>(std::find(supports.begin(), supports.end(), s) -
                                             supports.begin());
        if (x.support == supports.size()) supports.push_back(s);
      }
    }
  constexpr std::size_t kMaxSupports = 32;  // a hex has 18 edges and faces, a wedge 14
  assert(supports.size() <= kMaxSupports);
  const std::size_t n = std::min(children.size(), NChildren * parents.size());
  std::vector<char> bad(children.size(), 0);
  for (std::size_t i = n; i < children.size(); ++i) bad[i] = 1;  // children of no parent
  centre.assign(parents.size(), kInvalidIndex);
  const auto nodes = index_cast(origin.size());
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, parents.size(), 2048),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t e = range.begin(); e != range.end(); ++e) {
          const auto& elem = parents[e];
          // Per edge or face of this parent: the node last found for it, and whether its
          // origin is that edge or face.
          std::array<Index, kMaxSupports> seen;
          std::array<bool, kMaxSupports> seen_good{};
          seen.fill(kInvalidIndex);
          Index mid = kInvalidIndex;
          bool centre_agrees = true;
          if (NChildren * e + NChildren > children.size()) {  // a parent without all its children
            for (std::size_t i = NChildren * e; i < children.size(); ++i) bad[i] = 1;
            continue;
          }
          for (std::size_t ch = 0; ch < NChildren; ++ch) {
            const std::size_t i = NChildren * e + ch;
            bool good = i < parent_of.size() && parent_of[i] == index_cast(e);
            for (std::size_t k = 0; k < 8 && good; ++k) {
              const Index v = children[i][k];
              const Entry& x = entries[ch][k];
              if (v < 0 || v >= nodes) {
                good = false;
              } else if (x.corner >= 0) {
                good = v == elem[index_cast<std::size_t>(x.corner)];
              } else if (x.corner == -1) {
                good = v >= num_input_nodes &&
                       same_key(origin[index_cast<std::size_t>(v)], kNoOrigin) &&
                       (mid == kInvalidIndex || v == mid);
                mid = v;
              } else if (seen[x.support] == v) {
                good = seen_good[x.support];
              } else {
                FaceKey key = kNoOrigin;
                for (std::size_t m = 0; m < x.size; ++m) key[m] = elem[x.of[m]];
                good = v >= num_input_nodes &&
                       same_key(origin[index_cast<std::size_t>(v)], normalized_origin(key));
                seen[x.support] = v, seen_good[x.support] = good;
              }
            }
            if (!good) bad[i] = 1, centre_agrees = false;
          }
          centre[e] = centre_agrees ? mid : kInvalidIndex;
        }
      });
  std::vector<Index> out;
  for (std::size_t i = 0; i < bad.size(); ++i)
    if (bad[i]) out.push_back(index_cast(i));
  return out;
}

template <typename T>
void list_first(std::ostringstream& os, const char* what, const std::vector<T>& items) {
  if (items.empty()) return;
  os << "  " << what << ": " << items.size() << " (";
  for (std::size_t i = 0; i < std::min<std::size_t>(items.size(), 8); ++i)
    os << (i ? ", " : "") << items[i];
  os << (items.size() > 8 ? ", ...)\n" : ")\n");
}

}  // namespace

bool DicingCheck::ok() const {
  return wrong_hex_children.empty() && wrong_tet_children.empty() && wrong_wedge_children.empty() &&
         duplicated_nodes.empty() && missing_children == 0;
}

std::string DicingCheck::summary() const {
  std::ostringstream os;
  os << "dicing: " << (ok() ? "as its tables make it" : "NOT as its tables make it") << "\n";
  list_first(os, "hex children differing from the hex table", wrong_hex_children);
  list_first(os, "tet children differing from the tet table", wrong_tet_children);
  list_first(os, "wedge children differing from the wedge rule", wrong_wedge_children);
  if (missing_children > 0) os << "  children missing: " << missing_children << "\n";
  list_first(os, "nodes made from the origin of another node (cracks)", duplicated_nodes);
  return os.str();
}

DicingCheck check_dicing(const Model& model, const DicedModel& diced) {
  DicingCheck r;
  const auto V = index_cast(model.points.size());
  const auto& origin = diced.origin;
  std::array<std::vector<Index>, 3> centres;
  r.wrong_hex_children = wrong_children(model.hexes, hex_dicing_table(), diced.hex_children,
                                        diced.hex_parent, origin, V, centres[0]);
  r.wrong_tet_children = wrong_children(model.tets, tet_dicing_table(), diced.tet_children,
                                        diced.tet_parent, origin, V, centres[1]);
  static const auto wedge_table = wedge_dicing_table();
  r.wrong_wedge_children = wrong_children(model.wedges, wedge_table, diced.wedge_children,
                                          diced.wedge_parent, origin, V, centres[2]);
  auto missing = [](std::size_t parents, std::size_t per, std::size_t children) {
    return index_cast(per * parents > children ? per * parents - children : 0);
  };
  r.missing_children = missing(model.hexes.size(), 8, diced.hex_children.size()) +
                       missing(model.tets.size(), 4, diced.tet_children.size()) +
                       missing(model.wedges.size(), 6, diced.wedge_children.size());
  // Each parent's centre is a node of its own: a second parent on it is a duplicate use.
  std::vector<char> taken(origin.size(), 0);
  std::vector<char> duplicated(origin.size(), 0);
  for (const auto& part : centres)
    for (Index c : part)
      if (c != kInvalidIndex) {
        if (taken[index_cast<std::size_t>(c)]) duplicated[index_cast<std::size_t>(c)] = 1;
        taken[index_cast<std::size_t>(c)] = 1;
      }
  release(taken);
  // Origins made twice: the diced nodes bucketed by their smallest origin node (a counting sort,
  // no hashing), each bucket's few keys sorted and compared, buckets in parallel.
  std::vector<Index> start(index_cast<std::size_t>(V) + 1, 0);
  auto bucket = [&](std::size_t i) -> Index {
    const FaceKey& k = origin[i];
    if (k[0] == kInvalidIndex || k[0] < 0 || k[0] >= V) return kInvalidIndex;
    if (index_cast(i) < V && k[1] == kInvalidIndex) return kInvalidIndex;  // itself
    return k[0];
  };
  // Counted and placed in parallel (a bucket's order then varies; its sort below fixes it).
  auto each_in_bucket = [&](auto&& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, origin.size(), 8192),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i != range.end(); ++i)
                          if (const Index b = bucket(i); b != kInvalidIndex)
                            f(i, index_cast<std::size_t>(b));
                      });
  };
  each_in_bucket([&](std::size_t, std::size_t b) {
    std::atomic_ref<Index>(start[b + 1]).fetch_add(1, std::memory_order_relaxed);
  });
  for (std::size_t v = 0; v < index_cast<std::size_t>(V); ++v) start[v + 1] += start[v];
  std::vector<Index> members(index_cast<std::size_t>(start.back()));
  {
    std::vector<Index> fill(start.begin(), start.end() - 1);
    each_in_bucket([&](std::size_t i, std::size_t b) {
      const Index at = std::atomic_ref<Index>(fill[b]).fetch_add(1, std::memory_order_relaxed);
      members[index_cast<std::size_t>(at)] = index_cast(i);
    });
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, index_cast<std::size_t>(V), 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t v = range.begin(); v != range.end(); ++v) {
                        const auto first = members.begin() + start[v];
                        const auto last = members.begin() + start[v + 1];
                        std::sort(first, last, [&](Index a, Index b) {
                          return std::tie(origin[index_cast<std::size_t>(a)], a) <
                                 std::tie(origin[index_cast<std::size_t>(b)], b);
                        });
                        for (auto it = first; it != last; ++it) {
                          const FaceKey& k = origin[index_cast<std::size_t>(*it)];
                          // A single-node origin names an input node, made already as itself.
                          const bool twice =
                              k[1] == kInvalidIndex ||
                              (it != first && origin[index_cast<std::size_t>(*(it - 1))] == k) ||
                              (it + 1 != last && origin[index_cast<std::size_t>(*(it + 1))] == k);
                          if (twice) duplicated[index_cast<std::size_t>(*it)] = 1;
                        }
                      }
                    });
  for (std::size_t i = 0; i < duplicated.size(); ++i)
    if (duplicated[i]) r.duplicated_nodes.push_back(index_cast(i));
  return r;
}

double diced_wedge_min_scaled_jacobian(std::span<const Point> points,
                                       std::span<const std::array<Index, 6>> wedges) {
  double lowest = 1.0;
  for (const auto& c : wedges) {
    auto at = [&](std::initializer_list<int> local) {
      Point p = Point::Zero();
      for (int l : local) p += points[index_cast<std::size_t>(c[index_cast<std::size_t>(l)])];
      return Point(p / static_cast<double>(local.size()));
    };
    Point centre = Point::Zero();
    for (Index v : c) centre += points[index_cast<std::size_t>(v)] / 6.0;
    // The face centroid through corners k, a, b (wedge_face_corners picks the face).
    for (int k = 0; k < 6; ++k) {
      const auto& n = topology::kWedgeCornerNeighbors[index_cast<std::size_t>(k)];
      auto face = [&](int a, int b) {
        for (const auto& f : cell_topology(ElementKind::kWedge).face) {
          auto has = [&](int x) {
            return std::find(f.corners.begin(), f.corners.begin() + f.size, x) !=
                   f.corners.begin() + f.size;
          };
          if (f.size && has(k) && has(a) && has(b)) {
            Point p = Point::Zero();
            for (int i = 0; i < f.size; ++i)
              p += points[index_cast<std::size_t>(
                  c[index_cast<std::size_t>(f.corners[index_cast<std::size_t>(i)])])];
            return Point(p / static_cast<double>(f.size));
          }
        }
        return centre;
      };
      const HexCorners h{points[index_cast<std::size_t>(c[index_cast<std::size_t>(k)])],
                         at({k, n[0]}),
                         face(n[0], n[1]),
                         at({k, n[1]}),
                         at({k, n[2]}),
                         face(n[0], n[2]),
                         centre,
                         face(n[1], n[2])};
      lowest = std::min(lowest, hex_scaled_jacobian(h));
    }
  }
  return lowest;
}

DicedModel dice_model(const Model& model, std::span<const char> shareable, std::size_t tet_room,
                      std::size_t point_room) {
  if (!model.pyramids.empty())
    throw InvalidInput("dice_model: " + describe_element(model, {ElementKind::kPyramid, 0}) +
                       ": pyramids are not diced; split them into tets first (split_pyramids)");
  const Index V = index_cast(model.points.size());
  DicedModel out;
  // Room for the diced nodes, so that no doubling copies them at the run's peak: a connected
  // hex part makes about 7 new nodes per hex, a tet part about 4.2 per tet (V + E + F + T with
  // E ~ V + T, F ~ 2T), a wedge at most 16. Capacity never touched is never resident.
  const std::size_t room = model.points.size() + 7 * model.hexes.size() + 5 * model.tets.size() +
                           16 * model.wedges.size();
  out.points.reserve(room + point_room);
  out.origin.reserve(room);
  out.points = model.points;
  out.origin.resize(V);
  for (Index v = 0; v < V; ++v) out.origin[v] = {v, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  std::vector<char> share(index_cast<std::size_t>(V), 0);
  {
    std::vector<char> in_hex(index_cast<std::size_t>(V), 0);
    for (const auto& h : model.hexes)
      for (Index v : h) in_hex[v] = 1;
    std::size_t interface_nodes = 0;
    for (const auto& t : model.tets)
      for (Index v : t) share[v] |= in_hex[v];
    for (const auto& w : model.wedges)
      for (Index v : w) share[v] = 1;
    for (std::size_t v = 0; v < share.size(); ++v) {
      if (v < shareable.size()) share[v] |= shareable[v];
      interface_nodes += share[v];
    }
    out.shared = KeyMap<4>(8 * interface_nodes);
  }
  auto may_meet = [&](const FaceKey& key) {
    for (Index v : key)
      if (v != kInvalidIndex && !share[v]) return false;
    return true;
  };
  // Each part diced without building its diced mesh (dice_cells): its edge, face and centre
  // nodes are made here in dice()'s order and at dice()'s places, merged by origin where both
  // parts (or the caller) may meet them; the children are renumbered in place. What a part
  // needs beyond the output is its edge and face keys and one number per diced node.
  auto take = [&](const auto& elements, DicedCells d, std::vector<std::array<Index, 8>>& children,
                  std::vector<Index>& parent) {
    std::vector<Index> g(index_cast<std::size_t>(V) + d.edges.size() + d.faces.size() +
                         elements.size());
    for (Index v = 0; v < V; ++v) g[index_cast<std::size_t>(v)] = v;
    std::size_t next = index_cast<std::size_t>(V);
    // The new nodes numbered (and their origins listed) in dice()'s order first, on one core;
    // then placed, in parallel: the centroid of their origin nodes, a cell centre its corners'.
    const std::size_t first = out.origin.size();
    for (const auto* keys : {&d.edges, &d.faces}) {
      // dice_cells' keys are normalized already (dice.hpp: ascending, padded): not sorted again.
      for (const FaceKey& key : *keys) {
        const auto made = [&] {
          out.origin.push_back(key);
          return index_cast(out.origin.size() - 1);
        };
        if (!may_meet(key)) {
          g[next++] = made();
          continue;
        }
        auto [id, inserted] = out.shared.try_emplace(key, kInvalidIndex);
        if (inserted) *id = made();
        g[next++] = *id;
      }
    }
    release(d.edges, d.faces);
    const std::size_t centres = out.origin.size();
    for (std::size_t e = 0; e < elements.size(); ++e) {
      out.origin.push_back(kNoOrigin);
      g[next++] = index_cast(centres + e);
    }
    out.points.resize(out.origin.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(first, out.points.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t n = r.begin(); n != r.end(); ++n)
                          out.points[n] =
                              n < centres ? origin_centroid(model.points, out.origin[n])
                                          : corner_centroid(model.points, elements[n - centres]);
                      });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, d.children.size(), 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                          for (Index& v : d.children[i]) v = g[index_cast<std::size_t>(v)];
                      });
    children = std::move(d.children);
    parent = std::move(d.parent);
  };
  // The two parts' topologies need nothing of each other: diced side by side (TBB), merged in
  // order, so the node numbers are those of one after the other.
  DicedCells hexes, tets;
  tbb::parallel_invoke([&] { hexes = dice_cells(V, model.hexes); },
                       [&] { tets = dice_cells(V, model.tets, tet_room); });
  take(model.hexes, std::move(hexes), out.hex_children, out.hex_parent);
  take(model.tets, std::move(tets), out.tet_children, out.tet_parent);
  dice_wedges(model, out);
  return out;
}

std::vector<NodeSet> diced_node_sets(const Model& model, const DicedModel& diced,
                                     std::span<const Index> renumber) {
  std::vector<NodeSet> sets;
  for (const NodeSet& ns : model.node_sets) {
    std::vector<char> in(model.points.size(), 0);
    for (Index v : ns.nodes) in[v] = 1;
    NodeSet o{ns.id, ns.name, {}};
    // With pieces (model.hpp), a node made from nodes of one piece: its key's nodes, sorted.
    // Pieces that are single points say nothing of which nodes belong together: a set given
    // as points only (how a node set is written) follows the rule without pieces.
    const bool by_pieces =
        std::any_of(ns.pieces.begin(), ns.pieces.end(), [](const auto& p) { return p.size() > 1; });
    std::set<FaceKey> within;
    for (const auto& piece : ns.pieces) {
      const std::size_t n = std::min<std::size_t>(piece.size(), 4);
      for (std::size_t mask = 1; mask < (std::size_t{1} << n); ++mask) {
        FaceKey sub{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
        std::size_t used = 0;
        for (std::size_t k = 0; k < n; ++k)
          if (mask >> k & 1) sub[used++] = piece[k];
        within.insert(normalized_origin(sub));
      }
    }
    for (std::size_t g = 0; g < diced.origin.size() && g < renumber.size(); ++g) {
      if (renumber[g] == kInvalidIndex || diced.origin[g][0] == kInvalidIndex) continue;
      bool all = true;
      for (Index v : diced.origin[g])
        if (v != kInvalidIndex) all = all && in[v];
      if (all && by_pieces) all = within.count(normalized_origin(diced.origin[g])) > 0;
      if (all) o.nodes.push_back(renumber[g]);
    }
    std::sort(o.nodes.begin(), o.nodes.end());
    sets.push_back(std::move(o));
  }
  return sets;
}

std::vector<SideSet> diced_side_sets(const Model& model, const DicedModel& diced, Index hex_offset,
                                     Index tet_offset, Index wedge_offset) {
  std::vector<SideSet> sets;
  if (model.side_sets.empty()) return sets;
  if (wedge_offset == kInvalidIndex)
    wedge_offset = tet_offset + index_cast(diced.tet_children.size());
  // Per kind (pyramids have none: they are split before dicing): children, their hexes, offset.
  struct Part {
    std::vector<std::vector<Index>> children;
    const std::vector<std::array<Index, 8>>* hexes = nullptr;
    Index offset = 0;
  };
  std::array<Part, 4> parts;
  auto part = [&](ElementKind kind, const std::vector<Index>& parent,
                  const std::vector<std::array<Index, 8>>& hexes, Index offset) {
    Part& p = parts[static_cast<std::size_t>(kind)];
    p.children.resize(element_count(model, kind));
    for (std::size_t c = 0; c < parent.size(); ++c) p.children[parent[c]].push_back(index_cast(c));
    p.hexes = &hexes;
    p.offset = offset;
  };
  part(ElementKind::kHex, diced.hex_parent, diced.hex_children, hex_offset);
  part(ElementKind::kTet, diced.tet_parent, diced.tet_children, tet_offset);
  part(ElementKind::kWedge, diced.wedge_parent, diced.wedge_children, wedge_offset);
  for (const SideSet& ss : model.side_sets) {
    SideSet o{ss.id, ss.name, {}};
    for (const Side& side : ss.sides) {
      const std::vector<Index> face = element_face(model, side);
      const Part& p = parts[static_cast<std::size_t>(side.element.kind)];
      if (!p.hexes) continue;
      // A diced node lies on the face when every node it was made from does.
      auto on_face = [&](Index node) {
        const FaceKey& og = diced.origin[node];
        if (og[0] == kInvalidIndex) return false;
        for (Index v : og)
          if (v != kInvalidIndex && std::find(face.begin(), face.end(), v) == face.end())
            return false;
        return true;
      };
      for (Index c : p.children[index_cast<std::size_t>(side.element.index)])
        for (int f = 0; f < 6; ++f) {
          bool all = true;
          for (int k : topo::kHexFaceCorners[f]) all = all && on_face((*p.hexes)[c][k]);
          if (all) o.sides.push_back({{ElementKind::kHex, p.offset + c}, f});
        }
    }
    sets.push_back(std::move(o));
  }
  return sets;
}

}  // namespace geode::primal
