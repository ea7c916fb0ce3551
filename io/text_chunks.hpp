#pragma once
// Large outputs made in parallel: an array's bytes (text, base64) made a chunk at a time on every
// core (TBB), the chunks handed on in order with only a few held at once. The bytes are those a
// serial loop makes whatever the thread count, and no whole array's text is ever held: on a
// million-hex output, formatting numbers was most of the .vtk, .vtu and .msh writers' time.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace geode::io {

// Makes the bytes of items [0, n), `chunk` items at a time, by `make(begin, end, out)`
// (appending those of items [begin, end) to out), and passes each chunk's bytes to `write`, in
// item order, from one thread at a time. An exception from either stops the run and propagates.
void write_in_chunks(
    std::size_t n, std::size_t chunk,
    const std::function<void(std::size_t begin, std::size_t end, std::string& out)>& make,
    const std::function<void(std::string_view bytes)>& write);

// The shortest text that reads back to the same value, written at `at`, which has room for
// kIntegerText or kRealText characters (an int64 is at most 20, a double's shortest text 24:
// "-1.2345678901234567e-308"); returns one past its end. Chunks write into a string sized for
// their worst case and cut it to what was written: appending number by number cost more than
// formatting. {fmt} (libfmt-dev), not std::to_chars: an integer in 5 ns against libstdc++'s 18
// (a .msh's connectivity is ten million of them). A double's digits are {fmt}'s (Dragonbox, the
// shortest that read back) in {fmt}'s layout, written here: 40 ns against {fmt}'s 46. Both
// write exponents -4 to 15 in fixed notation, unlike std::to_chars (1e+06 as 1000000; at most
// 23 characters, "-0.00012345678901234567").
inline constexpr std::size_t kIntegerText = 20, kRealText = 24;
char* put_number(char* at, std::int64_t x);
char* put_number(char* at, double x);

}  // namespace geode::io
