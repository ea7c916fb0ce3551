#pragma once
// Whether this is the sanitized Debug build (scripts/test's second pass), where a test of many
// realistic conform runs takes ten times as long: such tests are skipped there
// (`* doctest::skip(test::kSanitized)`) when smaller tests run the same code under the
// sanitizers, which keeps scripts/test within its time.
namespace geode::test {
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
}  // namespace geode::test
