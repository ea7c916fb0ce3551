#include <geode/primal/quality_report.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numeric>

#include <geode/primal/errors.hpp>

namespace geode::primal {

namespace {

std::string three_digits(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

nlohmann::json bound(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

}  // namespace

MetricSummary summarize_metric(HexMetric metric, std::span<const double> q,
                               std::span<const Index> hexes, StdDevKind kind) {
  if (q.empty() || q.size() != hexes.size())
    throw InvalidInput("metric summary: " + std::to_string(q.size()) + " values for " +
                       std::to_string(hexes.size()) + " hexes");
  const double n = static_cast<double>(q.size());
  MetricSummary s;
  s.metric = metric;
  // Extremes (the first of equal ones, as min_element and max_element) and the sum in one pass,
  // summed in order as std::accumulate does.
  std::size_t lo = 0, hi = 0;
  double sum = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (q[i] < q[lo]) lo = i;
    if (q[hi] < q[i]) hi = i;
    sum += q[i];
  }
  s.minimum = q[lo];
  s.maximum = q[hi];
  s.min_hex = hexes[lo];
  s.max_hex = hexes[hi];
  s.average = sum / n;
  double ss = 0.0;  // two-pass: no cancellation for large, nearly equal values (volumes)
  for (double v : q) ss += (v - s.average) * (v - s.average);
  const double dof = kind == StdDevKind::kSample ? n - 1.0 : n;
  s.std_dev = dof > 0.0 ? std::sqrt(ss / dof) : 0.0;
  return s;
}

QualityReport hex_quality_report(const HexMesh& mesh, std::span<const Index> hexes,
                                 std::span<const HexMetric> metrics, StdDevKind kind,
                                 const MetricProgress& progress) {
  std::vector<Index> all;
  if (hexes.empty()) {
    all.resize(mesh.hexes.size());
    std::iota(all.begin(), all.end(), Index{0});
    hexes = all;
  }
  if (hexes.empty()) throw InvalidInput("hex quality report: the mesh has no hexes");

  std::vector<HexMetric> chosen;
  if (metrics.empty()) {
    for (const auto& m : hex_metrics()) chosen.push_back(m.metric);
  } else {
    chosen.assign(metrics.begin(), metrics.end());
  }

  // Check every hex number once; metrics then gather their corners straight from the mesh
  // (a copy of all corners would cost 192 bytes per hex).
  for (Index h : hexes) hex_corners(mesh, h);

  QualityReport report;
  report.num_hexes = index_cast(hexes.size());
  report.std_dev_kind = kind;
  std::vector<double> q(hexes.size());
  if (progress) progress(0, chosen.size());
  for (HexMetric id : chosen) {
    const HexMetricInfo& info = hex_metric_info(id);
    // Hexes are independent: evaluated in parallel (TBB), each value in its own slot, so the
    // summary does not depend on the thread count.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, hexes.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          HexCorners c;
                          const auto& hex = mesh.hexes[index_cast<std::size_t>(hexes[i])];
                          for (int k = 0; k < 8; ++k)
                            c[k] = mesh.points[index_cast<std::size_t>(hex[k])];
                          q[i] = info.evaluate(c);
                        }
                      });
    report.metrics.push_back(summarize_metric(id, q, hexes, kind));
    if (progress) progress(report.metrics.size(), chosen.size());
  }
  return report;
}

std::string format_quality_table(const QualityReport& report) {
  std::size_t width = std::string("Quality Measure").size();
  for (const auto& s : report.metrics)
    width = std::max(width, hex_metric_info(s.metric).name.size());
  auto pad = [](std::string s, std::size_t w) {
    s.resize(std::max(s.size(), w), ' ');
    return s;
  };
  const std::size_t col = 11;
  std::string out = pad("Quality Measure", width + 2) + pad("Average", col) +
                    pad("Std. Dev.", col) + pad("Minimum", col) + "Maximum\n";
  for (const auto& s : report.metrics) {
    out += pad(std::string(hex_metric_info(s.metric).name), width + 2) +
           pad(three_digits(s.average), col) + pad(three_digits(s.std_dev), col) +
           pad(three_digits(s.minimum), col) + three_digits(s.maximum) + "\n";
  }
  return out;
}

nlohmann::json quality_report_json(const QualityReport& report) {
  nlohmann::json metrics = nlohmann::json::array();
  for (const auto& s : report.metrics) {
    const HexMetricInfo& info = hex_metric_info(s.metric);
    metrics.push_back({{"key", info.key},
                       {"name", info.name},
                       {"average", s.average},
                       {"std_dev", s.std_dev},
                       {"min", s.minimum},
                       {"max", s.maximum},
                       {"min_hex", s.min_hex},
                       {"max_hex", s.max_hex},
                       {"acceptable", {bound(info.acceptable_min), bound(info.acceptable_max)}}});
  }
  return {{"num_hexes", report.num_hexes},
          {"std_dev", report.std_dev_kind == StdDevKind::kSample ? "sample" : "population"},
          {"metrics", metrics}};
}

}  // namespace geode::primal
