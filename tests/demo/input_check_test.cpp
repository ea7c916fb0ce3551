// The read-time covering check (primal/input_check.hpp) on inputs made the way users make them:
// every demo model (Gmsh's one-generate(3) hybrids with their pyramids and wedges, the potting,
// the Delaunay and swept models) passes it as saved by `--save-input`; a Gmsh model and a TetGen
// box with one tet folded over its neighbours (a node moved through a face, the tets it turned
// inside out written positively, as a mesher re-orienting them would), two parts overlapping,
// an interface opened by a gap and a part lying inside another are refused, naming the input
// elements, and `geode conform` exits 2 on them with one line and nothing written. Each of them,
// checked in 2 and 3 shares as geode_mpi's ranks share the check, gives the same findings.
#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <barrier>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gmsh.h>

#include <geode/demo/demo_models.hpp>
#include <geode/demo/gmsh_session.hpp>
#include <geode/io/formats.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/element_graph.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/submodel.hpp>
#include <geode/primal/unfold.hpp>
#include <geode/primal/validity.hpp>
#include "support/cli_run.hpp"
#include "support/demo_input.hpp"
#include "support/temp_dir.hpp"
#include "support/tetgen_files.hpp"

using namespace geode;
using primal::ElementKind;
using primal::Index;
using primal::InputFault;
using primal::Point;

namespace {

// The check shared among `shares` processes as geode_mpi shares it among ranks
// (InputCheckOptions::share, exchange), here threads meeting at a barrier for the all-gather:
// every share must find what one process finds, finding for finding.
// On a model the check passes, the face pairs (InputCheckOptions::element_pairs, geode_mpi's
// partition graph) too: the shares' together are one process's.
void require_same_when_shared(const primal::Model& m) {
  using Pairs = std::vector<std::array<Index, 2>>;
  const auto sorted = [](Pairs p) {
    std::sort(p.begin(), p.end());
    return p;
  };
  Pairs one_pairs;
  primal::InputCheckOptions with_pairs;
  with_pairs.element_pairs = &one_pairs;
  const primal::InputCheckResult one = primal::check_input(m, with_pairs);
  primal::InputCheckOptions alone;  // shares without an exchange: refused, not half a check
  alone.shares = 2;
  CHECK_THROWS_AS(primal::check_input(m, alone), std::invalid_argument);
  for (const int shares : {2, 3}) {
    CAPTURE(shares);
    std::vector<std::vector<char>> deposit(static_cast<std::size_t>(shares));
    std::barrier meet(shares);
    std::vector<primal::InputCheckResult> results(deposit.size());
    std::vector<Pairs> pairs(deposit.size());
    std::vector<std::thread> threads;
    for (int s = 0; s < shares; ++s)
      threads.emplace_back([&, s] {
        primal::InputCheckOptions o;
        o.share = s, o.shares = shares;
        o.element_pairs = &pairs[static_cast<std::size_t>(s)];
        o.exchange = [&, s](const std::vector<char>& mine) {
          deposit[static_cast<std::size_t>(s)] = mine;
          meet.arrive_and_wait();
          std::vector<char> all;
          for (const auto& d : deposit) all.insert(all.end(), d.begin(), d.end());
          meet.arrive_and_wait();  // every share has read the deposits
          return all;
        };
        results[static_cast<std::size_t>(s)] = primal::check_input(m, o);
      });
    for (auto& t : threads) t.join();
    if (one.ok()) {
      Pairs joined;
      for (const Pairs& p : pairs) joined.insert(joined.end(), p.begin(), p.end());
      CHECK(sorted(joined) == sorted(one_pairs));
    }
    for (const primal::InputCheckResult& r : results) {
      CHECK(r.boundary_faces == one.boundary_faces);
      CHECK(r.interface_quads == one.interface_quads);
      CHECK(r.boundary_components == one.boundary_components);
      REQUIRE(r.findings.size() == one.findings.size());
      for (std::size_t k = 0; k < r.findings.size(); ++k) {
        CHECK(r.findings[k].fault == one.findings[k].fault);
        CHECK(r.findings[k].elements == one.findings[k].elements);
        CHECK(r.findings[k].node == one.findings[k].node);
        CHECK(r.findings[k].edge_end == one.findings[k].edge_end);
        CHECK(r.findings[k].place == one.findings[k].place);
        CHECK(r.findings[k].measure == one.findings[k].measure);
      }
    }
  }
}

// A node with only tets around it and not on the boundary (every face at it shared).
Index interior_tet_node(const primal::Model& m) {
  std::vector<int> bad(m.points.size(), 0);
  for (ElementKind kind : primal::kElementKinds)
    if (kind != ElementKind::kTet)
      for (std::size_t e = 0; e < primal::element_count(m, kind); ++e)
        for (Index v : primal::element_corners(m, {kind, primal::index_cast(e)}))
          bad[primal::index_cast<std::size_t>(v)] = 1;
  const primal::InputCheckResult r = primal::check_input(m);
  REQUIRE(r.ok());
  // Boundary nodes: on a face used once (tets only, so a face key count).
  std::map<std::array<Index, 3>, int> faces;
  for (const auto& t : m.tets)
    for (const auto& f : primal::topology::kTetFaceCorners) {
      std::array<Index, 3> k{t[primal::index_cast<std::size_t>(f[0])],
                             t[primal::index_cast<std::size_t>(f[1])],
                             t[primal::index_cast<std::size_t>(f[2])]};
      std::sort(k.begin(), k.end());
      ++faces[k];
    }
  for (const auto& [k, uses] : faces)
    if (uses == 1)
      for (Index v : k) bad[primal::index_cast<std::size_t>(v)] = 1;
  // The middle one of the candidates: far from the parts' corners.
  std::vector<Index> candidates;
  for (const auto& t : m.tets)
    for (Index v : t)
      if (!bad[primal::index_cast<std::size_t>(v)]) candidates.push_back(v);
  REQUIRE(!candidates.empty());
  return candidates[candidates.size() / 2];
}

// Moves node v through the face opposite it in one of its tets (mirrored there) and re-orients
// every tet that turned inside out (swapping two corners, as a mesher writing positive elements
// does): all elements positive, the tet folded over its neighbours. Returns the moved tet.
Index fold_tet_at(primal::Model& m, Index v) {
  Index t = 0;
  while (std::find(m.tets[primal::index_cast<std::size_t>(t)].begin(),
                   m.tets[primal::index_cast<std::size_t>(t)].end(),
                   v) == m.tets[primal::index_cast<std::size_t>(t)].end())
    ++t;
  const auto& tet = m.tets[primal::index_cast<std::size_t>(t)];
  std::array<Point, 3> face;
  int k = 0;
  for (Index u : tet)
    if (u != v)
      face[primal::index_cast<std::size_t>(k++)] = m.points[primal::index_cast<std::size_t>(u)];
  const Point n = (face[1] - face[0]).cross(face[2] - face[0]).normalized();
  Point& p = m.points[primal::index_cast<std::size_t>(v)];
  p -= 2.0 * (p - face[0]).dot(n) * n;
  for (auto& c : m.tets) {
    auto at = [&](int i) -> const Point& {
      return m.points[primal::index_cast<std::size_t>(c[i])];
    };
    if (primal::tet_volume(at(0), at(1), at(2), at(3)) < 0.0) std::swap(c[1], c[2]);
  }
  return t;
}

// A copy of the model's hexes on nodes of their own, moved by `shift`: the hex part no longer
// shares the interface nodes with the tets.
void detach_hexes(primal::Model& m, const Point& shift) {
  std::map<Index, Index> copy;
  std::int64_t next_id =
      m.node_ids.empty() ? 0 : *std::max_element(m.node_ids.begin(), m.node_ids.end());
  for (auto& h : m.hexes)
    for (Index& v : h) {
      const auto [it, fresh] = copy.emplace(v, primal::index_cast(m.points.size()));
      if (fresh) {
        m.points.push_back(m.points[primal::index_cast<std::size_t>(v)] + shift);
        if (!m.node_ids.empty()) m.node_ids.push_back(++next_id);
      }
      v = it->second;
    }
}

// `geode conform` on the model saved as .msh: exit `code` (2: bad input, 3: a topology
// refusal), one line naming the file and holding the check's first finding on the file as read
// (its element and node ids are the file's) and `words`, no output file.
void refused_by_conform(const primal::Model& m, const std::string& name,
                        const std::vector<std::string>& words, const test::TempDir& dir,
                        int code = 2) {
  const auto in = dir.path / (name + ".msh");
  const auto out = dir.path / (name + "-out.exo");
  io::write_model(m, in);
  const primal::Model read = io::read_model(in, {}, false);
  const primal::InputCheckResult r = primal::check_input(read);
  REQUIRE(!r.ok());
  const auto run = test::geode_cli("conform " + in.string() + " -o " + out.string(), true);
  INFO(run.out);
  CHECK(run.code == code);
  CHECK(std::count(run.out.begin(), run.out.end(), '\n') == 1);
  CHECK(run.out.find(in.string() + ": " + r.findings[0].text(read)) != std::string::npos);
  for (const auto& w : words) CHECK(run.out.find(w) != std::string::npos);
  CHECK(!std::filesystem::exists(out));
}

// A TetGen mesh of the box [0,2] x [0,1] x [0,1] (quality mesh, volume bound 0.002), tets
// oriented positively (TetGen's own orientation is the other way round).
primal::Model tetgen_box(const test::TempDir& dir) {
  const auto poly = dir.path / "box.poly";
  {
    std::ofstream f(poly);
    f << "8 3 0 0\n1 0 0 0\n2 2 0 0\n3 2 1 0\n4 0 1 0\n5 0 0 1\n6 2 0 1\n7 2 1 1\n8 0 1 1\n"
         "6 0\n1\n4 1 2 3 4\n1\n4 5 6 7 8\n1\n4 1 2 6 5\n1\n4 2 3 7 6\n1\n4 3 4 8 7\n1\n"
         "4 4 1 5 8\n0\n0\n";
  }
  const std::string cmd = "tetgen -pqa0.002Q " + poly.string() + " > /dev/null 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  primal::Model m;
  m.points = test::read_tetgen_nodes(dir.path / "box.1.node");
  std::int64_t id = 0;
  for (const auto& t : test::read_tetgen_tets(dir.path / "box.1.ele", 1, m.points))
    primal::add_element(m, ElementKind::kTet, t, 2, ++id);
  for (std::size_t i = 0; i < m.points.size(); ++i)
    m.node_ids.push_back(static_cast<std::int64_t>(i + 1));
  return m;
}

// The boundary node at the corner of the model's bounding box (smallest x + y + z) and the next
// node up the box's edge through it (same x and y, smallest z above): a boundary edge.
std::pair<Index, Index> corner_edge(const primal::Model& m) {
  Index c = 0;
  for (std::size_t i = 1; i < m.points.size(); ++i)
    if (m.points[i].sum() < m.points[primal::index_cast<std::size_t>(c)].sum())
      c = primal::index_cast(i);
  const Point& pc = m.points[primal::index_cast<std::size_t>(c)];
  Index up = primal::kInvalidIndex;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const Point& p = m.points[i];
    if (std::abs(p.x() - pc.x()) > 1e-9 || std::abs(p.y() - pc.y()) > 1e-9 || p.z() <= pc.z())
      continue;
    if (up == primal::kInvalidIndex || p.z() < m.points[primal::index_cast<std::size_t>(up)].z())
      up = primal::index_cast(i);
  }
  REQUIRE(up != primal::kInvalidIndex);
  return {c, up};
}

