#include <doctest/doctest.h>

#include <array>
#include <unordered_map>
#include <vector>

#include <geode/primal/release.hpp>

namespace gp = geode::primal;

TEST_CASE("release frees a container's storage, where assigning {} keeps it") {
  std::vector<std::array<int, 8>> kept(1000), freed(1000);
  kept = {};  // the initializer_list assignment: empty, capacity kept
  CHECK(kept.empty());
  CHECK(kept.capacity() >= 1000);
  gp::release(freed);
  CHECK(freed.empty());
  CHECK(freed.capacity() == 0);

  std::vector<char> a(100);
  std::vector<double> b(100);
  std::unordered_map<int, int> c;
  for (int i = 0; i < 100; ++i) c[i] = i;
  gp::release(a, b, c);
  CHECK(a.capacity() == 0);
  CHECK(b.capacity() == 0);
  CHECK(c.empty());
  CHECK(c.bucket_count() < 100);
}
