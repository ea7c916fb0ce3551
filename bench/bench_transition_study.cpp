// The transition at hex-part edges and corners: per dihedral angle and corner kind, the minimum
// scaled Jacobian of the geode hexes before smoothing (--smooth none) and after it (the
// defaults), and their ratio to the local yardstick (ConformResult::local_yardstick), on the
// demo models with edges and corners (nugget, lshape, potting, cylinder) and on demo_wedge at
// dihedral angles from 60 to 300 degrees.
//
// Classes. Every interface edge shared by two interface quads has a dihedral angle measured
// inside the hex part (180: flat; below: convex; above: concave). A node where three or more
// edges at least 20 degrees from flat meet is a corner: convex if all are convex, concave if
// all are concave, a saddle otherwise. A buffer hex is classed by its quad's corners (saddle,
// then convex, then concave corner) or else by its sharpest edge (convex or concave edge, or
// flat), at the angle of its sharpest edge rounded to 5 degrees.
//
// Usage: bench_transition_study [n] [csv]   (defaults 3, notebooks-data/transition-corners.csv)
// Prints a table and writes the CSV that notebooks-data/plot.py draws.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <geode/conform/conform.hpp>
#include <geode/demo/demo_models.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/interface.hpp>
#include <geode/primal/quality.hpp>

