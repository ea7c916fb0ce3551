#include "conform/conform.hpp"

#include "primal/disjoint_sets.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <unordered_map>

#include "primal/boundary.hpp"
#include "primal/dice.hpp"
#include "primal/errors.hpp"
#include "primal/interface.hpp"
#include "primal/key_map.hpp"
#include "primal/multilinear.hpp"
#include "primal/quality.hpp"
#include "primal/topology.hpp"
#include "templates/geode.hpp"

namespace geode::conform {
namespace {

using primal::FaceKey;
using primal::Index;
using primal::kInvalidIndex;
using primal::Point;
namespace topo = primal::topology;
using templates::build_geode3d;
using templates::Diagonal;
using templates::GeodeOptions;
using templates::smooth_template;
using templates::Template;

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The origin key of a diced node: its origin nodes sorted ascending, padded with
// kInvalidIndex (1 node: an input node, 2: an edge midpoint, 3 / 4: a face centre).
FaceKey normalized(FaceKey k) {
  std::sort(k.begin(), k.end(), [](Index a, Index b) {
    if (a == kInvalidIndex || b == kInvalidIndex) return b == kInvalidIndex && a != kInvalidIndex;
    return a < b;
  });
  return k;
}

// Buffer hex side faces 0..3 (topology order: s-min, r-max, s-max, r-min) as template box-face
// bits (templates/geode.hpp: bit 2*axis + high) under r = z, s = x, t = y
// (primal/buffer_layer.hpp).
constexpr std::array<int, 4> kSideBit{0, 5, 1, 4};
constexpr int kBottomBit = 2, kTopBit = 3;

int corner_at(int r, int s, int t) {
  for (int c = 0; c < 8; ++c)
    if (topo::kHexCornerCoords[c] == std::array<int, 3>{r, s, t}) return c;
  return -1;
}

// A template prepared for one diagonal: reference coordinates (r, s, t) in [0,1]^3 of every
// node, and for tet/hex-side nodes the buffer hex corners whose diced node it is.
struct RefTemplate {
  Template tpl;
  double min_scaled_jacobian = 0.0;
  std::vector<Point> rst;
  std::vector<std::vector<int>> key_corners;  // empty: not a tet/hex-side node
  std::array<std::vector<int>, 4> side_nodes;
  std::array<std::vector<std::array<int, 4>>, 4> side_quads;
};

RefTemplate make_reference(const Eigen::Vector3d& box, std::array<int, 2> diagonal) {
  RefTemplate ref;
  GeodeOptions o;
  o.box = box;
  o.diagonal = diagonal == std::array<int, 2>{5, 7} ? Diagonal::Main : Diagonal::Anti;
  ref.tpl = build_geode3d(o);
  ref.min_scaled_jacobian = smooth_template(ref.tpl, false).final_min_scaled_jacobian;
  const auto& pts = ref.tpl.hex.points;
  const std::size_t n = pts.size();
  // A smoothed template with two nodes at one place would glue the model together there.
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if ((pts[i] - pts[j]).norm() < 1e-6 * box.norm()) {
        std::ostringstream m;
        m << "the smoothed geode template in a " << box.x() << " x " << box.y() << " x "
          << box.z() << " box has nodes " << i << " and " << j << " at one place ("
          << pts[i].transpose() << "); choose other template proportions";
        throw TopologyError(m.str());
      }
  ref.rst.resize(n);
  ref.key_corners.resize(n);
  constexpr double kTol = 1e-6;
  auto third = [&](double v) -> int {  // 0, 1, 2 for 0, 1/2, 1; -1 otherwise
    for (int k = 0; k < 3; ++k)
      if (std::abs(v - 0.5 * k) < kTol) return k;
    return -1;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const Point& p = pts[i];
    const Point q{p.z() / box.z() + 0.5, p.x() / box.x() + 0.5, p.y() / box.y() + 0.5};
    ref.rst[i] = q;
    const unsigned f = ref.tpl.node_faces[i];
    for (int k = 0; k < 4; ++k)
      if (f & (1u << kSideBit[k])) ref.side_nodes[k].push_back(static_cast<int>(i));
    const bool bottom = f & (1u << kBottomBit), top = f & (1u << kTopBit);
    if (!bottom && !top) continue;
    const int t = top ? 1 : 0;
    const int a = third(q.x()), b = third(q.y());
    std::vector<int>& key = ref.key_corners[i];
    if (a >= 0 && b >= 0 && a != 1 && b != 1) {
      key = {corner_at(a / 2, b / 2, t)};
    } else if (a == 1 && b >= 0 && b != 1) {
      key = {corner_at(0, b / 2, t), corner_at(1, b / 2, t)};
    } else if (b == 1 && a >= 0 && a != 1) {
      key = {corner_at(a / 2, 0, t), corner_at(a / 2, 1, t)};
    } else if (a == 1 && b == 1) {
      if (bottom) key = {0, 1, 2, 3};
      else key = {diagonal[0], diagonal[1]};
    } else if (top) {
      // A triangle centroid: the triangle of the split top face containing the point.
      const bool d46 = diagonal == std::array<int, 2>{4, 6};
      if (d46) key = q.x() > q.y() ? std::vector<int>{4, 5, 6} : std::vector<int>{4, 6, 7};
      else key = q.x() + q.y() < 1 ? std::vector<int>{4, 5, 7} : std::vector<int>{5, 6, 7};
      double cr = 0, cs = 0;
      for (int c : key) cr += topo::kHexCornerCoords[c][0], cs += topo::kHexCornerCoords[c][1];
      if (std::abs(cr / 3 - q.x()) > kTol || std::abs(cs / 3 - q.y()) > kTol) key.clear();
    }
    if (key.empty() || std::find(key.begin(), key.end(), -1) != key.end()) {
      std::ostringstream m;
      m << "geode template node " << i << " at (" << p.transpose()
        << ") lies on the " << (top ? "tet" : "hex")
        << " side but at no diced position (corner, edge midpoint, face centre)";
      throw TopologyError(m.str());
    }
  }
  for (int k = 0; k < 4; ++k) {
    const unsigned bit = 1u << kSideBit[k];
    for (const auto& h : ref.tpl.hex.hexes)
      for (const auto& fc : topo::kHexFaceCorners) {
        std::array<int, 4> q{};
        bool on = true;
        for (int j = 0; j < 4; ++j) {
          q[j] = h[fc[j]];
          on = on && (ref.tpl.node_faces[q[j]] & bit);
        }
        if (on) ref.side_quads[k].push_back(q);
      }
  }
  return ref;
}



// Matches the nodes of side face ka of template A with those of side face kb of template B
// (the same face of the model), starting from the nodes both share on the tet and hex sides
// (global ids ga / gb >= 0) and propagating across the quads of the face: a quad of A with an
// edge whose two ends are matched corresponds to the one unmatched quad of B having the
// images as an edge and agreeing with every match made so far. Returns A node -> B node;
// throws TopologyError when the face meshes do not correspond.
std::unordered_map<int, int> match_side(const RefTemplate& A, int ka,
                                        const std::vector<Index>& ga, const RefTemplate& B,
                                        int kb, const std::vector<Index>& gb,
                                        const std::string& where) {
  const auto& na = A.side_nodes[ka];
  const auto& nb = B.side_nodes[kb];
  const auto& qa = A.side_quads[ka];
  const auto& qb = B.side_quads[kb];
  auto fail = [&](const std::string& why) {
    throw TopologyError("side faces of " + where + " do not correspond: " + why);
  };
  if (na.size() != nb.size() || qa.size() != qb.size()) fail("different node or quad counts");
  std::unordered_map<int, int> m, inv;
  std::unordered_map<Index, int> b_of_global;
  for (int b : nb)
    if (gb[b] >= 0) b_of_global[gb[b]] = b;
  for (int a : na)
    if (ga[a] >= 0) {
      auto it = b_of_global.find(ga[a]);
      if (it == b_of_global.end()) fail("a tet/hex-side node of one is not on the other");
      m[a] = it->second, inv[it->second] = a;
    }
  std::vector<bool> done_a(qa.size(), false), done_b(qb.size(), false);
  bool progress = true;
  while (progress) {
    progress = false;
    for (std::size_t i = 0; i < qa.size(); ++i) {
      if (done_a[i]) continue;
      const auto& q = qa[i];
      int found = -1, found_dir = 0, found_s = 0, found_e = 0, candidates = 0;
      for (int e = 0; e < 4 && candidates == 0; ++e) {
        auto x0 = m.find(q[e]), x1 = m.find(q[(e + 1) % 4]);
        if (x0 == m.end() || x1 == m.end()) continue;
        for (std::size_t j = 0; j < qb.size(); ++j) {
          if (done_b[j]) continue;
          const auto& p = qb[j];
          for (int s = 0; s < 4; ++s) {
            if (p[s] != x0->second) continue;
            for (int dir : {1, 3}) {
              if (p[(s + dir) % 4] != x1->second) continue;
              // q[e + k] -> p[s + k * dir]; check every known match agrees.
              bool ok = true;
              for (int k = 0; k < 4 && ok; ++k) {
                const int a = q[(e + k) % 4], b = p[(s + k * dir) % 4];
                auto ia = m.find(a);
                auto ib = inv.find(b);
                if (ia != m.end() && ia->second != b) ok = false;
                if (ib != inv.end() && ib->second != a) ok = false;
              }
              if (ok) {
                ++candidates;
                found = static_cast<int>(j), found_dir = dir, found_s = s, found_e = e;
              }
            }
          }
        }
      }
      if (candidates != 1) continue;  // none yet or ambiguous: wait for more matches
      const auto& p = qb[found];
      for (int k = 0; k < 4; ++k) {
        const int a = q[(found_e + k) % 4], b = p[(found_s + k * found_dir) % 4];
        m[a] = b, inv[b] = a;
      }
      done_a[i] = done_b[found] = true;
      progress = true;
    }
  }
  if (m.size() != na.size() || inv.size() != nb.size()) fail("propagation left nodes unmatched");
  return m;
}

std::vector<Index> boundary_nodes(const primal::HexMesh& mesh) {
  std::vector<char> on(mesh.points.size(), 0);
  for (const auto& q : primal::boundary_quads(mesh))
    for (Index v : q.nodes) on[v] = 1;
  std::vector<Index> out;
  for (std::size_t i = 0; i < on.size(); ++i)
    if (on[i]) out.push_back(static_cast<Index>(i));
  return out;
}

double min_scaled_jacobian(const primal::HexMesh& mesh, std::vector<Index>* bad = nullptr) {
  double mn = 1.0;
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    const double sj = primal::hex_scaled_jacobian(primal::hex_corners(mesh, static_cast<Index>(h)));
    mn = std::min(mn, sj);
    if (bad && sj <= 0) bad->push_back(static_cast<Index>(h));
  }
  return mn;
}

// The output's block ids and names: the input's, plus the geode block when it has a name.
struct OutputBlocks {
  int geode_id = 0;  // 0: geode hexes join the tet-side block they were carved from
  std::map<int, std::string> names;
};

OutputBlocks output_blocks(const primal::Model& input, const std::string& geode_block) {
  OutputBlocks o;
  o.names = input.block_names;
  if (geode_block.empty()) return o;
  int top = 0;
  for (std::size_t h = 0; h < input.hexes.size(); ++h)
    top = std::max(top, primal::block_of(input, {primal::ElementKind::Hex, static_cast<Index>(h)}));
  for (std::size_t t = 0; t < input.tets.size(); ++t)
    top = std::max(top, primal::block_of(input, {primal::ElementKind::Tet, static_cast<Index>(t)}));
  o.geode_id = top + 1;
  o.names[o.geode_id] = geode_block;
  return o;
}

}  // namespace


