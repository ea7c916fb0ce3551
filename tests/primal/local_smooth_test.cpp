// The worst-first local smoother (primal/local_smooth.hpp): analytic derivatives against finite
// differences, untangling, the per-hex floors, boundary and block-interface nodes kept on their
// plane / edge (every block's volume kept), kSurface nodes on their triangulation, and the same
// result for any thread count.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <vector>

#include <geode/primal/errors.hpp>
#include <geode/primal/frame_derivatives.hpp>
#include <geode/primal/local_smooth.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>

namespace {

namespace gp = geode::primal;
using gp::HexMesh;
using gp::Index;
using gp::NodeConstraint;
using gp::Point;

// Deterministic pseudo-random numbers in [-1, 1] (no std distribution: portable sequences).
struct Lcg {
  std::uint64_t s;
  double next() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(s >> 11) / static_cast<double>(1ull << 52) - 1.0;
  }
};

// n x n x n unit cells over [0, n]^3, nodes mapped by `map`.
template <class Map>
HexMesh grid(int n, Map map) {
  HexMesh m;
  auto id = [n](int i, int j, int k) {
    return geode::primal::index_cast(i + (n + 1) * (j + (n + 1) * k));
  };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) m.points.push_back(map(Point(i, j, k)));
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        m.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                           id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                           id(i, j + 1, k + 1)});
  return m;
}

std::vector<double> scaled_jacobians(const HexMesh& m) {
  std::vector<double> q;
  for (Index h = 0; h < geode::primal::index_cast(m.hexes.size()); ++h)
    q.push_back(gp::hex_scaled_jacobian(gp::hex_corners(m, h)));
  return q;
}

// Interior nodes jittered by up to `amount` per coordinate.
HexMesh jittered_grid(int n, double amount, std::uint64_t seed) {
  Lcg r{seed};
  return grid(n, [&](const Point& p) {
    Point q = p;
    for (int a = 0; a < 3; ++a)
      if (p[a] > 0 && p[a] < n) q[a] += amount * r.next();
    return q;
  });
}

double distance_to(const gp::TriMesh& s, const Point& p) {
  double best = 1e300;
  for (const auto& t : s.tris) {
    // Sample-free: distance to the plane when the projection falls inside, else to the edges.
    const Point a = s.points[t[0]], b = s.points[t[1]], c = s.points[t[2]];
    const Point n = (b - a).cross(c - a).normalized();
    const Point q = p - (p - a).dot(n) * n;
    const double u = (b - a).cross(q - a).dot(n), v = (c - b).cross(q - b).dot(n),
                 w = (a - c).cross(q - c).dot(n);
    if (u >= -1e-12 && v >= -1e-12 && w >= -1e-12) best = std::min(best, (p - q).norm());
    for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      const double s01 = std::clamp((p - x).dot(y - x) / (y - x).squaredNorm(), 0.0, 1.0);
      best = std::min(best, (p - (x + s01 * (y - x))).norm());
    }
  }
  return best;
}

}  // namespace

TEST_CASE("frame derivatives match central differences") {
  Lcg r{7};
  for (int trial = 0; trial < 20; ++trial) {
    gp::FrameVector v;
    for (int i = 0; i < 9; ++i) v[i] = r.next() + (i % 4 == 0 ? 1.5 : 0.0);  // near the identity
    // 0 determinant, 1 scaled determinant, 2 and 3 the quad and hex corner shapes.
    for (int measure = 0; measure < 4; ++measure) {
      CAPTURE(trial);
      CAPTURE(measure);
      auto f = [&](const gp::FrameVector& x, gp::FrameVector* g, gp::FrameMatrix* h) {
        return measure == 0   ? gp::determinant_derivatives(x, g, h)
               : measure == 1 ? gp::scaled_determinant_derivatives(x, g, h)
                              : gp::corner_shape_derivatives(x, measure, g, h);
      };
      gp::FrameVector g;
      gp::FrameMatrix h;
      const double value = f(v, &g, &h);
      CHECK(value == doctest::Approx(f(v, nullptr, nullptr)));
      const double eps = 1e-6;
      for (int i = 0; i < 9; ++i) {
        gp::FrameVector vp = v, vm = v, gp_, gm;
        vp[i] += eps, vm[i] -= eps;
        CHECK(g[i] ==
              doctest::Approx((f(vp, nullptr, nullptr) - f(vm, nullptr, nullptr)) / (2 * eps))
                  .epsilon(1e-6));
        f(vp, &gp_, nullptr), f(vm, &gm, nullptr);
        const gp::FrameVector col = (gp_ - gm) / (2 * eps);
        for (int j = 0; j < 9; ++j)
          CHECK(h(j, i) == doctest::Approx(col[j]).epsilon(1e-5).scale(1.0));
      }
      CHECK((h - h.transpose()).norm() < 1e-12);
    }
  }
}