// Appends an element of `kind` on `corners` (positively oriented), reusing the model's nodes at
// those places and adding the others with file ids above the model's, in the first block of its
// kind (or block 1): glued to the model where its corners are the model's nodes.
void glue(primal::Model& m, ElementKind kind, const std::vector<Point>& corners) {
  std::int64_t next_node =
      m.node_ids.empty() ? 0 : *std::max_element(m.node_ids.begin(), m.node_ids.end());
  std::vector<Index> c;
  for (const Point& p : corners) {
    Index v = primal::kInvalidIndex;
    for (std::size_t i = 0; i < m.points.size() && v == primal::kInvalidIndex; ++i)
      if ((m.points[i] - p).norm() < 1e-12) v = primal::index_cast(i);
    if (v == primal::kInvalidIndex) {
      m.points.push_back(p);
      if (!m.node_ids.empty()) m.node_ids.push_back(++next_node);
      v = primal::index_cast(m.points.size() - 1);
    }
    c.push_back(v);
  }
  std::int64_t next_element = 0;
  for (ElementKind k : primal::kElementKinds)
    for (std::int64_t id : primal::element_ids(m, k)) next_element = std::max(next_element, id);
  const auto& blocks = kind == ElementKind::kHex ? m.hex_block : m.tet_block;
  primal::add_element(m, kind, c, blocks.empty() ? 1 : blocks.front(), next_element + 1);
}

