#include <geode/viewer/html.hpp>

#include <charconv>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <string_view>

#include <geode/io/atomic_file.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>

namespace geode::viewer {

using namespace primal;

// Embedded at build time from resources/ and libjs-three (CMakeLists.txt).
extern const char kViewerHtml[];
extern const char kViewerJs[];
extern const char kThreeJs[];

namespace {

// JSON written by hand for the bulk arrays: coordinates to 7 significant digits keep the file
// small; strings go through nlohmann::json for escaping. Numbers through std::to_chars (its
// general format at precision 7 is printf's "%.7g"; snprintf took a third of a million-hex
// page's writing).
class JsonOut {
 public:
  void key(const char* k) {
    comma();
    s_ += '"';
    s_ += k;
    s_ += "\":";
    first_ = true;
  }
  void raw(std::string_view v) {
    comma();
    s_ += v;
  }
  // '<' only occurs inside strings here; escaping it keeps "</script>" out of the page. A caption
  // naming a file whose name is not UTF-8 gets U+FFFD in its place (JSON text is UTF-8).
  void str(const std::string& v) {
    comma();
    for (char c :
         nlohmann::json(v).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)) {
      if (c == '<')
        s_ += "\\u003c";
      else
        s_ += c;
    }
  }
  void open(char c) {
    comma();
    s_ += c;
    first_ = true;
  }
  void close(char c) {
    s_ += c;
    first_ = false;
  }
  void number(double v) {
    char b[32];
    raw({b,
         std::to_chars(b, b + sizeof b, std::isfinite(v) ? v : 0.0, std::chars_format::general, 7)
             .ptr});
  }
  void index(Index v) {
    char b[16];
    raw({b, std::to_chars(b, b + sizeof b, v).ptr});
  }
  void points(const std::vector<Point>& pts) {
    open('[');
    for (const auto& p : pts) number(p.x()), number(p.y()), number(p.z());
    close(']');
  }
  template <class Rows>
  void rows(const Rows& rows) {
    open('[');
    for (const auto& r : rows)
      for (auto v : r) index(index_cast(v));
    close(']');
  }
  const std::string& text() const { return s_; }

