// The HTML viewer end to end: `geode template --format html` and `geode view` write files that
// headless Chromium (Debian's chromium, WebGL through SwiftShader) opens with the network off,
// with no error reported by the page, a screenshot that is not blank, and a picture that changes
// when a sheet is hidden through the URL hash.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>

#include <geode/io/vtk.hpp>
#include <geode/viewer/html.hpp>
#include "support/cli_run.hpp"
#include "support/fixtures.hpp"
#include "support/png.hpp"

using namespace geode;
using test::geode_cli;

namespace {

using test::slurp;

// Runs headless Chromium on `url` with `mode` (--dump-dom, or --screenshot=FILE); returns its
// standard output. The network is off: a dead proxy and no host names resolve.
std::string chromium(const test::TempDir& dir, const std::string& mode, const std::string& url) {
  const std::string cmd =
      "chromium --headless --no-sandbox --disable-gpu --no-first-run "
      "--disable-background-networking"
      " --disable-component-update --disable-sync --user-data-dir='" +
      (dir.path / "profile").string() +
      "'"
      " --use-angle=swiftshader --enable-unsafe-swiftshader --proxy-server=127.0.0.1:9"
      " --host-resolver-rules='MAP * ~NOTFOUND' --window-size=480,360 --virtual-time-budget=5000 " +
      mode + " '" + url + "' 2>/dev/null";
  FILE* p = ::popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  std::string out;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  ::pclose(p);
  return out;
}

// What the page wrote into #status after loading ("viewer-ok ..." or "viewer-error: ...").
std::string page_status(const test::TempDir& dir, const std::string& url) {
  const std::string dom = chromium(dir, "--dump-dom", url);
  const std::smatch m = [&] {
    std::smatch r;
    std::regex_search(dom, r, std::regex("<pre id=\"status\">([^<]*)<"));
    return r;
  }();
  return m.size() > 1 ? m[1].str() : "no status in: " + dom.substr(0, 200);
}

test::Image screenshot(const test::TempDir& dir, const std::string& url, const std::string& name) {
  const auto png = dir.path / name;
  chromium(dir, "--screenshot=" + png.string(), url);
  REQUIRE_MESSAGE(std::filesystem::exists(png), "chromium wrote no screenshot of " << url);
  return test::read_png(png);
}

double fraction_not_white(const test::Image& im) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < im.rgb.size(); i += 3)
    n += im.rgb[i] < 245 || im.rgb[i + 1] < 245 || im.rgb[i + 2] < 245;
  return static_cast<double>(n) / (im.rgb.size() / 3);
}

double fraction_changed(const test::Image& a, const test::Image& b) {
  REQUIRE(a.rgb.size() == b.rgb.size());
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.rgb.size(); i += 3)
    n += a.rgb[i] != b.rgb[i] || a.rgb[i + 1] != b.rgb[i + 1] || a.rgb[i + 2] != b.rgb[i + 2];
  return static_cast<double>(n) / (a.rgb.size() / 3);
}

// The page without the bodies of its inline scripts (the opening tags are kept).
std::string markup_only(const std::string& html) {
  std::string out;
  std::size_t at = 0;
  while (true) {
    const std::size_t open = html.find("<script", at);
    if (open == std::string::npos) break;
    const std::size_t body = html.find('>', open);
    REQUIRE(body != std::string::npos);
    out.append(html, at, body + 1 - at);
    at = html.find("</script>", body);
    REQUIRE(at != std::string::npos);
  }
  return out + html.substr(at);
}

bool have_chromium() { return std::system("command -v chromium >/dev/null 2>&1") == 0; }

}  // namespace

TEST_CASE("viewer: the geode's HTML opens offline, draws, and hiding a sheet changes the picture") {
  REQUIRE_MESSAGE(have_chromium(), "chromium is not installed (scripts/common.sh installs it)");
  test::TempDir dir;
  const auto html = dir.path / "geode.html";
  REQUIRE(geode_cli("template geode3d --format html -o " + html.string()).code == 0);
  const std::string text = slurp(html);

  // Nothing to fetch: no element loads a file, and the only URLs are inside three.js's own code
  // (the XHTML namespace it passes to createElementNS, a reference in a shader comment).
  const std::string markup = markup_only(text);
  for (const char* load :
       {"src=", "href=", "url(", "<link", "<iframe", "<object", "<embed", "@import"})
    CHECK_MESSAGE(markup.find(load) == std::string::npos,
                  "the page's markup loads something: " << load);
  const std::regex url("https?://[^\"' )]*");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), url); it != std::sregex_iterator();
       ++it) {
    const std::string u = it->str();
    CHECK_MESSAGE((u == "http://www.w3.org/1999/xhtml" ||
                   u == "https://graphics.stanford.edu/papers/envmap/envmap.pdf"),
                  "unexpected URL in the page: " << u);
  }
  CHECK(text.find("default-src 'none'") !=
        std::string::npos);  // and the page's policy forbids loads

  const std::string file = "file://" + html.string();
  // Loaded with the sheets hidden and a layer picked, then hovered at the centre: the tip names a
  // hex and its nodes exactly as the CSV output numbers them (1-based).
  const std::string status = page_status(dir, file + "#sheets=none&layer=tunnel-x&probe=240,180");
  CHECK_MESSAGE(
      status.rfind("viewer-ok hexes=26 sheets=6 shown=0 layer=tunnel-x peel=0 depth=1 probe: hex ",
                   0) == 0,
      status);
  std::smatch tip;
  REQUIRE_MESSAGE(
      std::regex_search(status, tip,
                        std::regex("probe: hex ([0-9]+) .*nodes ([0-9 ]+) \\| node ([0-9]+) ")),
      status);
  const auto csv = geode_cli("template geode3d --format csv");
  REQUIRE(csv.code == 0);
  const std::string row =
      "\n" + tip[1].str() + "," + std::regex_replace(tip[2].str(), std::regex(" "), ",") + "\n";
  CHECK_MESSAGE(csv.out.find(row) != std::string::npos,
                "hex row " << row << " not in the CSV output");
  CHECK((" " + tip[2].str() + " ").find(" " + tip[3].str() + " ") != std::string::npos);

  const test::Image all = screenshot(dir, file + "#hexes=0&ui=0", "all.png");
  CHECK(all.width == 480);
  CHECK(fraction_not_white(all) > 0.1);
  const test::Image hidden = screenshot(dir, file + "#hexes=0&ui=0&hide=tunnel-x", "hidden.png");
  CHECK(fraction_changed(all, hidden) > 0.01);
}