TEST_CASE("a tangled grid is untangled, boundary nodes on their planes") {
  // Interior nodes pushed across their neighbours: several hexes inverted.
  HexMesh mesh = grid(4, [](const Point& p) { return p; });
  Lcg r{3};
  for (Point& p : mesh.points)
    if (p.minCoeff() > 0 && p.maxCoeff() < 4)
      for (int a = 0; a < 3; ++a) p[a] += 0.9 * r.next();
  const HexMesh before = mesh;
  const auto initial = scaled_jacobians(mesh);
  const int inverted = static_cast<int>(
      std::count_if(initial.begin(), initial.end(), [](double q) { return q <= 0; }));
  REQUIRE(inverted > 0);
  const auto cons = gp::boundary_slide_constraints(mesh);
  const auto res = gp::smooth_hexes_local(mesh, cons);
  CHECK(res.initial_inverted == inverted);
  CHECK(res.final_inverted == 0);
  const auto after = scaled_jacobians(mesh);
  CHECK(*std::min_element(after.begin(), after.end()) > 0.2);
  CHECK(res.final_min_scaled_jacobian == *std::min_element(after.begin(), after.end()));
  MESSAGE("untangled " << inverted << " hexes: min SJ " << res.initial_min_scaled_jacobian << " -> "
                       << res.final_min_scaled_jacobian << " in " << res.patches << " patches, "
                       << res.rounds << " rounds, " << res.iterations << " iterations");
  // Face nodes slide in their face planes, edge nodes along their edges, corners stay.
  int moved_on_boundary = 0;
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    const Point& p = mesh.points[v];
    const Point& q = before.points[v];
    for (int a = 0; a < 3; ++a)
      if (q[a] == 0 || q[a] == 4) CHECK(std::abs(p[a] - q[a]) < 1e-12);
    if (cons[v].kind != NodeConstraint::Kind::kFree && (p - q).norm() > 1e-3) ++moved_on_boundary;
  }
  CHECK(moved_on_boundary > 0);
}

TEST_CASE("hexes near the worst never lose; others lose at most `loss`") {
  gp::LocalSmoothOptions o;
  o.target = 0.9;
  HexMesh mesh = jittered_grid(5, 0.3, 11);
  const auto start = scaled_jacobians(mesh);
  const double worst = *std::min_element(start.begin(), start.end());
  REQUIRE(worst > 0.0);
  const auto res =
      gp::smooth_hexes_local(mesh, gp::boundary_slide_constraints(mesh), nullptr, {}, o);
  const auto end = scaled_jacobians(mesh);
  int improved = 0;
  for (std::size_t h = 0; h < start.size(); ++h) {
    CAPTURE(h);
    CHECK(end[h] >= worst);  // floors never go below a patch's worst, itself >= the mesh's
    if (start[h] < worst + o.margin) CHECK(end[h] >= start[h]);
    CHECK(end[h] >= start[h] - o.loss);
    improved += end[h] > start[h] + 1e-3;
  }
  CHECK(res.final_min_scaled_jacobian > res.initial_min_scaled_jacobian + 0.05);
  CHECK(improved > 10);
}

