// put_number's double text: {fmt}'s own (the shortest that reads back) laid out by io itself,
// so it is checked against {fmt} on every kind of double, and read back.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <geode/io/text_chunks.hpp>

namespace {

std::string text_of(double x) {
  std::string s(geode::io::kRealText, '\0');
  char* end = geode::io::put_number(s.data(), x);
  REQUIRE(end - s.data() <= static_cast<std::ptrdiff_t>(geode::io::kRealText));
  s.resize(static_cast<std::size_t>(end - s.data()));
  return s;
}

void check(double x) {
  const std::string ours = text_of(x);
  CHECK_MESSAGE(ours == fmt::format("{}", x), "bits ", std::bit_cast<std::uint64_t>(x));
  if (std::isfinite(x))
    CHECK(std::bit_cast<std::uint64_t>(std::strtod(ours.c_str(), nullptr)) ==
          std::bit_cast<std::uint64_t>(x));
}

}  // namespace

TEST_CASE("put_number writes a double as {fmt} does, and it reads back") {
  using L = std::numeric_limits<double>;
  // Every layout's edges: zero of both signs, the fixed range's ends (1e-4 to 1e16), integers
  // with trailing zeros, the exponent's two and three digits, subnormals, the extremes.
  const std::vector<double> edges = {0.0,
                                     -0.0,
                                     1.0,
                                     -1.0,
                                     0.1,
                                     0.5,
                                     1e-4,
                                     9.9999e-5,
                                     1.2345e-4,
                                     1e-5,
                                     1e15,
                                     1e16,
                                     9999999999999998.0,
                                     1e17,
                                     123e13,
                                     1e21,
                                     1e100,
                                     1e-100,
                                     1e308,
                                     1e-308,
                                     L::min(),
                                     L::max(),
                                     L::lowest(),
                                     L::denorm_min(),
                                     L::epsilon(),
                                     0.30000000000000004,
                                     1.0 / 3.0,
                                     -2.5e-7,
                                     4096.0,
                                     65536.25,
                                     L::infinity(),
                                     -L::infinity(),
                                     L::quiet_NaN()};
  for (double x : edges) check(x);
  std::mt19937_64 random(7);
  for (int i = 0; i < 200000; ++i) {  // any bit pattern: every exponent and digit count
    const double x = std::bit_cast<double>(random());
    check(x);
  }
  std::uniform_real_distribution<double> coordinate(-10.0, 10.0);
  for (int i = 0; i < 200000; ++i) check(coordinate(random));  // what meshes hold
  for (int e = -330; e <= 310; ++e) check(std::pow(10.0, e)), check(-3.0 * std::pow(10.0, e));
}