// A hex beside the corner edge (c, up) of the model, outside it (x and y below the corner's):
// along that edge when `along_edge`, else below the corner (z below it), touching at c only.
std::vector<Point> hex_beside(const primal::Model& m, Index c, Index up, bool along_edge) {
  const Point pc = m.points[primal::index_cast<std::size_t>(c)];
  const double l = m.points[primal::index_cast<std::size_t>(up)].z() - pc.z();
  const double x[8] = {-1, 0, 0, -1, -1, 0, 0, -1}, y[8] = {-1, -1, 0, 0, -1, -1, 0, 0},
               z[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  std::vector<Point> p;
  for (int k = 0; k < 8; ++k)
    p.push_back(pc + Point(l * x[k], l * y[k], l * (z[k] - (along_edge ? 0.0 : 1.0))));
  return p;
}

// A tet outside the model at its corner edge (c, up): on that edge when `along_edge`, else
// touching at c only; positively oriented.
std::vector<Point> tet_beside(const primal::Model& m, Index c, Index up, bool along_edge) {
  const Point pc = m.points[primal::index_cast<std::size_t>(c)];
  const Point pu = m.points[primal::index_cast<std::size_t>(up)];
  const double l = pu.z() - pc.z();
  std::vector<Point> p =
      along_edge
          ? std::vector<Point>{pc, pu, pc + l * Point(-1, -0.2, 0.3), pc + l * Point(-0.2, -1, 0.6)}
          : std::vector<Point>{pc, pc + l * Point(-1, -0.1, -0.1), pc + l * Point(-0.1, -1, -0.1),
                               pc + l * Point(-0.1, -0.1, -1)};
  if (primal::tet_volume(p[0], p[1], p[2], p[3]) < 0.0) std::swap(p[1], p[2]);
  return p;
}

// The face pairs of a model the check passes are primal::element_graph's edges, each face once,
// but where a quad meets triangles: the graph joins a quad to a triangle on three of its nodes,
// the check a quad to the two or four triangles covering it (four around a centre node share
// two nodes each with the quad: no edge of the graph).
void require_face_pairs_are_graph_edges(const primal::Model& m) {
  std::vector<std::array<Index, 2>> pairs;
  primal::InputCheckOptions o;
  o.element_pairs = &pairs;
  REQUIRE(primal::check_input(m, o).ok());
  const primal::ElementGraph g = primal::element_graph(m);
  std::set<std::array<Index, 2>> edges, seen;
  for (std::size_t e = 0; e + 1 < g.offset.size(); ++e)
    for (std::size_t k = g.offset[e]; k < g.offset[e + 1]; ++k)
      edges.insert({primal::index_cast(e), g.neighbour[k]});
  const auto offsets = primal::element_offsets(m);
  const auto is_tet = [&](Index e) {
    const auto i = primal::index_cast<std::size_t>(e);
    return i >= offsets[1] && i < offsets[2];
  };
  for (const auto& [a, b] : pairs) {
    if (!edges.count({a, b})) CHECK(is_tet(a) != is_tet(b));
    CHECK(seen.insert({std::min(a, b), std::max(a, b)}).second);  // each face once
  }
  std::size_t unpaired = 0, quad_triangle = 0;
  for (const auto& [a, b] : edges)
    if (a < b && !seen.count({a, b})) {
      ++unpaired;
      quad_triangle += is_tet(a) != is_tet(b);
    }
  CHECK(unpaired == quad_triangle);
  CHECK(!pairs.empty());
}

// A hex box beside a wedge layer between two tet boxes, as a user builds it with OCC: the lower
// box's top face swept th high in k recombined layers (wedges), the layer's top swept again
// (tets), a transfinite hex box of k cells through th fragmented against the layer's side. The
// hexes meet the wedges through quads and the tets above and below along edges only.
primal::Model gmsh_hexes_beside_wedges(int n, int k) {
  demo::GmshSession session;
  namespace occ = gmsh::model::occ;
  const double th = 0.2;
  const int bottom = occ::addBox(0, 0, 0, 2, 2, 0.8);
  occ::synchronize();
  int top = 0;
  gmsh::vectorpair faces;
  gmsh::model::getBoundary({{3, bottom}}, faces, false, false);
  for (const auto& [dim, tag] : faces) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(2, std::abs(tag), x0, y0, z0, x1, y1, z1);
    if (z0 > 0.79) top = std::abs(tag);
  }
  gmsh::vectorpair layer, upper, parts;
  occ::extrude({{2, top}}, 0, 0, th, layer, {k}, {}, true);
  occ::extrude({layer[0]}, 0, 0, 0.8, upper);
  const auto volume = [](const gmsh::vectorpair& v) {
    for (const auto& [dim, tag] : v)
      if (dim == 3) return tag;
    return 0;
  };
  const int hexes = occ::addBox(2, 0, 0.8, 0.6, 2, th);
  std::vector<gmsh::vectorpair> children;
  occ::fragment({{3, bottom}, {3, volume(layer)}, {3, volume(upper)}}, {{3, hexes}}, parts,
                children);
  occ::synchronize();
  gmsh::model::getBoundary({{3, volume(children[3])}}, faces, false, false);
  for (const auto& [dim, face] : faces) {
    gmsh::vectorpair curves;
    gmsh::model::getBoundary({{2, std::abs(face)}}, curves, false, false);
    for (const auto& [d, curve] : curves) {
      double x0, y0, z0, x1, y1, z1;
      gmsh::model::getBoundingBox(1, std::abs(curve), x0, y0, z0, x1, y1, z1);
      const double length = std::max({x1 - x0, y1 - y0, z1 - z0});
      gmsh::model::mesh::setTransfiniteCurve(
          std::abs(curve), z1 - z0 > 1e-6 ? k + 1 : static_cast<int>(std::lround(length * n)) + 1);
    }
    gmsh::model::mesh::setTransfiniteSurface(std::abs(face));
    gmsh::model::mesh::setRecombine(2, std::abs(face));
  }
  gmsh::model::mesh::setTransfiniteVolume(volume(children[3]));
  gmsh::model::mesh::setRecombine(3, volume(children[3]));
  for (int b = 0; b < 4; ++b)
    gmsh::model::addPhysicalGroup(3, {volume(children[static_cast<std::size_t>(b)])}, b + 1);
  gmsh::option::setNumber("Mesh.MeshSizeMax", 1.0 / n);
  gmsh::model::mesh::generate(3);
  return demo::model_from_gmsh("beside");
}

}  // namespace

TEST_CASE("input check: every demo model, as saved, covers its domain once") {
  test::TempDir dir;
  for (const std::string& name : demo::demo_model_names()) {
    CAPTURE(name);
    const primal::Model m = test::demo_input(name, name == "potting" ? 2 : 3, dir, ".msh", false);
    const primal::InputCheckResult r = primal::check_input(m);
    INFO((r.ok() ? std::string() : r.findings[0].text(m)));
    CHECK(r.ok());
    require_same_when_shared(m);
    require_face_pairs_are_graph_edges(m);
    CHECK(r.boundary_components == 1);
    CHECK(r.boundary_faces > 0);
    // Read again with the check: nothing refused.
    CHECK_NOTHROW(io::read_model(dir.path / (name + ".msh")));
  }
}

