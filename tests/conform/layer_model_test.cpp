// A thin hex layer with a few wedges in it between tets on both sides, as Gmsh makes one
// (tests/conform/layer_model.py: a curved surface recombined with a few triangles left, extruded
// in 2 cells into tet potting, tets inside too, pyramids on the layer's quads). Split into tets
// only, the wedges left holes through the layer: on the sphere two layer hexes met along an edge
// only between two holes (exit 3 from either side), on the cylinder the buffer hexes at the holes'
// walls were flat (0.004, 0.08 x the yardstick) or inverted from the tet side (exit 4). conform
// now splits the layer into tets and dices it with the tets around it; a layer that cannot be
// split (a quad under four tet triangles, which no split of its hex follows) keeps its hexes as
// before.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <initializer_list>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <geode/conform/buffer_layer.hpp>
#include <geode/conform/conform.hpp>
#include <geode/conform/report.hpp>
#include <geode/io/formats.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/split_pyramids.hpp>
#include <geode/primal/unfold.hpp>
#include <geode/primal/validity.hpp>

#include "../support/cli_run.hpp"
#include "../support/conform_checks.hpp"
#include "../support/sanitized.hpp"
#include "../support/temp_dir.hpp"

namespace geode {

using primal::Index;
using primal::Point;

namespace {

// `covering`: read_model's covering check (off: a folded mesh read as it is).
primal::Model layer_model(const test::TempDir& dir, const std::string& args, bool covering = true) {
  const std::string file = (dir.path / "layer.msh").string();
  const std::string cmd = "/usr/bin/python3 '" + std::string(GEODE_SOURCE_DIR) +
                          "/tests/conform/layer_model.py' '" + file + "' " + args;
  REQUIRE_MESSAGE(std::system(cmd.c_str()) == 0, cmd);
  return io::read_model(file, {}, covering);
}

double side_set_area(const primal::Model& m, const primal::SideSet& s) {
  double area = 0.0;
  for (const primal::Side& side : s.sides) {
    const auto f = primal::element_face(m, side);
    const auto at = [&](std::size_t i) { return m.points[primal::index_cast<std::size_t>(f[i])]; };
    for (std::size_t i = 1; i + 1 < f.size(); ++i)  // a fan: exact for triangles
      area += 0.5 * (at(i) - at(0)).cross(at(i + 1) - at(0)).norm();
  }
  return area;
}

// Whether some warning of r holds every one of `parts`.
bool layer_warned(const conform::ConformResult& r, std::initializer_list<std::string_view> parts) {
  return std::any_of(r.warnings.begin(), r.warnings.end(), [&](const std::string& w) {
    return std::all_of(parts.begin(), parts.end(),
                       [&](std::string_view p) { return w.find(p) != std::string::npos; });
  });
}

}  // namespace

TEST_CASE("a thin hex layer with wedges through it between tets is split into tets, valid") {
  const test::TempDir dir;
  // sphere: exit 3 before (two layer hexes along an edge); cylinder 0.04 thick: 0.004 from the
  // hex side, exit 4 from the tet side.
  for (const std::string args : {"sphere 6 out 0.1", "cylinder 6 out 0.04"}) {
    CAPTURE(args);
    const primal::Model input = layer_model(dir, args);
    REQUIRE(!input.wedges.empty());
    REQUIRE(!input.pyramids.empty());
    Point lo = input.points.front(), hi = lo;
    for (const Point& p : input.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double box = (hi - lo).prod();
    // Either side, with and without smoothing: no buffer layer is left to carve.
    for (const auto& [side, smooth] :
         {std::pair{conform::BufferSide::kHex, conform::ConformSmooth::kLocal},
          std::pair{conform::BufferSide::kTet, conform::ConformSmooth::kLocal},
          std::pair{conform::BufferSide::kHex, conform::ConformSmooth::kNone}}) {
      CAPTURE(static_cast<int>(side));
      CAPTURE(static_cast<int>(smooth));
      conform::ConformOptions o;
      o.buffer.side = side;
      o.smooth = smooth;
      const conform::ConformResult r = conform::conform(input, o);
      test::check_conform_result(r, 0, 1);
      CHECK(r.warnings.front().find(std::to_string(input.hexes.size()) + " hexes and " +
                                    std::to_string(input.wedges.size()) +
                                    " wedges split into tets: wedges go through the layer of "
                                    "wedge ") == 0);
      CHECK(r.hexes_split == primal::index_cast(input.hexes.size()));
      CHECK(r.wedges_split == primal::index_cast(input.wedges.size()));
      CHECK(r.input_hexes == primal::index_cast(input.hexes.size()));
      CHECK(r.input_tets == primal::index_cast(input.tets.size()));
      CHECK(r.interface_quads == 0);
      // At or above the yardstick (its cells as conform split them, diced alone).
      const double lowest = primal::min_scaled_jacobian(primal::hex_part(r.model));
      CHECK(lowest >= r.yardstick());
      CHECK(lowest > 0.01);  // the buffer at the holes gave 0.004 on the cylinder
      // The blocks keep their names and cells: the core's and the potting's tets 4 hexes
      // each and their pyramids 8, the layer the rest; the sphere's box's volume to rounding.
      for (const auto& [id, name] : input.block_names) CHECK(r.model.block_names.at(id) == name);
      std::map<int, std::size_t> count, expected;
      for (int b : r.model.hex_block) ++count[b];
      for (int b : input.tet_block) expected[b] += 4;
      for (int b : input.pyramid_block) expected[b] += 8;
      REQUIRE(count.size() == 3);
      CHECK(count.at(1) == expected.at(1));
      CHECK(count.at(3) == expected.at(3));
      CHECK(count.at(2) >= 4 * 5 * input.hexes.size() + 12 * input.wedges.size());
      double sum = 0.0;
      for (const auto& [block, volume] : test::hex_block_volumes(r.model)) sum += volume;
      // (The cylinder's layer ends stick out of the box's bottom and top by up to 0.0018:
      // Gmsh's normals at its rims are not quite level.)
      if (args.starts_with("sphere")) CHECK(std::abs(sum - box) <= 1e-9 * box);
      // The sets: the skin is every boundary quad of the output; the surface the layer was
      // extruded from keeps its area (its quads' triangles, to their non-planarity).
      const primal::HexValidityReport v = primal::check_validity(primal::hex_part(r.model));
      REQUIRE(r.model.side_sets.size() == 2);
      std::set<std::array<Index, 4>> boundary, skin;
      for (const auto& q : v.boundary.faces) boundary.insert(primal::face_key(q.nodes));
      for (const primal::Side& s : r.model.side_sets[0].sides)
        skin.insert(primal::face_key(primal::element_face(r.model, s)));
      CHECK(r.model.side_sets[0].name == "skin");
      CHECK(skin == boundary);
      CHECK(r.model.side_sets[1].name == "surface");
      const double area = side_set_area(input, input.side_sets[1]);
      CHECK(std::abs(side_set_area(r.model, r.model.side_sets[1]) - area) <= 1e-2 * area);
    }
  }
}

TEST_CASE("a thin layer in 3 or 4 cells, equal or graded, is split into tets, valid") {
  // The extruded surface's nodes are numbered before the cells' inner ones, so the outermost
  // cell's lowest node is on its top face, whose pyramid's split gives it a diagonal; its faces
  // are warped about as much as the cell is high, so the lowest-node diagonal below crossing it
  // left a tet inverted: the layer kept its hexes (0.0036 to 0.0048 from the hex side, exit 4
  // from the tet side) until the faces between the cells took their diagonals along the
  // columns (primal/split_hexes.hpp).
  const test::TempDir dir;
  for (const std::string args :
       {"cylinder 6 out 0.06 cells=3", "cylinder 6 out 0.06 cells=3 ratio=1.3",
        "cylinder 6 out 0.08 cells=4"}) {
    CAPTURE(args);
    const primal::Model input = layer_model(dir, args);
    REQUIRE(!input.wedges.empty());
    for (const auto side : {conform::BufferSide::kHex, conform::BufferSide::kTet}) {
      if (side == conform::BufferSide::kTet && !args.ends_with("cells=3")) continue;
      CAPTURE(static_cast<int>(side));
      conform::ConformOptions o;
      o.buffer.side = side;
      const conform::ConformResult r = conform::conform(input, o);
      test::check_conform_result(r, 0, 1);
      CHECK(r.warnings.front().find(std::to_string(input.hexes.size()) + " hexes and " +
                                    std::to_string(input.wedges.size()) +
                                    " wedges split into tets: ") == 0);
      CHECK(r.hexes_split == primal::index_cast(input.hexes.size()));
      CHECK(r.wedges_split == primal::index_cast(input.wedges.size()));
      const double lowest = primal::min_scaled_jacobian(primal::hex_part(r.model));
      CHECK(lowest >= r.yardstick());
      CHECK(lowest > 0.03);  // 0.048 to 0.05
    }
  }
}

TEST_CASE("a layer whose pyramids force crossing diagonals is split, their pyramids re-split") {
  // Cells 0.01 high on a radius of 0.4 (0.02 in 2 cells, 0.03 in 3): a face's triangles dip
  // about as much as the cell is high, and the pyramids on both sides force the column's two
  // end diagonals so that some cell's must cross the wrong way. The layer kept its hexes (0.0012
  // with the defaults, 0.0001 without smoothing, exit 4 from the tet side, and in 3 cells exit
  // 4 without smoothing too) until a pyramid's face took the diagonal its column needs, its two
  // tets split along it instead (its side triangles kept).
  const test::TempDir dir;
  for (const std::string args : {"cylinder 5 out 0.02", "cylinder 5 out 0.03 cells=3"}) {
    CAPTURE(args);
    const primal::Model input = layer_model(dir, args);
    REQUIRE(!input.wedges.empty());
    REQUIRE(!input.pyramids.empty());
    for (const auto smooth : {conform::ConformSmooth::kLocal, conform::ConformSmooth::kNone})
      for (const auto side : {conform::BufferSide::kHex, conform::BufferSide::kTet}) {
        if (smooth == conform::ConformSmooth::kNone && side == conform::BufferSide::kTet) continue;
        CAPTURE(static_cast<int>(smooth));
        CAPTURE(static_cast<int>(side));
        conform::ConformOptions o;
        o.smooth = smooth;
        o.buffer.side = side;
        const conform::ConformResult r = conform::conform(input, o);
        test::check_conform_result(r, 0, 1);
        CHECK(r.hexes_split == primal::index_cast(input.hexes.size()));
        const double lowest = primal::min_scaled_jacobian(primal::hex_part(r.model));
        CHECK(lowest >= r.yardstick());
        CHECK(lowest > 0.02);  // 0.028 to 0.029
      }
  }
}

TEST_CASE("a thin layer that cannot be split keeps its hexes, valid, and says which one") {
  // The 0.1 cylinder's layer with one pyramid on it made four tets around its base's middle (a
  // node a tet mesher may put there): no split of the hex under it follows those four
  // triangles, so only the wedges are split, as for a thick layer, and the four-triangle quad
  // gets its template: valid, the hex named in a warning, rather than a refusal.
  const test::TempDir dir;
  primal::Model input = layer_model(dir, "cylinder 6 out 0.1");
  REQUIRE(!input.pyramids.empty());
  const std::size_t p = 0, last = input.pyramids.size() - 1;
  const auto pyramid = input.pyramids[p];
  const int block = primal::block_of(input, {primal::ElementKind::kPyramid, primal::index_cast(p)});
  Point middle = Point::Zero();
  for (std::size_t i = 0; i < 4; ++i)
    middle += input.points[primal::index_cast<std::size_t>(pyramid[i])] / 4.0;
  input.points.push_back(middle);
  if (!input.node_ids.empty())  // the next file id
    input.node_ids.push_back(*std::max_element(input.node_ids.begin(), input.node_ids.end()) + 1);
  const Index centre = primal::index_cast(input.points.size() - 1);
  std::int64_t id = 1;
  for (std::int64_t t : input.tet_ids) id = std::max(id, t + 1);
  for (std::size_t i = 0; i < 4; ++i)
    primal::add_element(input, primal::ElementKind::kTet,
                        std::array<Index, 4>{pyramid[i], pyramid[(i + 1) % 4], centre, pyramid[4]},
                        block, id++);
  // The pyramid gone: the last one in its place (no side names the pyramid, inside the model).
  for (primal::SideSet& set : input.side_sets)
    for (primal::Side& side : set.sides)
      if (side.element.kind == primal::ElementKind::kPyramid) {
        REQUIRE(side.element.index != primal::index_cast(p));
        if (side.element.index == primal::index_cast(last))
          side.element.index = primal::index_cast(p);
      }
  input.pyramids[p] = input.pyramids[last];
  input.pyramids.pop_back();
  if (!input.pyramid_block.empty())
    input.pyramid_block[p] = input.pyramid_block.back(), input.pyramid_block.pop_back();
  if (!input.pyramid_ids.empty())
    input.pyramid_ids[p] = input.pyramid_ids.back(), input.pyramid_ids.pop_back();
  const conform::ConformResult r = conform::conform(input);
  // Three warnings: the layer kept (naming the hex), its wedges split, the buffer carved
  // from the tets; one four-triangle quad, whose template is larger than the geode.
  test::check_conform_result(r, r.geode_hexes, 3);
  CHECK(r.geode_hexes > 26 * r.interface_quads);
  CHECK(r.hexes_split == 0);
  CHECK(r.wedges_split > 0);
  CHECK(r.interface_quads > 0);
  CHECK(primal::min_scaled_jacobian(primal::hex_part(r.model)) > 0.0);
  CHECK(layer_warned(r, {"its hexes stay hexes: hex ", "lies under four tet triangles"}));
}

TEST_CASE("a thicker layer whose holes give a poor transition is split into tets after all") {
  // 0.2 thick in 2 cells, 0.6 of their width high: too thick to be split at once, so its wedges
  // alone were split and the buffer hexes at the holes' walls (60 degrees apart around a
  // triangle) gave 0.015 with --smooth none and 0.025 with the defaults, below the input's own
  // elements diced alone (0.037). Conformed again split into tets: 0.145.
  const test::TempDir dir;
  const primal::Model input = layer_model(dir, "cylinder 6 out 0.2");
  REQUIRE(!input.wedges.empty());
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;
  // The output handed to the caller's writer is the one returned, once: the holes' pass wrote
  // its own (0.0066 on the 0.3-thick layer, in the file of a run that reported 0.118).
  std::vector<primal::Model> written;
  std::vector<double> written_sj;
  o.write_ahead_scaled_jacobians = true;
  o.write_ahead = [&](const primal::Model& m, std::span<const double> sj) {
    written.push_back(m);
    written_sj.assign(sj.begin(), sj.end());
  };
  const conform::ConformResult r = conform::conform(input, o);
  REQUIRE(written.size() == 1);
  CHECK(written.front().points == r.model.points);
  CHECK(written.front().hexes == r.model.hexes);
  REQUIRE(written_sj.size() == r.model.hexes.size());
  CHECK(*std::min_element(written_sj.begin(), written_sj.end()) ==
        conform::output_min_scaled_jacobian(r));
  test::check_conform_result(r, -1, r.warnings.size());            // the split's and the volumes'
  CHECK(r.hexes_split == primal::index_cast(input.hexes.size()));  // the layer is every hex
  CHECK(r.diced_hexes == 0);
  CHECK(r.wedges_split == primal::index_cast(input.wedges.size()));
  CHECK(conform::output_min_scaled_jacobian(r) >= r.yardstick());
  REQUIRE(!r.warnings.empty());
  CHECK(r.warnings.front().find("with its wedges alone split, the buffer hexes at the holes") !=
        std::string::npos);
}

// Skipped in the sanitized build (tests/support/sanitized.hpp; 133 s there): the next test runs
// a quads-only layer's conform under the sanitizers, placement, untangling and smoothing.
TEST_CASE("the same layer recombined into quads only keeps its hexes and gets the geode" *
          doctest::skip(test::kSanitized)) {
  const test::TempDir dir;
  const primal::Model input = layer_model(dir, "cylinder 6 out 0.1 quads");
  REQUIRE(input.wedges.empty());
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;  // the smoothing is most of its time, and not this
  const conform::ConformResult r = conform::conform(input, o);
  test::check_conform_result(r, -1, 1);  // carved from the tets (the layer's cells are thin)
  CHECK(r.warnings.front().find("buffer layer carved from the tet part") == 0);
  CHECK(r.hexes_split == 0);
  CHECK(r.interface_quads == primal::index_cast(input.pyramids.size()));
  CHECK(r.diced_hexes == 8 * primal::index_cast(input.hexes.size()));
  // The hex side chosen (--buffer-side hex) is kept where its output is valid: no switch, no
  // warning (with --smooth none 4 hexes stay inverted: the tet part's is taken then, as the
  // test below checks on a thinner layer).
  conform::set_buffer_side(o, "hex");
  o.smooth = conform::ConformSmooth::kLocal;
  const conform::ConformResult chosen = conform::conform(input, o);
  CHECK(conform::result_valid(chosen));
  CHECK(chosen.buffer_side == conform::BufferSide::kHex);
  for (const std::string& w : chosen.warnings)
    CHECK(w.find("buffer layer carved from the tet part") == std::string::npos);
  conform::set_buffer_side(o, "");
  CHECK(!o.buffer_side_chosen);
  CHECK(o.buffer.side == conform::BufferSide::kHex);
}

TEST_CASE("a layer whose holes take no buffer layer is split into tets after all") {
  // The sphere's layer 0.15 thick at n = 6 (Gmsh folds a tet of it too: unfolded first) is too
  // thick to be split at once; with its wedges alone split, no direction at a node where a
  // hole's wall meets the layer's face lies above all its interface faces, from either side:
  // refused (exit 3) until the layer was split into tets on that refusal as on a poor result.
  const test::TempDir dir;
  primal::Model input = layer_model(dir, "sphere 6 out 0.15", false);
  REQUIRE(!input.wedges.empty());
  REQUIRE(primal::unfold(input).unfolded());
  const conform::ConformResult r = conform::conform(input);
  test::check_conform_result(r, 0, r.warnings.size());
  CHECK(r.hexes_split == primal::index_cast(input.hexes.size()));
  CHECK(r.wedges_split == primal::index_cast(input.wedges.size()));
  CHECK(conform::output_min_scaled_jacobian(r) >= r.yardstick());
  CHECK(layer_warned(r, {"split into tets: ", "the holes they leave take no buffer layer"}));
}

TEST_CASE("a pyramid Gmsh folds over a quads-only layer's hex is turned back by unfold") {
  // At n = 4 and 8 Gmsh puts a pyramid's apex on the hex's side of its twisted base quad, positive
  // along one diagonal and ordered to read so: it lies on the same side as the hex and its four
  // tets (refused, exit 2). unfold turns it back and moves its apex out into its tets.
  const test::TempDir dir;
  const primal::Model folded = layer_model(dir, "cylinder 4 out 0.15 quads", false);
  primal::InputCheckOptions every;
  every.max_findings = 100;
  const primal::InputCheckResult before = primal::check_input(folded, every);
  REQUIRE(before.findings.size() == 5);  // the pyramid against the hex and its four tets
  for (const primal::InputFinding& f : before.findings) {
    CHECK(f.fault == primal::InputFault::kSameSideFace);
    REQUIRE(f.elements.size() == 2);
    CHECK(f.elements[1] == before.findings[0].elements[1]);
    CHECK(f.elements[1].kind == primal::ElementKind::kPyramid);
  }
  const primal::ElementRef pyramid = before.findings[0].elements[1];
  CHECK(before.findings[0].elements[0].kind == primal::ElementKind::kHex);

  primal::Model m = folded;
  const primal::UnfoldResult u = primal::unfold(m);
  REQUIRE(u.unfolded());
  REQUIRE(u.turned.size() == 1);
  CHECK(u.turned[0] == pyramid);
  const auto p = primal::index_cast<std::size_t>(pyramid.index);
  REQUIRE(u.moved.size() == 1);
  CHECK(u.moved[0] == folded.pyramids[p][4]);  // its apex
  CHECK(u.covered_once);
  CHECK(primal::check_input(m).ok());
  REQUIRE_NOTHROW(primal::check_geometry(m, "unfolded"));
  // The pyramid's base reversed, nothing else: the apex alone moved, by less than the layer is
  // thick.
  CHECK(m.pyramids[p] == std::array<Index, 5>{folded.pyramids[p][0], folded.pyramids[p][3],
                                              folded.pyramids[p][2], folded.pyramids[p][1],
                                              folded.pyramids[p][4]});
  for (std::size_t i = 0; i < m.pyramids.size(); ++i)
    if (i != p) CHECK(m.pyramids[i] == folded.pyramids[i]);
  CHECK(m.tets == folded.tets);
  CHECK(m.hexes == folded.hexes);
  std::size_t moved = 0;
  for (std::size_t v = 0; v < m.points.size(); ++v) moved += m.points[v] != folded.points[v];
  CHECK(moved == 1);
  CHECK(u.farthest < 0.15);
  // Now along both diagonals positive, the apex beyond the base as the hex's face has it.
  const auto& c = m.pyramids[p];
  const auto at = [&](std::size_t i) { return m.points[primal::index_cast<std::size_t>(c[i])]; };
  for (std::size_t k = 0; k < 4; ++k)
    CHECK(primal::tet_volume(at((k + 3) % 4), at(k), at((k + 1) % 4), at(4)) > 0.0);

  // Another pyramid's apex pushed just through its base, its node order kept: inverted along
  // both diagonals as read (Gmsh writes such pyramids, beside tets it writes twice), refused by
  // the readers' geometry check, which --unfold runs after it instead. Its apex moves back out.
  primal::Model pushed = m;
  const std::size_t q = (p + 1) % m.pyramids.size();
  const auto qc = pushed.pyramids[q];
  Point centre = Point::Zero();
  for (std::size_t i = 0; i < 4; ++i)
    centre += pushed.points[primal::index_cast<std::size_t>(qc[i])] / 4.0;
  Point& apex = pushed.points[primal::index_cast<std::size_t>(qc[4])];
  apex = centre - 0.2 * (apex - centre);
  CHECK_THROWS_WITH_AS(primal::check_geometry(pushed, "pushed"), doctest::Contains("inverted"),
                       InvalidInput);
  const primal::Model before_mend = pushed;
  const primal::UnfoldResult mended = primal::unfold(pushed);
  REQUIRE(mended.unfolded());
  CHECK(mended.turned.empty());
  CHECK(std::find(mended.inverted.begin(), mended.inverted.end(),
                  primal::ElementRef{primal::ElementKind::kPyramid, primal::index_cast(q)}) !=
        mended.inverted.end());
  CHECK(mended.moved == std::vector<Index>{qc[4]});
  CHECK(primal::check_input(pushed).ok());
  CHECK_NOTHROW(primal::check_geometry(pushed, "mended"));
  CHECK(pushed.pyramids == before_mend.pyramids);
  CHECK(pushed.tets == before_mend.tets);

  // Not in the sanitized build (the thin layer's conform: tens of seconds there; the unfold
  // above runs there).
  if (test::kSanitized) return;
  const conform::ConformResult r = conform::conform(m);
  CHECK(conform::result_valid(r));
  test::check_conform_result(r, -1, r.warnings.size());
  CHECK(conform::output_min_scaled_jacobian(r) >= r.yardstick());
  // The command: the file with the folded pyramid and the inverted one, refused naming the
  // inverted one (the geometry check comes first), conformed with --unfold.
  const auto file = dir.path / "pushed.msh", out = dir.path / "pushed.exo";
  primal::Model both = before_mend;
  both.pyramids[p] = folded.pyramids[p];
  both.points[primal::index_cast<std::size_t>(folded.pyramids[p][4])] =
      folded.points[primal::index_cast<std::size_t>(folded.pyramids[p][4])];
  io::write_model(both, file);
  const auto refused = test::geode_cli("conform " + file.string() + " -o " + out.string(), true);
  CHECK(refused.code == 2);
  CHECK(refused.out.find("is inverted at its base corner") != std::string::npos);
  CHECK(refused.out.find("--unfold mends such cells") != std::string::npos);
  const auto run = test::geode_cli(
      "conform " + file.string() + " -o " + out.string() + " --unfold --quiet", true);
  INFO(run.out);
  CHECK(run.code == 0);
  CHECK(run.out.find("--unfold: 1 pyramid folded over its neighbours turned back, 1 pyramid "
                     "read inverted, nodes ") != std::string::npos);
  CHECK(std::filesystem::exists(out));
}

TEST_CASE("templates a quads-only layer's buffer hexes invert are untangled, then smoothed") {
  // Placement leaves 32 hexes inverted in 16 templates (warped interface quads); two rings of
  // untangling left 4 (exit 4, found by a fault hunt), four rings none.
  const test::TempDir dir;
  const primal::Model input = layer_model(dir, "cylinder 6 in 0.1 quads");
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;
  const conform::ConformResult r = conform::conform(input, o);
  CHECK(r.placement_inverted > 0);
  test::check_conform_result(r, -1, r.warnings.size());  // the volumes' warnings only
  CHECK(r.smoothing.final_inverted == 0);
  CHECK(conform::result_valid(r));
  // Not in the sanitized build (85 s there): the run above untangles under the sanitizers, and
  // the smoothing below runs there in the materials and local-yardstick tests.
  if (test::kSanitized) return;
  // The default smoothing untangles them first, then only raises the minimum: before, its
  // passes started from the inverted hexes and ended at 0.029, below --smooth none's 0.033.
  const conform::ConformResult smoothed = conform::conform(input);
  CHECK(conform::result_valid(smoothed));
  CHECK(conform::output_min_scaled_jacobian(smoothed) >= conform::output_min_scaled_jacobian(r));
}

TEST_CASE("a quads-only layer nearly thin: the tets' layer is tried too, the better kept") {
  // 0.15 thick outward in 2 cells: carved from the hex part, its buffer hexes are 0.228 of their
  // edge high (not thin: 0.2), the tet part's 0.195; yet the hex part's gave 0.0178 with
  // --smooth none and 0.029 with the defaults, the tet part's 0.0222 and 0.073 (found by a fault
  // hunt).
  const test::TempDir dir;
  const primal::Model input = layer_model(dir, "cylinder 6 out 0.15 quads");
  REQUIRE(input.wedges.empty());
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;
  std::vector<primal::Model> written;
  o.write_ahead = [&](const primal::Model& m, std::span<const double>) { written.push_back(m); };
  const conform::ConformResult r = conform::conform(input, o);
  test::check_conform_result(r, -1, r.warnings.size());  // this warning and the volumes'
  CHECK(r.buffer_side == conform::BufferSide::kTet);
  CHECK(r.warnings.front().find("from the hex part's thin cells") != std::string::npos);
  REQUIRE(written.size() == 1);  // the one returned, not the hex part's first
  CHECK(written.front().points == r.model.points);
  conform::set_buffer_side(o, "hex");
  o.write_ahead = nullptr;
  const conform::ConformResult hex = conform::conform(input, o);
  CHECK(conform::result_valid(hex));
  CHECK(conform::output_min_scaled_jacobian(r) > 1.2 * conform::output_min_scaled_jacobian(hex));
}

TEST_CASE("--buffer-side hex on a thin graded layer gives an invalid output: the tets' is taken") {
  // Graded by 1.5 in 3 cells, the hex part's buffer is 0.072 of the quads' edge high: 67
  // hexes stayed inverted with the defaults, exit 4 (found by a fault hunt); the automatic side
  // takes the tets' at once.
  const test::TempDir dir;
  const primal::Model input = layer_model(dir, "cylinder 6 out 0.1 quads cells=3 ratio=1.5");
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;  // invalid too, and faster
  conform::set_buffer_side(o, "hex");
  const conform::ConformResult r = conform::conform(input, o);
  test::check_conform_result(r, -1, r.warnings.size());  // this warning and the volumes'
  CHECK(r.buffer_side == conform::BufferSide::kTet);
  CHECK(r.warnings.front().find("not the hex part given") != std::string::npos);
  CHECK(r.warnings.front().find("the output was invalid") != std::string::npos);
}

TEST_CASE("a quads-only layer graded from a thin side is carved from the tets: per piece") {
  // Graded out by 1.3 from a 0.048-high first cell to a 0.107-high last: carved from the hex
  // part, the inner side's buffer hexes are 0.16 of their edge high, the outer's more, 0.2 on
  // average over both; decided over the whole interface, the hex part's layer was kept and
  // geode hexes on the thin side came out inverted (exit 4, found by a fault hunt).
  const test::TempDir dir;
  const primal::Model input = layer_model(dir, "cylinder 5 out 0.3 quads cells=4 ratio=1.3");
  REQUIRE(input.wedges.empty());
  const primal::Model tets = primal::split_pyramids(input).model;  // as conform does first
  const conform::BufferLayer from_hexes =
      conform::insert_buffer_layer(tets, primal::find_interface(tets));
  const std::vector<Index> piece = conform::interface_pieces(from_hexes);
  const std::vector<double> ratio = conform::buffer_height_ratios(from_hexes);
  REQUIRE(ratio.size() == piece.size());
  double sum = 0.0, mean[2] = {0.0, 0.0};
  int count[2] = {0, 0};
  for (std::size_t h = 0; h < piece.size(); ++h) {
    REQUIRE(piece[h] >= 0);
    REQUIRE(piece[h] < 2);  // the layer's inner and outer sides
    sum += ratio[h];
    mean[piece[h]] += ratio[h], ++count[piece[h]];
  }
  REQUIRE(count[0] > 0);
  REQUIRE(count[1] > 0);
  CHECK(sum / static_cast<double>(piece.size()) >= 0.2);          // the whole interface: not thin
  CHECK(std::min(mean[0] / count[0], mean[1] / count[1]) < 0.2);  // one side is
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;  // invalid with it too, and faster
  const conform::ConformResult r = conform::conform(input, o);
  test::check_conform_result(r, -1, 1);  // the warning below
  CHECK(r.buffer_side == conform::BufferSide::kTet);
  CHECK(r.warnings.front().find("on the interface's thinnest piece") != std::string::npos);
}

}  // namespace geode
