// libFuzzer target: the JSON arrangement spec reader (templates/spec.hpp) on arbitrary bytes:
// parsing with its nesting bound, validation against the format, and the sheets' fields built
// and evaluated once (the arrangement itself is not computed: it is not a reader). InvalidInput
// (TopologyError for a completion that cannot be completed) is the expected answer to bad bytes.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <geode/primal/errors.hpp>
#include <geode/templates/spec.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto json = geode::templates::parse_spec_text(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    const auto spec = geode::templates::parse_spec(json, "fuzz.json");
    const geode::primal::Point middle = 0.5 * (spec.domain.lo + spec.domain.hi);
    for (const auto& sheet : geode::templates::spec_sheets(spec)) (void)sheet.field(middle);
    (void)geode::templates::spec_sweep(json, "fuzz.json");
  } catch (const geode::InvalidInput&) {
  } catch (const geode::TopologyError&) {  // a completion's patches that cannot be completed
  }
  return 0;
}