// A goal below the target ends the call once every seed reaches it: fewer patches than the
// target alone takes, and no seed below the goal.
TEST_CASE("the call ends when every seed reaches the goal") {
  gp::LocalSmoothOptions o;
  o.target = 0.9;
  const HexMesh start = jittered_grid(5, 0.3, 11);
  HexMesh full = start;
  const auto all =
      gp::smooth_hexes_local(full, gp::boundary_slide_constraints(full), nullptr, {}, o);
  o.goal = 0.5 * (all.initial_min_scaled_jacobian + all.final_min_scaled_jacobian);
  REQUIRE(o.goal > all.initial_min_scaled_jacobian + 0.02);
  HexMesh part = start;
  const auto res =
      gp::smooth_hexes_local(part, gp::boundary_slide_constraints(part), nullptr, {}, o);
  CHECK(res.final_min_scaled_jacobian >= o.goal);
  CHECK(res.patches < all.patches);
  CHECK(res.final_min_scaled_jacobian < all.final_min_scaled_jacobian);
}

// The scaled Jacobian normalises edge lengths, so only the edge floor keeps edges from
// shrinking: without it (fraction 0) some edge ends below 0.9 of its hex's shortest one.
TEST_CASE("no edge ends below min_edge_fraction of its hex's shortest edge at the start") {
  const HexMesh start = jittered_grid(5, 0.3, 11);
  auto shortest = [](const HexMesh& m, Index h) {
    const auto c = gp::hex_corners(m, h);
    double s = 1e300;
    for (int a = 0; a < 8; ++a)
      for (int b = a + 1; b < 8; ++b)
        if (std::abs(gp::topology::kHexCornerCoords[a][0] - gp::topology::kHexCornerCoords[b][0]) +
                std::abs(gp::topology::kHexCornerCoords[a][1] -
                         gp::topology::kHexCornerCoords[b][1]) +
                std::abs(gp::topology::kHexCornerCoords[a][2] -
                         gp::topology::kHexCornerCoords[b][2]) ==
            1)
          s = std::min(s, (c[a] - c[b]).norm());
    return s;
  };
  auto below = [&](double fraction) {
    gp::LocalSmoothOptions o;
    o.target = 0.95;
    o.max_visits = 4;
    o.min_edge_fraction = fraction;
    HexMesh mesh = start;
    gp::smooth_hexes_local(mesh, gp::boundary_slide_constraints(mesh), nullptr, {}, o);
    int n = 0;
    for (Index h = 0; h < geode::primal::index_cast(mesh.hexes.size()); ++h)
      n += shortest(mesh, h) < 0.9 * shortest(start, h);
    return n;
  };
  CHECK(below(0.9) == 0);
  CHECK(below(0.0) > 0);
}

// Passes: floors measured from the values before the first call hold over all calls; measured
// afresh by each call, the losses add up. A fixed interior node pushed toward a corner makes
// the hexes around it poor, and they rise only at their neighbours' expense.
TEST_CASE("smoothing in passes from one SmoothStart keeps every hex within `loss` of it") {
  const int n = 4;
  const HexMesh first =
      grid(n, [&](const Point& p) { return p == Point(2, 2, 2) ? Point(2.6, 2.6, 2.6) : p; });
  const gp::SmoothStart start = gp::smooth_start(first);
  auto lost = [&](bool shared) {
    HexMesh mesh = first;
    auto cons = gp::boundary_slide_constraints(mesh);
    cons[geode::primal::index_cast<std::size_t>(2 + (n + 1) * (2 + (n + 1) * 2))] =
        NodeConstraint::fixed();
    gp::LocalSmoothOptions o;
    o.max_visits = 4;
    for (double target : {0.9, 0.95, 0.99}) {
      o.target = target;
      gp::smooth_hexes_local(mesh, cons, nullptr, {}, o, shared ? &start : nullptr);
    }
    const auto end = scaled_jacobians(mesh);
    int k = 0;
    for (std::size_t h = 0; h < end.size(); ++h)
      k += end[h] < start.scaled_jacobian[h] - o.loss - 1e-12;
    return k;
  };
  CHECK(lost(true) == 0);
  CHECK(lost(false) > 0);
  HexMesh mesh = first;
  gp::SmoothStart wrong = start;
  wrong.shortest_edge.pop_back();
  CHECK_THROWS_AS(gp::smooth_hexes_local(mesh, {}, nullptr, {}, {}, &wrong), geode::InvalidInput);
}

