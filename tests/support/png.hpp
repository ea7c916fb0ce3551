#pragma once
// A small PNG reader for tests that look at screenshots (8-bit RGB or RGBA, not interlaced:
// what Chromium writes), decoded with zlib.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace geode::test {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // 3 bytes per pixel, row by row
};

// Throws std::runtime_error naming the file for anything else.
Image read_png(const std::filesystem::path& path);

}  // namespace geode::test
