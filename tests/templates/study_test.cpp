// Parameter studies (templates/study.hpp): the interleave sweep must find the paper's geode as
// one class among others, the class key must be a graph invariant, and templates mapped into
// distorted buffer cells must keep their nodes on the cell's faces.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>

#include <tbb/global_control.h>

#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity.hpp>
#include <geode/templates/study.hpp>

using namespace geode;
using templates::GeodeOptions;

TEST_CASE("interleave study: the default push is the 26-hex geode, and other outcomes exist") {
  // A 2 x 2 x 2 x 2 grid around the paper's push (0.85, 0.6, 0.9, 0.6); 0.3 for the low roof and
  // 0.5 for the dome depth leave the tunnels' crossing curve untouched by any dome, which
  // cannot dualize (a 1-cell with no vertex), so the sweep must report errors as well.
  const templates::PushGrid grid{{0.85, 0.95}, {0.3, 0.6}, {0.5, 0.9}, {0.3, 0.6}};
  const auto study = templates::interleave_study(GeodeOptions{}, grid, "geode3d");
  REQUIRE(study.runs.size() == 16);
  const auto def = std::find_if(study.runs.begin(), study.runs.end(), [](const auto& r) {
    return r.push.high_roof == 0.85 && r.push.low_roof == 0.6 && r.push.dome_depth == 0.9 &&
           r.push.dome_radius == 0.6;
  });
  REQUIRE(def != study.runs.end());
  CHECK(def->valid);
  CHECK(def->hexes == 26);
  CHECK(def->conditions_ok);
  const auto cls = std::find_if(study.classes.begin(), study.classes.end(),
                                [&](const auto& c) { return c.label == def->class_label; });
  REQUIRE(cls != study.classes.end());
  CHECK(cls->hexes == 26);
  CHECK(cls->key.rfind("26h|", 0) == 0);
  // Its key is the key of the template built directly.
  CHECK(cls->key == templates::template_class_key(templates::build_geode3d(GeodeOptions{})));
  CHECK(study.classes.size() >= 2);
  const bool has_error =
      std::any_of(study.runs.begin(), study.runs.end(), [](const auto& r) { return !r.valid; });
  CHECK(has_error);
  // Every run is counted in exactly one class.
  int total = 0;
  for (const auto& c : study.classes) total += c.count;
  CHECK(total == primal::index_cast<int>(study.runs.size()));
  for (const auto& r : study.runs)
    if (!r.valid) CHECK(r.diagnosis.find_first_of("0123456789.") == r.diagnosis.find("1-cell"));
  // The geode's class is a usable template; no class with an obstruction is ever untangled.
  CHECK(cls->obstructions.empty());
  CHECK(cls->usable);
  CHECK(cls->min_sj_fixed > 0.3);
  CHECK(cls->min_sj_slide > 0.3);
  // Every obstruction but the pinched corner forbids positive Jacobians outright.
  for (const auto& c : study.classes) {
    if (!c.valid || c.obstructions.empty()) continue;
    CHECK_FALSE(c.usable);
    const bool absolute =
        std::any_of(c.obstructions.begin(), c.obstructions.end(), [](const primal::Obstruction& o) {
          return o.kind != primal::ObstructionKind::kPinchedCorner;
        });
    if (!absolute) continue;
    CHECK(c.min_sj_fixed <= 0.0);
    CHECK(c.min_sj_slide <= 0.0);
  }
}