TEST_CASE("seeds limit the smoothing to their neighbourhood") {
  HexMesh mesh = jittered_grid(5, 0.3, 5);
  const HexMesh before = mesh;
  const std::vector<Index> seeds{62};  // the centre hex of 125
  gp::smooth_hexes_local(mesh, gp::boundary_slide_constraints(mesh), nullptr, seeds);
  std::vector<char> near(mesh.points.size(), 0);
  for (Index h : gp::hexes_around(mesh, seeds))
    for (Index v : mesh.hexes[h]) near[v] = 1;
  int moved = 0;
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    if (!near[v]) CHECK(mesh.points[v] == before.points[v]);
    moved += mesh.points[v] != before.points[v];
  }
  CHECK(moved > 0);
}

// Volume of each block (mesh.block; 0 for all when empty): the exact volumes of the trilinear
// hexes.
std::map<int, double> block_volumes(const HexMesh& m) {
  std::map<int, double> v;
  for (Index h = 0; h < geode::primal::index_cast(m.hexes.size()); ++h)
    v[m.block.empty() ? 0 : m.block[geode::primal::index_cast<std::size_t>(h)]] +=
        gp::hex_volume(gp::hex_corners(m, h));
  return v;
}

void check_volumes_kept(const HexMesh& before, const HexMesh& after) {
  const auto a = block_volumes(before), b = block_volumes(after);
  REQUIRE(a.size() == b.size());
  for (const auto& [id_, volume] : a) {
    // Named again: clang 14 cannot capture a structured binding (CAPTURE's lambda).
    const auto& id = id_;
    CAPTURE(id);
    CHECK(std::abs(b.at(id) - volume) <= 1e-9 * volume);
  }
}

TEST_CASE(
    "curved boundary nodes are fixed: the volume is kept; given kSurface nodes stay on the "
    "triangulation") {
  // A grid whose top bulges (z = 3 + 0.4 sin): top nodes on a curved surface, the sides planes.
  HexMesh mesh = grid(3, [](const Point& p) {
    return Point(p.x(), p.y(), p.z() * (1.0 + 0.13 * std::sin(p.x()) * std::sin(p.y())));
  });
  Lcg r{9};
  for (Point& p : mesh.points)  // skew the interior so that the top nodes want to move
    if (p.minCoeff() > 0 && p.x() < 3 && p.y() < 3)
      p.x() += 0.35 * r.next(), p.y() += 0.35 * r.next();
  const auto cons = gp::boundary_slide_constraints(mesh);
  int planes = 0, curved = 0;
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    CHECK(cons[v].kind != NodeConstraint::Kind::kSurface);
    planes += cons[v].kind == NodeConstraint::Kind::kPlane;
    // Inside the bulging top (off its edges): fixed.
    const Point& p = mesh.points[v];
    if (p.z() > 3.0 && p.x() > 0 && p.x() < 3 && p.y() > 0 && p.y() < 3) {
      ++curved;
      CHECK(cons[v].kind == NodeConstraint::Kind::kFixed);
    }
  }
  CHECK(planes > 0);
  CHECK(curved == 4);
  const HexMesh before = mesh;
  gp::LocalSmoothOptions o;
  o.target = 0.95;
  const auto res = gp::smooth_hexes_local(mesh, cons, nullptr, {}, o);
  CHECK(res.final_min_scaled_jacobian > res.initial_min_scaled_jacobian);
  check_volumes_kept(before, mesh);

  // kSurface constraints given explicitly: those nodes move on the boundary triangulation.
  HexMesh sliding = before;
  auto surface_cons = cons;
  const gp::TriMesh surface = gp::boundary_triangulation(sliding);
  for (std::size_t v = 0; v < sliding.points.size(); ++v)
    if (cons[v].kind == NodeConstraint::Kind::kFixed && sliding.points[v].z() > 3.0)
      surface_cons[v] = NodeConstraint::surface(sliding.points[v], Point::UnitZ());
  gp::smooth_hexes_local(sliding, surface_cons, &surface, {}, o);
  int moved = 0;
  for (std::size_t v = 0; v < sliding.points.size(); ++v) {
    if (surface_cons[v].kind != NodeConstraint::Kind::kSurface) continue;
    CHECK(distance_to(surface, sliding.points[v]) < 1e-9);
    moved += (sliding.points[v] - before.points[v]).norm() > 1e-3;
  }
  CHECK(moved > 0);
  gp::HexMesh unconstrained = before;
  CHECK_THROWS_AS(gp::smooth_hexes_local(unconstrained, surface_cons), geode::InvalidInput);
}