ConformSmooth parse_conform_smooth(const std::string& word) {
  if (word == "local") return ConformSmooth::kLocal;
  if (word == "global") return ConformSmooth::kGlobal;
  if (word == "none") return ConformSmooth::kNone;
  throw InvalidInput("smoothing mode '" + word + "': expected local, global or none");
}

ConformResult conform(const primal::Model& input, const ConformOptions& options) {
  const auto t_start = Clock::now();
  auto say = [&](const std::string& line) {
    if (options.progress) options.progress(line);
  };
  ConformResult res;
  res.input_hexes = static_cast<Index>(input.hexes.size());
  res.input_tets = static_cast<Index>(input.tets.size());
  if (input.hexes.empty() || input.tets.empty())
    throw InvalidInput("conform: the model needs a hex part and a tet part (it has " +
                       std::to_string(input.hexes.size()) + " hexes, " +
                       std::to_string(input.tets.size()) + " tets)");

  // 1. Interface and buffer layer.
  auto t0 = Clock::now();
  const primal::Interface iface = primal::find_interface(input, options.interface_tolerance);
  if (iface.quads.empty())
    throw InvalidInput("conform: the hex part and the tet part share no interface quad");
  res.interface_quads = static_cast<Index>(iface.quads.size());
  say("interface: " + std::to_string(iface.quads.size()) + " quads (" +
      std::to_string(since(t0)) + " s)");
  t0 = Clock::now();
  const BufferLayer layer = insert_buffer_layer(input, iface, options.buffer);
  res.buffer = layer.report;
  say("buffer layer: " + std::to_string(layer.hexes.size()) + " hexes, min scaled Jacobian " +
      std::to_string(layer.report.min_scaled_jacobian) + " (" + std::to_string(since(t0)) + " s)");

  // 2. Dice both parts over the layer model's point array and merge their nodes by origin.
  t0 = Clock::now();
  const primal::Model& lm = layer.model;
  const Index V = static_cast<Index>(lm.points.size());
  primal::DicedHexMesh dh = primal::dice(primal::hex_part(lm));
  primal::DicedHexMesh dt = primal::dice(primal::tet_part(lm));
  std::vector<Point> points(lm.points.begin(), lm.points.end());
  std::vector<FaceKey> origin_key(V);  // per global node; {-1..} for cell / template nodes
  for (Index v = 0; v < V; ++v) origin_key[v] = {v, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  const FaceKey kNoKey{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  // A diced node can be met twice (by the other part's dicing, or as a template's tet/hex-side
  // node) only if every origin node of it is a buffer hex corner or used by both parts; dice()
  // numbers each origin once per part, so only those go through the map (a few per interface
  // quad instead of every diced edge and face).
  std::vector<char> shared(static_cast<std::size_t>(V), 0);
  {
    std::vector<char> in_hex(static_cast<std::size_t>(V), 0);
    for (const auto& h : lm.hexes)
      for (Index v : h) in_hex[v] = 1;
    for (const auto& t : lm.tets)
      for (Index v : t) shared[v] |= in_hex[v];
    for (const auto& b : layer.hexes)
      for (Index v : b.corners) shared[v] = 1;
  }
  auto may_meet = [&](const FaceKey& key) {
    for (Index v : key)
      if (v != kInvalidIndex && !shared[v]) return false;
    return true;
  };
  primal::KeyMap<4> by_key(16 * layer.hexes.size());
  auto add_node = [&](const Point& p, const FaceKey& key) {
    points.push_back(p);
    origin_key.push_back(key);
    return static_cast<Index>(points.size() - 1);
  };
  auto global_of = [&](const primal::DicedHexMesh& d) {
    std::vector<Index> g(d.mesh.points.size());
    for (std::size_t i = 0; i < g.size(); ++i) {
      if (static_cast<Index>(i) < V) {
        g[i] = static_cast<Index>(i);
        continue;
      }
      const primal::NodeOrigin& o = d.origin[i];
      if (o.kind == primal::NodeOriginKind::kCell) {
        g[i] = add_node(d.mesh.points[i], kNoKey);
        continue;
      }
      const FaceKey key = normalized(o.nodes);
      if (!may_meet(key)) {
        g[i] = add_node(d.mesh.points[i], key);
        continue;
      }
      auto [id, inserted] = by_key.try_emplace(key, kInvalidIndex);
      if (inserted) *id = add_node(d.mesh.points[i], key);
      g[i] = *id;
    }
    return g;
  };
  std::vector<Index> gh = global_of(dh), gt = global_of(dt);
  // Positions now live in `points`; origins are needed again only for side sets.
  for (primal::DicedHexMesh* d : {&dh, &dt}) {
    d->mesh.points = {};
    if (lm.side_sets.empty()) d->origin = {};
  }
  res.diced_hexes = static_cast<Index>(dh.mesh.hexes.size());
  res.diced_tet_hexes = static_cast<Index>(dt.mesh.hexes.size());
  say("dicing: " + std::to_string(res.diced_hexes) + " hexes from hexes, " +
      std::to_string(res.diced_tet_hexes) + " from tets (" + std::to_string(since(t0)) + " s)");

  // 3. Reference templates, one per diagonal, built and smoothed once.
  t0 = Clock::now();
  std::array<std::optional<RefTemplate>, 2> refs;  // [0]: {4,6}, [1]: {5,7}
  auto ref_index = [](const BufferHex& b) { return b.diagonal[0] == 5 ? 1 : 0; };
  res.template_min_scaled_jacobian = 1.0;
  for (const auto& b : layer.hexes) {
    const int r = ref_index(b);
    if (!refs[r]) {
      refs[r] = make_reference(options.template_box, b.diagonal);
      res.template_min_scaled_jacobian =
          std::min(res.template_min_scaled_jacobian, refs[r]->min_scaled_jacobian);
    }
  }
  say("templates: built and smoothed, min scaled Jacobian " +
      std::to_string(res.template_min_scaled_jacobian) + " (" + std::to_string(since(t0)) +
      " s)");

  // 4. Map a template into every buffer hex. Tet/hex-side nodes become their diced node;
  // interior nodes new nodes; side-face nodes union-find items merged across shared faces.
  t0 = Clock::now();
  const std::size_t nb = layer.hexes.size();
  std::vector<std::vector<Index>> inst_global(nb), inst_side(nb);
  primal::DisjointSets uf;
  std::vector<Point> side_pos;
  for (std::size_t b = 0; b < nb; ++b) {
    const BufferHex& bh = layer.hexes[b];
    const RefTemplate& ref = *refs[ref_index(bh)];
    std::array<Point, 8> P;
    for (int c = 0; c < 8; ++c) P[c] = lm.points[bh.corners[c]];
    const std::size_t n = ref.rst.size();
    inst_global[b].assign(n, kInvalidIndex);
    inst_side[b].assign(n, kInvalidIndex);
    for (std::size_t i = 0; i < n; ++i) {
      const Point x = primal::multilinear_point(P, ref.rst[i], 3);
      if (!ref.key_corners[i].empty()) {
        FaceKey key = kNoKey;
        for (std::size_t k = 0; k < ref.key_corners[i].size(); ++k)
          key[k] = bh.corners[ref.key_corners[i][k]];
        key = normalized(key);
        Index g = kInvalidIndex;
        if (key[1] == kInvalidIndex) {
          g = key[0];
        } else if (const Index* id = by_key.find(key)) {
          g = *id;
        }
        if (g == kInvalidIndex)
          throw TopologyError("buffer hex " + std::to_string(b) +
                              ": a template node has no diced node to merge with");
        inst_global[b][i] = g;
      } else if (ref.tpl.node_faces[i] != 0) {
        inst_side[b][i] = uf.add();
        side_pos.push_back(x);
      } else {
        inst_global[b][i] = add_node(x, kNoKey);
      }
    }
  }
  by_key = primal::KeyMap<4>();  // every template node is placed
  // Side faces shared by two buffer hexes.
  std::unordered_map<FaceKey, std::vector<std::pair<int, int>>, primal::IndexArrayHash> side_uses;
  for (std::size_t b = 0; b < nb; ++b)
    for (int k = 0; k < 4; ++k) {
      std::array<Index, 4> f{};
      for (int j = 0; j < 4; ++j) f[j] = layer.hexes[b].corners[topo::kHexFaceCorners[k][j]];
      side_uses[primal::face_key(f)].push_back({static_cast<int>(b), k});
    }
  Index shared_faces = 0;
  for (const auto& [key, uses] : side_uses) {
    if (uses.size() > 2) {
      std::ostringstream m;
      m << "side face (" << key[0] << " " << key[1] << " " << key[2] << " " << key[3]
        << ") of the buffer layer is shared by " << uses.size()
        << " buffer hexes (the interface is non-manifold along edge " << key[0] << "-"
        << key[1] << ")";
      throw TopologyError(m.str());
    }
    if (uses.size() < 2) continue;
    ++shared_faces;
    const auto [ba, ka] = uses[0];
    const auto [bb, kb] = uses[1];
    const RefTemplate& A = *refs[ref_index(layer.hexes[ba])];
    const RefTemplate& B = *refs[ref_index(layer.hexes[bb])];
    const auto m = match_side(A, ka, inst_global[ba], B, kb, inst_global[bb],
                              "buffer hexes " + std::to_string(ba) + " and " +
                                  std::to_string(bb));
    for (const auto& [a, b] : m) {
      const Index sa = inst_side[ba][a], sb = inst_side[bb][b];
      if ((sa == kInvalidIndex) != (sb == kInvalidIndex))
        throw TopologyError("buffer hexes " + std::to_string(ba) + " and " + std::to_string(bb) +
                            ": a side node matches a tet/hex-side node");
      if (sa != kInvalidIndex) uf.unite(sa, sb);
    }
  }
  // One node per union-find class at the mean of its members.
  {
    const Index ns = static_cast<Index>(uf.size());
    std::vector<Point> sum(ns, Point::Zero());
    std::vector<int> cnt(ns, 0);
    for (Index s = 0; s < ns; ++s) sum[uf.find(s)] += side_pos[s], ++cnt[uf.find(s)];
    std::vector<Index> gid(ns, kInvalidIndex);
    for (Index s = 0; s < ns; ++s)
      if (uf.find(s) == s) gid[s] = add_node(sum[s] / cnt[s], kNoKey);
    for (std::size_t b = 0; b < nb; ++b)
      for (std::size_t i = 0; i < inst_side[b].size(); ++i)
        if (inst_side[b][i] != kInvalidIndex) inst_global[b][i] = gid[uf.find(inst_side[b][i])];
  }
  res.geode_hexes = static_cast<Index>(26 * nb);
  say("geode templates: " + std::to_string(nb) + " buffer hexes, " +
      std::to_string(shared_faces) + " shared side faces merged (" + std::to_string(since(t0)) +
      " s)");

  // 5. Assemble the hexes (diced hexes, geode hexes, diced tets) and drop unused nodes. Each
  // output hex is in the input block of the element it comes from (dice() copies it); a geode
  // hex in the block of the tet its buffer hex was carved from, or in a block of its own.
  const OutputBlocks blocks = output_blocks(input, options.geode_block);
  std::vector<std::array<Index, 8>> hexes;
  std::vector<int> block;
  hexes.reserve(dh.mesh.hexes.size() + 26 * nb + dt.mesh.hexes.size());
  block.reserve(hexes.capacity());
  for (std::size_t k = 0; k < dh.mesh.hexes.size(); ++k) {
    std::array<Index, 8> o{};
    for (int c = 0; c < 8; ++c) o[c] = gh[dh.mesh.hexes[k][c]];
    hexes.push_back(o), block.push_back(dh.mesh.block[k]);
  }
  for (std::size_t b = 0; b < nb; ++b) {
    const RefTemplate& ref = *refs[ref_index(layer.hexes[b])];
    const Index carved_from = iface.quads[layer.hexes[b].quad].tets[0];
    const int id = blocks.geode_id ? blocks.geode_id
                                   : primal::block_of(input, {primal::ElementKind::Tet, carved_from});
    for (const auto& h : ref.tpl.hex.hexes) {
      std::array<Index, 8> o{};
      for (int c = 0; c < 8; ++c) o[c] = inst_global[b][h[c]];
      hexes.push_back(o), block.push_back(id);
    }
  }
  for (std::size_t k = 0; k < dt.mesh.hexes.size(); ++k) {
    std::array<Index, 8> o{};
    for (int c = 0; c < 8; ++c) o[c] = gt[dt.mesh.hexes[k][c]];
    hexes.push_back(o), block.push_back(dt.mesh.block[k]);
  }
  std::vector<Index> renum(points.size(), kInvalidIndex);
  primal::HexMesh mesh;
  mesh.points.reserve(points.size());
  for (auto& h : hexes)
    for (Index& v : h) {
      if (renum[v] == kInvalidIndex) {
        renum[v] = static_cast<Index>(mesh.points.size());
        mesh.points.push_back(points[v]);
      }
      v = renum[v];
    }
  mesh.hexes = std::move(hexes);
  mesh.block = std::move(block);

  // Node sets and side sets carried over (they depend only on the numbering, not on node
  // positions); after them the dicing and merging data are released before smoothing and
  // verification, which need room of their own.
  std::vector<primal::NodeSet> node_sets;
  std::vector<primal::SideSet> side_sets;
  for (const primal::NodeSet& ns : lm.node_sets) {
    std::vector<char> in(V, 0);
    for (Index v : ns.nodes) in[v] = 1;
    primal::NodeSet o{ns.id, ns.name, {}};
    for (std::size_t g = 0; g < origin_key.size(); ++g) {
      if (renum[g] == kInvalidIndex || origin_key[g][0] == kInvalidIndex) continue;
      bool all = true;
      for (Index v : origin_key[g])
        if (v != kInvalidIndex) all = all && in[v];
      if (all) o.nodes.push_back(renum[g]);
    }
    std::sort(o.nodes.begin(), o.nodes.end());
    node_sets.push_back(std::move(o));
  }
  if (!lm.side_sets.empty()) {
    // Children of each input element, with their output hex number.
    std::vector<std::vector<Index>> hex_children(lm.hexes.size()), tet_children(lm.tets.size());
    for (std::size_t c = 0; c < dh.parent.size(); ++c)
      hex_children[dh.parent[c]].push_back(static_cast<Index>(c));
    for (std::size_t c = 0; c < dt.parent.size(); ++c)
      tet_children[dt.parent[c]].push_back(static_cast<Index>(c));
    const Index tet_offset = res.diced_hexes + res.geode_hexes;
    for (const primal::SideSet& ss : lm.side_sets) {
      primal::SideSet o{ss.id, ss.name, {}};
      for (const primal::Side& side : ss.sides) {
        const bool is_hex = side.element.kind == primal::ElementKind::Hex;
        std::vector<Index> face;
        if (is_hex) {
          for (int c : topo::kHexFaceCorners[side.face])
            face.push_back(lm.hexes[side.element.index][c]);
        } else {
          for (int c : topo::kTetFaceCorners[side.face])
            face.push_back(lm.tets[side.element.index][c]);
        }
        const primal::DicedHexMesh& d = is_hex ? dh : dt;
        const auto& children = is_hex ? hex_children[side.element.index]
                                      : tet_children[side.element.index];
        auto on_face = [&](Index node) {
          const primal::NodeOrigin& og = d.origin[node];
          if (node < V) return std::find(face.begin(), face.end(), node) != face.end();
          if (og.kind == primal::NodeOriginKind::kCell) return false;
          for (Index v : og.nodes)
            if (v != kInvalidIndex && std::find(face.begin(), face.end(), v) == face.end())
              return false;
          return true;
        };
        for (Index c : children)
          for (int f = 0; f < 6; ++f) {
            bool all = true;
            for (int k : topo::kHexFaceCorners[f]) all = all && on_face(d.mesh.hexes[c][k]);
            if (all)
              o.sides.push_back({{primal::ElementKind::Hex, is_hex ? c : tet_offset + c}, f});
          }
      }
      side_sets.push_back(std::move(o));
    }
  }
  dh = {}, dt = {};
  for (auto* v : {&gh, &gt, &renum}) *v = {};
  points = {}, origin_key = {}, inst_global = {}, inst_side = {};
  // Without smoothing the positions do not change: the inverted hexes found here are the
  // verification's too.
  std::vector<Index> bad;
  res.min_scaled_jacobian_before_smoothing =
      min_scaled_jacobian(mesh, options.smooth == ConformSmooth::kNone ? &bad : nullptr);

  // 6. Smoothing, model boundary nodes fixed. Local: one small problem per buffer hex (its 26
  // geode hexes' nodes move, with every hex touching them; the rest is fixed), swept in order,
  // so the cost grows linearly with the interface (the optimiser is built for template-sized
  // meshes). Global: one problem over the whole mesh (slow beyond a few thousand hexes).
  if (options.smooth != ConformSmooth::kNone) {
    t0 = Clock::now();
    const std::size_t np = mesh.points.size();
    std::vector<char> on_boundary(np, 0);
    for (Index v : boundary_nodes(mesh)) on_boundary[v] = 1;
    // Node -> hexes (CSR).
    std::vector<Index> start(np + 1, 0), node_hexes;
    for (const auto& h : mesh.hexes)
      for (Index v : h) ++start[v + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    node_hexes.resize(start.back());
    {
      std::vector<Index> fill(start.begin(), start.end() - 1);
      for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
        for (Index v : mesh.hexes[h]) node_hexes[fill[v]++] = static_cast<Index>(h);
    }
    res.smoothing.initial_min_scaled_jacobian = res.min_scaled_jacobian_before_smoothing;
    std::vector<Index> local(np, kInvalidIndex);
    std::vector<char> in_sub(mesh.hexes.size(), 0);
    Index smoothed_hexes = 0;
    // Moves `movable` (global nodes, not on the boundary) with all hexes around them.
    auto smooth_patch = [&](const std::vector<Index>& movable) {
      primal::HexMesh sub;
      std::vector<Index> global, sub_hexes;
      std::vector<primal::NodeConstraint> cons;
      for (Index v : movable)
        for (Index k = start[v]; k < start[v + 1]; ++k)
          if (!in_sub[node_hexes[k]]) in_sub[node_hexes[k]] = 1, sub_hexes.push_back(node_hexes[k]);
      for (Index h : sub_hexes) {
        std::array<Index, 8> o{};
        for (int c = 0; c < 8; ++c) {
          const Index v = mesh.hexes[h][c];
          if (local[v] == kInvalidIndex) {
            local[v] = static_cast<Index>(sub.points.size());
            sub.points.push_back(mesh.points[v]);
            global.push_back(v);
            cons.push_back(primal::NodeConstraint::fixed());
          }
          o[c] = local[v];
        }
        sub.hexes.push_back(o);
      }
      for (Index v : movable) cons[local[v]] = primal::NodeConstraint::free();
      if (!sub.hexes.empty()) {
        const primal::SmoothResult r = primal::smooth_hex_mesh(
            sub, cons,
            options.smooth == ConformSmooth::kLocal ? options.local_smooth_options
                                                    : options.smooth_options);
        // Keep the patch only if it did not lower its minimum (the optimiser returns its best
        // iterate, but an untangling failure could still leave it worse).
        if (r.final_min_scaled_jacobian >= r.initial_min_scaled_jacobian)
          for (std::size_t i = 0; i < global.size(); ++i) mesh.points[global[i]] = sub.points[i];
        res.smoothing.iterations += r.iterations;
        res.smoothing.untangle_iterations += r.untangle_iterations;
        res.smoothing.shape_iterations += r.shape_iterations;
      }
      smoothed_hexes += static_cast<Index>(sub.hexes.size());
      for (Index v : global) local[v] = kInvalidIndex;
      for (Index h : sub_hexes) in_sub[h] = 0;
    };
    if (options.smooth == ConformSmooth::kGlobal) {
      std::vector<Index> movable;
      for (std::size_t v = 0; v < np; ++v)
        if (!on_boundary[v]) movable.push_back(static_cast<Index>(v));
      smooth_patch(movable);
    } else {
      const Index first_geode = res.diced_hexes;
      for (std::size_t b = 0; b < nb; ++b) {
        std::vector<Index> movable;
        for (Index h = first_geode + static_cast<Index>(26 * b);
             h < first_geode + static_cast<Index>(26 * (b + 1)); ++h)
          for (Index v : mesh.hexes[h])
            if (!on_boundary[v]) movable.push_back(v);
        std::sort(movable.begin(), movable.end());
        movable.erase(std::unique(movable.begin(), movable.end()), movable.end());
        smooth_patch(movable);
        if (options.smoothing_progress)
          options.smoothing_progress(b + 1, nb);
        else if ((b + 1) % 100 == 0)
          say("smoothing: " + std::to_string(b + 1) + " / " + std::to_string(nb) +
              " buffer hexes (" + std::to_string(since(t0)) + " s)");
      }
    }
    res.smoothing.final_min_scaled_jacobian = min_scaled_jacobian(mesh, &bad);  // also for step 7
    res.smoothing.untangled = res.smoothing.final_min_scaled_jacobian > 0;
    res.smoothing.seconds = since(t0);
    say("smoothing (" + std::string(options.smooth == ConformSmooth::kLocal ? "local" : "global") +
        "): " + std::to_string(smoothed_hexes) + " hex-patches, min scaled Jacobian " +
        std::to_string(res.smoothing.initial_min_scaled_jacobian) + " -> " +
        std::to_string(res.smoothing.final_min_scaled_jacobian) + " (" +
        std::to_string(since(t0)) + " s)");
  }

  // 7. Verify and report.
  t0 = Clock::now();
  res.validity = primal::check_validity(mesh);
  if (!res.validity.ok()) res.warnings.push_back("invalid mesh: " + res.validity.summary());
  if (!bad.empty()) {
    std::ostringstream m;
    m << bad.size() << " hexes with scaled Jacobian <= 0:";
    for (std::size_t i = 0; i < std::min<std::size_t>(bad.size(), 20); ++i) m << " " << bad[i];
    if (bad.size() > 20) m << " ...";
    res.warnings.push_back(m.str());
  }
  {
    std::map<int, std::vector<Index>> members;  // output block -> its hexes, ascending id
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h) members[mesh.block[h]].push_back(static_cast<Index>(h));
    for (const auto& [id, sel] : members) {
      const auto name = blocks.names.find(id);
      res.quality.push_back({id, name != blocks.names.end() ? name->second : "block " + std::to_string(id),
                             primal::hex_quality_report(mesh, sel)});
    }
  }
  say("verification: " + std::string(res.validity.ok() ? "valid" : "INVALID") + " (" +
      std::to_string(since(t0)) + " s)");

  // 8. The output model.
  primal::Model& out = res.model;
  for (const BlockQuality& q : res.quality)
    if (auto it = blocks.names.find(q.block); it != blocks.names.end()) out.block_names.insert(*it);
  out.hex_block = std::move(mesh.block);
  out.hexes = std::move(mesh.hexes);
  out.points = std::move(mesh.points);
  out.node_sets = std::move(node_sets);
  out.side_sets = std::move(side_sets);
  res.seconds = since(t_start);
  return res;
}

}  // namespace geode::conform