TEST_CASE("input check: a folded tet in a Gmsh hybrid and in a TetGen box is refused by name") {
  test::TempDir dir;
  for (const std::string source : {"hybrid", "tetgen"}) {
    CAPTURE(source);
    primal::Model m =
        source == "tetgen" ? tetgen_box(dir) : test::demo_input("hybrid", 4, dir, ".msh", false);
    const Index v = interior_tet_node(m);
    const Index t = fold_tet_at(m, v);
    REQUIRE_NOTHROW(primal::check_geometry(m, source));  // every element positive
    const primal::InputCheckResult r = primal::check_input(m);
    REQUIRE(!r.ok());
    require_same_when_shared(m);
    const primal::InputFinding& f = r.findings[0];
    CHECK((f.fault == InputFault::kSameSideFace || f.fault == InputFault::kFoldedNode));
    // The finding is at the moved node: one of its elements holds it.
    CHECK(std::any_of(f.elements.begin(), f.elements.end(), [&](const primal::ElementRef& e) {
      const auto c = primal::element_corners(m, e);
      return std::find(c.begin(), c.end(), v) != c.end();
    }));
    const std::string text = f.text(m);
    CHECK(text.find("folds") != std::string::npos);
    // The moved tet or one of its neighbours around the node.
    CHECK(text.find(" tet ") != std::string::npos);
    refused_by_conform(m, std::string("folded-") + source, {"folds"}, dir);
    (void)t;
  }
}

TEST_CASE("input check: a tet and a hex written twice in a Gmsh hybrid are named as such") {
  // A mesher or a merge that writes an element twice: its faces are each used by the element
  // and its copy, seen the same way round, which is one element twice, not a fold.
  test::TempDir dir;
  const primal::Model base = test::demo_input("hybrid", 4, dir, ".msh", false);
  for (const ElementKind kind : {ElementKind::kTet, ElementKind::kHex}) {
    CAPTURE(primal::element_kind_name(kind));
    primal::Model m = base;
    const Index copied = primal::index_cast(primal::element_count(m, kind) / 2);
    const auto corners = primal::element_corners(m, {kind, copied});
    const std::vector<Index> nodes(corners.begin(), corners.end());
    primal::add_element(m, kind, nodes, primal::block_of(m, {kind, copied}), 999999);
    const primal::InputCheckResult r = primal::check_input(m);
    REQUIRE(!r.ok());
    require_same_when_shared(m);
    const primal::InputFinding& f = r.findings[0];
    CHECK(f.fault == InputFault::kDuplicateElement);
    REQUIRE(f.elements.size() == 2);
    const Index copy = primal::index_cast(primal::element_count(m, kind) - 1);
    CHECK(std::find(f.elements.begin(), f.elements.end(), primal::ElementRef{kind, copied}) !=
          f.elements.end());
    CHECK(std::find(f.elements.begin(), f.elements.end(), primal::ElementRef{kind, copy}) !=
          f.elements.end());
    CHECK(f.text(m).find("one element twice") != std::string::npos);
    CHECK(f.text(m).find("999999") != std::string::npos);  // by the file's own id
  }
}

TEST_CASE("input check: many tets written twice, named in one order for any thread count") {
  // Faces are paired in pieces in parallel: the findings, joined in piece order, must be those
  // of one pass in order, the first max_findings of them when there are more.
  test::TempDir dir;
  primal::Model m = test::demo_input("hybrid", 4, dir, ".msh", false);
  const std::size_t tets = m.tets.size();
  for (std::size_t t = 0; t < tets; t += 7) {  // spread over the node range: over the pieces
    const auto c = m.tets[t];
    primal::add_element(m, ElementKind::kTet, std::vector<Index>(c.begin(), c.end()),
                        m.tet_block[t], static_cast<std::int64_t>(900000 + t));
  }
  const std::size_t copies = (tets + 6) / 7;
  REQUIRE(copies > 64);  // more than the pieces
  primal::InputCheckOptions all;
  all.max_findings = 100000;
  auto elements = [](const primal::InputCheckResult& r) {
    std::vector<std::vector<primal::ElementRef>> e;
    for (const primal::InputFinding& f : r.findings) e.push_back(f.elements);
    return e;
  };
  const primal::InputCheckResult two = primal::check_input(m, all);
  primal::InputCheckResult one;
  {
    const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = primal::check_input(m, all);
  }
  REQUIRE(two.findings.size() >= copies);
  CHECK(elements(one) == elements(two));
  // Every copy named as one, once (at one of its faces, not at each: copies side by side share
  // a face; the later stages find more).
  std::set<Index> named;
  std::size_t said = 0;
  for (const primal::InputFinding& f : two.findings)
    if (f.fault == InputFault::kDuplicateElement) {
      ++said;
      for (const primal::ElementRef& e : f.elements)
        if (e.index >= primal::index_cast(tets)) named.insert(e.index);
    }
  CHECK(named.size() == copies);
  CHECK(said == copies);
  CHECK(two.findings.front().fault == InputFault::kDuplicateElement);
  const primal::InputCheckResult few = primal::check_input(m);  // the first 8
  REQUIRE(few.findings.size() == 8);
  auto first = elements(two);
  first.resize(8);
  CHECK(elements(few) == first);
}