TEST_CASE(
    "materials never move: block interfaces slide in their plane or stay, every block's volume "
    "kept") {
  // A jittered 6^3 grid in three blocks: a curved interface (a sphere's octant: the hexes whose
  // centre is within 3.5 of the origin), a planar one (x = 4, flat: its nodes slide in it) and
  // the boundary.
  HexMesh mesh = jittered_grid(6, 0.3, 41);
  for (Point& p : mesh.points)  // the x = 4 plane flat again
    if (std::abs(p.x() - 4.0) < 0.31 && p.x() != 4.0 && std::abs(std::round(p.x()) - 4.0) < 0.5)
      p.x() = 4.0;
  for (Index h = 0; h < geode::primal::index_cast(mesh.hexes.size()); ++h) {
    Point c = Point::Zero();
    for (Index v : mesh.hexes[geode::primal::index_cast<std::size_t>(h)])
      c += mesh.points[geode::primal::index_cast<std::size_t>(v)] / 8.0;
    mesh.block.push_back(c.norm() < 3.5 ? 1 : c.x() > 4.0 ? 3 : 2);
  }
  const auto between = gp::block_interface_quads(mesh);
  CHECK(!between.empty());
  const auto cons = gp::boundary_slide_constraints(mesh);
  int on_interface_plane = 0;
  for (const auto& q : between)
    for (Index v : q.nodes) {
      CHECK(cons[geode::primal::index_cast<std::size_t>(v)].kind != NodeConstraint::Kind::kFree);
      on_interface_plane +=
          cons[geode::primal::index_cast<std::size_t>(v)].kind == NodeConstraint::Kind::kPlane;
    }
  CHECK(on_interface_plane > 0);  // x = 4 inside the grid
  const HexMesh before = mesh;
  gp::LocalSmoothOptions o;
  o.target = 0.95;
  const auto res = gp::smooth_hexes_local(mesh, cons, nullptr, {}, o);
  CHECK(res.final_min_scaled_jacobian > res.initial_min_scaled_jacobian);
  check_volumes_kept(before, mesh);
  int slid = 0;  // nodes of the x = 4 interface that moved, in it
  for (std::size_t v = 0; v < mesh.points.size(); ++v)
    if (cons[v].kind == NodeConstraint::Kind::kPlane && before.points[v].x() == 4.0 &&
        before.points[v].y() > 0 && before.points[v].y() < 6 && before.points[v].z() > 0 &&
        before.points[v].z() < 6) {
      CHECK(std::abs(mesh.points[v].x() - 4.0) < 1e-12);
      slid += (mesh.points[v] - before.points[v]).norm() > 1e-3;
    }
  CHECK(slid > 0);
  // The submesh smoother keeps them too.
  HexMesh around = before;
  std::vector<Index> seeds;
  for (Index h = 0; h < static_cast<Index>(around.hexes.size()); h += 2) seeds.push_back(h);
  gp::smooth_hexes_around(around, seeds, o);
  check_volumes_kept(before, around);
  CHECK(gp::min_scaled_jacobian(around) > gp::min_scaled_jacobian(before));
}

