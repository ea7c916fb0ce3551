#pragma once

#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace geode::primal::detail {

// Values laid end to end as bytes and read back in the same order: what one rank or thread
// hands the others (geode_mpi's transition zone, the shared input check's findings and faces,
// the shared Exodus read's answers per share: io/exodus_read.cpp).
// Trivially copyable values go as their bytes, strings as their length and characters. Reading
// past the end throws rather than reading out of bounds.
class BytePacket {
 public:
  BytePacket() = default;
  explicit BytePacket(std::vector<char> bytes) : bytes_(std::move(bytes)) {}

  template <typename T>
  void put(const T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&x);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void put(const std::string& s) {
    put(s.size());
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }

  template <typename T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T> && std::is_default_constructible_v<T>);
    T x;
    std::memcpy(&x, take(sizeof(T)), sizeof(T));
    return x;
  }
  template <typename T>
  void get(T& x) {
    x = get<T>();
  }
  std::string get_string() { return std::string(get_view()); }
  // A string's characters where they lie in the packet (valid as long as it is): a large one
  // read without a copy.
  std::string_view get_view() {
    const auto n = get<std::size_t>();
    return std::string_view(take(n), n);
  }

  // The bytes, to send, or to fill before reading (a receiver resizes them).
  std::vector<char>& bytes() { return bytes_; }

 private:
  const char* take(std::size_t n) {
    if (n > bytes_.size() - at_)
      throw std::runtime_error("a packet of " + std::to_string(bytes_.size()) +
                               " bytes read past its end");
    const char* p = bytes_.data() + at_;
    at_ += n;
    return p;
  }

  std::vector<char> bytes_;
  std::size_t at_ = 0;  // where the next value is read
};

}  // namespace geode::primal::detail