 private:
  void comma() {
    if (!first_) s_ += ',';
    first_ = false;
  }
  std::string s_;
  bool first_ = true;
};

template <class Rows>
void check_ids(const Rows& rows, std::size_t n, const std::string& what) {
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (auto v : rows[r])
      if (v < 0 || index_cast<std::size_t>(v) >= n)
        throw InvalidInput("html viewer: " + what + " " + std::to_string(r + 1) + " refers to id " +
                           std::to_string(static_cast<long long>(v) + 1) + ", out of 1.." +
                           std::to_string(n));
}

std::string html_escape(const std::string& t) {
  std::string out;
  for (char c : t) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

// Passes the page to `out` in pieces, each @NAME@ replaced by its value; inserted text is not
// scanned again. The pieces go to the file as they are: a million-hex page is hundreds of MB,
// and copying it whole (once filled, once escaped) doubled the memory and cost seconds.
template <class Out>
void fill(std::string_view page, const std::map<std::string_view, std::string_view>& values,
          Out&& out) {
  std::size_t at = 0;
  while (true) {
    const std::size_t a = page.find('@', at);
    const std::size_t b = a == std::string_view::npos ? a : page.find('@', a + 1);
    const auto it =
        b == std::string_view::npos ? values.end() : values.find(page.substr(a + 1, b - a - 1));
    if (it == values.end()) {
      if (a == std::string_view::npos) break;
      out(page.substr(at, a + 1 - at));
      at = a + 1;
      continue;
    }
    out(page.substr(at, a - at));
    out(it->second);
    at = b + 1;
  }
  out(page.substr(at));
}

template <std::size_t K, std::size_t C, class Facets>
void write_topology(JsonOut& j, int dim, const std::array<std::array<int, K>, C>& faces,
                    const Facets& facets, const std::vector<std::array<int, 2>>& edges) {
  j.key("dim"), j.index(dim);
  j.key("faces"), j.open('[');
  for (const auto& f : faces) j.rows(std::array<std::array<int, K>, 1>{f});
  j.close(']');
  j.key("facets"), j.open('[');
  for (const auto& f : facets) j.rows(std::array<std::decay_t<decltype(f)>, 1>{f});
  j.close(']');
  j.key("edges"), j.open('[');
  for (const auto& e : edges) j.rows(std::array<std::array<int, 2>, 1>{e});
  j.close(']');
}

// The scene's data (the page's JSON) into j.
template <class Cells>
void page_data(const std::vector<Point>& points, const Cells& cells, const std::vector<int>* block,
               const std::vector<double>& quality, const ViewScene& scene, int dim, JsonOut& j) {
  const std::size_t n = points.size();
  check_ids(cells, n, dim == 3 ? "hex" : "quad");
  j.key("title"), j.str(scene.title);
  j.key("caption"), j.str(scene.caption);
  j.key("corners"), j.index(dim == 3 ? 8 : 4);
  j.key("nodes"), j.points(points);
  j.key("cells"), j.rows(cells);
  j.key("quality_name"),
      j.str(dim == 3 ? "scaled Jacobian (Verdict, hex)" : "scaled Jacobian (Verdict, quad)");
  j.key("quality"), j.open('[');
  for (double q : quality) j.number(q);
  j.close(']');
  if (block && block->size() == cells.size()) {
    j.key("block"), j.open('[');
    for (int b : *block) j.index(b);
    j.close(']');
  }
  j.key("sheets"), j.open('[');
  for (const auto& s : scene.sheets) {
    const bool tris = dim == 3;
    if (tris)
      check_ids(s.surface.tris, s.surface.points.size(), "sheet '" + s.name + "' triangle");
    else
      check_ids(s.curve.segments, s.curve.points.size(), "sheet '" + s.name + "' segment");
    for (Index c : s.layer)
      if (c < 0 || index_cast<std::size_t>(c) >= cells.size())
        throw InvalidInput("html viewer: sheet '" + s.name + "' layer has cell " +
                           std::to_string(c + 1) + ", out of 1.." + std::to_string(cells.size()));
    j.open('{');
    j.key("name"), j.str(s.name);
    j.key("kind"), j.str(s.kind);
    j.key("smooth"), j.raw(s.smooth ? "true" : "false");
    j.key("points"), j.points(tris ? s.surface.points : s.curve.points);
    if (tris)
      j.key("triangles"), j.rows(s.surface.tris);
    else
      j.key("segments"), j.rows(s.curve.segments);
    j.key("layer"), j.open('[');
    for (Index c : s.layer) j.index(c);
    j.close(']');
    j.close('}');
  }
  j.close(']');
  j.key("groups"), j.open('[');
  for (const auto& g : scene.groups) {
    check_ids(g.quads, n, "group '" + g.name + "' face");
    j.open('{');
    j.key("name"), j.str(g.name);
    j.key("quads"), j.rows(g.quads);
    j.close('}');
  }
  j.close(']');
  j.close('}');
}

// The page of `data` (page_data's) passed to `out` in pieces.
template <class Out>
void emit_page(const ViewScene& scene, const JsonOut& data, Out&& out) {
  const std::string title = html_escape(scene.title);
  fill(kViewerHtml,
       {{"GEODE_TITLE", title},
        {"GEODE_THREE", kThreeJs},
        {"GEODE_DATA", data.text()},
        {"GEODE_VIEWER_JS", kViewerJs}},
       out);
}

std::string page_text(const ViewScene& scene, const JsonOut& data) {
  std::string out;
  emit_page(scene, data, [&out](std::string_view piece) { out += piece; });
  return out;
}

void write_page(const std::filesystem::path& path, const ViewScene& scene, const JsonOut& data) {
  io::write_file_atomically(path, [&](std::ostream& os) {
    emit_page(scene, data, [&os](std::string_view piece) {
      os.write(piece.data(), static_cast<std::streamsize>(piece.size()));
    });
  });
}

}  // namespace

ViewFaceGroup boundary_face_group(std::string name, const primal::HexMesh& mesh,
                                  const std::vector<unsigned>& node_faces, int face) {
  if (node_faces.size() != mesh.points.size())
    throw std::invalid_argument("boundary_face_group: " + std::to_string(node_faces.size()) +
                                " node masks for " + std::to_string(mesh.points.size()) + " nodes");
  ViewFaceGroup group{std::move(name), {}};
  for (const auto& q : primal::boundary_quads(mesh)) {
    unsigned common = ~0u;
    for (auto n : q.nodes) common &= node_faces[primal::index_cast<std::size_t>(n)];
    if (common & (1u << face)) group.quads.push_back(q.nodes);
  }
  return group;
}

namespace {

JsonOut scene_data(const HexMesh& mesh, const ViewScene& scene) {
  check_ids(mesh.hexes, mesh.points.size(), "hex");
  std::vector<double> q;
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    q.push_back(hex_scaled_jacobian(hex_corners(mesh, index_cast(h))));
  JsonOut j;
  j.open('{');
  std::vector<std::array<int, 2>> edges(topology::kHexEdgeCorners.begin(),
                                        topology::kHexEdgeCorners.end());
  write_topology(j, 3, topology::kHexFaceCorners, topology::kHexFaceCorners, edges);
  page_data(mesh.points, mesh.hexes, &mesh.block, q, scene, 3, j);
  return j;
}

JsonOut scene_data(const QuadMesh& mesh, const ViewScene& scene) {
  check_ids(mesh.quads, mesh.points.size(), "quad");
  // A planar mesh in z = 0 (a 2D template) is measured against +z, so that a flipped quad shows
  // as inverted; a quad surface in space by its own corners.
  bool planar = true;
  for (const auto& p : mesh.points) planar = planar && p.z() == 0.0;
  std::vector<double> q;
  for (std::size_t i = 0; i < mesh.quads.size(); ++i) {
    const QuadCorners c = quad_corners(mesh, index_cast(i));
    q.push_back(planar ? quad_scaled_jacobian(c, Point::UnitZ()) : quad_scaled_jacobian(c));
  }
  JsonOut j;
  j.open('{');
  std::vector<std::array<int, 2>> edges(topology::kQuadEdgeCorners.begin(),
                                        topology::kQuadEdgeCorners.end());
  write_topology(j, 2, std::array<std::array<int, 4>, 1>{{{0, 1, 2, 3}}},
                 topology::kQuadEdgeCorners, edges);
  page_data(mesh.points, mesh.quads, nullptr, q, scene, 2, j);
  return j;
}

}  // namespace

std::string html_view(const HexMesh& mesh, const ViewScene& scene) {
  return page_text(scene, scene_data(mesh, scene));
}

std::string html_view(const QuadMesh& mesh, const ViewScene& scene) {
  return page_text(scene, scene_data(mesh, scene));
}

void write_html(const std::filesystem::path& path, const HexMesh& mesh, const ViewScene& scene) {
  write_page(path, scene, scene_data(mesh, scene));
}

void write_html(const std::filesystem::path& path, const QuadMesh& mesh, const ViewScene& scene) {
  write_page(path, scene, scene_data(mesh, scene));
}

}  // namespace geode::viewer
