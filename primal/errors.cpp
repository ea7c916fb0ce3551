#include <geode/primal/errors.hpp>

#include <cstddef>
#include <cstdint>

#include <geode/primal/utf8.hpp>

namespace geode::detail {

std::string one_line(std::string_view message) {
  std::string out;
  out.reserve(message.size());
  constexpr char kHex[] = "0123456789abcdef";
  for (std::size_t i = 0; i < message.size();) {
    const auto b = static_cast<std::uint8_t>(message[i]);
    const std::size_t n = primal::utf8_length(message, i);
    if (n > 1 || (n == 1 && b >= 0x20 && b < 0x7f)) {
      out.append(message.substr(i, n));
      i += n;
    } else {
      out += "\\x";
      out += kHex[b >> 4];
      out += kHex[b & 15];
      ++i;
    }
  }
  return out;
}

}  // namespace geode::detail
