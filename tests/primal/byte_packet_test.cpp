#include <doctest/doctest.h>

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include <geode/primal/detail/byte_packet.hpp>

using geode::primal::detail::BytePacket;

TEST_CASE("BytePacket: values and strings read back in order, from the bytes alone") {
  BytePacket out;
  out.put(7);
  out.put(std::string("steel: soft"));
  out.put(std::array<int, 3>{1, -2, 3});
  out.put(2.5);
  out.put(std::string());
  // A receiver holds only the bytes.
  BytePacket in(out.bytes());
  CHECK(in.get<int>() == 7);
  CHECK(in.get_string() == "steel: soft");
  CHECK(in.get<std::array<int, 3>>() == std::array<int, 3>{1, -2, 3});
  double x = 0;
  in.get(x);
  CHECK(x == 2.5);
  CHECK(in.get_string().empty());
  CHECK_THROWS_AS(in.get<char>(), std::runtime_error);  // nothing left
}

TEST_CASE("BytePacket: reading past the end throws, whatever the bytes say") {
  BytePacket out;
  out.put(std::size_t{1} << 40);  // a string length far past the packet
  BytePacket in(out.bytes());
  CHECK_THROWS_AS(in.get_string(), std::runtime_error);
  BytePacket short_one(std::vector<char>(3, 'x'));
  CHECK_THROWS_AS(short_one.get<int>(), std::runtime_error);
}
