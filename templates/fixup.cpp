#include <geode/templates/fixup.hpp>

#include <algorithm>
#include <sstream>

#include <geode/primal/errors.hpp>
#include <geode/primal/realizability.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity.hpp>

namespace geode::templates {
namespace {

using primal::Index;

std::vector<primal::Obstruction> obstructions(const primal::HexMesh& mesh,
                                              const std::vector<unsigned>& node_faces) {
  primal::RealizabilityOptions o;
  o.node_faces = node_faces;
  return primal::find_obstructions(mesh, o);
}

// The sheet of hex h that separates its local face f from the opposite face: of the hex's
// three sheets, the other two cut the face, this one leaves all its corners on one side.
int sheet_across(const Template& t, Index h, int f) {
  const auto& hex = t.hex.hexes[primal::index_cast<std::size_t>(h)];
  const auto& face = primal::topology::kHexFaceCorners[primal::index_cast<std::size_t>(f)];
  for (int s : t.element_sheets[primal::index_cast<std::size_t>(h)]) {
    const auto sign = [&](int i) {
      return t.node_signs[primal::index_cast<std::size_t>(hex[primal::index_cast<std::size_t>(
          face[primal::index_cast<std::size_t>(i)])])][primal::index_cast<std::size_t>(s)];
    };
    if (sign(0) == sign(1) && sign(1) == sign(2) && sign(2) == sign(3)) return s;
  }
  return -1;
}

// Apply a pillowing to the template's bookkeeping: the new sheet, the signs of every node on
// it, the new nodes' faces (none: interior), the layer hexes' sheets.
void apply(Template& t, const std::vector<Index>& set, primal::PillowResult r) {
  const int sheet = primal::index_cast<int>(t.sheets.size());
  t.sheets.push_back({"pillow " + std::to_string(sheet), "pillow"});
  std::vector<std::vector<int>> layer_sheets;
  for (const Index l : r.layer) {
    // The layer hex's corners 4..7 are the old face's nodes; find the set hex and face.
    const auto& lh = r.mesh.hexes[primal::index_cast<std::size_t>(l)];
    std::vector<int> sheets{sheet};
    for (Index h : set) {
      const auto& hex = t.hex.hexes[primal::index_cast<std::size_t>(h)];
      for (int f = 0; f < 6; ++f) {
        bool same = true;
        for (int i = 0; i < 4; ++i)
          same &= hex[primal::index_cast<std::size_t>(
                      primal::topology::kHexFaceCorners[primal::index_cast<std::size_t>(f)]
                                                       [primal::index_cast<std::size_t>(i)])] ==
                  lh[primal::index_cast<std::size_t>(i) + 4];
        if (!same) continue;
        const int across = sheet_across(t, h, f);
        for (int s : t.element_sheets[primal::index_cast<std::size_t>(h)])
          if (s != across) sheets.push_back(s);
      }
    }
    std::sort(sheets.begin(), sheets.end());
    layer_sheets.push_back(sheets);
  }
  std::vector<char> inside(r.mesh.points.size(), 0);
  for (Index h : set)
    for (Index n : r.mesh.hexes[primal::index_cast<std::size_t>(h)])
      inside[primal::index_cast<std::size_t>(n)] = 1;
  for (std::size_t i = 0; i < r.copy_of.size(); ++i) {
    t.node_signs.push_back(t.node_signs[primal::index_cast<std::size_t>(r.copy_of[i])]);
    t.node_faces.push_back(0u);
  }
  for (std::size_t n = 0; n < t.node_signs.size(); ++n)
    t.node_signs[n].push_back(inside[n] ? -1 : 1);
  for (auto& s : layer_sheets) t.element_sheets.push_back(s);
  t.hex = std::move(r.mesh);
}

// Shrink sets to try for one obstruction: every non-empty subset of its hexes, smallest first
// (fewer new hexes), or each hex alone and all of them when there are too many for subsets.
std::vector<std::vector<Index>> candidate_sets(const std::vector<Index>& hexes,
                                               int max_subset_hexes) {
  std::vector<std::vector<Index>> c;
  const int k = primal::index_cast<int>(hexes.size());
  if (k > max_subset_hexes) {
    for (Index h : hexes) c.push_back({h});
    if (k > 1) c.push_back(hexes);
    return c;
  }
  for (unsigned m = 1; m < (1u << k); ++m) {
    std::vector<Index> set;
    for (int i = 0; i < k; ++i)
      if ((m >> i) & 1u) set.push_back(hexes[primal::index_cast<std::size_t>(i)]);
    c.push_back(set);
  }
  std::stable_sort(c.begin(), c.end(),
                   [](const auto& a, const auto& b) { return a.size() < b.size(); });
  return c;
}

bool combinatorially_valid(const primal::HexValidityReport& v) {
  return v.overshared_faces.empty() && v.misoriented_faces.empty() && v.nonmanifold_edges.empty() &&
         v.nonmanifold_vertices.empty() && v.euler == 1 && v.boundary.closed && v.boundary.manifold;
}

}  // namespace

FixupResult fix_up(Template& t, const FixupOptions& options) {
  if (t.dim != 3) throw InvalidInput("fix_up: only 3D templates are fixed up");
  FixupResult out;
  auto current = obstructions(t.hex, t.node_faces);
  out.obstructions_before = primal::index_cast<int>(current.size());
  for (int step = 0; step < options.max_steps && !current.empty(); ++step) {
    // The first obstruction (in find_obstructions' order) that some shrink set reduces.
    std::size_t best = current.size();
    std::vector<Index> best_set;
    const primal::Obstruction* fixed = nullptr;
    for (const auto& o : current) {
      for (const auto& set : candidate_sets(o.hexes, options.max_subset_hexes)) {
        const auto r = primal::pillow(t.hex, set, options.pillow);
        if (!combinatorially_valid(primal::check_validity(r.mesh)))
          continue;  // the set's surface is not manifold
        std::vector<unsigned> faces = t.node_faces;
        faces.resize(r.mesh.points.size(), 0u);
        const std::size_t left = obstructions(r.mesh, faces).size();
        if (left < best) best = left, best_set = set, fixed = &o;
      }
      if (fixed) break;
    }
    if (!fixed) break;
    std::ostringstream s;
    s << "pillow hexes";
    for (Index h : best_set) s << " " << h;
    s << " (" << primal::to_string(fixed->kind) << "): " << current.size() << " -> " << best
      << " obstructions";
    out.steps.push_back(s.str());
    apply(t, best_set, primal::pillow(t.hex, best_set, options.pillow));
    current = obstructions(t.hex, t.node_faces);
  }
  out.obstructions_after = primal::index_cast<int>(current.size());
  return out;
}

}  // namespace geode::templates
