#pragma once
// What a conform run amounts to, shared by `geode conform` and the Python module (geode.conform):
// whether the result may be written, why not, and the JSON report.
#include <nlohmann/json_fwd.hpp>
#include <string>

#include <geode/conform/conform.hpp>

namespace geode::conform {

// The minimum scaled Jacobian of one block's report (0 when the report lacks the metric).
double block_min_scaled_jacobian(const primal::QualityReport& report);
// The minimum over every output block (1 for no block).
double output_min_scaled_jacobian(const ConformResult& result);

// Valid: faces shared by two hexes, closed boundary, every node covered once, and no hex with
// scaled Jacobian <= 0. Only a valid result is written (exit 4 otherwise).
bool result_valid(const ConformResult& result);
// Why an invalid result is refused: its warnings joined by "; " ("verification failed" if none).
std::string invalid_reason(const ConformResult& result);

// Nodes at one place as other nodes (within 1e-9 of the model's size): the parts were meshed
// separately. A hint for a failed interface naming `merge_option` (how the caller spells the
// merge tolerance: "--merge-tolerance", "merge_tolerance="), empty when there are none.
std::string duplicate_node_hint(const primal::Model& model, const std::string& merge_option);

// The kinds the input holds as conform dices them alone (ConformResult::yardstick): its hexes not
// split into tets; tets, with the pyramids, split wedges and split hexes as their tets; wedges
// not split. A kind without elements has no minimum (the result's 1 is a placeholder), so the
// summary line leaves it out and the JSON report says null.
struct DicedAloneKinds {
  bool hexes = false, tets = false, wedges = false;
};
DicedAloneKinds diced_alone_kinds(const ConformResult& result);

// {"input": {...}, "output": {...}, "valid", minima before and after smoothing, "smoothing",
// the yardstick "input_diced_alone_min_scaled_jacobian", "seconds", "warnings",
// "blocks": [{"id", "name", "quality"}]}: the report `geode conform --report` writes. A minimum
// over nothing is null: a kind the input lacks (diced_alone_kinds), and without geode hexes
// the template's, the buffer layer's and the local yardstick ratios.
nlohmann::json report_json(const ConformResult& result);

}  // namespace geode::conform
