#pragma once
// A self-contained HTML viewer of a hex (or planar quad) mesh with named surfaces: one file that
// opens in any browser with no network. three.js (Debian's libjs-three) and the viewer's own page
// and script (viewer/viewer.html, viewer/viewer.js) are embedded at build time; the mesh,
// surfaces and layers go in as JSON. The page shows the cells (shrink, explode, peeling from the
// outside in), each surface with a toggle and its name, the layer of cells of each surface
// (alone or highlighted), colour by scaled Jacobian with a legend, and ids on hover, 1-based as
// the appendix and CSV outputs print them. URL hash parameters select a view (listed at the top
// of viewer/viewer.js), for figures and tests.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::viewer {

// A sheet (or any named surface) to show: a triangulated surface in 3D, a curve in 2D, and
// the cells of its layer (0-based).
struct ViewSheet {
  std::string name;
  std::string kind;  // e.g. "tunnel", "dome", "mesh"; tunnels and domes get their own colours
  primal::TriMesh surface;           // 3D
  primal::SegmentMesh curve;         // 2D
  bool smooth = false;               // consistently oriented: shade with interpolated normals
  std::vector<primal::Index> layer;  // cells dual to the sheet
};

// Named faces of the mesh to show on demand (e.g. the tet and hex sides of a template).
struct ViewFaceGroup {
  std::string name;
  std::vector<std::array<primal::Index, 4>> quads;  // node ids, 0-based
};

// The boundary quads of `mesh` whose four nodes all have bit `face` in `node_faces` (one mask
// per node: the box faces a template's node lies on, templates::Template::node_faces), in
// boundary_quads order: a template's tet or hex side. Throws std::invalid_argument when
// node_faces does not have one mask per node.
ViewFaceGroup boundary_face_group(std::string name, const primal::HexMesh& mesh,
                                  const std::vector<unsigned>& node_faces, int face);

struct ViewScene {
  std::string title;
  std::string caption;  // how the file was made
  std::vector<ViewSheet> sheets;
  std::vector<ViewFaceGroup> groups;
};

// The page as text. Throws InvalidInput for a node id out of range (in a cell, surface, group)
// or a layer cell out of range, naming the sheet or group and the id (1-based).
std::string html_view(const primal::HexMesh& mesh, const ViewScene& scene);
std::string html_view(const primal::QuadMesh& mesh, const ViewScene& scene);  // quads in any plane

// Written atomically (io/atomic_file.hpp).
void write_html(const std::filesystem::path& path, const primal::HexMesh& mesh,
                const ViewScene& scene);
void write_html(const std::filesystem::path& path, const primal::QuadMesh& mesh,
                const ViewScene& scene);

}  // namespace geode::viewer
