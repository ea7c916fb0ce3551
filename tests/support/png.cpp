#include "support/png.hpp"

#include <zlib.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

namespace geode::test {
namespace {

std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         p[3];
}

// The Paeth predictor of the PNG specification (section 9.4).
int paeth(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  return pa <= pb && pa <= pc ? a : (pb <= pc ? b : c);
}

}  // namespace

Image read_png(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> f((std::istreambuf_iterator<char>(in)),
                                    std::istreambuf_iterator<char>());
  auto fail = [&](const std::string& why) {
    return std::runtime_error(path.string() + ": " + why);
  };
  static const std::uint8_t sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  if (f.size() < 8 || !std::equal(sig, sig + 8, f.begin())) throw fail("not a PNG file");
  Image im;
  int channels = 0;
  std::vector<std::uint8_t> idat;
  for (std::size_t at = 8; at + 12 <= f.size();) {
    const std::uint32_t len = be32(&f[at]);
    if (at + 12 + len > f.size()) throw fail("truncated chunk");
    const std::string type(reinterpret_cast<const char*>(&f[at + 4]), 4);
    const std::uint8_t* d = &f[at + 8];
    if (type == "IHDR") {
      im.width = static_cast<int>(be32(d));
      im.height = static_cast<int>(be32(d + 4));
      if (d[8] != 8 || (d[9] != 2 && d[9] != 6) || d[12] != 0)
        throw fail("only 8-bit RGB(A), not interlaced");
      channels = d[9] == 6 ? 4 : 3;
    } else if (type == "IDAT") {
      idat.insert(idat.end(), d, d + len);
    } else if (type == "IEND") {
      break;
    }
    at += 12 + len;
  }
  if (!channels || im.width <= 0 || im.height <= 0) throw fail("no image header");
  const std::size_t stride = static_cast<std::size_t>(im.width) * channels;
  std::vector<std::uint8_t> raw((stride + 1) * static_cast<std::size_t>(im.height));
  uLongf size = static_cast<uLongf>(raw.size());
  if (uncompress(raw.data(), &size, idat.data(), static_cast<uLong>(idat.size())) != Z_OK ||
      size != raw.size())
    throw fail("bad image data");
  std::vector<std::uint8_t> px(stride * static_cast<std::size_t>(im.height));
  for (std::size_t y = 0; y < static_cast<std::size_t>(im.height); ++y) {
    const std::uint8_t filter = raw[y * (stride + 1)];
    const std::uint8_t* src = &raw[y * (stride + 1) + 1];
    std::uint8_t* row = &px[y * stride];
    const std::uint8_t* up = y ? &px[(y - 1) * stride] : nullptr;
    for (std::size_t i = 0; i < stride; ++i) {
      const int a =
          i >= static_cast<std::size_t>(channels) ? row[i - static_cast<std::size_t>(channels)] : 0;
      const int b = up ? up[i] : 0;
      const int c = up && i >= static_cast<std::size_t>(channels)
                        ? up[i - static_cast<std::size_t>(channels)]
                        : 0;
      int v = src[i];
      switch (filter) {
        case 0:
          break;
        case 1:
          v += a;
          break;
        case 2:
          v += b;
          break;
        case 3:
          v += (a + b) / 2;
          break;
        case 4:
          v += paeth(a, b, c);
          break;
        default:
          throw fail("bad row filter");
      }
      row[i] = static_cast<std::uint8_t>(v);
    }
  }
  im.rgb.reserve(static_cast<std::size_t>(im.width) * im.height * 3);
  for (std::size_t p = 0; p < px.size(); p += static_cast<std::size_t>(channels))
    im.rgb.insert(im.rgb.end(), px.begin() + static_cast<std::ptrdiff_t>(p),
                  px.begin() + static_cast<std::ptrdiff_t>(p) + 3);
  return im;
}

}  // namespace geode::test
