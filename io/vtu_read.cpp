#include <geode/io/vtk.hpp>

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <geode/io/detail/vtk_read_text.hpp>
#include <geode/io/file_format.hpp>
#include <geode/io/mapped_file.hpp>
#include <geode/primal/errors.hpp>

namespace geode::io {

using namespace primal;
using detail::check_cells;
using detail::fail;
using detail::Numbers;
using detail::parse_double;
using detail::parse_int;
using detail::parse_int32;
using detail::point_from;
using detail::split_numbers;

namespace {

// ---- XML (.vtu) -------------------------------------------------------------------------------

struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::string text;
  int line = 0;       // of the start tag
  int text_line = 0;  // where the text content starts
  std::vector<XmlElement> children;

  const XmlElement* child(const std::string& n) const {
    for (const auto& c : children) {
      if (c.name == n) return &c;
    }
    return nullptr;
  }
  std::string attr(const std::string& n) const {
    const auto it = attrs.find(n);
    return it == attrs.end() ? std::string() : it->second;
  }
};

// A small XML reader for what VTK writes: tags, attributes, text, comments, declarations.
class XmlParser {
 public:
  XmlParser(std::string text, std::string file) : s_(std::move(text)), file_(std::move(file)) {}

  XmlElement parse() {
    skip_misc();
    if (pos_ >= s_.size() || s_[pos_] != '<')
      fail(file_, line_, "not an XML file (no root element)");
    XmlElement root = element(0);
    return root;
  }

 private:
  std::string s_, file_;
  std::size_t pos_ = 0;
  int line_ = 1;