TEST_CASE("viewer: geode view shows any hex or quad mesh with its dual sheets") {
  REQUIRE_MESSAGE(have_chromium(), "chromium is not installed (scripts/common.sh installs it)");
  test::TempDir dir;
  const auto hex = dir.path / "grid.vtu", quad = dir.path / "grid2d.vtu";
  io::write_vtu(hex, test::structured_hex_grid(3, 2, 2));
  io::write_vtu(quad, test::structured_quad_grid(3, 2));
  const auto h = dir.path / "grid.html", q = dir.path / "grid2d.html";
  REQUIRE(geode_cli("view " + hex.string() + " -o " + h.string()).code == 0);
  REQUIRE(geode_cli("view " + quad.string() + " -o " + q.string()).code == 0);
  // A 3 x 2 x 2 grid has 3 + 2 + 2 sheets (planes); a 3 x 2 quad grid 5 chords.
  const std::string hs = page_status(dir, "file://" + h.string()),
                    qs = page_status(dir, "file://" + q.string());
  CHECK_MESSAGE(hs.rfind("viewer-ok hexes=12 sheets=7 shown=7", 0) == 0, hs);
  CHECK_MESSAGE(qs.rfind("viewer-ok quads=6 sheets=5", 0) == 0, qs);
  // Its stages on stderr as they end (the page is the output: all it prints); none with --quiet.
  const auto said = geode_cli("view " + hex.string() + " -o " + h.string(), true);
  REQUIRE(said.code == 0);
  test::check_stage_lines(said.out, {"read " + hex.string() + ": 12 hexes, 36 nodes",
                                     "dual: 7 sheets", "sheet surfaces", "wrote " + h.string()});
  const auto quads = geode_cli("view " + quad.string() + " -o " + q.string(), true);
  REQUIRE(quads.code == 0);
  test::check_stage_lines(quads.out, {"read " + quad.string() + ": 6 quads, 12 nodes",
                                      "dual: 5 chords", "chord curves", "wrote " + q.string()});
  const auto quiet = geode_cli("view " + hex.string() + " -o " + h.string() + " --quiet", true);
  REQUIRE(quiet.code == 0);
  CHECK(quiet.out.empty());
  // Refusals: an output that is not .html, a missing input.
  CHECK(geode_cli("view " + hex.string() + " -o " + (dir.path / "x.vtu").string()).code == 2);
  CHECK(geode_cli("view " + (dir.path / "missing.vtu").string() + " -o " + h.string()).code == 2);
}

TEST_CASE("viewer: the page's data: coordinates as printf's %.7g, strings escaped, file = text") {
  // One hex with a corner per awkward value: rounding up a digit, exponents both ways, the
  // smallest subnormal, the largest double, a negative zero; NaN is written as 0.
  primal::HexMesh m = test::structured_hex_grid(1, 1, 1);
  const std::vector<double> values = {0.1,
                                      -0.0,
                                      1e-5,
                                      123456789.0,
                                      1234567.,
                                      0.00012345678,
                                      9.9999995,
                                      0.000099999995,
                                      1e300,
                                      5e-324,
                                      1.0 / 3,
                                      -2.5e-5,
                                      1.7976931348623157e308,
                                      0.5,
                                      1e16,
                                      std::numeric_limits<double>::quiet_NaN()};
  std::size_t k = 0;
  for (auto& p : m.points)
    for (int i = 0; i < 3; ++i) p[i] = values[k++ % values.size()];
  viewer::ViewScene scene;
  scene.title = "a </script> & \"b\"";
  const std::string page = viewer::html_view(m, scene);
  const std::size_t from = page.find("\"nodes\":[");
  REQUIRE(from != std::string::npos);
  const std::size_t begin = from + 9, end = page.find(']', begin);
  std::string expected;
  k = 0;
  for (std::size_t n = 0; n < 3 * m.points.size(); ++n) {
    const double v = values[k++ % values.size()];
    char b[40];
    std::snprintf(b, sizeof b, "%.7g", std::isfinite(v) ? v : 0.0);
    expected += (n ? "," : "") + std::string(b);
  }
  CHECK(page.substr(begin, end - begin) == expected);
  // The title: in the data as a JSON string with '<' escaped (no "</script>" ends the script
  // early), in <title> HTML-escaped.
  CHECK(page.find("a \\u003c/script> & \\\"b\\\"") != std::string::npos);
  CHECK(page.find("a &lt;/script&gt; &amp; &quot;b&quot;") != std::string::npos);
  CHECK(page.find("a </script>") == std::string::npos);
  test::TempDir dir;
  viewer::write_html(dir.path / "one.html", m, scene);
  CHECK(slurp(dir.path / "one.html") == page);
}
