#include <geode/conform/corner_study.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

#include <geode/primal/boundary.hpp>
#include <geode/primal/quality.hpp>

namespace geode::conform {

using primal::Index;
using primal::Point;

std::vector<QuadClass> classify_interface_quads(const primal::Model& m,
                                                const primal::Interface& itf) {
  const auto& p = m.points;
  std::vector<Point> normal, centre;
  std::map<primal::EdgeKey, std::vector<std::size_t>> edges;
  for (std::size_t q = 0; q < itf.quads.size(); ++q) {
    const auto& c = itf.quads[q].corners;
    auto at = [&](int i) {
      return p[primal::index_cast<std::size_t>(c[primal::index_cast<std::size_t>(i)])];
    };
    normal.push_back((at(2) - at(0)).cross(at(3) - at(1)).normalized());  // towards the tets
    centre.push_back((at(0) + at(1) + at(2) + at(3)) / 4.0);
    for (int i = 0; i < 4; ++i)
      edges[primal::edge_key(c[primal::index_cast<std::size_t>(i)],
                             c[primal::index_cast<std::size_t>((i + 1) % 4)])]
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
    if (std::abs(a - 180.0) < kCornerFeatureAngle) continue;
    for (Index v : e) (convex ? at_node[v].first : at_node[v].second)++;
  }
  std::vector<QuadClass> out;
  for (const auto& q : itf.quads) {
    QuadClass k;
    double sharpest = 180.0;
    for (int i = 0; i < 4; ++i) {
      const auto it =
          angle.find(primal::edge_key(q.corners[primal::index_cast<std::size_t>(i)],
                                      q.corners[primal::index_cast<std::size_t>((i + 1) % 4)]));
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
    k.kind = rank == 3                                          ? "saddle corner"
             : rank == 2                                        ? "convex corner"
             : rank == 1                                        ? "concave corner"
             : std::abs(sharpest - 180.0) < kCornerFeatureAngle ? "flat"
             : sharpest < 180.0                                 ? "convex edge"
                                                                : "concave edge";
    k.angle = 5.0 * std::round(sharpest / 5.0);
    out.push_back(k);
  }
  return out;
}

std::vector<double> geode_minima(const ConformResult& r) {
  const Index nb = r.interface_quads;
  std::vector<double> out(primal::index_cast<std::size_t>(nb), 1.0);
  if (nb == 0) return out;
  const Index per = r.geode_hexes / nb;  // one template kind per model in the studied demos
  for (Index b = 0; b < nb; ++b)
    for (Index h = r.diced_hexes + per * b; h < r.diced_hexes + per * (b + 1); ++h) {
      primal::HexCorners c;
      for (int k = 0; k < 8; ++k)
        c[primal::index_cast<std::size_t>(k)] = r.model.points[primal::index_cast<std::size_t>(
            r.model.hexes[primal::index_cast<std::size_t>(h)][primal::index_cast<std::size_t>(k)])];
      out[primal::index_cast<std::size_t>(b)] =
          std::min(out[primal::index_cast<std::size_t>(b)], primal::hex_scaled_jacobian(c));
    }
  return out;
}

CornerStudy corner_study(const std::vector<CornerStudyModel>& models, int n,
                         const std::function<void(const CornerStudyModelSummary&)>& done,
                         const std::string& side) {
  CornerStudy study;
  study.n = n;
  for (const auto& [name, make] : models) {
    CornerStudyModelSummary s;
    s.name = name;
    primal::Model input;
    ConformResult a, b, g;
    try {
      input = make();
    } catch (const std::exception& e) {
      s.failure = std::string("not built: ") + e.what();
    }
    if (s.failure.empty()) try {
        ConformOptions defaults;  // every short buffer hex's ceiling: the classes' capped ratios
        set_buffer_side(defaults, side);
        defaults.all_template_ceilings = true;
        b = conform(input, defaults);
        // Before smoothing: the same part carved (conform may take either where none is given,
        // and the choice of a run without smoothing need not be the defaults').
        ConformOptions none;
        set_buffer_side(none, buffer_side_name(b.buffer_side));
        none.smooth = ConformSmooth::kNone;
        a = conform(input, none);
        ConformOptions global = none;
        global.smooth = ConformSmooth::kGlobal;
        g = conform(input, global);
      } catch (const std::exception& e) {
        s.failure = std::string("refused: ") + e.what();
      }
    if (s.failure.empty()) {
      const auto classes = classify_interface_quads(input, primal::find_interface(input));
      const auto before = geode_minima(a), after = geode_minima(b), global = geode_minima(g);
      std::map<std::tuple<std::string, double>, CornerStudyRow> rows;
      for (std::size_t q = 0; q < classes.size() && q < after.size(); ++q) {
        CornerStudyRow& r = rows[{classes[q].kind, classes[q].angle}];
        ++r.buffer_hexes;
        r.min_none = std::min(r.min_none, before[q]);
        r.min_default = std::min(r.min_default, after[q]);
        r.min_global = std::min(r.min_global, global[q]);
        r.min_local_yardstick = std::min(r.min_local_yardstick, b.local_yardstick[q]);
        r.min_local_ratio = std::min(r.min_local_ratio, after[q] / b.local_yardstick[q]);
        r.min_capped_ratio = std::min(
            r.min_capped_ratio, after[q] / std::min(b.local_yardstick[q], b.template_ceiling[q]));
      }
      for (auto& [key, r] : rows) {
        r.model = name;
        std::tie(r.kind, r.angle) = key;
        study.rows.push_back(r);
      }
      s.buffer_side = b.buffer_side;
      s.valid_none = a.validity.ok();
      s.valid_default = b.validity.ok();
      s.valid_global = g.validity.ok();
      s.seconds_none = a.seconds;
      s.seconds_default = b.seconds;
      s.seconds_global = g.seconds;
      s.patches = static_cast<int>(b.smoothing.patches);
    }
    study.models.push_back(s);
    if (done) done(s);
  }
  return study;
}

void write_corner_csv(std::ostream& out, const CornerStudy& study) {
  out << "model,n,kind,angle,buffer_hexes,min_sj_none,min_sj_default,min_local_ratio_default,"
         "min_local_yardstick,min_capped_ratio_default,min_sj_global\n";
  for (const auto& r : study.rows)
    out << r.model << "," << study.n << "," << r.kind << "," << r.angle << "," << r.buffer_hexes
        << "," << r.min_none << "," << r.min_default << "," << r.min_local_ratio << ","
        << r.min_local_yardstick << "," << r.min_capped_ratio << "," << r.min_global << "\n";
}

void write_corner_table(std::ostream& out, const CornerStudy& study) {
  char line[256];
  std::snprintf(line, sizeof line, "%-10s %-15s %6s %6s %9s %9s %9s %9s %9s %9s\n", "model", "kind",
                "angle", "count", "none", "default", "x local", "local", "x capped", "global");
  out << line;
  for (const auto& r : study.rows) {
    std::snprintf(line, sizeof line, "%-10s %-15s %6.0f %6d %9.3f %9.3f %9.2f %9.3f %9.2f %9.3f\n",
                  r.model.c_str(), r.kind.c_str(), r.angle, r.buffer_hexes, r.min_none,
                  r.min_default, r.min_local_ratio, r.min_local_yardstick, r.min_capped_ratio,
                  r.min_global);
    out << line;
  }
  for (const auto& s : study.models) {
    if (!s.failure.empty()) {
      out << s.name << ": " << s.failure << "\n";
      continue;
    }
    std::snprintf(line, sizeof line,
                  "%-10s carved from the %s part, valid %s / %s / %s, %.2f s / %.2f s / %.2f s "
                  "(none / default / global), smoothing %d patches (default)\n",
                  s.name.c_str(), buffer_side_name(s.buffer_side), s.valid_none ? "yes" : "NO",
                  s.valid_default ? "yes" : "NO", s.valid_global ? "yes" : "NO", s.seconds_none,
                  s.seconds_default, s.seconds_global, s.patches);
    out << line;
  }
}

}  // namespace geode::conform
