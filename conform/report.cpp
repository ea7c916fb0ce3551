// The verdict and report of a conform run (conform/report.hpp).
#include <geode/conform/report.hpp>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <sstream>

namespace geode::conform {

double block_min_scaled_jacobian(const primal::QualityReport& q) {
  for (const auto& m : q.metrics)
    if (m.metric == primal::HexMetric::kScaledJacobian) return m.minimum;
  return 0.0;
}

double output_min_scaled_jacobian(const ConformResult& r) {
  double m = 1.0;
  for (const auto& b : r.quality) m = std::min(m, block_min_scaled_jacobian(b.report));
  return m;
}

bool result_valid(const ConformResult& r) {
  if (!r.validity.ok() || !r.dicing.ok()) return false;
  return std::all_of(r.quality.begin(), r.quality.end(), [](const BlockQuality& b) {
    return block_min_scaled_jacobian(b.report) > 0.0;
  });
}

std::string invalid_reason(const ConformResult& r) {
  std::string why = r.warnings.empty() ? std::string("verification failed") : r.warnings.front();
  for (std::size_t w = 1; w < r.warnings.size(); ++w) why += "; " + r.warnings[w];
  return why;
}

std::string duplicate_node_hint(const primal::Model& model, const std::string& merge_option) {
  if (model.points.empty()) return {};
  const double tolerance = primal::coincident_tolerance(model);
  primal::Model copy = model;
  const primal::Index merged = primal::merge_coincident_nodes(copy, tolerance);
  if (merged == 0) return {};
  std::ostringstream s;
  s << "; hint: " << merged
    << " nodes lie at the same place as others (parts meshed separately?): " << merge_option
    << (merge_option.ends_with('=') ? "" : " ") << tolerance << " merges them";
  return s.str();
}

DicedAloneKinds diced_alone_kinds(const ConformResult& r) {
  return {r.input_hexes > r.hexes_split,
          r.input_tets + r.input_pyramids + r.wedges_split + r.hexes_split > 0,
          r.input_wedges > r.wedges_split};
}

nlohmann::json report_json(const ConformResult& r) {
  // null where the minimum is over nothing (the result holds 1 or 0 there).
  const auto over = [](bool any, double value) { return any ? nlohmann::json(value) : nullptr; };
  const DicedAloneKinds kinds = diced_alone_kinds(r);
  const bool geode = r.geode_hexes > 0;
  nlohmann::json j;
  j["input"] = {{"hexes", r.input_hexes},
                {"tets", r.input_tets},
                {"pyramids", r.input_pyramids},
                {"wedges", r.input_wedges},
                {"wedges_split", r.wedges_split},
                {"hexes_split", r.hexes_split},
                {"interface_quads", r.interface_quads}};
  j["output"] = {
      {"hexes", r.model.hexes.size()},        {"nodes", r.model.points.size()},
      {"diced_hexes", r.diced_hexes},         {"geode_hexes", r.geode_hexes},
      {"diced_tet_hexes", r.diced_tet_hexes}, {"diced_wedge_hexes", r.diced_wedge_hexes}};
  j["valid"] = r.validity.ok() && r.dicing.ok();
  j["verification"] = {{"scope", r.verified == ConformVerify::kLocal ? "local" : "full"},
                       {"hexes_checked_whole", r.verified_hexes}};
  j["template_min_scaled_jacobian"] = over(geode, r.template_min_scaled_jacobian);
  j["min_scaled_jacobian_before_smoothing"] = r.min_scaled_jacobian_before_smoothing;
  j["min_scaled_jacobian_after_smoothing"] = r.smoothing.final_min_scaled_jacobian;
  j["hexes_inverted_by_placement"] = r.placement_inverted;
  j["templates_settled"] = r.templates_settled;
  j["smoothing"] = {{"patches", r.smoothing.patches},
                    {"seconds", r.smoothing.seconds},
                    {"cpu_seconds", r.smoothing.cpu_seconds}};
  j["tet_relaxation"] = {{"nodes_moved", r.relaxation.nodes_moved},
                         {"min_before", r.relaxation.min_before},
                         {"min_after", r.relaxation.min_after},
                         {"seconds", r.relaxation.seconds}};
  j["buffer_layer_min_scaled_jacobian"] = over(geode, r.buffer.min_scaled_jacobian);
  j["buffer_side"] = buffer_side_name(r.buffer_side);
  j["input_diced_alone_min_scaled_jacobian"] = {
      {"hexes", over(kinds.hexes, r.input_diced_hex_min_scaled_jacobian)},
      {"tets", over(kinds.tets, r.input_diced_tet_min_scaled_jacobian)},
      {"wedges", over(kinds.wedges, r.input_diced_wedge_min_scaled_jacobian)}};
  j["output_min_scaled_jacobian"] = output_min_scaled_jacobian(r);
  j["seconds"] = r.seconds;
  j["warnings"] = r.warnings;
  // How min_hex and max_hex number the hexes: as the written file does (with no file written,
  // as Exodus would).
  j["numbering"] = {
      {"index_base", r.numbering.base},
      {"element_order",
       r.numbering.order == primal::ElementOrder::kByBlock ? "by block" : "as given"}};
  j["blocks"] = nlohmann::json::array();
  j["local_yardstick_ratio"] = over(geode, r.local_yardstick_ratio);
  j["capped_local_ratio"] = over(geode, r.capped_local_ratio);
  for (const auto& b : r.quality) {
    nlohmann::json block = {
        {"id", b.block},
        {"name", b.name},
        {"quality", primal::quality_report_json(b.report)},
        {"input_diced_alone_min_scaled_jacobian", b.input_diced_min_scaled_jacobian}};
    if (b.geode_hexes > 0)
      block["geode"] = {{"hexes", b.geode_hexes},
                        {"min_scaled_jacobian", b.geode_min_scaled_jacobian},
                        {"local_yardstick", b.local_yardstick},
                        {"local_ratio", b.local_ratio},
                        {"capped_local_ratio", b.capped_local_ratio}};
    j["blocks"].push_back(std::move(block));
  }
  return j;
}

}  // namespace geode::conform