  void advance(std::size_t n) {
    for (std::size_t k = 0; k < n && pos_ < s_.size(); ++k) line_ += s_[pos_++] == '\n';
  }
  bool starts(std::string_view p) const { return s_.compare(pos_, p.size(), p) == 0; }
  [[noreturn]] void eof(const std::string& inside, int opened) {
    fail(file_, line_,
         "unexpected end of file inside " + inside + " opened at line " + std::to_string(opened) +
             " (truncated file?)");
  }
  void skip_space() {
    while (pos_ < s_.size() && detail::ascii_space(s_[pos_])) advance(1);
  }
  void skip_until(std::string_view end, const std::string& what) {
    const int opened = line_;
    const auto e = s_.find(end, pos_);
    if (e == std::string::npos) eof(what, opened);
    advance(e + end.size() - pos_);
  }
  void skip_misc() {
    while (true) {
      skip_space();
      if (starts("<?"))
        skip_until("?>", "an XML declaration");
      else if (starts("<!--"))
        skip_until("-->", "a comment");
      else if (starts("<!"))
        skip_until(">", "a DOCTYPE");
      else
        return;
    }
  }
  std::string name() {
    const std::size_t start = pos_;
    while (pos_ < s_.size() &&
           (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_' ||
            s_[pos_] == ':' || s_[pos_] == '-' || s_[pos_] == '.')) {
      advance(1);
    }
    return s_.substr(start, pos_ - start);
  }
  static std::string unescape(const std::string& v) {
    std::string out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (v[i] == '&') {
        static const std::pair<const char*, char> ents[] = {
            {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
        bool done = false;
        for (const auto& [ent, ch] : ents) {
          if (v.compare(i, std::char_traits<char>::length(ent), ent) == 0) {
            out += ch;
            i += std::char_traits<char>::length(ent) - 1;
            done = true;
            break;
          }
        }
        if (!done) out += '&';
      } else {
        out += v[i];
      }
    }
    return out;
  }

  // VTK files nest five deep; a deeper file is refused before recursion can exhaust the stack.
  static constexpr int kMaxDepth = 64;

  XmlElement element(int depth) {
    if (depth >= kMaxDepth)
      fail(file_, line_,
           "elements nested more than " + std::to_string(kMaxDepth) + " deep (not a VTK file)");
    XmlElement el;
    el.line = line_;
    advance(1);  // '<'
    el.name = name();
    if (el.name.empty()) fail(file_, line_, "malformed tag");
    const std::string tag = "<" + el.name + ">";
    // Attributes.
    while (true) {
      skip_space();
      if (pos_ >= s_.size()) eof("the tag " + tag, el.line);
      if (starts("/>")) {
        advance(2);
        return el;
      }
      if (s_[pos_] == '>') {
        advance(1);
        break;
      }
      const std::string key = name();
      skip_space();
      if (key.empty() || pos_ >= s_.size() || s_[pos_] != '=') {
        if (pos_ >= s_.size()) eof("the tag " + tag, el.line);
        fail(file_, line_, "malformed attribute in " + tag);
      }
      advance(1);
      skip_space();
      if (pos_ >= s_.size()) eof("the tag " + tag, el.line);
      const char q = s_[pos_];
      if (q != '"' && q != '\'')
        fail(file_, line_, "attribute " + key + " in " + tag + " is not quoted");
      advance(1);
      const auto e = s_.find(q, pos_);
      if (e == std::string::npos) eof("the tag " + tag, el.line);
      el.attrs[key] = unescape(s_.substr(pos_, e - pos_));
      advance(e + 1 - pos_);
    }
    // Content.
    el.text_line = line_;
    while (true) {
      const std::size_t lt = s_.find('<', pos_);
      if (lt == std::string::npos) {
        advance(s_.size() - pos_);
        eof(tag, el.line);
      }
      el.text += s_.substr(pos_, lt - pos_);
      advance(lt - pos_);
      if (starts("</")) {
        advance(2);
        const std::string end = name();
        skip_space();
        if (pos_ >= s_.size()) eof(tag, el.line);
        if (end != el.name || s_[pos_] != '>') {
          fail(file_, line_,
               "closing tag </" + end + "> does not match " + tag + " opened at line " +
                   std::to_string(el.line));
        }
        advance(1);
        return el;
      }
      if (starts("<!--")) {
        skip_until("-->", "a comment");
        continue;
      }
      el.children.push_back(element(depth + 1));
    }
  }
};

// How a .vtu stores binary DataArrays: the VTKFile's header_type and compressor, and the
// <AppendedData> bytes (after its '_'), cut out before the XML is parsed.
struct VtuStorage {
  std::size_t header_bytes = 4;  // UInt32 (default) or UInt64
  bool zlib = false;
  std::string_view appended;
  bool appended_base64 = false;
  // What zlib may still inflate over the whole file (array_bytes): real meshes compress a few
  // times (points hardly, connectivity 5 to 10 x), while a bomb repeats one block or points
  // several arrays at the same bytes; 64 MiB plus 64 bytes per byte of the file bounds both.
  mutable std::uint64_t inflate_budget = 0;
};

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// Decodes base64 one 4-character quantum at a time, so that parts encoded apart (VTK encodes a
// header and its data separately, each padded) decode as their concatenation.
std::string decode_base64(std::string_view text, const std::string& file, int line) {
  std::string out;
  out.reserve(text.size() / 4 * 3);
  int quantum[4];
  int n = 0, pad = 0;
  for (char c : text) {
    if (detail::ascii_space(c)) continue;
    if (c == '=') {
      if (n < 2) fail(file, line, "base64: misplaced padding");
      ++pad;
      quantum[n++] = 0;
    } else {
      const int v = base64_value(c);
      if (v < 0) fail(file, line, std::string("base64: invalid character '") + c + "'");
      if (pad) fail(file, line, "base64: data after padding inside a quantum");
      quantum[n++] = v;
    }
    if (n == 4) {
      const unsigned bits =
          static_cast<unsigned>(quantum[0] << 18 | quantum[1] << 12 | quantum[2] << 6 | quantum[3]);
      out += static_cast<char>(bits >> 16);
      if (pad < 2) out += static_cast<char>(bits >> 8 & 0xff);
      if (pad < 1) out += static_cast<char>(bits & 0xff);
      n = pad = 0;
    }
  }
  if (n != 0) fail(file, line, "base64: the text ends inside a quantum (truncated?)");
  return out;
}

std::size_t type_size(const std::string& t) {
  if (t == "Int8" || t == "UInt8") return 1;
  if (t == "Int16" || t == "UInt16") return 2;
  if (t == "Int32" || t == "UInt32" || t == "Float32") return 4;
  if (t == "Int64" || t == "UInt64" || t == "Float64") return 8;
  return 0;
}

// The array's raw bytes from a (header, data) stream: uncompressed, the header is the byte
// count; zlib-compressed, it is [blocks, block size, last block size, compressed sizes...]
// (VTK's vtkZLibDataCompressor layout). `want` bytes are expected; anything else is refused
// before it is allocated.
std::string array_bytes(std::string_view stream, const VtuStorage& enc, std::size_t want,
                        const std::string& file, int line, const std::string& what) {
  std::size_t at = 0;
  auto header = [&]() -> std::uint64_t {
    if (stream.size() - at < enc.header_bytes)
      fail(file, line, what + ": binary header cut short (truncated?)");
    std::uint64_t v = 0;
    if (enc.header_bytes == 4) {
      std::uint32_t x;
      std::memcpy(&x, stream.data() + at, 4);
      v = x;
    } else {
      std::memcpy(&v, stream.data() + at, 8);
    }
    at += enc.header_bytes;
    return v;
  };
  if (!enc.zlib) {
    const std::uint64_t n = header();
    if (n != want)
      fail(file, line,
           what + ": binary data of " + std::to_string(n) + " bytes, expected " +
               std::to_string(want));
    if (stream.size() - at < n) fail(file, line, what + ": binary data cut short (truncated?)");
    return std::string(stream.substr(at, n));
  }
  const std::uint64_t blocks = header(), block_size = header(), last_size = header();
  if (blocks > stream.size() / enc.header_bytes)
    fail(file, line, what + ": compressed header announces " + std::to_string(blocks) + " blocks");
  const std::uint64_t last = last_size == 0 ? block_size : last_size;
  // block_size is the nominal size of every block but the last (meshio writes 32768 for one
  // short block); the sizes must add up to what the array holds.
  if (blocks > 0 &&
      (last > block_size || last > want || (blocks > 1 && block_size > want / (blocks - 1)) ||
       (blocks - 1) * block_size + last != want))
    fail(file, line,
         what + ": compressed blocks do not add up to the " + std::to_string(want) +
             " bytes expected");
  if (blocks == 0 && want != 0)
    fail(file, line, what + ": no compressed blocks for " + std::to_string(want) + " bytes");
  // zlib inflates at most about 1032:1: a header that promises more is corrupt, and is refused
  // before anything of that size is allocated.
  if (want / 1032 > stream.size())
    fail(file, line,
         what + ": " + std::to_string(want) + " bytes cannot come from " +
             std::to_string(stream.size()) + " compressed bytes");
  if (want > enc.inflate_budget)
    fail(file, line,
         what + ": inflating to " + std::to_string(want) +
             " bytes would pass the file's bound of " + std::to_string(enc.inflate_budget) +
             " more bytes (64 MiB plus 64 times the file's size: a zlib bomb?)");
  enc.inflate_budget -= want;
  std::vector<std::uint64_t> sizes;
  for (std::uint64_t b = 0; b < blocks; ++b) sizes.push_back(header());
  std::string out;
  out.reserve(want);
  for (std::uint64_t b = 0; b < blocks; ++b) {
    if (stream.size() - at < sizes[b])
      fail(file, line,
           what + ": compressed block " + std::to_string(b + 1) + " cut short (truncated?)");
    const std::uint64_t size = b + 1 == blocks ? last : block_size;
    std::string block(size, '\0');
    uLongf got = static_cast<uLongf>(size);
    const int status = uncompress(reinterpret_cast<Bytef*>(block.data()), &got,
                                  reinterpret_cast<const Bytef*>(stream.data() + at),
                                  static_cast<uLong>(sizes[b]));
    if (status != Z_OK || got != size)
      fail(file, line,
           what + ": compressed block " + std::to_string(b + 1) + " does not inflate to " +
               std::to_string(size) + " bytes (zlib status " + std::to_string(status) + ")");
    out += block;
    at += sizes[b];
  }
  return out;
}

template <class T>
void append_values(std::string& text, const std::string& bytes) {
  for (std::size_t i = 0; i + sizeof(T) <= bytes.size(); i += sizeof(T)) {
    T x;
    std::memcpy(&x, bytes.data() + i, sizeof(T));
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, x);
    text.append(buf, res.ptr);
    text += ' ';
  }
}

// A binary DataArray's values as text tokens, so that ASCII and binary arrays share one path.
Numbers binary_values(const std::string& file, const XmlElement& a, std::size_t expected,
                      const std::string& what, const VtuStorage& enc) {
  const std::string type = a.attr("type"), format = a.attr("format");
  const std::size_t size = type_size(type);
  if (size == 0) fail(file, a.line, what + ": unsupported type \"" + type + "\"");
  if (expected > (std::numeric_limits<std::size_t>::max() / 16) / size)
    fail(file, a.line, what + ": too many values");
  const std::size_t want = expected * size;
  std::string bytes;
  if (format == "binary") {
    bytes = array_bytes(decode_base64(a.text, file, a.text_line), enc, want, file, a.line, what);
  } else {
    const std::string offset_text = a.attr("offset");
    std::size_t offset = 0;
    const auto res =
        std::from_chars(offset_text.data(), offset_text.data() + offset_text.size(), offset);
    if (offset_text.empty() || res.ec != std::errc() ||
        res.ptr != offset_text.data() + offset_text.size())
      fail(file, a.line, what + ": appended DataArray without a valid offset");
    if (offset > enc.appended.size())
      fail(file, a.line,
           what + ": offset " + offset_text + " lies beyond the appended data (truncated?)");
    const std::string_view rest = enc.appended.substr(offset);
    if (enc.appended_base64) {
      // Decoded to the end: the array's header and data, encoded apart or together, come
      // first; the arrays after it follow and are ignored.
      std::string_view piece =
          rest.substr(0, rest.find_first_not_of(
                             "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/="));
      piece = piece.substr(0, piece.size() - piece.size() % 4);
      const std::string decoded = decode_base64(piece, file, a.line);
      bytes = array_bytes(decoded, enc, want, file, a.line, what);
    } else {
      bytes = array_bytes(rest, enc, want, file, a.line, what);
    }
  }
  auto text = std::make_shared<std::string>();
  if (type == "Int8") append_values<std::int8_t>(*text, bytes);
  if (type == "UInt8") append_values<std::uint8_t>(*text, bytes);
  if (type == "Int16") append_values<std::int16_t>(*text, bytes);
  if (type == "UInt16") append_values<std::uint16_t>(*text, bytes);
  if (type == "Int32") append_values<std::int32_t>(*text, bytes);
  if (type == "UInt32") append_values<std::uint32_t>(*text, bytes);
  if (type == "Int64") append_values<std::int64_t>(*text, bytes);
  if (type == "UInt64") append_values<std::uint64_t>(*text, bytes);
  if (type == "Float32") append_values<float>(*text, bytes);
  if (type == "Float64") append_values<double>(*text, bytes);
  Numbers n = split_numbers(*text, a.line);
  n.storage = std::move(text);
  std::fill(n.lines.begin(), n.lines.end(), a.line);
  return n;
}

// A DataArray's values as tokens, checked for encoding and count.
Numbers data_array_values(const std::string& file, const XmlElement& a, std::size_t expected,
                          const std::string& what, const VtuStorage& enc) {
  const std::string format = a.attr("format");
  if (format == "binary" || format == "appended")
    return binary_values(file, a, expected, what, enc);
  if (format != "ascii") {
    fail(file, a.line,
         what + ": format=\"" + format +
             "\" is not supported (ascii, binary and appended are read)");
  }
  Numbers n = split_numbers(a.text, a.text_line);
  if (n.tokens.size() != expected) {
    fail(file, a.line,
         what + ": " + std::to_string(n.tokens.size()) + " values, expected " +
             std::to_string(expected) + (n.tokens.size() < expected ? " (truncated?)" : ""));
  }
  return n;
}

const XmlElement& required(const std::string& file, const XmlElement& parent,
                           const std::string& name) {
  const XmlElement* c = parent.child(name);
  if (!c) fail(file, parent.line, "<" + parent.name + "> has no <" + name + ">");
  return *c;
}

std::size_t count_attr(const std::string& file, const XmlElement& el, const std::string& key) {
  const std::string v = el.attr(key);
  const long long n =
      parse_int(file, el.line, v.empty() ? std::string_view("missing") : std::string_view(v));
  if (n < 0) fail(file, el.line, key + " is negative");
  return index_cast<std::size_t>(n);
}

bool is_float_type(const std::string& t) { return t == "Float32" || t == "Float64"; }
bool is_int_type(const std::string& t) {
  return t == "Int8" || t == "UInt8" || t == "Int16" || t == "UInt16" || t == "Int32" ||
         t == "UInt32" || t == "Int64" || t == "UInt64";
}

}  // namespace

