#pragma once
// Quality summaries of a hex mesh: per metric the average, standard deviation, minimum and
// maximum over a set of hexes, printed like the CUBIT report of the paper's Table 1 or as JSON.
#include <cstddef>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/primal/quality.hpp>

namespace geode::primal {

// Sample: sqrt(sum (q - mean)^2 / (n - 1)), Bessel-corrected (0 for one hex); population: / n.
enum class StdDevKind { kSample, kPopulation };

struct MetricSummary {
  HexMetric metric;
  double average = 0.0;
  double std_dev = 0.0;
  double minimum = 0.0;
  double maximum = 0.0;
  Index min_hex = kInvalidIndex;  // mesh hex number where the minimum (first occurrence) is
  Index max_hex = kInvalidIndex;
};

struct QualityReport {
  Index num_hexes = 0;
  StdDevKind std_dev_kind = StdDevKind::kSample;
  std::vector<MetricSummary> metrics;  // in the order asked for
};

// Called with (metrics done, metrics) before the first metric and after each: for a progress
// bar (about 0.6 s a metric on 5 million hexes).
using MetricProgress = std::function<void(std::size_t done, std::size_t total)>;

// Summary of `metrics` (default: every registered hex metric, registry order) over the hexes
// numbered in `hexes` (default: all). Throws geode::InvalidInput on an empty selection or a
// bad hex or node number.
QualityReport hex_quality_report(const HexMesh& mesh, std::span<const Index> hexes = {},
                                 std::span<const HexMetric> metrics = {},
                                 StdDevKind kind = StdDevKind::kSample,
                                 const MetricProgress& progress = {});

// The summary of one metric from values already computed: values[i] belongs to hexes[i]
// (hex numbers for min_hex / max_hex). Throws geode::InvalidInput when empty or the sizes differ.
MetricSummary summarize_metric(HexMetric metric, std::span<const double> values,
                               std::span<const Index> hexes, StdDevKind kind = StdDevKind::kSample);

// The table of the paper's Table 1: a header `Quality Measure  Average  Std. Dev.  Minimum
// Maximum` and one row per metric, numbers with 3 significant digits like CUBIT's report.
std::string format_quality_table(const QualityReport& report);

// {"num_hexes": n, "std_dev": "sample"|"population", "metrics": [{"key", "name", "average",
// "std_dev", "min", "max", "min_hex", "max_hex", "acceptable": [lo|null, hi|null]}...]};
// an infinite bound of the acceptable range is null.
nlohmann::json quality_report_json(const QualityReport& report);

}  // namespace geode::primal