// A surface kept inside the mesh (conform: a side set embedded in a block) and kept nodes (a
// node set's): the surface's nodes slide in its plane, its rim's along the rim where it is
// straight, its corners and the kept interior node stay, a kept node on the boundary slides on
// it; the same through smooth_hexes_local with kept_slide_constraints and smooth_hexes_around
// with LocalSmoothOptions::kept. A node set's node slides only within the set (a face it
// covers, a line it runs along); alone, or inside the model, it stays.
TEST_CASE("kept surfaces keep their plane and extent, kept nodes stay") {
  constexpr int n = 4;
  // The kept patch: the 2 x 2 quads of the plane z = 2 over [1, 3]^2; its centre (2, 2, 2) is
  // jittered in the plane, every other interior node in 3D except the kept node (2, 2, 1).
  const auto on_patch = [](const Point& p) {
    return p.z() == 2 && p.x() >= 1 && p.x() <= 3 && p.y() >= 1 && p.y() <= 3;
  };
  Lcg r{17};
  const HexMesh start = grid(n, [&](const Point& p) {
    Point q = p;
    if (p == Point(2, 2, 2)) return Point(2 + 0.3 * r.next(), 2 + 0.3 * r.next(), 2);
    if (on_patch(p) || p == Point(2, 2, 1)) return q;
    for (int a = 0; a < 3; ++a)
      if (p[a] > 0 && p[a] < n) q[a] += 0.3 * r.next();
    return q;
  });
  const auto id = [](int i, int j, int k) {
    return gp::index_cast(i + (n + 1) * (j + (n + 1) * k));
  };
  gp::KeptFeatures kept;
  kept.surfaces.emplace_back();
  for (int j = 1; j < 3; ++j)
    for (int i = 1; i < 3; ++i)
      kept.surfaces[0].push_back(
          {id(i, j, 2), id(i + 1, j, 2), id(i + 1, j + 1, 2), id(i, j + 1, 2)});
  // A node set: the whole face x = 0 (a boundary condition's), one node inside and one alone on
  // the face y = 0 (points).
  kept.node_sets.emplace_back();
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j) kept.node_sets[0].push_back(id(0, j, k));
  kept.node_sets[0].push_back(id(2, 2, 1));
  kept.node_sets[0].push_back(id(2, 0, 2));
  // A point set at (0, 2, 2) too, inside the face set: the point stays.
  kept.node_sets.push_back({id(0, 1, 2)});

  // The constraints, node by node.
  const auto cons = gp::kept_slide_constraints(start, kept);
  using Kind = NodeConstraint::Kind;
  struct Expected {
    Index node;
    Kind kind;
    Point direction;  // the plane's normal or the line's direction, up to sign
  };
  for (const Expected& e : {Expected{id(2, 2, 2), Kind::kPlane, {0, 0, 1}},
                            Expected{id(1, 2, 2), Kind::kLine, {0, 1, 0}},
                            Expected{id(2, 3, 2), Kind::kLine, {1, 0, 0}},
                            Expected{id(1, 1, 2), Kind::kFixed, {0, 0, 0}},
                            Expected{id(3, 3, 2), Kind::kFixed, {0, 0, 0}},
                            Expected{id(2, 2, 1), Kind::kFixed, {0, 0, 0}},
                            Expected{id(2, 0, 2), Kind::kFixed, {0, 0, 0}},
                            Expected{id(0, 2, 2), Kind::kPlane, {1, 0, 0}},
                            Expected{id(0, 1, 2), Kind::kFixed, {0, 0, 0}},
                            Expected{id(0, 0, 2), Kind::kLine, {0, 0, 1}},
                            Expected{id(0, 0, 0), Kind::kFixed, {0, 0, 0}},
                            Expected{id(2, 1, 1), Kind::kFree, {0, 0, 0}}}) {
    CAPTURE(e.node);
    const NodeConstraint& c = cons[gp::index_cast<std::size_t>(e.node)];
    CHECK(c.kind == e.kind);
    if (e.kind == Kind::kPlane || e.kind == Kind::kLine)
      CHECK(c.direction.normalized().cross(e.direction).norm() < 1e-12);
  }

  // A side set listing both sides of each face (as one inside a block may): the same.
  gp::KeptFeatures both = kept;
  for (const auto& q : kept.surfaces[0]) both.surfaces[0].push_back({q[0], q[3], q[2], q[1]});
  const auto cons_both = gp::kept_slide_constraints(start, both);
  for (std::size_t v = 0; v < cons.size(); ++v) {
    CAPTURE(v);
    CHECK(cons_both[v].kind == cons[v].kind);
  }

  gp::LocalSmoothOptions o;
  o.target = 0.99;
  std::vector<Index> all(start.hexes.size());
  std::iota(all.begin(), all.end(), 0);
  HexMesh local = start, around = start;
  gp::smooth_hexes_local(local, cons, nullptr, {}, o);
  o.kept = &kept;
  gp::smooth_hexes_around(around, all, o);
  for (const HexMesh* m : {&local, &around}) {
    double area = 0.0;
    for (const auto& q : kept.surfaces[0]) {
      for (Index v : q) {
        const Point& x = m->points[gp::index_cast<std::size_t>(v)];
        CHECK(x.z() == 2.0);
        CHECK((x.x() >= 1.0 && x.x() <= 3.0 && x.y() >= 1.0 && x.y() <= 3.0));
      }
      const auto at = [&](int k) { return m->points[gp::index_cast<std::size_t>(q[k])]; };
      area += 0.5 * (at(2) - at(0)).cross(at(3) - at(1)).norm();
    }
    CHECK(area == doctest::Approx(4.0).epsilon(1e-12));
    CHECK(m->points[id(2, 2, 1)] == start.points[id(2, 2, 1)]);
    CHECK(m->points[id(1, 1, 2)] == start.points[id(1, 1, 2)]);
    CHECK(m->points[id(0, 2, 2)].x() == 0.0);
    CHECK(m->points[id(2, 0, 2)] == start.points[id(2, 0, 2)]);
    // The centre and the rims moved (the test would pass on fixed nodes otherwise).
    CHECK((m->points[id(2, 2, 2)] - start.points[id(2, 2, 2)]).norm() > 1e-3);
    CHECK((m->points[id(1, 2, 2)] - start.points[id(1, 2, 2)]).norm() > 1e-6);
  }
}