// ---- .vtu reader ------------------------------------------------------------------------------

VtkGrid read_vtu(const std::filesystem::path& path) {
  check_mesh_format(path, MeshFileFormat::kVtu);
  return parse_vtu(MappedFile(path).bytes(), path.string());
}

VtkGrid parse_vtu(std::string_view content, const std::string& source) {
  VtkGrid g;
  g.source = source;
  const std::string& file = g.source;
  // Appended data is raw bytes that may hold '<': cut out before the XML is parsed.
  std::string xml(content);
  VtuStorage enc;
  enc.inflate_budget = (std::uint64_t{64} << 20) + 64 * static_cast<std::uint64_t>(content.size());
  std::string appended_bytes;
  if (const auto tag = xml.find("<AppendedData"); tag != std::string::npos) {
    const auto close = xml.find('>', tag);
    const auto underscore = close == std::string::npos ? close : xml.find('_', close);
    const auto end = xml.rfind("</AppendedData>");
    if (underscore == std::string::npos || end == std::string::npos || end < underscore)
      fail(file,
           static_cast<int>(
               std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(tag), '\n')) +
               1,
           "<AppendedData> without its '_' marker or its end tag (truncated file?)");
    appended_bytes = xml.substr(underscore + 1, end - underscore - 1);
    // Keep the line count of what follows for messages.
    const auto lines = std::count(appended_bytes.begin(), appended_bytes.end(), '\n');
    xml.replace(underscore, end - underscore, std::string(index_cast<std::size_t>(lines), '\n'));
    enc.appended = appended_bytes;
  }
  const XmlElement root = XmlParser(std::move(xml), file).parse();
  if (const std::string h = root.attr("header_type"); !h.empty() && h != "UInt32" && h != "UInt64")
    fail(file, root.line, "header_type \"" + h + "\" is not supported (UInt32 and UInt64 are)");
  enc.header_bytes = root.attr("header_type") == "UInt64" ? 8 : 4;
  if (const std::string c = root.attr("compressor"); !c.empty()) {
    if (c != "vtkZLibDataCompressor")
      fail(file, root.line, "compressor \"" + c + "\" is not supported (vtkZLibDataCompressor is)");
    enc.zlib = true;
  }
  if (const std::string order = root.attr("byte_order"); !order.empty() && order != "LittleEndian")
    fail(file, root.line, "byte_order \"" + order + "\" is not supported (LittleEndian is)");
  if (const XmlElement* ad = root.child("AppendedData")) {
    const std::string e = ad->attr("encoding");
    if (e != "raw" && e != "base64")
      fail(file, ad->line,
           "AppendedData encoding \"" + e + "\" is not supported (raw and base64 are)");
    enc.appended_base64 = e == "base64";
  }
  if (root.name != "VTKFile" || root.attr("type") != "UnstructuredGrid") {
    fail(file, root.line,
         "not a VTK UnstructuredGrid file (root <" + root.name + "> type \"" + root.attr("type") +
             "\")");
  }
  const XmlElement& ug = required(file, root, "UnstructuredGrid");
  const XmlElement& piece = required(file, ug, "Piece");
  if (std::count_if(ug.children.begin(), ug.children.end(),
                    [](const XmlElement& e) { return e.name == "Piece"; }) != 1) {
    fail(file, piece.line, "only single-Piece files are supported");
  }
  const std::size_t np = count_attr(file, piece, "NumberOfPoints");
  const std::size_t nc = count_attr(file, piece, "NumberOfCells");

  // Integer field arrays of the dataset (block names, sets); others are skipped.
  if (const XmlElement* fd = ug.child("FieldData")) {
    for (const auto& a : fd->children) {
      if (a.name != "DataArray" || !is_int_type(a.attr("type"))) continue;
      const std::string nm = a.attr("Name");
      const std::size_t tuples = count_attr(file, a, "NumberOfTuples");
      const std::string comps = a.attr("NumberOfComponents");
      const std::size_t components = comps.empty() ? 1 : count_attr(file, a, "NumberOfComponents");
      if (components < 1 || components > 16)
        fail(file, a.line, "FieldData '" + nm + "': " + comps + " components");
      if (tuples > (std::numeric_limits<std::size_t>::max() >> 8))
        fail(file, a.line, "FieldData '" + nm + "': too many tuples");
      const Numbers n =
          data_array_values(file, a, tuples * components, "FieldData '" + nm + "'", enc);
      VtkGrid::FieldArray array{nm, components, {}};
      for (std::size_t i = 0; i < n.tokens.size(); ++i)
        array.values.push_back(parse_int(file, n.lines[i], n.tokens[i]));
      g.field_data.push_back(std::move(array));
    }
  }

  // Points.
  const XmlElement& pts = required(file, piece, "Points");
  const XmlElement& pa = required(file, pts, "DataArray");
  if (pa.attr("NumberOfComponents") != "3")
    fail(file, pa.line, "Points: NumberOfComponents must be 3");
  {
    const Numbers n = data_array_values(file, pa, 3 * np, "Points", enc);
    for (std::size_t i = 0; i < np; ++i) {
      double x[3];
      for (int k = 0; k < 3; ++k)
        x[k] = parse_double(file, n.lines[3 * i + k], n.tokens[3 * i + k]);
      g.points.push_back(point_from(file, n.lines[3 * i], i, x[0], x[1], x[2]));
    }
  }

  // Cells.
  const XmlElement& cells = required(file, piece, "Cells");
  const XmlElement *conn = nullptr, *offs = nullptr, *types = nullptr;
  for (const auto& a : cells.children) {
    const std::string nm = a.attr("Name");
    if (nm == "connectivity") conn = &a;
    if (nm == "offsets") offs = &a;
    if (nm == "types") types = &a;
  }
  if (!conn || !offs || !types) {
    fail(file, cells.line, "<Cells> needs DataArrays connectivity, offsets and types");
  }
  const Numbers on = data_array_values(file, *offs, nc, "offsets", enc);
  const Numbers tn = data_array_values(file, *types, nc, "types", enc);
  std::vector<std::size_t> offsets;
  for (std::size_t c = 0; c < nc; ++c) {
    const long long o = parse_int(file, on.lines[c], on.tokens[c]);
    if (o < 0 || (c > 0 && index_cast<std::size_t>(o) < offsets.back())) {
      fail(file, on.lines[c],
           "offsets: cell " + std::to_string(c) + ": offset " + std::to_string(o) +
               " is negative or decreasing");
    }
    offsets.push_back(index_cast<std::size_t>(o));
  }
  const Numbers cn = data_array_values(file, *conn, nc ? offsets.back() : 0, "connectivity", enc);
  std::vector<int> cell_line(nc, conn->line), type_line(nc, types->line);
  for (std::size_t c = 0; c < nc; ++c) {
    g.cell_types.push_back(parse_int32(file, tn.lines[c], tn.tokens[c]));
    type_line[c] = tn.lines[c];
    std::vector<Index> cell;
    const std::size_t begin = c ? offsets[c - 1] : 0;
    for (std::size_t i = begin; i < offsets[c]; ++i) {
      cell.push_back(parse_int32(file, cn.lines[i], cn.tokens[i]));
    }
    if (begin < offsets[c]) cell_line[c] = cn.lines[begin];
    g.cells.push_back(std::move(cell));
  }
  check_cells(g, [&](std::size_t c, bool type) { return type ? type_line[c] : cell_line[c]; });

  // Cell data.
  if (const XmlElement* cd = piece.child("CellData")) {
    for (const auto& a : cd->children) {
      if (a.name != "DataArray") continue;
      const std::string nm = a.attr("Name"), type = a.attr("type");
      if (nm.empty()) fail(file, a.line, "CellData: DataArray without a Name");
      const std::string comps = a.attr("NumberOfComponents");
      if (!comps.empty() && comps != "1") {
        fail(file, a.line, "CellData '" + nm + "': only 1-component arrays are read");
      }
      const Numbers n = data_array_values(file, a, nc, "CellData '" + nm + "'", enc);
      if (is_float_type(type)) {
        std::vector<double> v;
        for (std::size_t i = 0; i < nc; ++i)
          v.push_back(parse_double(file, n.lines[i], n.tokens[i]));
        g.cell_data.doubles.emplace_back(nm, std::move(v));
      } else if (is_int_type(type)) {
        std::vector<int> v;
        for (std::size_t i = 0; i < nc; ++i)
          v.push_back(parse_int32(file, n.lines[i], n.tokens[i]));
        g.cell_data.ints.emplace_back(nm, std::move(v));
      } else {
        fail(file, a.line, "CellData '" + nm + "': unsupported type \"" + type + "\"");
      }
    }
  }
  return g;
}

}  // namespace geode::io
