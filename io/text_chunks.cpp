#include <geode/io/text_chunks.hpp>

#include <fmt/compile.h>
#include <fmt/format.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <mutex>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::io {

using primal::index_cast;

char* put_number(char* at, std::int64_t x) { return fmt::format_to(at, FMT_COMPILE("{}"), x); }

namespace {

// "00" to "99": two digits a division.
constexpr auto kDigitPairs = [] {
  std::array<char, 200> t{};
  for (int i = 0; i < 100; ++i) {
    t[index_cast<std::size_t>(2 * i)] = static_cast<char>('0' + i / 10);
    t[index_cast<std::size_t>(2 * i + 1)] = static_cast<char>('0' + i % 10);
  }
  return t;
}();

// The decimal digits of x, ending at `end`; returns where they begin.
char* digits_before(char* end, std::uint64_t x) {
  while (x >= 100) {
    end -= 2;
    std::memcpy(end, &kDigitPairs[2 * (x % 100)], 2);
    x /= 100;
  }
  if (x >= 10) {
    end -= 2;
    std::memcpy(end, &kDigitPairs[2 * x], 2);
  } else {
    *--end = static_cast<char>('0' + x);
  }
  return end;
}

}  // namespace

// {fmt}'s own text, laid out here: its general layout (fmt::detail::do_write_float, through
// format specs and digit grouping) took half of a double's 40 ns. The shortest digits are
// still {fmt}'s (Dragonbox); io's text_chunks_test holds the two texts equal.
char* put_number(char* at, double x) {
  if (!std::isfinite(x)) return fmt::format_to(at, FMT_COMPILE("{}"), x);
  if (std::signbit(x)) *at++ = '-', x = -x;
  if (x == 0.0) {
    *at++ = '0';
    return at;
  }
  const auto dec = fmt::detail::dragonbox::to_decimal(x);
  std::array<char, 20> buf;  // a uint64's 20 digits at most; a double's at most 17
  char* const end = buf.data() + buf.size();
  const char* digits = digits_before(end, dec.significand);
  const int n = static_cast<int>(end - digits);
  const int exp10 = dec.exponent + n - 1;  // of the first digit
  const auto copy = [&at](const char* from, int count) {
    std::memcpy(at, from, index_cast<std::size_t>(count));
    at += count;
  };
  if (exp10 < -4 || exp10 >= 16) {  // {fmt}'s exponent form: d[.ddd]e+XX, two digits at least
    *at++ = digits[0];
    if (n > 1) *at++ = '.', copy(digits + 1, n - 1);
    *at++ = 'e';
    *at++ = exp10 < 0 ? '-' : '+';
    const int e = exp10 < 0 ? -exp10 : exp10;
    if (e >= 100) *at++ = static_cast<char>('0' + e / 100);
    copy(&kDigitPairs[index_cast<std::size_t>(2 * (e % 100))], 2);
  } else if (dec.exponent >= 0) {  // an integer: its digits, then zeros
    copy(digits, n);
    std::memset(at, '0', index_cast<std::size_t>(dec.exponent));
    at += dec.exponent;
  } else if (exp10 >= 0) {  // d.ddd
    copy(digits, exp10 + 1);
    *at++ = '.';
    copy(digits + exp10 + 1, n - exp10 - 1);
  } else {  // 0.000ddd
    *at++ = '0';
    *at++ = '.';
    std::memset(at, '0', index_cast<std::size_t>(-exp10 - 1));
    at += -exp10 - 1;
    copy(digits, n);
  }
  return at;
}

void write_in_chunks(
    std::size_t n, std::size_t chunk,
    const std::function<void(std::size_t begin, std::size_t end, std::string& out)>& make,
    const std::function<void(std::string_view bytes)>& write) {
  const std::size_t chunks = (n + chunk - 1) / chunk;
  std::size_t next = 0;
  // The chunks' strings, reused once written: a fresh one's pages were faulted in and cleared
  // by the kernel for every chunk (a tenth of a 150 MB ASCII .msh's writing).
  std::mutex pool_mutex;
  std::vector<std::string> pool;
  // TBB's pipeline: chunk numbers in order, made in parallel, written in their order. Two chunks
  // in flight per thread keep every thread busy while one is written, and few are held.
  tbb::parallel_pipeline(2 * index_cast<std::size_t>(tbb::this_task_arena::max_concurrency()),
                         tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                                             [&](tbb::flow_control& control) {
                                                               if (next == chunks) control.stop();
                                                               return next++;
                                                             }) &
                             tbb::make_filter<std::size_t, std::string>(
                                 tbb::filter_mode::parallel,
                                 [&](std::size_t c) {
                                   std::string out;
                                   {
                                     const std::lock_guard lock(pool_mutex);
                                     if (!pool.empty()) {
                                       out = std::move(pool.back());
                                       pool.pop_back();
                                     }
                                   }
                                   out.clear();  // its capacity kept
                                   make(c * chunk, std::min(n, (c + 1) * chunk), out);
                                   return out;
                                 }) &
                             tbb::make_filter<std::string, void>(
                                 tbb::filter_mode::serial_in_order, [&](std::string out) {
                                   write(out);
                                   const std::lock_guard lock(pool_mutex);
                                   pool.push_back(std::move(out));
                                 }));
}

}  // namespace geode::io