TEST_CASE(
    "a pinched corner the smoother 'untangles' is a double cover, and check_validity says so") {
  // A 30-hex class meeting the paper's conditions with one pinched corner at an interior node:
  // with the tet and hex sides sliding, the smoother reaches positive Jacobians, but the hexes
  // around that node wrap twice around it (their corner solid angles sum to 8 pi).
  GeodeOptions o;
  o.push = {0.55, 0.5, 0.97, 0.8};
  templates::Template t = templates::build_geode3d(o);
  REQUIRE(t.hex.hexes.size() == 30);
  CHECK(t.checks.ok());
  const auto obstructions = templates::template_obstructions(t);
  REQUIRE(obstructions.size() == 1);
  REQUIRE(obstructions[0].kind == primal::ObstructionKind::kPinchedCorner);
  const primal::Index v = obstructions[0].nodes[0];
  CHECK(t.node_faces[v] == 0u);  // interior
  const auto r = templates::smooth_template(t, true);
  const auto report = primal::check_validity(t.hex);
  INFO(report.summary());
  // Never valid: inverted, or (what the smoother reaches today) positive but overlapping.
  CHECK_FALSE(report.ok());
  if (r.final_min_scaled_jacobian <= 0.0)
    return;  // whether it untangles is the smoother's business
  CHECK(report.inverted_hexes.empty());
  // That node and no other, interior or boundary.
  REQUIRE(report.overlapping_nodes.size() == 1);
  CHECK(report.overlapping_nodes[0].node == v);
  CHECK(report.overlapping_nodes[0].angle == doctest::Approx(8 * M_PI));
  CHECK(report.overlapping_nodes[0].expected == doctest::Approx(4 * M_PI));
  CHECK(report.summary().find("cover more than once (corner solid angles): 1 (" +
                              std::to_string(v) + ": 8 pi, not 4 pi)") != std::string::npos);
}

TEST_CASE(
    "template_obstructions: none on the geode, pinched corners and doublets on four-triangle "
    "duals") {
  auto kinds = [](const std::vector<primal::Obstruction>& o) {
    std::map<primal::ObstructionKind, int> n;
    for (const auto& x : o) ++n[x.kind];
    return n;
  };
  CHECK(templates::template_obstructions(templates::build_geode3d(GeodeOptions{})).empty());
  CHECK(templates::template_obstructions(templates::build_geode2d(GeodeOptions{})).empty());
  GeodeOptions four;
  four.split = templates::TopSplit::kFourTriangles;
  const auto plain = kinds(templates::template_obstructions(templates::build_geode3d(four)));
  CHECK(plain.count(primal::ObstructionKind::kPinchedCorner));
  four.push = {0.5, 0.45, 0.9, 0.4};
  const auto t24 = templates::build_geode3d(four);
  CHECK(t24.hex.hexes.size() == 24);
  const auto c24 = kinds(templates::template_obstructions(t24));
  CHECK(c24.count(primal::ObstructionKind::kDoublet));
}

TEST_CASE("interleave study: the same tables on one thread and on every core") {
  // The pushes are built in parallel; the runs are grouped in case order, so the CSV tables
  // must not depend on the thread count (nor on which push finishes first).
  const templates::PushGrid grid{{0.85, 0.95}, {0.3, 0.6}, {0.5, 0.9}, {0.3, 0.6}};
  auto tables = [&] {
    const auto study = templates::interleave_study(GeodeOptions{}, grid, "geode3d");
    std::ostringstream csv, summary;
    templates::write_interleave_csv(csv, study);
    templates::write_interleave_summary(summary, study);
    return csv.str() + "\n" + summary.str();
  };
  std::string one;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = tables();
  }
  const std::string all = tables();
  CHECK(one.find("V1") != std::string::npos);
  CHECK(one == all);
}

TEST_CASE("interleave study: grid points with low >= high are skipped") {
  const templates::PushGrid grid{{0.6}, {0.6, 0.7}, {0.9}, {0.6}};
  CHECK(templates::interleave_study(GeodeOptions{}, grid, "geode3d").runs.empty());
}