TEST_CASE("input check: overlapping parts, a gap at the interface, a part inside another") {
  test::TempDir dir;
  const primal::Model base =
      test::demo_input("delaunay", 4, dir, ".msh", false);  // hexes [0,1]^3, tets x in [1,2]
  {
    // The hex part misplaced 0.3 into the tet part (and 0.1 off along y and z): their
    // boundaries cross.
    primal::Model m = base;
    detach_hexes(m, Point(0.3, 0.1, 0.1));
    const primal::InputCheckResult r = primal::check_input(m);
    REQUIRE(!r.ok());
    require_same_when_shared(m);
    CHECK(r.findings[0].fault == InputFault::kCrossingFaces);
    REQUIRE(r.findings[0].elements.size() == 2);
    std::set<ElementKind> kinds{r.findings[0].elements[0].kind, r.findings[0].elements[1].kind};
    CHECK(kinds == std::set<ElementKind>{ElementKind::kHex, ElementKind::kTet});
    CHECK(r.findings[0].place.x() > 0.99);
    CHECK(r.findings[0].place.x() < 1.31);
    refused_by_conform(m, "overlap", {"overlap", "crosses"}, dir);
  }
  {
    // The hex part moved 0.004 away (a quarter-cell is 0.25 here): an interface with a gap.
    primal::Model m = base;
    detach_hexes(m, Point(-0.004, 0.0, 0.0));
    const primal::InputCheckResult r = primal::check_input(m);
    REQUIRE(!r.ok());
    require_same_when_shared(m);
    CHECK(r.findings[0].fault == InputFault::kGap);
    CHECK(r.findings[0].measure == doctest::Approx(0.004).epsilon(0.01));
    CHECK(r.findings[0].place.x() == doctest::Approx(1.0).epsilon(0.01));
    refused_by_conform(m, "gap", {"gap"}, dir);
  }
  {
    // Duplicated interface nodes in place: refused on read, conformed once merged.
    primal::Model m = base;
    detach_hexes(m, Point::Zero());
    const primal::InputCheckResult r = primal::check_input(m);
    REQUIRE(!r.ok());
    require_same_when_shared(m);
    CHECK(r.findings[0].fault == InputFault::kGap);
    CHECK(r.findings[0].measure < 1e-12);
    refused_by_conform(m, "duplicated", {"--merge-tolerance"}, dir);
    const auto in = dir.path / "duplicated.msh";
    const auto run =
        test::geode_cli("conform " + in.string() + " --merge-tolerance 1e-6 --quiet -o " +
                            (dir.path / "merged.exo").string(),
                        true);
    INFO(run.out);
    CHECK(run.code == 0);
  }
  {
    // One tet using a copy of an interface node (a merge that missed one element): the tet
    // meets the rest only along its edges there, refused as non-manifold, and the message
    // names the node and its copy, which --merge-tolerance merges.
    primal::Model m = base;
    std::vector<char> in_hex(m.points.size(), 0);
    for (const auto& h : m.hexes)
      for (Index v : h) in_hex[primal::index_cast<std::size_t>(v)] = 1;
    std::size_t tet = 0, corner = 0;
    for (; tet < m.tets.size(); ++tet) {
      for (corner = 0; corner < 4; ++corner)
        if (in_hex[primal::index_cast<std::size_t>(m.tets[tet][corner])]) break;
      if (corner < 4) break;
    }
    REQUIRE(tet < m.tets.size());
    const Index shared = m.tets[tet][corner];
    m.points.push_back(m.points[primal::index_cast<std::size_t>(shared)]);
    if (!m.node_ids.empty())
      m.node_ids.push_back(*std::max_element(m.node_ids.begin(), m.node_ids.end()) + 1);
    m.tets[tet][corner] = primal::index_cast(m.points.size() - 1);
    const primal::InputCheckResult r = primal::check_input(m);
    REQUIRE(!r.ok());
    require_same_when_shared(m);
    CHECK(r.findings[0].topological());
    const std::string copy = std::to_string(primal::node_id(m, m.tets[tet][corner]));
    const std::string text = r.findings[0].text(m);
    INFO(text);
    CHECK(text.find("hint: node " + std::to_string(primal::node_id(m, shared))) !=
          std::string::npos);
    CHECK(text.find("at the same place as node " + copy) != std::string::npos);
    refused_by_conform(m, "copied", {"--merge-tolerance"}, dir, 3);
    const auto run = test::geode_cli("conform " + (dir.path / "copied.msh").string() +
                                         " --merge-tolerance 1e-6 --quiet -o " +
                                         (dir.path / "copied.exo").string(),
                                     true);
    INFO(run.out);
    CHECK(run.code == 0);
  }
  {
    // A hex box [1.3, 1.7]^3 inside the tet box (no hole cut for it): covered twice.
    primal::Model m = base;
    m.hexes.resize(1);
    m.hex_block.resize(std::min<std::size_t>(m.hex_block.size(), 1));
    if (!m.hex_ids.empty()) m.hex_ids.resize(1);
    detach_hexes(m, Point::Zero());
    for (int c = 0; c < 8; ++c) {
      const auto& r = primal::topology::kHexCornerCoords[primal::index_cast<std::size_t>(c)];
      m.points[primal::index_cast<std::size_t>(m.hexes[0][primal::index_cast<std::size_t>(c)])] =
          Point(1.3, 0.3, 0.3) + 0.4 * Point(r[0], r[1], r[2]);
    }
    REQUIRE_NOTHROW(primal::check_geometry(m, "inside"));
    const primal::InputCheckResult r = primal::check_input(m);
    REQUIRE(!r.ok());
    require_same_when_shared(m);
    CHECK(r.findings[0].fault == InputFault::kCoveredTwice);
    CHECK(r.findings[0].elements[0].kind == ElementKind::kHex);
    CHECK(r.findings[0].measure == doctest::Approx(2.0).epsilon(0.01));
    refused_by_conform(m, "inside", {"hex", "inside other elements"}, dir);
  }
}

TEST_CASE(
    "input check: a Gmsh hybrid and a TetGen box with one more element glued along an edge or at "
    "a node are refused as non-manifold, by the file's node ids") {
  test::TempDir dir;
  for (const std::string source : {"hybrid", "tetgen"}) {
    const primal::Model base =
        source == "tetgen" ? tetgen_box(dir) : test::demo_input("hybrid", 4, dir, ".msh", false);
    REQUIRE(primal::check_input(base).ok());
    const auto [c, up] = corner_edge(base);
    for (const bool along_edge : {true, false}) {
      CAPTURE(source);
      CAPTURE(along_edge);
      primal::Model m = base;
      // A hex on the Gmsh model, a tet on the TetGen one.
      if (source == "hybrid")
        glue(m, ElementKind::kHex, hex_beside(m, c, up, along_edge));
      else
        glue(m, ElementKind::kTet, tet_beside(m, c, up, along_edge));
      REQUIRE_NOTHROW(primal::check_geometry(m, source));
      const primal::InputCheckResult r = primal::check_input(m);
      REQUIRE(!r.ok());
      require_same_when_shared(m);
      const primal::InputFinding& f = r.findings[0];
      CHECK(f.topological());
      if (along_edge) {
        CHECK(f.fault == InputFault::kNonManifoldEdge);
        CHECK(std::minmax(f.node, f.edge_end) == std::minmax(c, up));
        CHECK(f.measure == 4);  // two faces of the glued element, two of the model's
      } else {
        CHECK(f.fault == InputFault::kNonManifoldNode);
        CHECK(f.node == c);
        CHECK(f.measure == 2);
      }
      // The extra element is among the named ones.
      const ElementKind glued = source == "hybrid" ? ElementKind::kHex : ElementKind::kTet;
      const primal::ElementRef extra{glued,
                                     primal::index_cast(primal::element_count(m, glued) - 1)};
      CHECK(std::find(f.elements.begin(), f.elements.end(), extra) != f.elements.end());
      // Refused when read, naming the nodes by the ids the file gives them (the model's).
      const std::string name = source + (along_edge ? "-edge" : "-node");
      refused_by_conform(m, name, {"not a manifold", "surface sheets"}, dir, 3);
      const primal::Model read = io::read_model(dir.path / (name + ".msh"), {}, false);
      const primal::InputCheckResult rr = primal::check_input(read);
      REQUIRE(!rr.ok());
      const primal::InputFinding& g = rr.findings[0];
      auto id = [](const primal::Model& model, Index v) {
        return std::to_string(primal::node_id(model, v));
      };
      if (along_edge) {
        CHECK(std::set<std::string>{id(read, g.node), id(read, g.edge_end)} ==
              std::set<std::string>{id(m, c), id(m, up)});
        CHECK(g.text(read).find("nodes " + id(read, g.node) + " " + id(read, g.edge_end)) !=
              std::string::npos);
      } else {
        CHECK(id(read, g.node) == id(m, c));
        CHECK(g.text(read).find("at node " + id(m, c)) != std::string::npos);
      }
      CHECK_THROWS_AS(io::read_model(dir.path / (name + ".msh")), TopologyError);
    }
  }
}

