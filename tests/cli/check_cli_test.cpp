// The `geode check` command end to end: the geode has no obstruction, the plain four-triangle
// dual has pinched corners and its 24-hex class doublets (each confirmed here by counting faces
// in the file read back, not by the library), ids are the file's own, refusals exit 2.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include <geode/io/gmsh.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/topology.hpp>
#include "support/cli_run.hpp"
#include "support/demo_input.hpp"
#include "support/fixtures.hpp"

using namespace geode;
using primal::Index;
using test::geode_cli;

namespace {

// The faces of hex h as sorted node keys.
std::set<primal::FaceKey> faces_of(const primal::HexMesh& m, Index h) {
  std::set<primal::FaceKey> out;
  for (const auto& f : primal::topology::kHexFaceCorners) {
    std::array<Index, 4> q{};
    for (int i = 0; i < 4; ++i) q[i] = m.hexes[h][f[i]];
    out.insert(primal::face_key(q));
  }
  return out;
}

// Distinct faces of the mesh with a corner at v whose two neighbours in the face are a and b.
std::size_t faces_at_corner(const primal::HexMesh& m, Index v, Index a, Index b) {
  std::set<primal::FaceKey> found;
  for (std::size_t h = 0; h < m.hexes.size(); ++h)
    for (const auto& f : primal::topology::kHexFaceCorners)
      for (int i = 0; i < 4; ++i) {
        if (m.hexes[h][f[i]] != v) continue;
        const Index p = m.hexes[h][f[(i + 3) % 4]], n = m.hexes[h][f[(i + 1) % 4]];
        if ((p == a && n == b) || (p == b && n == a)) {
          std::array<Index, 4> q{};
          for (int k = 0; k < 4; ++k) q[k] = m.hexes[h][f[k]];
          found.insert(primal::face_key(q));
        }
      }
  return found.size();
}

nlohmann::json check_json(const std::filesystem::path& file) {
  const auto r = geode_cli("check " + file.string() + " --format json");
  REQUIRE(r.code == 0);
  return nlohmann::json::parse(r.out);
}

std::size_t count_kind(const nlohmann::json& j, const std::string& kind) {
  return static_cast<std::size_t>(
      std::count_if(j["obstructions"].begin(), j["obstructions"].end(),
                    [&](const nlohmann::json& o) { return o["kind"] == kind; }));
}

}  // namespace