namespace {

using namespace geode;
using primal::Index;
using primal::Point;

constexpr double kFeature = 20.0;  // degrees from flat that make an edge count

struct QuadClass {
  std::string kind;
  double angle = 180.0;
};

// Per interface quad: its class (see the header).
std::vector<QuadClass> classify(const primal::Model& m, const primal::Interface& itf) {
  const auto& p = m.points;
  std::vector<Point> normal, centre;
  std::map<primal::EdgeKey, std::vector<std::size_t>> edges;
  for (std::size_t q = 0; q < itf.quads.size(); ++q) {
    const auto& c = itf.quads[q].corners;
    auto at = [&](int i) { return p[static_cast<std::size_t>(c[static_cast<std::size_t>(i)])]; };
    normal.push_back((at(2) - at(0)).cross(at(3) - at(1)).normalized());  // towards the tets
    centre.push_back((at(0) + at(1) + at(2) + at(3)) / 4.0);
    for (int i = 0; i < 4; ++i)
      edges[primal::edge_key(c[static_cast<std::size_t>(i)],
                             c[static_cast<std::size_t>((i + 1) % 4)])]
          .push_back(q);
  }
  std::map<primal::EdgeKey, double> angle;       // inside the hex part
  std::map<Index, std::pair<int, int>> at_node;  // convex, concave feature edges
  for (const auto& [e, qs] : edges) {
    if (qs.size() != 2) continue;
    const double phi =
        std::acos(std::clamp(normal[qs[0]].dot(normal[qs[1]]), -1.0, 1.0)) * 180.0 / M_PI;
    const bool convex = (centre[qs[1]] - centre[qs[0]]).dot(normal[qs[0]]) < 0.0;
    const double a = convex ? 180.0 - phi : 180.0 + phi;
    angle[e] = a;
    if (std::abs(a - 180.0) < kFeature) continue;
    for (Index v : e) (convex ? at_node[v].first : at_node[v].second)++;
  }
  std::vector<QuadClass> out;
  for (const auto& q : itf.quads) {
    QuadClass k;
    double sharpest = 180.0;
    for (int i = 0; i < 4; ++i) {
      const auto it =
          angle.find(primal::edge_key(q.corners[static_cast<std::size_t>(i)],
                                      q.corners[static_cast<std::size_t>((i + 1) % 4)]));
      if (it != angle.end() && std::abs(it->second - 180.0) > std::abs(sharpest - 180.0))
        sharpest = it->second;
    }
    int rank = 0;  // 3 saddle, 2 convex corner, 1 concave corner
    for (Index v : q.corners) {
      const auto it = at_node.find(v);
      if (it == at_node.end() || it->second.first + it->second.second < 3) continue;
      const auto [convex, concave] = it->second;
      rank = std::max(rank, convex && concave ? 3 : convex ? 2 : 1);
    }
    k.kind = rank == 3                               ? "saddle corner"
             : rank == 2                             ? "convex corner"
             : rank == 1                             ? "concave corner"
             : std::abs(sharpest - 180.0) < kFeature ? "flat"
             : sharpest < 180.0                      ? "convex edge"
                                                     : "concave edge";
    k.angle = 5.0 * std::round(sharpest / 5.0);
    out.push_back(k);
  }
  return out;
}

// Per buffer hex, the lowest scaled Jacobian of its 26 geode hexes.
std::vector<double> geode_minima(const conform::ConformResult& r) {
  std::vector<double> out(static_cast<std::size_t>(r.interface_quads), 1.0);
  for (Index b = 0; b < r.interface_quads; ++b)
    for (Index h = r.diced_hexes + 26 * b; h < r.diced_hexes + 26 * (b + 1); ++h) {
      primal::HexCorners c;
      for (int k = 0; k < 8; ++k)
        c[static_cast<std::size_t>(k)] = r.model.points[static_cast<std::size_t>(
            r.model.hexes[static_cast<std::size_t>(h)][static_cast<std::size_t>(k)])];
      out[static_cast<std::size_t>(b)] =
          std::min(out[static_cast<std::size_t>(b)], primal::hex_scaled_jacobian(c));
    }
  return out;
}

struct Row {
  int count = 0;
  double none = 1.0, smoothed = 1.0, ratio = 1e9, local = 1.0;
};

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 3;
  const std::string csv =
      argc > 2 ? argv[2] : std::string(GEODE_SOURCE_DIR) + "/notebooks-data/transition-corners.csv";
  std::vector<std::pair<std::string, std::function<primal::Model()>>> models;
  for (const char* name : {"nugget", "lshape", "potting", "cylinder"})
    models.emplace_back(name, [name, n] { return demo::demo_model(name, n); });
  for (double a : {60.0, 90.0, 120.0, 150.0, 210.0, 240.0, 270.0, 300.0})
    models.emplace_back("wedge-" + std::to_string(static_cast<int>(a)),
                        [a, n] { return demo::demo_wedge(n, a); });
  std::ofstream out(csv);
  out << "model,n,kind,angle,buffer_hexes,min_sj_none,min_sj_default,min_local_ratio_default,min_"
         "local_yardstick\n";
  std::printf("%-10s %-15s %6s %6s %9s %9s %9s %9s\n", "model", "kind", "angle", "count", "none",
              "default", "x local", "local");
  for (const auto& [name, make] : models) {
    primal::Model input;
    try {
      input = make();
    } catch (const std::exception& e) {
      std::printf("%-10s: not built: %s\n", name.c_str(), e.what());
      continue;
    }
    const primal::Interface itf = primal::find_interface(input);
    const auto classes = classify(input, itf);
    conform::ConformOptions none;
    none.smooth = conform::ConformSmooth::kNone;
    conform::ConformResult a, b;
    try {
      a = conform::conform(input, none);
      b = conform::conform(input, {});
    } catch (const std::exception& e) {
      std::printf("%-10s: refused: %s\n", name.c_str(), e.what());
      continue;
    }
    const auto before = geode_minima(a), after = geode_minima(b);
    std::map<std::tuple<std::string, double>, Row> rows;
    for (std::size_t q = 0; q < classes.size(); ++q) {
      Row& r = rows[{classes[q].kind, classes[q].angle}];
      ++r.count;
      r.none = std::min(r.none, before[q]);
      r.smoothed = std::min(r.smoothed, after[q]);
      r.local = std::min(r.local, b.local_yardstick[q]);
      r.ratio = std::min(r.ratio, after[q] / b.local_yardstick[q]);
    }
    for (const auto& [key, r] : rows) {
      const auto& [kind, angle] = key;
      std::printf("%-10s %-15s %6.0f %6d %9.3f %9.3f %9.2f %9.3f\n", name.c_str(), kind.c_str(),
                  angle, r.count, r.none, r.smoothed, r.ratio, r.local);
      out << name << "," << n << "," << kind << "," << angle << "," << r.count << "," << r.none
          << "," << r.smoothed << "," << r.ratio << "," << r.local << "\n";
    }
    std::printf("%-10s valid %s / %s, %.2f s / %.2f s (none / default), smoothing %d patches\n",
                name.c_str(), a.validity.ok() ? "yes" : "NO", b.validity.ok() ? "yes" : "NO",
                a.seconds, b.seconds, static_cast<int>(b.smoothing.patches));
  }
  std::printf("wrote %s\n", csv.c_str());
  return 0;
}