TEST_CASE(
    "input check: a part meshed finer beside a coarser one, sharing only their corners (hanging "
    "nodes), is refused as non-manifold") {
  test::TempDir dir;
  // A unit hex on [0,1]^3 and 2 x 2 x 2 hexes on [1,2] x [0,1]^2: the face x = 1 is the big
  // hex's one quad on one side and four quads on the other, whose middle nodes hang.
  primal::Model m;
  const double x[8] = {0, 1, 1, 0, 0, 1, 1, 0}, y[8] = {0, 0, 1, 1, 0, 0, 1, 1},
               z[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  auto box = [&](const Point& lo, double size) {
    std::vector<Point> p;
    for (int k = 0; k < 8; ++k) p.push_back(lo + size * Point(x[k], y[k], z[k]));
    return p;
  };
  glue(m, ElementKind::kHex, box(Point::Zero(), 1.0));
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        glue(m, ElementKind::kHex, box(Point(1.0 + 0.5 * i, 0.5 * j, 0.5 * k), 0.5));
  REQUIRE(m.hexes.size() == 9);
  REQUIRE_NOTHROW(primal::check_geometry(m, "hanging"));
  const primal::InputCheckResult r = primal::check_input(m);
  REQUIRE(!r.ok());
  require_same_when_shared(m);
  CHECK(r.findings[0].topological());
  CHECK(m.points[primal::index_cast<std::size_t>(r.findings[0].node)].x() ==
        1.0);  // on the interface
  refused_by_conform(m, "hanging", {"not a manifold", "not matched node for node"}, dir, 3);
}

TEST_CASE("input check: parts meshed separately, their nodes merged: the interface named as such") {
  // A hex box and a tet box meshed by Gmsh without fragmenting the geometry (a user's usual slip):
  // once --merge-tolerance merges their interface nodes, the tets' triangles still do not split
  // the hexes' quads (Gmsh triangulates the tet box's face on its own), which the check sees as a
  // non-manifold boundary; the message says the interface does not conform and how to mesh it.
  primal::Model m;
  {
    demo::GmshSession session;
    const int a = gmsh::model::occ::addBox(0, 0, 0, 1, 1, 1);
    const int b = gmsh::model::occ::addBox(1, 0, 0, 1, 1, 1);
    gmsh::model::occ::synchronize();
    gmsh::vectorpair curves;
    gmsh::model::getEntities(curves, 1);
    for (const auto& [dim, tag] : curves) gmsh::model::mesh::setTransfiniteCurve(tag, 4);
    gmsh::vectorpair faces;
    gmsh::model::getBoundary({{3, a}}, faces, false, false);
    for (const auto& [dim, tag] : faces) {
      gmsh::model::mesh::setTransfiniteSurface(tag);
      gmsh::model::mesh::setRecombine(2, tag);
    }
    gmsh::model::mesh::setTransfiniteVolume(a);
    gmsh::model::addPhysicalGroup(3, {a}, 1);
    gmsh::model::addPhysicalGroup(3, {b}, 2);
    gmsh::option::setNumber("Mesh.MeshSizeMax", 0.3);
    gmsh::model::mesh::generate(3);
    m = demo::model_from_gmsh("separate");
  }
  REQUIRE(!m.hexes.empty());
  REQUIRE(!m.tets.empty());
  CHECK(primal::merge_coincident_nodes(m, 1e-9) > 0);
  const primal::InputCheckResult r = primal::check_input(m);
  REQUIRE(!r.ok());
  CHECK(r.findings[0].topological());
  const std::string text = r.findings[0].text(m);
  INFO(text);
  CHECK(text.find("the interface does not conform") != std::string::npos);
  CHECK(text.find("gmsh.model.occ.fragment") != std::string::npos);
  // The hint names a hex's quad and a tet's triangle.
  CHECK(text.find("'s quad and tet ") != std::string::npos);
}

TEST_CASE("input check: a hex box and a tet box fragmented, touching along an edge: no hint") {
  // The boxes meet only along the edge x = y = 1: the hex's quad at x = 1 and the tet's triangle
  // at x = 1 lie in one plane, opposed, on either side of that edge, touching, not against each
  // other. The refusal names the edge; the hint that the parts were meshed separately (sent a
  // user who had fragmented them to fragment them) is not given (found by a fault hunt).
  primal::Model m;
  {
    demo::GmshSession session;
    const int a = gmsh::model::occ::addBox(0, 0, 0, 1, 1, 1);
    const int b = gmsh::model::occ::addBox(1, 1, 0, 1, 1, 1);
    gmsh::vectorpair parts;
    std::vector<gmsh::vectorpair> children;
    gmsh::model::occ::fragment({{3, a}}, {{3, b}}, parts, children);
    gmsh::model::occ::synchronize();
    gmsh::vectorpair faces, curves;
    gmsh::model::getBoundary({{3, a}}, faces, false, false);
    for (const auto& [dim, face] : faces) {
      gmsh::model::getBoundary({{2, std::abs(face)}}, curves, false, false);
      for (const auto& [d, curve] : curves)
        gmsh::model::mesh::setTransfiniteCurve(std::abs(curve), 5);
      gmsh::model::mesh::setTransfiniteSurface(std::abs(face));
      gmsh::model::mesh::setRecombine(2, std::abs(face));
    }
    gmsh::model::mesh::setTransfiniteVolume(a);
    gmsh::model::addPhysicalGroup(3, {a}, 1);
    gmsh::model::addPhysicalGroup(3, {b}, 2);
    gmsh::option::setNumber("Mesh.MeshSizeMax", 0.3);
    gmsh::model::mesh::generate(3);
    m = demo::model_from_gmsh("edge");
  }
  REQUIRE(!m.hexes.empty());
  REQUIRE(!m.tets.empty());
  const primal::InputCheckResult r = primal::check_input(m);
  REQUIRE(!r.ok());
  CHECK(r.findings[0].fault == InputFault::kNonManifoldEdge);
  const std::string text = r.findings[0].text(m);
  INFO(text);
  CHECK(text.find("hint") == std::string::npos);
}

namespace {

// A hex ring (an annulus of radii 0.5 and 1, recombined and swept 0.5 in n layers) in a tet box
// [-2, 2]^2 x [-1, 1], meshed by Gmsh in one generate(3) with the built-in kernel, as a user
// scripts it (the box's boundary the outer shell of the tet volume, the ring's its hole): Gmsh
// puts pyramids on the ring's quads, and Debian's 4.8 folds tets near them (at n = 3 one tet;
// most sizes tried fold somewhere).
primal::Model gmsh_ring(int n) {
  demo::GmshSession session;
  namespace geo = gmsh::model::geo;
  const double ring_size = 1.0 / n, box_size = 1.5 / n;
  const auto circle = [&](double r) {
    const int c = geo::addPoint(0, 0, -0.25, ring_size);
    std::vector<int> p, arcs;
    for (int i = 0; i < 4; ++i)
      p.push_back(geo::addPoint(r * std::cos(i * std::numbers::pi / 2),
                                r * std::sin(i * std::numbers::pi / 2), -0.25, ring_size));
    for (int i = 0; i < 4; ++i) {
      arcs.push_back(geo::addCircleArc(p[static_cast<std::size_t>(i)], c,
                                       p[static_cast<std::size_t>((i + 1) % 4)]));
      geo::mesh::setTransfiniteCurve(arcs.back(), 2 * n + 1);
    }
    return geo::addCurveLoop(arcs);
  };
  const int outer = circle(1.0), inner = circle(0.5);
  const int annulus = geo::addPlaneSurface({outer, inner});
  geo::mesh::setRecombine(2, annulus);
  gmsh::vectorpair swept;
  geo::extrude({{2, annulus}}, 0, 0, 0.5, swept, {n}, {}, true);
  int ring = 0;
  std::vector<int> ring_faces{annulus};
  for (const auto& [dim, tag] : swept) {
    if (dim == 3) ring = tag;
    if (dim == 2) ring_faces.push_back(tag);
  }
  // The box: corners (x, y, z) in {-2, 2}^2 x {-1, 1}, corner c at bits (x, y, z) = (c & 1,
  // c & 2, c & 4), its six faces by their corners in cycle.
  std::vector<int> corner;
  for (int c = 0; c < 8; ++c)
    corner.push_back(geo::addPoint(c & 1 ? 2 : -2, c & 2 ? 2 : -2, c & 4 ? 1 : -1, box_size));
  std::map<std::pair<int, int>, int> lines;
  const auto line = [&](int a, int b) {
    if (const auto it = lines.find({b, a}); it != lines.end()) return -it->second;
    if (const auto it = lines.find({a, b}); it != lines.end()) return it->second;
    return lines[{a, b}] = geo::addLine(corner[static_cast<std::size_t>(a)],
                                        corner[static_cast<std::size_t>(b)]);
  };
  std::vector<int> box_faces;
  for (const std::array<int, 4> f : {std::array<int, 4>{0, 1, 3, 2},
                                     {4, 5, 7, 6},
                                     {0, 1, 5, 4},
                                     {1, 3, 7, 5},
                                     {3, 2, 6, 7},
                                     {2, 0, 4, 6}}) {
    std::vector<int> loop;
    for (int i = 0; i < 4; ++i)
      loop.push_back(
          line(f[static_cast<std::size_t>(i)], f[static_cast<std::size_t>((i + 1) % 4)]));
    box_faces.push_back(geo::addPlaneSurface({geo::addCurveLoop(loop)}));
  }
  const int potting =
      geo::addVolume({geo::addSurfaceLoop(box_faces), geo::addSurfaceLoop(ring_faces)});
  geo::synchronize();
  gmsh::model::addPhysicalGroup(3, {ring}, 1);
  gmsh::model::addPhysicalGroup(3, {potting}, 2);
  gmsh::model::mesh::generate(3);
  return demo::model_from_gmsh("ring");
}

// A hex part with a dihedral angle not 90 degrees, as a user builds one with OCC: a cylinder
// sector of `degrees` about a vertical edge (radius 1.2, 1 high, its base transfinite and
// recombined, swept in layers), fragmented with a tet box of [0,3]x[0,3]x[0,2] and meshed
// together (Gmsh's pyramids on the sector's quads).
primal::Model gmsh_sector(int n, double degrees) {
  demo::GmshSession session;
  namespace occ = gmsh::model::occ;
  const int box = occ::addBox(0, 0, 0, 3, 3, 2);
  const double cx = 1.5, cy = 1.0, z = 0.5, r = 1.2;
  const double a0 = (90 - degrees / 2) * std::numbers::pi / 180,
               a1 = (90 + degrees / 2) * std::numbers::pi / 180, am = (a0 + a1) / 2;
  const auto at = [&](double a) {
    return occ::addPoint(cx + r * std::cos(a), cy + r * std::sin(a), z);
  };
  const int o = occ::addPoint(cx, cy, z), a = at(a0), m = at(am), b = at(a1),
            c = occ::addPoint(cx, cy, z);  // the arcs' centre
  const std::vector<int> curves{occ::addLine(o, a), occ::addCircleArc(a, c, m),
                                occ::addCircleArc(m, c, b), occ::addLine(b, o)};
  const int base = occ::addPlaneSurface({occ::addCurveLoop(curves)});
  occ::remove({{0, c}});
  occ::synchronize();
  for (const int curve : curves)
    gmsh::model::mesh::setTransfiniteCurve(curve, static_cast<int>(std::lround(r * n)) + 1);
  gmsh::model::mesh::setTransfiniteSurface(base);
  gmsh::model::mesh::setRecombine(2, base);
  gmsh::vectorpair swept, parts;
  occ::extrude({{2, base}}, 0, 0, 1, swept, {n}, {}, true);
  std::vector<int> sector;
  for (const auto& [dim, tag] : swept)
    if (dim == 3) sector.push_back(tag);
  std::vector<gmsh::vectorpair> children;
  occ::fragment({{3, box}}, {{3, sector.front()}}, parts, children);
  occ::synchronize();
  std::vector<int> potting;
  for (const auto& [dim, tag] : children.front())
    if (dim == 3 && tag != sector.front()) potting.push_back(tag);
  gmsh::model::addPhysicalGroup(3, sector, 1);
  gmsh::model::addPhysicalGroup(3, potting, 2);
  gmsh::option::setNumber("Mesh.MeshSizeMax", 1.0 / n);
  gmsh::model::mesh::generate(3);
  return demo::model_from_gmsh("sector");
}

}  // namespace

TEST_CASE("--unfold: the tets Gmsh folds near its pyramids turned back, the ring conformed") {
  test::TempDir dir;
  const primal::Model folded = gmsh_ring(3);
  REQUIRE(!folded.pyramids.empty());
  const primal::InputCheckResult before = primal::check_input(folded);
  REQUIRE(!before.ok());
  CHECK(before.findings[0].fault == InputFault::kSameSideFace);

  primal::Model m = folded;
  const primal::UnfoldResult u = primal::unfold(m);
  REQUIRE(u.unfolded());
  CHECK(u.turned.size() == u.moved.size());
  CHECK(primal::check_input(m).ok());
  REQUIRE_NOTHROW(primal::check_geometry(m, "unfolded"));  // every element positive
  // Only the moved nodes moved, by less than the box's mesh size; the turned tets' node order
  // is the only change to the elements.
  std::size_t moved = 0;
  for (std::size_t v = 0; v < m.points.size(); ++v)
    if (m.points[v] != folded.points[v]) {
      ++moved;
      CHECK(std::find(u.moved.begin(), u.moved.end(), primal::index_cast(v)) != u.moved.end());
      CHECK((m.points[v] - folded.points[v]).norm() < 0.5);
    }
  CHECK(moved == u.moved.size());
  CHECK(m.hexes == folded.hexes);
  CHECK(m.pyramids == folded.pyramids);
  std::size_t changed = 0;
  for (std::size_t t = 0; t < m.tets.size(); ++t) changed += m.tets[t] != folded.tets[t];
  CHECK(changed == u.turned.size());

  // The command: refused with the hint, conformed with --unfold (a warning naming the nodes).
  const auto in = dir.path / "ring.msh", out = dir.path / "ring.exo";
  io::write_model(folded, in);
  const auto refused = test::geode_cli("conform " + in.string() + " -o " + out.string(), true);
  CHECK(refused.code == 2);
  CHECK(refused.out.find("--unfold turns such cells back") != std::string::npos);
  const auto run =
      test::geode_cli("conform " + in.string() + " -o " + out.string() + " --unfold --quiet", true);
  INFO(run.out);
  CHECK(run.code == 0);
  CHECK(run.out.find("--unfold: " + std::to_string(u.turned.size())) != std::string::npos);
  CHECK(std::filesystem::exists(out));

  // A fault --unfold does not mend (one tet twice, as Gmsh writes some): the folds are mended
  // and the tet twice is what the check names, not a fold unfold mended.
  primal::Model twice = folded;
  twice.tets.push_back(twice.tets.front());
  if (!twice.tet_block.empty()) twice.tet_block.push_back(twice.tet_block.front());
  if (!twice.tet_ids.empty())
    twice.tet_ids.push_back(*std::max_element(twice.tet_ids.begin(), twice.tet_ids.end()) + 1);
  const primal::UnfoldResult partly = primal::unfold(twice);
  CHECK(partly.turned.size() == u.turned.size());
  CHECK(!partly.covered_once);
  const primal::InputCheckResult left = primal::check_input(twice);
  REQUIRE(!left.ok());
  CHECK(left.findings.size() == 1);  // said once, not on each of its four faces
  CHECK(left.findings[0].fault == InputFault::kDuplicateElement);
  // Folds unfold cannot mend (every node in a node set, which stays) leave the model as it was.
  primal::Model stuck = folded;
  primal::NodeSet all{1, "all", {}};
  for (std::size_t v = 0; v < stuck.points.size(); ++v) all.nodes.push_back(primal::index_cast(v));
  stuck.node_sets.push_back(all);
  const primal::Model kept = stuck;
  CHECK(!primal::unfold(stuck).unfolded());
  CHECK(stuck.points == kept.points);
  CHECK(stuck.tets == kept.tets);
}

TEST_CASE("--unfold: folds around a pyramid at a 45-degree sector's edge, turned back together") {
  // Gmsh folds two tets over the pyramid on a sector's quad and over their other neighbours:
  // each is on the pyramid's side, which turned with them would put its base on the hex's side.
  // The tets alone are turned (the model was refused with --unfold, found by a fault hunt).
  const primal::Model folded = gmsh_sector(6, 45);
  REQUIRE(!primal::check_input(folded).ok());
  primal::Model m = folded;
  const primal::UnfoldResult u = primal::unfold(m);
  REQUIRE(u.unfolded());
  CHECK(u.covered_once);
  CHECK(primal::check_input(m).ok());
  REQUIRE_NOTHROW(primal::check_geometry(m, "unfolded"));
  CHECK(m.pyramids == folded.pyramids);  // no pyramid turned
  CHECK(m.hexes == folded.hexes);
}

TEST_CASE("conform: hexes beside a wedge layer, touching the tets along edges only, are diced") {
  // No hex quad meets a tet triangle: no transition to make, each part diced alone and the
  // dicing conforms along the shared edges. find_interface refused the model (a node of both
  // parts on no interface quad), found by a fault hunt.
  test::TempDir dir;
  const primal::Model m = gmsh_hexes_beside_wedges(4, 2);
  REQUIRE(!m.hexes.empty());
  REQUIRE(!m.wedges.empty());
  REQUIRE(!m.tets.empty());
  REQUIRE(m.pyramids.empty());
  std::vector<char> in_hex(m.points.size(), 0);
  for (const auto& h : m.hexes)
    for (Index v : h) in_hex[static_cast<std::size_t>(v)] = 1;
  std::size_t shared = 0;  // nodes of both parts: the edges where they touch
  std::set<Index> tet_nodes;
  for (const auto& t : m.tets)
    for (Index v : t) tet_nodes.insert(v);
  for (Index v : tet_nodes) shared += in_hex[static_cast<std::size_t>(v)];
  REQUIRE(shared > 0);
  const auto in = dir.path / "beside.msh", out = dir.path / "beside.exo";
  io::write_model(m, in);
  const auto run = test::geode_cli("conform " + in.string() + " -o " + out.string() + " -q", true);
  INFO(run.out);
  REQUIRE(run.code == 0);
  CHECK(run.out.find("share no interface quad: each is diced alone") != std::string::npos);
  const primal::Model diced = io::read_model(out);
  CHECK(diced.hexes.size() == 8 * m.hexes.size() + 6 * m.wedges.size() + 4 * m.tets.size());
  CHECK(primal::check_validity(primal::hex_part(diced)).ok());
}