TEST_CASE("template_class_key: invariant under renumbering, different for a different template") {
  const auto T = templates::build_geode3d(GeodeOptions{});
  const std::string key = templates::template_class_key(T);
  // Reverse the node numbering and rotate the hex list: an isomorphic template.
  auto R = T;
  const auto n = primal::index_cast(T.hex.points.size());
  for (std::size_t i = 0; i < T.hex.points.size(); ++i) {
    R.hex.points[primal::index_cast<std::size_t>(n) - 1 - i] = T.hex.points[i];
    R.node_faces[primal::index_cast<std::size_t>(n) - 1 - i] = T.node_faces[i];
  }
  std::rotate(R.hex.hexes.begin(), R.hex.hexes.begin() + 5, R.hex.hexes.end());
  std::rotate(R.element_sheets.begin(), R.element_sheets.begin() + 5, R.element_sheets.end());
  for (auto& h : R.hex.hexes)
    for (auto& v : h) v = n - 1 - v;
  CHECK(templates::template_class_key(R) == key);
  // Swapping the two tunnels' heights mirrors the geode: same kinds, still the same class.
  GeodeOptions z;
  z.higher = templates::Higher::kZ;
  CHECK(templates::template_class_key(templates::build_geode3d(z)) == key);
  // Four triangles on the tet side: five domes, a different template.
  GeodeOptions four;
  four.split = templates::TopSplit::kFourTriangles;
  CHECK(templates::template_class_key(templates::build_geode3d(four)) != key);
}

TEST_CASE("strip_numbers: measures go, names stay") {
  CHECK(templates::strip_numbers("sheets 'dome (+x,-z)' meet at (0.25, -1e-3, 7) near node 12") ==
        "sheets 'dome (+x,-z)' meet at (#) near node #");
  CHECK(templates::strip_numbers("condition 2: a 1-cell from face 3") ==
        "condition 2: a 1-cell from face #");
}

TEST_CASE(
    "smooth_in_cell: a sheared cell keeps tet/hex-side nodes on their planes and side nodes on "
    "theirs") {
  const GeodeOptions o;
  const auto cell = templates::sheared_cell(o.box, 30.0);
  const double shift = 14.0 * std::tan(M_PI / 6);  // top face moved by h tan(30 deg) along +x
  CHECK(cell[2].x() == doctest::Approx(-12 + shift));
  CHECK(cell[7].x() == doctest::Approx(12 + shift));
  for (bool slide : {false, true}) {
    auto T = templates::build_geode3d(o);
    const auto before = T.hex.points;
    const auto r = templates::smooth_in_cell(T, o.box, cell, slide);
    CHECK(r.untangled);
    CHECK(r.final_min_scaled_jacobian > 0.0);
    // The checks below only look at nodes on faces: make sure there are such nodes (9 on the
    // diced hex side, 11 on the diced tet side, and some on the x- and z-faces).
    int on_y = 0, on_x = 0, on_z = 0;
    for (unsigned f : T.node_faces)
      on_y += (f & (3u << 2)) != 0, on_x += (f & 3u) != 0, on_z += (f & (3u << 4)) != 0;
    CHECK(on_y == 20);
    CHECK(on_x > 0);
    CHECK(on_z > 0);
    for (std::size_t i = 0; i < T.hex.points.size(); ++i) {
      const auto& p = T.hex.points[i];
      const auto& q = before[i];
      const unsigned f = T.node_faces[i];
      // y-faces: the planes y = -7, 7; fixed mode: exactly the mapped diced position
      // (x shifted by (y + 7)/14 * shift, as the trilinear map of a shear is affine).
      if (f & (3u << 2)) {
        CHECK(p.y() == doctest::Approx(q.y()));
        if (!slide) {
          CHECK(p.x() == doctest::Approx(q.x() + (q.y() + 7) / 14 * shift));
          CHECK(p.z() == doctest::Approx(q.z()));
        }
      }
      // z-faces stay planes z = -12, 12; x-faces are the slanted planes x - (y + 7)/14 shift =
      // +-12.
      if (f & (3u << 4)) CHECK(std::abs(p.z()) == doctest::Approx(12));
      if (f & 3u) CHECK(std::abs(p.x() - (p.y() + 7) / 14 * shift) == doctest::Approx(12));
    }
  }
}

TEST_CASE("smooth_in_cell: a twisted (non-planar) cell is rejected") {
  auto cell = templates::box_cell({24, 14, 24});
  cell[7].y() += 3.0;  // lifts one top corner: the top face is no longer planar
  auto T = templates::build_geode3d(GeodeOptions{});
  CHECK_THROWS_AS(templates::smooth_in_cell(T, {24, 14, 24}, cell, false), InvalidInput);
}