TEST_CASE("geode check: the geode has no obstruction, the four-triangle duals do") {
  test::TempDir dir;
  const auto geode = dir.path / "geode.vtu", plain = dir.path / "plain4.vtu",
             c24 = dir.path / "class24.vtu";
  REQUIRE(geode_cli("template geode3d --format vtu -o " + geode.string()).code == 0);
  // The plain four-triangle duals are invalid (exit 4); written on request to be checked.
  REQUIRE(geode_cli("template geode4tri --no-fixup --no-smooth --write-invalid --format vtu -o " +
                    plain.string())
              .code == 4);
  REQUIRE(geode_cli("template geode4tri --no-fixup --no-smooth --write-invalid --high-roof 0.5 "
                    "--low-roof 0.45 "
                    "--dome-depth 0.9 --dome-radius 0.4 --format vtu -o " +
                    c24.string())
              .code == 4);

  const auto g = check_json(geode);
  CHECK(g["valid"] == true);
  CHECK(g["index_base"] == 0);
  CHECK(g["obstructions"].empty());
  CHECK(g["quality"]["num_hexes"] == 26);

  SUBCASE("plain four-triangle dual: pinched corners") {
    const auto j = check_json(plain);
    const primal::HexMesh m = io::to_hex_mesh(io::read_vtu(plain));
    CHECK(m.hexes.size() == 36);
    REQUIRE(count_kind(j, "pinched-corner") >= 1);
    for (const auto& o : j["obstructions"]) {
      if (o["kind"] != "pinched-corner") continue;
      const auto n = o["nodes"].get<std::vector<Index>>();
      REQUIRE(n.size() == 3);
      CHECK(faces_at_corner(m, n[0], n[1], n[2]) >= 2);
    }
  }

  SUBCASE("its 24-hex class: doublets") {
    const auto j = check_json(c24);
    const primal::HexMesh m = io::to_hex_mesh(io::read_vtu(c24));
    CHECK(m.hexes.size() == 24);
    REQUIRE(count_kind(j, "doublet") >= 1);
    for (const auto& o : j["obstructions"]) {
      if (o["kind"] != "doublet") continue;
      const auto h = o["hexes"].get<std::vector<Index>>();
      REQUIRE(h.size() == 2);
      std::vector<primal::FaceKey> shared;
      const auto a = faces_of(m, h[0]), b = faces_of(m, h[1]);
      std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(shared));
      CHECK(shared.size() >= 2);
    }
  }

  SUBCASE("template --format json and the warning name the same obstructions") {
    const auto t =
        geode_cli("template geode4tri --no-fixup --no-smooth --write-invalid --format json");
    REQUIRE(t.code == 4);
    const auto tj = nlohmann::json::parse(t.out);
    const auto cj = check_json(plain);
    REQUIRE(tj["obstructions"].size() == cj["obstructions"].size());
    for (std::size_t i = 0; i < cj["obstructions"].size(); ++i) {
      CHECK(tj["obstructions"][i]["kind"] == cj["obstructions"][i]["kind"]);
      // The template numbers from 1, the .vtu file from 0.
      for (std::size_t k = 0; k < cj["obstructions"][i]["nodes"].size(); ++k)
        CHECK(tj["obstructions"][i]["nodes"][k].get<int>() ==
              cj["obstructions"][i]["nodes"][k].get<int>() + 1);
    }
    const auto smoothed =
        geode_cli("template geode4tri --no-fixup --write-invalid --format csv", true);
    const std::size_t n = cj["obstructions"].size();
    CHECK(smoothed.out.find(
              "smoothing could not untangle every element; no placement can: " + std::to_string(n) +
              (n == 1 ? " obstruction" : " obstructions")) != std::string::npos);
    CHECK(smoothed.out.find("pinched-corner: hexes") != std::string::npos);
  }
}

TEST_CASE("geode check: text report, quad meshes, the file's own numbering") {
  test::TempDir dir;
  SUBCASE("a clean quad grid, in text") {
    const auto in = dir.path / "quads.vtk";
    io::write_vtk(in, test::structured_quad_grid(3, 2));
    const auto r = geode_cli("check " + in.string());
    REQUIRE(r.code == 0);
    CHECK(r.out.find("quad mesh") != std::string::npos);
    CHECK(r.out.find("realizability: no obstructions found") != std::string::npos);
  }
  SUBCASE("a quad doublet") {
    primal::QuadMesh q = test::structured_quad_grid(3, 3);
    const Index e = primal::index_cast(q.points.size());
    q.points.emplace_back(1.6, 1.4, 0.0);
    const auto c = q.quads[4];
    q.quads[4] = {c[0], c[1], c[2], e};
    q.quads.push_back({c[0], e, c[2], c[3]});
    const auto in = dir.path / "doublet.vtu";
    io::write_vtu(in, q);
    const auto j = check_json(in);
    CHECK(j["dimension"] == 2);
    REQUIRE(j["obstructions"].size() == 1);
    CHECK(j["obstructions"][0]["kind"] == "doublet");
    CHECK(j["obstructions"][0]["hexes"] == nlohmann::json{4, 9});
  }
  SUBCASE("Gmsh numbers from 1") {
    // Two unit hexes side by side.
    primal::Model model = primal::grid_model({2, 1, 1}, 1.0, [](int, int, int) { return false; });
    const auto in = dir.path / "two.msh";
    io::write_gmsh(model, in);
    const auto j = check_json(in);
    CHECK(j["index_base"] == 1);
    CHECK(j["valid"] == true);
    CHECK(j["obstructions"].empty());
    CHECK(j["quality"]["metrics"][0]["min_hex"].get<int>() >= 1);
    // The second hex mirrored (x -> 2 - x, its corners as they were): inverted. The validity
    // lines number it and its face's nodes as the file does (they were 0-based under the header
    // "numbered from 1": hex 1, nodes {1 4 7 10}; found by a fault hunt).
    for (primal::Point& p : model.points)
      if (p.x() > 1.5) p.x() = 0.5;
    io::write_gmsh(model, in);
    const auto t = geode_cli("check " + in.string());
    REQUIRE(t.code == 0);
    CHECK(t.out.find("numbered from 1") != std::string::npos);
    CHECK(t.out.find("hexes with a non-positive corner Jacobian: 1 (2)") != std::string::npos);
    const auto k = check_json(in);
    CHECK(k["validity"].get<std::string>().find("Jacobian: 1 (2)") != std::string::npos);
  }
  SUBCASE("refusals") {
    CHECK(geode_cli("check " + (dir.path / "missing.vtu").string()).code == 2);
    // A Gmsh file named .vtu: refused before any parser, naming what it holds.
    const auto in = dir.path / "gmsh.vtu";
    io::write_gmsh(primal::grid_model({2, 1, 1}, 1.0, [](int, int, int) { return false; }), in);
    const auto r = geode_cli("check " + in.string(), true);
    CHECK(r.code == 2);
    CHECK(r.out.find(in.string() + ": ") != std::string::npos);
    CHECK(r.out.find("Gmsh") != std::string::npos);
    CHECK(geode_cli("check " + in.string() + " --format yaml").code != 0);
  }
}

