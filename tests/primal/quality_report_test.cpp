// Quality report statistics and formats (primal/quality_report.hpp), on meshes whose metric
// values are known by hand.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <geode/primal/errors.hpp>
#include <geode/primal/quality_report.hpp>

namespace {

namespace gp = geode::primal;
using gp::HexMetric;
using gp::Point;

// Hex 0: the unit cube. Hex 1: the unit cube with its top face moved by (1,0,0) (scaled
// Jacobian 1/sqrt2, edge ratio sqrt2, volume 1: see quality_test.cpp). Hex 2: the cube again,
// shifted by (5,0,0). Nodes are not shared, which the report does not care about.
gp::HexMesh three_hexes() {
  gp::HexMesh m;
  const Point cube[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                         {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (int h = 0; h < 3; ++h) {
    std::array<gp::Index, 8> hex;
    for (int c = 0; c < 8; ++c) {
      Point p = cube[c];
      if (h == 1 && c >= 4) p.x() += 1.0;
      if (h == 2) p.x() += 5.0;
      hex[c] = static_cast<gp::Index>(m.points.size());
      m.points.push_back(p);
    }
    m.hexes.push_back(hex);
  }
  return m;
}

const gp::MetricSummary& find(const gp::QualityReport& r, HexMetric m) {
  for (const auto& s : r.metrics) {
    if (s.metric == m) return s;
  }
  FAIL("metric missing from report");
  return r.metrics.front();
}

}  // namespace

TEST_CASE("report statistics: average, sample and population std dev, min, max") {
  const auto mesh = three_hexes();
  const double r = 1 / std::sqrt(2.0);
  // Scaled Jacobian values 1, 1/sqrt2, 1: mean (2 + r)/3; squared deviations from the mean
  // sum to (1 - r)^2 * (1/9 + 1/9 + 4/9) = (1 - r)^2 * 2/3.
  const double mean = (2 + r) / 3;
  const double ss = (1 - r) * (1 - r) * 2.0 / 3.0;
  const auto sample = gp::hex_quality_report(mesh);
  CHECK(sample.num_hexes == 3);
  CHECK(sample.metrics.size() == gp::hex_metrics().size());
  const auto& sj = find(sample, HexMetric::kScaledJacobian);
  CHECK(sj.average == doctest::Approx(mean));
  CHECK(sj.std_dev == doctest::Approx(std::sqrt(ss / 2)));
  CHECK(sj.minimum == doctest::Approx(r));
  CHECK(sj.min_hex == 1);
  CHECK(sj.maximum == doctest::Approx(1.0));
  CHECK(sj.max_hex == 0);  // first occurrence
  // Volumes all 1: no spread.
  CHECK(find(sample, HexMetric::kVolume).std_dev == doctest::Approx(0.0));

  const HexMetric only[] = {HexMetric::kScaledJacobian};
  const auto pop = gp::hex_quality_report(mesh, {}, only, gp::StdDevKind::kPopulation);
  REQUIRE(pop.metrics.size() == 1);
  CHECK(pop.metrics[0].std_dev == doctest::Approx(std::sqrt(ss / 3)));

  // A subset: hexes 1 and 2 only. Edge ratios sqrt2 and 1: mean (1 + sqrt2)/2, sample std dev
  // |sqrt2 - 1| / sqrt2.
  const gp::Index subset[] = {1, 2};
  const auto sub = gp::hex_quality_report(mesh, subset);
  const auto& er = find(sub, HexMetric::kEdgeRatio);
  CHECK(sub.num_hexes == 2);
  CHECK(er.average == doctest::Approx((1 + std::sqrt(2.0)) / 2));
  CHECK(er.std_dev == doctest::Approx((std::sqrt(2.0) - 1) / std::sqrt(2.0)));
  CHECK(er.max_hex == 1);
  CHECK(er.min_hex == 2);

  // One hex: the sample std dev has no degrees of freedom and is reported as 0.
  const gp::Index one[] = {1};
  CHECK(find(gp::hex_quality_report(mesh, one), HexMetric::kSkew).std_dev == 0.0);
}

TEST_CASE("report progress: before the first metric and after each, the report the same") {
  const gp::HexMesh m = three_hexes();
  std::vector<std::pair<std::size_t, std::size_t>> told;
  const auto r = gp::hex_quality_report(
      m, {}, {}, gp::StdDevKind::kSample,
      [&told](std::size_t done, std::size_t total) { told.emplace_back(done, total); });
  const auto plain = gp::hex_quality_report(m);
  REQUIRE(r.metrics.size() == plain.metrics.size());
  for (std::size_t i = 0; i < r.metrics.size(); ++i)
    CHECK(r.metrics[i].minimum == plain.metrics[i].minimum);
  REQUIRE(told.size() == plain.metrics.size() + 1);
  for (std::size_t i = 0; i < told.size(); ++i) {
    CHECK(told[i].first == i);
    CHECK(told[i].second == plain.metrics.size());
  }
}

TEST_CASE("report table looks like the paper's Table 1") {
  const auto report = gp::hex_quality_report(three_hexes());
  const std::string table = gp::format_quality_table(report);
  std::istringstream in(table);
  std::string header;
  std::getline(in, header);
  CHECK(header.rfind("Quality Measure", 0) == 0);
  CHECK(header.find("Average") < header.find("Std. Dev."));
  CHECK(header.find("Std. Dev.") < header.find("Minimum"));
  CHECK(header.find("Minimum") < header.find("Maximum"));
  // Scaled Jacobian: mean 0.902, sample std dev 0.169, min 0.707, max 1 (3 digits).
  CHECK(table.find("Scaled Jacobian") != std::string::npos);
  std::string line;
  bool seen = false;
  while (std::getline(in, line)) {
    if (line.rfind("Scaled Jacobian", 0) != 0) continue;
    seen = true;
    std::istringstream row(line.substr(std::string("Scaled Jacobian").size()));
    std::string avg, sd, lo, hi;
    row >> avg >> sd >> lo >> hi;
    CHECK(avg == "0.902");
    CHECK(sd == "0.169");
    CHECK(lo == "0.707");
    CHECK(hi == "1");
  }
  CHECK(seen);
}

TEST_CASE("report JSON carries every statistic and the acceptable ranges") {
  const auto report = gp::hex_quality_report(three_hexes());
  const nlohmann::json j = nlohmann::json::parse(gp::quality_report_json(report).dump());
  CHECK(j["num_hexes"] == 3);
  CHECK(j["std_dev"] == "sample");
  REQUIRE(j["metrics"].size() == report.metrics.size());
  bool seen = false;
  for (const auto& m : j["metrics"]) {
    if (m["key"] != "scaled_jacobian") continue;
    seen = true;
    CHECK(m["name"] == "Scaled Jacobian");
    CHECK(m["min"].get<double>() == doctest::Approx(1 / std::sqrt(2.0)));
    CHECK(m["min_hex"] == 1);
    CHECK(m["acceptable"][0].get<double>() == 0.5);
    CHECK(m["acceptable"][1].get<double>() == 1.0);
  }
  CHECK(seen);
  for (const auto& m : j["metrics"]) {
    if (m["key"] == "volume") CHECK(m["acceptable"][1].is_null());  // no upper bound
  }
}

TEST_CASE("report rejects an empty selection and bad hex numbers") {
  gp::HexMesh empty;
  CHECK_THROWS_AS(gp::hex_quality_report(empty), geode::InvalidInput);
  const gp::Index bad[] = {7};
  CHECK_THROWS_WITH(gp::hex_quality_report(three_hexes(), bad), doctest::Contains("hex 7"));
}