TEST_CASE("one thread and two threads give the same mesh") {
  HexMesh a = jittered_grid(6, 0.35, 21);
  HexMesh b = a;
  gp::LocalSmoothOptions o;
  o.threads = 1;
  const auto ra = gp::smooth_hexes_local(a, gp::boundary_slide_constraints(a), nullptr, {}, o);
  o.threads = 2;
  const auto rb = gp::smooth_hexes_local(b, gp::boundary_slide_constraints(b), nullptr, {}, o);
  CHECK(ra.patches == rb.patches);
  CHECK(ra.iterations == rb.iterations);
  CHECK(a.points == b.points);  // bit for bit
  CHECK(ra.final_min_scaled_jacobian > ra.initial_min_scaled_jacobian);
}

TEST_CASE("smooth_hexes_around: the submesh around the seeds gives the whole-mesh result") {
  // A bulging top (kSurface nodes), planar sides, a skewed interior; seeds on the boundary and
  // inside, so that the submesh's own boundary differs from the model's.
  HexMesh mesh = grid(5, [](const Point& p) {
    return Point(p.x(), p.y(), p.z() * (1.0 + 0.1 * std::sin(p.x()) * std::sin(p.y())));
  });
  Lcg r{17};
  for (Point& p : mesh.points)
    if (p.minCoeff() > 0 && p.maxCoeff() < 5) p += 0.3 * Point(r.next(), r.next(), r.next());
  std::vector<Index> seeds;
  for (Index h = 0; h < geode::primal::index_cast(mesh.hexes.size()); h += 3) seeds.push_back(h);
  gp::LocalSmoothOptions o;
  o.target = 0.9;
  HexMesh whole = mesh, around = mesh;
  const gp::TriMesh surface = gp::boundary_triangulation(mesh);
  const auto rw =
      gp::smooth_hexes_local(whole, gp::boundary_slide_constraints(mesh), &surface, seeds, o);
  const auto ra = gp::smooth_hexes_around(around, seeds, o);
  CHECK(ra.patches == rw.patches);
  CHECK(ra.patches > 10);
  int moved = 0;
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    CHECK((around.points[v] - whole.points[v]).norm() < 1e-9);
    moved += (around.points[v] - mesh.points[v]).norm() > 1e-3;
  }
  CHECK(moved > 10);
  CHECK(gp::min_scaled_jacobian(around) > gp::min_scaled_jacobian(mesh));
  CHECK_THROWS_AS(gp::smooth_hexes_around(around, std::vector<Index>{999}), geode::InvalidInput);
}