TEST_CASE("geode check: -o picks the report's format by its extension, the input is never -o") {
  test::TempDir dir;
  const auto in = dir.path / "quads.vtk";
  io::write_vtk(in, test::structured_quad_grid(3, 2));
  const auto contents = [](const std::filesystem::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  SUBCASE("-o r.json writes JSON, -o r.txt text") {
    const auto json = dir.path / "r.json", text = dir.path / "r.txt";
    REQUIRE(geode_cli("check " + in.string() + " -o " + json.string()).code == 0);
    const auto j = nlohmann::json::parse(contents(json));
    CHECK(j["dimension"] == 2);
    CHECK(j["valid"] == true);
    REQUIRE(geode_cli("check " + in.string() + " -o " + text.string()).code == 0);
    CHECK(contents(text).find("realizability: no obstructions found") != std::string::npos);
  }
  SUBCASE("a --format that contradicts the extension is refused, nothing written") {
    const auto out = dir.path / "r.txt";
    const auto r = geode_cli("check " + in.string() + " --format json -o " + out.string(), true);
    CHECK(r.code == 2);
    CHECK(r.out.find("contradicts the extension") != std::string::npos);
    CHECK(!std::filesystem::exists(out));
  }
  SUBCASE("-o the input: refused without a --force hint (check has none), the input kept") {
    // Through a link with a report's name: the mesh's own name is refused by its extension.
    const auto link = dir.path / "r.txt";
    std::filesystem::create_symlink(in, link);
    const std::string before = contents(in);
    const auto r = geode_cli("check " + in.string() + " -o " + link.string(), true);
    CHECK(r.code == 2);
    CHECK(r.out.find("is the input file") != std::string::npos);
    CHECK(r.out.find("--force") == std::string::npos);
    CHECK(contents(in) == before);
    const auto v = geode_cli("view " + in.string() + " -o " + in.string(), true);
    CHECK(v.code == 2);
    CHECK(v.out.find("is the input file") != std::string::npos);
    CHECK(v.out.find("--force") == std::string::npos);
    CHECK(contents(in) == before);
    // conform has --force: its refusal names it.
    const auto c = geode_cli("conform " + in.string() + " -o " + in.string(), true);
    CHECK(c.code == 2);
    CHECK(c.out.find("(--force overwrites it)") != std::string::npos);
  }
}

TEST_CASE("geode check: an invalid mesh is reported INVALID in every format, not refused") {
  // The plain four-triangle dual (inverted hexes) written to each format: .exo and .msh were
  // refused at the read (exit 2, the read-time check's "is inverted"), .vtu and .vtk reported
  // (found by a fault hunt).
  test::TempDir dir;
  for (const std::string ext : {"vtu", "vtk", "exo", "msh"}) {
    CAPTURE(ext);
    const auto file = dir.path / ("plain4." + ext);
    REQUIRE(geode_cli("template geode4tri --no-fixup --no-smooth --write-invalid --format " + ext +
                      " -o " + file.string())
                .code == 4);
    const auto j = check_json(file);  // exit 0: checked
    CHECK(j["valid"] == false);
    CHECK(j["quality"]["num_hexes"] == 36);
    bool scaled = false;
    for (const auto& metric : j["quality"]["metrics"])
      if (metric["key"] == "scaled_jacobian") {
        scaled = true;
        CHECK(metric["min"].get<double>() <= 0.0);
      }
    CHECK(scaled);
  }
}

TEST_CASE("geode check: hexes that interpenetrate are invalid, though a valid complex") {
  // Two unit hexes, the second moved by (0.3, 0.3, 0.3): they share no face, so the complex is
  // valid and every Jacobian positive; `check` said "valid" where conform refuses the file
  // (a fault hunt's). The covering check is run on an all-hex mesh too.
  test::TempDir dir;
  primal::HexMesh m;
  for (const double shift : {0.0, 0.3})
    for (const auto& c : primal::topology::kHexCornerCoords)
      m.points.emplace_back(c[0] + shift, c[1] + shift, c[2] + shift);
  m.hexes = {{0, 1, 2, 3, 4, 5, 6, 7}, {8, 9, 10, 11, 12, 13, 14, 15}};
  const auto file = dir.path / "overlap.vtu";
  io::write_vtu(file, m);
  const auto j = check_json(file);
  CHECK(j["valid"] == false);
  const std::string text = j["validity"].get<std::string>();
  CHECK(text.find("invalid (it overlaps itself)") != std::string::npos);
  CHECK(text.find("the mesh overlaps itself or folds") != std::string::npos);
  CHECK(text.find("the boundary of hex 0 ") != std::string::npos);
  // Apart, the same two are valid.
  for (std::size_t v = 8; v < 16; ++v) m.points[v] += primal::Point(3, 0, 0);
  io::write_vtu(file, m);
  CHECK(check_json(file)["valid"] == true);
}

TEST_CASE("geode check: its stages on stderr as they end, none with --quiet, the report the same") {
  test::TempDir dir;
  const auto hex = dir.path / "grid.vtu", quad = dir.path / "grid2d.vtk";
  io::write_vtu(hex, test::structured_hex_grid(3, 2, 2));
  io::write_vtk(quad, test::structured_quad_grid(3, 2));
  const auto contents = [](const std::filesystem::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  for (const auto& in : {hex, quad}) {
    CAPTURE(in);
    const std::string cells = in == hex ? "12 hexes" : "6 quads";
    // The report to a file: what the command prints is its standard error alone.
    const auto report = dir.path / "r.txt";
    const auto r = geode_cli("check " + in.string() + " -o " + report.string(), true);
    REQUIRE(r.code == 0);
    test::check_stage_lines(r.out, {"read " + in.string() + ": " + cells + ", ", "validity: valid",
                                    "quality: ", "realizability: 0 obstructions"});
    const std::string text = contents(report);
    const auto quiet =
        geode_cli("check " + in.string() + " -o " + report.string() + " --quiet", true);
    REQUIRE(quiet.code == 0);
    CHECK(quiet.out.empty());
    CHECK(contents(report) == text);
    // Standard output holds the report alone, as before.
    const auto out = geode_cli("check " + in.string());
    REQUIRE(out.code == 0);
    CHECK(out.out == text);
  }
  // A refused input is still one line: nothing is said before the read.
  const auto misnamed = dir.path / "gmsh.vtu";  // Gmsh's content under another extension
  io::write_gmsh(primal::grid_model({2, 1, 1}, 1.0, [](int, int, int) { return false; }), misnamed);
  const auto bad = geode_cli("check " + misnamed.string(), true);
  CHECK(bad.code == 2);
  CHECK(std::count(bad.out.begin(), bad.out.end(), '\n') == 1);
}

TEST_CASE("geode check: a hybrid mesh gets conform's input checks, every finding listed") {
  test::TempDir dir;
  // Gmsh's hexdominant demo as a user saves it (hexes, tets, Gmsh's pyramids, wedges): passes.
  // Saved as .vtu too (the demo's default), whose reader gave hexes or nothing.
  (void)test::demo_input("hexdominant", 4, dir, ".msh");
  (void)test::demo_input("hexdominant", 4, dir, ".vtu");
  for (const std::string ext : {".msh", ".vtu"}) {
    CAPTURE(ext);
    const auto ok = check_json(dir.path / ("hexdominant" + ext));
    CHECK(ok["valid"] == true);
    CHECK(ok["elements"]["hexes"].get<int>() > 0);
    CHECK(ok["elements"]["tets"].get<int>() > 0);
    CHECK(ok["elements"]["pyramids"].get<int>() > 0);
    CHECK(ok["elements"]["wedges"].get<int>() > 0);
    CHECK(ok["quality"].is_null());
    CHECK(ok["finding_count"] == 0);
    CHECK(ok["findings"].empty());
  }
  // Two hex cells beside two tet cells on copies of every node (parts meshed apart, not
  // merged): each tet face against a hex face is a finding, all of them listed (conform
  // refuses at the first), ids as the file numbers them.
  io::write_gmsh(test::unmerged_parts({4, 3, 3}), dir.path / "unmerged.msh");
  const auto r = geode_cli("check " + (dir.path / "unmerged.msh").string());
  INFO(r.out);
  CHECK(r.code == 0);
  std::size_t against = 0;
  for (std::size_t at = r.out.find("lie against each other"); at != std::string::npos;
       at = r.out.find("lie against each other", at + 1))
    ++against;
  CHECK(against > 8);  // past conform's first few
  CHECK(r.out.find("conform's input checks: " + std::to_string(against) + " findings") !=
        std::string::npos);
  const nlohmann::json unmerged = check_json(dir.path / "unmerged.msh");
  CHECK(unmerged["valid"] == false);
  CHECK(unmerged["finding_count"] == against);
  REQUIRE(unmerged["findings"].size() == against);
  CHECK(unmerged["findings"][0].get<std::string>().find("lie against each other") !=
        std::string::npos);
  // Two inverted tets and an inverted hex: every element the geometry check refuses (conform's
  // read names the first), each once, by its file id.
  primal::Model inverted =
      primal::grid_model({2, 1, 1}, 1.0, [](int i, int, int) { return i >= 1; });
  std::swap(inverted.tets[0][0], inverted.tets[0][1]);
  std::swap(inverted.tets[3][0], inverted.tets[3][1]);
  auto& hex = inverted.hexes[0];  // top and bottom faces swapped: inverted at every corner
  std::rotate(hex.begin(), hex.begin() + 4, hex.end());
  io::write_gmsh(inverted, dir.path / "inverted.msh");
  const auto bad = geode_cli("check " + (dir.path / "inverted.msh").string());
  INFO(bad.out);
  CHECK(bad.code == 0);
  std::size_t listed = 0;
  for (std::size_t at = bad.out.find(" is inverted"); at != std::string::npos;
       at = bad.out.find(" is inverted", at + 1))
    ++listed;
  CHECK(listed == 3);
  CHECK(bad.out.find("conform's input checks: 3 elements or nodes refused") != std::string::npos);
  CHECK(bad.out.find("\n  hex ") != std::string::npos);
  const nlohmann::json j = check_json(dir.path / "inverted.msh");
  CHECK(j["valid"] == false);
  CHECK(j["finding_count"] == 3);
  REQUIRE(j["findings"].size() == 3);
  for (const auto& f : j["findings"])
    CHECK(f.get<std::string>().find(" is inverted") != std::string::npos);
}
