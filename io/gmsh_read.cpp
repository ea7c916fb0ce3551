// Our own reader of Gmsh .msh 2.2 and 4.1 (ASCII and binary): user files never reach libgmsh,
// whose open() runs any text that is not a mesh as a Gmsh script. Format reference: Gmsh
// reference manual, "MSH file format" (version 4.1) and "Legacy formats" (version 2.2).
// Sections read: $MeshFormat, $PhysicalNames, $Entities, $Nodes, $Elements; any other section
// is skipped up to its $End line. Counts are checked against the bytes left before anything
// is allocated, so that a corrupt count cannot exhaust memory.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>

#include <geode/io/detail/ascii_space.hpp>
#include <geode/io/file_format.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/names.hpp>
#include <geode/io/read_warnings.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::io {

using namespace primal;

namespace {

constexpr int kTri3 = 2, kQuad4 = 3, kLine2 = 1, kPoint1 = 15;

struct GmshType {
  int type;
  int dim;
  int nodes;
  const char* name;
};

// Element types as the reference manual numbers them ("MSH file format", elm-type), with
// their dimension and node count: enough to step over any element a mesh may hold.
constexpr GmshType kGmshTypes[] = {
    {1, 1, 2, "2-node line"},
    {2, 2, 3, "3-node triangle"},
    {3, 2, 4, "4-node quadrangle"},
    {4, 3, 4, "4-node tetrahedron"},
    {5, 3, 8, "8-node hexahedron"},
    {6, 3, 6, "6-node prism"},
    {7, 3, 5, "5-node pyramid"},
    {8, 1, 3, "3-node line"},
    {9, 2, 6, "6-node triangle"},
    {10, 2, 9, "9-node quadrangle"},
    {11, 3, 10, "10-node tetrahedron"},
    {12, 3, 27, "27-node hexahedron"},
    {13, 3, 18, "18-node prism"},
    {14, 3, 14, "14-node pyramid"},
    {15, 0, 1, "1-node point"},
    {16, 2, 8, "8-node quadrangle"},
    {17, 3, 20, "20-node hexahedron"},
    {18, 3, 15, "15-node prism"},
    {19, 3, 13, "13-node pyramid"},
    {20, 2, 9, "9-node triangle"},
    {21, 2, 10, "10-node triangle"},
    {22, 2, 12, "12-node triangle"},
    {23, 2, 15, "15-node triangle"},
    {24, 2, 15, "15-node triangle"},
    {25, 2, 21, "21-node triangle"},
    {26, 1, 4, "4-node line"},
    {27, 1, 5, "5-node line"},
    {28, 1, 6, "6-node line"},
    {29, 3, 20, "20-node tetrahedron"},
    {30, 3, 35, "35-node tetrahedron"},
    {31, 3, 56, "56-node tetrahedron"},
    {92, 3, 64, "64-node hexahedron"},
    {93, 3, 125, "125-node hexahedron"},
};

const GmshType* gmsh_type(long long type) {
  for (const GmshType& t : kGmshTypes)
    if (t.type == type) return &t;
  return nullptr;
}

struct RawElement {
  std::int64_t tag = 0;
  int type = 0;
  int entity = 0;
  int physical = 0;       // version 2.2: the element's own physical tag (0: none)
  std::size_t first = 0;  // into MshReader::element_nodes_
};

// Node tag -> model index. Tags that are about 1..n (Gmsh numbers its nodes so; up to 4 n +
// 1024, which the file's own size bounds) go through a table, a look-up per element corner (1.1
// million on the n = 36 bench) that a hash map made a random probe; others through a hash map.
class NodeIndex {
 public:
  explicit NodeIndex(const std::vector<std::int64_t>& tags) {
    std::int64_t top = 0;
    for (std::int64_t t : tags) top = std::max(top, t);
    if (static_cast<std::uint64_t>(top) <= 4 * static_cast<std::uint64_t>(tags.size()) + 1024)
      table_.assign(static_cast<std::size_t>(top) + 1, kInvalidIndex);
    else
      map_.reserve(tags.size());
  }
  // The index of `tag`, or kInvalidIndex.
  Index find(std::int64_t tag) const {
    if (!table_.empty())
      return tag >= 0 && static_cast<std::uint64_t>(tag) < table_.size()
                 ? table_[static_cast<std::size_t>(tag)]
                 : kInvalidIndex;
    const auto it = map_.find(tag);
    return it == map_.end() ? kInvalidIndex : it->second;
  }
  void add(std::int64_t tag, Index index) {  // tag > 0, not there yet
    if (!table_.empty())
      table_[static_cast<std::size_t>(tag)] = index;
    else
      map_.emplace(tag, index);
  }

 private:
  std::vector<Index> table_;
  std::unordered_map<std::int64_t, Index> map_;
};

class MshReader {
 public:
  MshReader(std::string_view data, std::string source, FilePartition* partition)
      : s_(data), source_(std::move(source)), partition_(partition) {}

  Model read() {
    if (sniff_mesh_format(s_) != MeshFileFormat::kGmsh)
      fail_at(0,
              "not in Gmsh .msh format (it does not start with $MeshFormat; Gmsh scripts are not "
              "read)");
    bool have_nodes = false, have_elements = false;
    while (true) {
      skip_space();
      if (pos_ >= s_.size()) break;
      const std::size_t start = pos_;
      const std::string name = section_name();
      // $Comments may stand before $MeshFormat; no section that needs the version may.
      if (version_ == 0 && name != "MeshFormat" && name != "Comments")
        fail_at(start, "$" + name + " before $MeshFormat");
      if (name == "ParametricNodes")  // Gmsh 2.2's Mesh.SaveParametric=1 writes it for $Nodes
        fail_at(start,
                "$ParametricNodes (Gmsh 2.2 saved with Mesh.SaveParametric=1) is not read; save "
                "without it, or as 4.1");
      if (name == "MeshFormat") {
        mesh_format();
      } else if (name == "PhysicalNames") {
        physical_names();
      } else if (name == "Entities") {
        if (version_ == 2) fail_at(start, "$Entities in a version 2 file");
        entities();
      } else if (name == "PartitionedEntities") {
        if (version_ == 2) fail_at(start, "$PartitionedEntities in a version 2 file");
        partitioned_entities();
      } else if (name == "Nodes") {
        if (have_nodes) fail_at(start, "a second $Nodes section");
        version_ == 4 ? nodes41() : nodes22();
        have_nodes = true;
      } else if (name == "Elements") {
        if (have_elements) fail_at(start, "a second $Elements section");
        version_ == 4 ? elements41() : elements22();
        have_elements = true;
      } else {
        // Periodic meshes (representative volumes): nothing carries the pairing, and nodes on
        // those faces may move within them (buffer layer, smoothing) on one side only.
        if (name == "Periodic")
          read_warning(source_ +
                       ": $Periodic is not read: the output has no periodic node pairs, and its "
                       "periodic faces match node for node only where the transition and "
                       "smoothing moved no node on them");
        skip_section(name, start);
        continue;
      }
      end_section(name, start);
    }
    if (!have_nodes) fail_at(pos_, "no $Nodes section (truncated file?)");
    if (!have_elements) fail_at(pos_, "no $Elements section (truncated file?)");
    return build();
  }

 private:
  std::string_view s_;
  std::string source_;
  std::size_t pos_ = 0;
  int version_ = 0;  // 2 (2.x) or 4 (4.1); 0 before $MeshFormat
  bool binary_ = false;
  std::map<std::pair<int, int>, std::string> physical_names_;         // (dim, tag) -> name
  std::map<std::pair<int, int>, std::vector<int>> entity_physicals_;  // (dim, entity) -> tags
  // $PartitionedEntities (a partitioned 4.1 file): elements then name these entities, each
  // with its parent entity of $Entities and physical tags of its own (Gmsh copies the
  // parent's; when none are given the parent's hold).
  struct Partitioned {
    int parent_dim = 0, parent_tag = 0;
    std::vector<int> partitions;  // Gmsh's tags, 1-based
    std::vector<int> physicals;
  };
  bool partitioned_ = false;
  std::size_t partitions_ = 0;  // $PartitionedEntities' count
  FilePartition* partition_;    // filled when not null
  std::map<std::pair<int, int>, Partitioned> partitioned_entities_;
  std::vector<std::int64_t> node_tags_;
  std::vector<Point> node_points_;
  std::vector<RawElement> elements_;
  std::vector<std::int64_t> element_nodes_;

  // ---- Messages --------------------------------------------------------------------------

  [[noreturn]] void fail_at(std::size_t at, const std::string& what) const {
    std::string where = source_ + ": ";
    if (!binary_ || version_ == 0) {
      const auto line =
          std::count(s_.begin(), s_.begin() + static_cast<std::ptrdiff_t>(std::min(at, s_.size())),
                     '\n') +
          1;
      where += "line " + std::to_string(line) + ": ";
    } else {
      where += "byte " + std::to_string(at) + ": ";
    }
    throw InvalidInput(where + what);
  }
  [[noreturn]] void fail(const std::string& what) const { fail_at(pos_, what); }

  // ---- Lexing ----------------------------------------------------------------------------

  void skip_space() {
    while (pos_ < s_.size() && detail::ascii_space(s_[pos_])) ++pos_;
  }
  std::string_view token(const char* what) {
    skip_space();
    const std::size_t start = pos_;
    while (pos_ < s_.size() && !detail::ascii_space(s_[pos_])) ++pos_;
    if (start == pos_)
      fail(std::string("unexpected end of file reading ") + what + " (truncated file?)");
    const std::string_view t = s_.substr(start, pos_ - start);
    if (t.front() == '$') {
      pos_ = start;
      fail(std::string("expected ") + what + ", found " + std::string(t) + " (truncated section?)");
    }
    return t;
  }
  template <class T>
  T ascii_integer(const char* what) {
    const std::string_view t = token(what);
    T x{};
    const auto res = std::from_chars(t.data(), t.data() + t.size(), x);
    if (res.ec != std::errc() || res.ptr != t.data() + t.size())
      fail_at(pos_ - t.size(),
              std::string(what) + ": '" + std::string(t) + "' is not an integer in range");
    return x;
  }
  double ascii_real(const char* what) {
    std::string_view t = token(what);
    if (t.front() == '+') t.remove_prefix(1);
    double x = 0.0;
    const auto res = std::from_chars(t.data(), t.data() + t.size(), x);
    // Beyond the range of a double: infinite, refused with the node's tag by check_points.
    if (res.ec == std::errc::result_out_of_range && res.ptr == t.data() + t.size() && !t.empty() &&
        t.find_first_of("eE") != std::string_view::npos && t.find("e-") == std::string_view::npos &&
        t.find("E-") == std::string_view::npos)
      return t.front() == '-' ? -HUGE_VAL : HUGE_VAL;
    if (res.ec == std::errc::result_out_of_range && res.ptr == t.data() + t.size())
      return 0.0;  // underflow
    if (res.ec != std::errc() || res.ptr != t.data() + t.size())
      fail_at(pos_ - t.size(), std::string(what) + ": '" + std::string(t) + "' is not a number");
    return x;
  }
  template <class T>
  T raw(const char* what) {
    if (s_.size() - pos_ < sizeof(T))
      fail(std::string("unexpected end of file reading ") + what + " (truncated file?)");
    T x;
    std::memcpy(&x, s_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return x;
  }
  // Fields: 4-byte int, size_t (8 bytes in 4.1 binary; int in 2.2 binary), double.
  long long int_field(const char* what) {
    return binary_ ? raw<std::int32_t>(what) : ascii_integer<long long>(what);
  }
  long long size_field(const char* what) {
    if (!binary_) return ascii_integer<long long>(what);
    if (version_ == 2) return raw<std::int32_t>(what);
    const std::uint64_t v = raw<std::uint64_t>(what);
    if (v > static_cast<std::uint64_t>(INT64_MAX))
      fail_at(pos_ - 8, std::string(what) + ": " + std::to_string(v) + " is out of range");
    return static_cast<long long>(v);
  }
  double real_field(const char* what) { return binary_ ? raw<double>(what) : ascii_real(what); }
  // A count read from the file, refused when the bytes left cannot hold `count` items of at
  // least `min_bytes` each.
  std::size_t count_field(const char* what, std::size_t min_bytes) {
    const std::size_t at = pos_;
    const long long n = size_field(what);
    if (n < 0) fail_at(at, std::string(what) + " " + std::to_string(n) + " is negative");
    if (static_cast<unsigned long long>(n) >
        (s_.size() - pos_) / std::max<std::size_t>(min_bytes, 1))
      fail_at(at, std::string(what) + " " + std::to_string(n) +
                      " is more than the rest of the file can hold (truncated file?)");
    return index_cast<std::size_t>(n);
  }
  // Per-item minimum sizes for count_field: ASCII items are at least "d " per number.
  std::size_t item_bytes(std::size_t ascii_numbers, std::size_t binary_bytes) const {
    return binary_ ? binary_bytes : 2 * ascii_numbers;
  }
  std::size_t size_bytes() const { return version_ == 2 ? 4 : 8; }

  // ---- Sections --------------------------------------------------------------------------

  std::string section_name() {
    if (s_[pos_] != '$')
      fail("expected a section ($Name), found '" + std::string(s_.substr(pos_, 20)) + "'");
    const std::size_t start = ++pos_;
    while (pos_ < s_.size() && !detail::ascii_space(s_[pos_])) ++pos_;
    const std::string name(s_.substr(start, pos_ - start));
    // The rest of the line: binary data starts right after it.
    while (pos_ < s_.size() && s_[pos_] != '\n' && detail::ascii_space(s_[pos_])) ++pos_;
    if (pos_ < s_.size() && s_[pos_] == '\n') ++pos_;
    return name;
  }
  void end_section(const std::string& name, std::size_t start) {
    skip_space();
    const std::string end = "$End" + name;
    if (s_.substr(pos_, end.size()) != end ||
        (pos_ + end.size() < s_.size() && !detail::ascii_space(s_[pos_ + end.size()]))) {
      if (pos_ >= s_.size()) fail_at(start, "$" + name + " has no " + end + " (truncated file?)");
      fail("$" + name + " ends without " + end + " (found '" +
           std::string(s_.substr(pos_, std::min<std::size_t>(20, s_.find('\n', pos_) - pos_))) +
           "')");
    }
    pos_ += end.size();
  }
  void skip_section(const std::string& name, std::size_t start) {
    const std::string end = "$End" + name;
    const std::size_t e = s_.find(end, pos_);
    if (e == std::string_view::npos)
      fail_at(start, "$" + name + " has no " + end + " (truncated file?)");
    pos_ = e + end.size();
  }

  void mesh_format() {
    const std::size_t at = pos_;
    const std::string_view v = token("the version");
    int file_type = static_cast<int>(ascii_integer<long long>("the file type"));
    const long long data_size = ascii_integer<long long>("the data size");
    if (v == "4.1")
      version_ = 4;
    else if (v == "2" || v == "2.0" || v == "2.1" || v == "2.2")
      version_ = 2;
    else
      fail_at(at, "MSH version " + std::string(v) + " is not read (versions 2.2 and 4.1 are)");
    if (file_type != 0 && file_type != 1)
      fail_at(at,
              "file type " + std::to_string(file_type) + " is neither 0 (ASCII) nor 1 (binary)");
    if (data_size != 8)
      fail_at(at, "data size " + std::to_string(data_size) + " is not read (8 is)");
    binary_ = file_type == 1;
    if (binary_) {
      if (pos_ < s_.size() && s_[pos_] == '\r') ++pos_;
      if (pos_ >= s_.size() || s_[pos_] != '\n')
        fail("binary $MeshFormat: no line end after the header");
      ++pos_;
      const std::int32_t one = raw<std::int32_t>("the endianness check");
      if (one != 1)
        fail_at(pos_ - 4, "binary file of another byte order (the check integer reads " +
                              std::to_string(one) + ")");
    }
  }

  void physical_names() {
    const bool was_binary = binary_;
    binary_ = false;  // always text
    const std::size_t n = count_field("the number of physical names", 6);
    for (std::size_t i = 0; i < n; ++i) {
      const int dim = static_cast<int>(ascii_integer<int>("a physical dimension"));
      const int tag = ascii_integer<int>("a physical tag");
      skip_space();
      if (pos_ >= s_.size() || s_[pos_] != '"')
        fail("physical name " + std::to_string(tag) + ": expected a quoted name");
      const std::size_t close = s_.find('"', pos_ + 1);
      const std::size_t eol = s_.find('\n', pos_);
      if (close == std::string_view::npos || close > eol)
        fail("physical name " + std::to_string(tag) + ": no closing quote on its line");
      physical_names_[{dim, tag}] = std::string(s_.substr(pos_ + 1, close - pos_ - 1));
      pos_ = close + 1;
    }
    binary_ = was_binary;
  }

  void entities() {
    std::array<std::size_t, 4> counts{};
    for (std::size_t d = 0; d < 4; ++d)
      counts[d] = count_field("an entity count", item_bytes(5, 36));
    for (int dim = 0; dim < 4; ++dim)
      for (std::size_t i = 0; i < counts[index_cast<std::size_t>(dim)]; ++i) {
        const int tag = static_cast<int>(int_field("an entity tag"));
        for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) real_field("an entity bounding box");
        const std::size_t np = count_field("a physical tag count", item_bytes(1, 4));
        std::vector<int> physicals;
        for (std::size_t p = 0; p < np; ++p)
          physicals.push_back(static_cast<int>(int_field("a physical tag")));
        entity_physicals_[{dim, tag}] = std::move(physicals);
        if (dim > 0) {
          const std::size_t nb = count_field("a bounding entity count", item_bytes(1, 4));
          for (std::size_t b = 0; b < nb; ++b) int_field("a bounding entity tag");
        }
      }
  }

  void partitioned_entities() {
    partitioned_ = true;
    partitions_ = count_field("the number of partitions", item_bytes(1, 4));
    const std::size_t ghosts = count_field("the number of ghost entities", item_bytes(2, 8));
    for (std::size_t g = 0; g < ghosts; ++g) {
      int_field("a ghost entity tag");
      int_field("a ghost entity's partition");
    }
    std::array<std::size_t, 4> counts{};
    for (std::size_t d = 0; d < 4; ++d)
      counts[d] = count_field("a partitioned entity count", item_bytes(8, 48));
    for (int dim = 0; dim < 4; ++dim)
      for (std::size_t i = 0; i < counts[index_cast<std::size_t>(dim)]; ++i) {
        const int tag = static_cast<int>(int_field("a partitioned entity tag"));
        Partitioned p;
        p.parent_dim = static_cast<int>(int_field("a partitioned entity's parent dimension"));
        p.parent_tag = static_cast<int>(int_field("a partitioned entity's parent tag"));
        const std::size_t np = count_field("a partition count", item_bytes(1, 4));
        for (std::size_t k = 0; k < np; ++k)
          p.partitions.push_back(static_cast<int>(int_field("a partition tag")));
        for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) real_field("an entity bounding box");
        const std::size_t nph = count_field("a physical tag count", item_bytes(1, 4));
        for (std::size_t k = 0; k < nph; ++k)
          p.physicals.push_back(static_cast<int>(int_field("a physical tag")));
        if (dim > 0) {
          const std::size_t nb = count_field("a bounding entity count", item_bytes(1, 4));
          for (std::size_t b = 0; b < nb; ++b) int_field("a bounding entity tag");
        }
        partitioned_entities_[{dim, tag}] = std::move(p);
      }
  }

  void add_node(std::int64_t tag, const Point& p) {
    node_tags_.push_back(tag);
    node_points_.push_back(p);
  }

  // The header of $Nodes and $Elements in 4.1: block count, item count, smallest and largest
  // tag (the tags are checked one by one instead).
  std::pair<std::size_t, std::size_t> blocks_header(const char* items, std::size_t ascii_min,
                                                    std::size_t binary_min) {
    const std::size_t blocks =
        count_field((std::string("the number of ") + items + " blocks").c_str(), item_bytes(4, 20));
    const std::size_t total = count_field((std::string("the number of ") + items + "s").c_str(),
                                          item_bytes(ascii_min, binary_min));
    size_field("the smallest tag");
    size_field("the largest tag");
    return {blocks, total};
  }

  void nodes41() {
    const auto [blocks, total] = blocks_header("node", 4, 32);
    node_tags_.reserve(total);
    node_points_.reserve(total);
    for (std::size_t b = 0; b < blocks; ++b) {
      const long long dim = int_field("a node block's entity dimension");
      int_field("a node block's entity tag");
      const long long parametric = int_field("a node block's parametric flag");
      if (dim < 0 || dim > 3)
        fail("node block " + std::to_string(b + 1) + ": entity dimension " + std::to_string(dim));
      if (parametric != 0 && parametric != 1)
        fail("node block " + std::to_string(b + 1) + ": parametric flag " +
             std::to_string(parametric));
      const std::size_t extra = parametric ? index_cast<std::size_t>(dim) : 0;
      const std::size_t n =
          count_field("a node block's node count", item_bytes(4 + extra, 32 + 8 * extra));
      std::vector<std::int64_t> tags(n);
      for (std::size_t i = 0; i < n; ++i) tags[i] = size_field("a node tag");
      for (std::size_t i = 0; i < n; ++i) {
        Point p;
        for (int k = 0; k < 3; ++k) p[k] = real_field("a node coordinate");
        for (std::size_t k = 0; k < extra; ++k) real_field("a parametric coordinate");
        add_node(tags[i], p);
      }
    }
    // Gmsh itself reads the blocks whatever the total says, and writes a total other than
    // theirs after some API edits (nodes added to a cleared mesh): the blocks are read.
    if (node_tags_.size() != total)
      read_warning(source_ + ": $Nodes announces " + std::to_string(total) +
                   " nodes, its blocks hold " + std::to_string(node_tags_.size()) +
                   ": read as its blocks hold them");
  }

  // A count written as text even in binary files (version 2.2), then its line end.
  std::size_t text_count(const char* what, std::size_t ascii_min_bytes,
                         std::size_t binary_min_bytes) {
    const bool was_binary = binary_;
    binary_ = false;
    const std::size_t n = count_field(what, was_binary ? binary_min_bytes : ascii_min_bytes);
    binary_ = was_binary;
    if (binary_) {
      while (pos_ < s_.size() && s_[pos_] != '\n' && detail::ascii_space(s_[pos_])) ++pos_;
      if (pos_ >= s_.size() || s_[pos_] != '\n') fail(std::string("no line end after ") + what);
      ++pos_;
    }
    return n;
  }

  void nodes22() {
    const std::size_t n = text_count("the number of nodes", 8, 28);
    node_tags_.reserve(n);
    node_points_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const std::int64_t tag =
          binary_ ? raw<std::int32_t>("a node tag") : ascii_integer<long long>("a node tag");
      Point p;
      for (int k = 0; k < 3; ++k) p[k] = real_field("a node coordinate");
      add_node(tag, p);
    }
  }

  const GmshType& known_type(long long type, std::size_t at) const {
    const GmshType* t = gmsh_type(type);
    if (!t)
      fail_at(at, "element type " + std::to_string(type) +
                      " is not a Gmsh element type this reader knows");
    return *t;
  }

  void elements41() {
    const auto [blocks, total] = blocks_header("element", 2, 16);
    elements_.reserve(total);
    for (std::size_t b = 0; b < blocks; ++b) {
      int_field("an element block's entity dimension");
      const int entity = static_cast<int>(int_field("an element block's entity tag"));
      const std::size_t at = pos_;
      const GmshType& type = known_type(int_field("an element block's element type"), at);
      const auto nn = index_cast<std::size_t>(type.nodes);
      const std::size_t n =
          count_field("an element block's element count", item_bytes(1 + nn, 8 * (1 + nn)));
      for (std::size_t e = 0; e < n; ++e) {
        RawElement el{size_field("an element tag"), type.type, entity, 0, element_nodes_.size()};
        for (std::size_t k = 0; k < nn; ++k)
          element_nodes_.push_back(size_field("an element's node tag"));
        elements_.push_back(el);
      }
    }
    if (elements_.size() != total)  // as for $Nodes
      read_warning(source_ + ": $Elements announces " + std::to_string(total) +
                   " elements, its blocks hold " + std::to_string(elements_.size()) +
                   ": read as its blocks hold them");
  }

  void elements22() {
    const std::size_t total = text_count("the number of elements", 8, 8);
    elements_.reserve(total);
    auto element = [&](std::int64_t tag, const GmshType& type, const std::vector<long long>& tags) {
      RawElement el{tag, type.type, tags.size() > 1 ? static_cast<int>(tags[1]) : 0,
                    tags.empty() ? 0 : static_cast<int>(tags[0]), element_nodes_.size()};
      for (int k = 0; k < type.nodes; ++k)
        element_nodes_.push_back(int_field("an element's node tag"));
      elements_.push_back(el);
    };
    std::vector<long long> tags;
    if (!binary_) {
      for (std::size_t e = 0; e < total; ++e) {
        const std::int64_t tag = ascii_integer<long long>("an element tag");
        const std::size_t at = pos_;
        const GmshType& type = known_type(ascii_integer<long long>("an element type"), at);
        const std::size_t nt = count_field("an element's tag count", 2);
        tags.clear();
        for (std::size_t k = 0; k < nt; ++k)
          tags.push_back(ascii_integer<long long>("an element tag"));
        element(tag, type, tags);
      }
      return;
    }
    while (elements_.size() < total) {
      const std::size_t at = pos_;
      const GmshType& type = known_type(raw<std::int32_t>("an element type"), at);
      const std::size_t nt_at = pos_ + 4;
      const std::size_t follow = count_field("an element header's element count", 4);
      const std::int32_t nt = raw<std::int32_t>("an element header's tag count");
      if (nt < 0 || nt > 64) fail_at(nt_at, "element header: tag count " + std::to_string(nt));
      if (follow > total - elements_.size())
        fail_at(at, "element header: more elements than $Elements announces");
      if (follow * (1 + index_cast<std::size_t>(nt) + index_cast<std::size_t>(type.nodes)) >
          (s_.size() - pos_) / 4)
        fail_at(at, "element header: " + std::to_string(follow) +
                        " elements are more than the rest of the file can hold (truncated file?)");
      for (std::size_t e = 0; e < follow; ++e) {
        const std::int64_t tag = raw<std::int32_t>("an element tag");
        tags.clear();
        for (std::int32_t k = 0; k < nt; ++k) tags.push_back(raw<std::int32_t>("an element tag"));
        element(tag, type, tags);
      }
      if (follow == 0) fail_at(at, "element header announces no elements");
    }
  }

  // ---- The model ---------------------------------------------------------------------------

  // The entity of $Entities an element belongs to: its own, or in a partitioned file the
  // parent of its partitioned entity.
  int model_entity(const RawElement& e, int dim) const {
    if (!partitioned_) return e.entity;
    const auto it = partitioned_entities_.find({dim, e.entity});
    return it == partitioned_entities_.end() || it->second.parent_dim != dim
               ? e.entity
               : it->second.parent_tag;
  }
  // Gmsh meshes the boundaries between partitions (Mesh.PartitionCreateTopology): their
  // triangles, quads, lines and points live on partitioned entities whose parent has a higher
  // dimension (a volume for the faces between two parts), and carry the parent's physical tags,
  // a volume's among the surfaces. They are no part of the user's model: skipped, else a
  // physical volume would come back as a side set of interior faces as well.
  bool on_partition_boundary(const RawElement& e, int dim) const {
    if (!partitioned_) return false;
    const auto it = partitioned_entities_.find({dim, e.entity});
    return it != partitioned_entities_.end() && it->second.parent_dim > dim;
  }
  // A volume element's part (0-based): its partitioned entity's one partition; -1 when the file
  // does not say one (then the model is read without its partition: nothing else depends on it).
  int part_of(const RawElement& e) const {
    const auto it = partitioned_entities_.find({3, e.entity});
    if (it == partitioned_entities_.end()) return -1;
    const std::vector<int>& p = it->second.partitions;
    if (p.size() != 1 || p[0] < 1 || index_cast<std::size_t>(p[0]) > partitions_) return -1;
    return p[0] - 1;
  }
  // One file of a set Gmsh writes with Mesh.PartitionSplitMeshFiles=1 (name_1.msh, ...) holds
  // one partition's elements: refused, since reading it alone would drop the other parts.
  void check_one_file(const std::vector<int>& volume_part) const {
    if (partitions_ < 2 || volume_part.empty()) return;
    if (std::all_of(volume_part.begin(), volume_part.end(),
                    [&](int p) { return p == volume_part.front(); }))
      throw InvalidInput(source_ + ": holds partition " + std::to_string(volume_part.front() + 1) +
                         " of " + std::to_string(partitions_) +
                         " only (one file of a mesh Gmsh wrote with "
                         "Mesh.PartitionSplitMeshFiles=1): not read; write the partitioned mesh "
                         "as one file");
  }
  // Two elements whose physical groups and entity are the same (physicals_of, model_entity).
  bool same_groups(const RawElement& a, const RawElement& b) const {
    return a.entity == b.entity && a.physical == b.physical && more_physicals_.empty();
  }

  // Gmsh 2.2 writes a volume element once per physical volume it is in (an entity in "steel"
  // and in "all"), each copy with a tag of its own: the copies (same type, entity and nodes)
  // are one element in all those groups, the first copy's tag its id. Looked for only where an
  // entity's volume elements carry two physical tags or more.
  void merge_group_copies() {
    if (version_ != 2) return;
    std::map<int, int> tag_of;  // entity -> its volume elements' first physical tag
    bool several = false;
    for (const RawElement& e : elements_)
      if (gmsh_type(e.type)->dim == 3 && e.physical != 0) {
        const auto [it, added] = tag_of.try_emplace(e.entity, e.physical);
        several = several || (!added && it->second != e.physical);
      }
    if (!several) return;
    copy_.assign(elements_.size(), 0);
    std::map<std::vector<std::int64_t>, std::size_t> first;  // type, entity, nodes -> element
    for (std::size_t i = 0; i < elements_.size(); ++i) {
      const RawElement& e = elements_[i];
      const GmshType& type = *gmsh_type(e.type);
      if (type.dim != 3 || e.physical == 0) continue;
      std::vector<std::int64_t> key{e.type, e.entity};
      key.insert(key.end(), element_nodes_.begin() + static_cast<std::ptrdiff_t>(e.first),
                 element_nodes_.begin() + static_cast<std::ptrdiff_t>(e.first + type.nodes));
      const auto [it, added] = first.try_emplace(std::move(key), i);
      if (added) continue;
      copy_[i] = 1;
      std::vector<int>& more = more_physicals_[it->second];
      if (elements_[it->second].physical != e.physical &&
          std::find(more.begin(), more.end(), e.physical) == more.end())
        more.push_back(e.physical);
    }
  }
  std::vector<char> copy_;  // per element: a copy merge_group_copies dropped
  std::map<std::size_t, std::vector<int>> more_physicals_;  // element -> its copies' physical tags
  // Physical groups of an element: its entity's (4.1; a partitioned entity's own, else its
  // parent's) or its own tag (2.2).
  std::vector<int> physicals_of(const RawElement& e, int dim) const {
    if (version_ == 2) {
      if (e.physical == 0) return {};
      std::vector<int> tags{e.physical};
      if (const auto it = more_physicals_.find(index_cast<std::size_t>(&e - elements_.data()));
          it != more_physicals_.end())
        tags.insert(tags.end(), it->second.begin(), it->second.end());
      return tags;
    }
    if (partitioned_) {
      const auto it = partitioned_entities_.find({dim, e.entity});
      if (it == partitioned_entities_.end()) return {};
      if (!it->second.physicals.empty()) return it->second.physicals;
      const auto parent = entity_physicals_.find({it->second.parent_dim, it->second.parent_tag});
      return parent == entity_physicals_.end() ? std::vector<int>{} : parent->second;
    }
    const auto it = entity_physicals_.find({dim, e.entity});
    return it == entity_physicals_.end() ? std::vector<int>{} : it->second;
  }

  // An element's block among the physical volumes of its entity. A model has one block per
  // element, while Gmsh lets an entity be in several physical groups (a material "tets" and
  // an aggregate "steel" over several materials): the block is the group over the fewest
  // entities of $Entities (the most specific; ties: the first listed), and a group left
  // without elements that way is reported in a warning (build()).
  int block_among(const std::vector<int>& physicals) {
    if (physicals.size() == 1) return physicals.front();
    if (group_sizes_.empty() && version_ == 2) {  // each element's groups: count entities
      std::map<int, std::set<int>> entities;
      for (const RawElement& e : elements_)
        if (gmsh_type(e.type)->dim == 3)
          for (int p : physicals_of(e, 3)) entities[p].insert(e.entity);
      for (const auto& [p, in] : entities) group_sizes_[p] = in.size();
    }
    if (group_sizes_.empty())
      for (const auto& [key, tags] : entity_physicals_)
        if (key.first == 3)
          for (int p : tags) ++group_sizes_[p];
    int best = physicals.front();
    for (int p : physicals)
      if (group_sizes_[p] < group_sizes_[best]) best = p;
    return best;
  }
  std::map<int, std::size_t> group_sizes_;  // physical volume -> entities in it

  // Blocks of elements in no physical volume (an entity's tag, or the default block for
  // meshio's 0), beside physical volumes in one file (Gmsh writes such elements with
  // Mesh.SaveAll=1): their tags are entity tags, which may be a physical volume's too, so they
  // are numbered above every physical volume (named or holding elements) instead, unnamed, each
  // with a warning. A file without physical volumes keeps its entity tags as block ids.
  template <class Volumes>
  void number_entity_blocks(Volumes& volumes, const std::set<int>& volume_groups) const {
    if (volume_groups.empty()) return;
    std::int64_t top = *volume_groups.rbegin();
    for (const auto& [key, name] : physical_names_)
      if (key.first == 3) top = std::max<std::int64_t>(top, key.second);
    std::map<int, std::pair<std::int64_t, std::size_t>> moved;  // tag -> first element, count
    for (auto& v : volumes) {
      if (!v.entity) continue;
      const std::int64_t block = top + v.block;
      if (block > INT32_MAX)
        throw InvalidInput(source_ + ": element " + std::to_string(elements_[v.element].tag) +
                           " is in no physical volume, and its entity's tag " +
                           std::to_string(v.block) + " above the highest physical volume's (" +
                           std::to_string(top) + ") is out of range for a block id");
      auto [it, added] = moved.try_emplace(v.block, elements_[v.element].tag, 0);
      ++it->second.second;
      v.block = static_cast<int>(block);
    }
    for (const auto& [tag, first] : moved)
      read_warning(source_ + ": " + std::to_string(first.second) + " volume elements (element " +
                   std::to_string(first.first) +
                   " the first) are in no physical volume, beside others that are (saved with "
                   "Mesh.SaveAll=1?): they are block " +
                   std::to_string(top + tag) + ", unnamed (their entity's tag " +
                   std::to_string(tag) + " numbered above the physical volumes)");
  }

  // Volume entities in no physical group and without elements, in a file where other volumes
  // are in one: Gmsh saves only the elements of physical groups unless Mesh.SaveAll=1, so
  // their space is left empty in every output (a ball in potting came out a hole, a whole part
  // missing, without a word). Not partitioned files: there elements live on partitioned
  // entities, not on the entities they came from.
  std::vector<int> unsaved_volumes() const {
    std::vector<int> unsaved;
    if (version_ != 4 || partitioned_) return unsaved;
    const bool physical =
        std::any_of(entity_physicals_.begin(), entity_physicals_.end(),
                    [](const auto& e) { return e.first.first == 3 && !e.second.empty(); });
    if (!physical) return unsaved;
    std::set<int> with_elements;
    int last = 0;  // an entity's elements come in a run: one insert per run
    for (const RawElement& e : elements_)
      if (e.entity != last && gmsh_type(e.type)->dim == 3) with_elements.insert(last = e.entity);
    for (const auto& [key, physicals] : entity_physicals_)
      if (key.first == 3 && physicals.empty() && !with_elements.count(key.second))
        unsaved.push_back(key.second);
    return unsaved;
  }
  std::string unsaved_text(const std::vector<int>& unsaved) const {
    std::string tags;
    for (int t : unsaved) tags += (tags.empty() ? "" : ", ") + std::to_string(t);
    return std::string(unsaved.size() == 1 ? "volume entity " : "volume entities ") + tags +
           (unsaved.size() == 1 ? " is" : " are") +
           " in no physical group and without elements (Gmsh saves only the elements of "
           "physical groups unless Mesh.SaveAll=1)";
  }

  Model build() {
    Model model;
    // Nodes by ascending tag; a tag listed twice must name one point.
    std::vector<std::size_t> order(node_tags_.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    if (!std::is_sorted(node_tags_.begin(), node_tags_.end()))  // Gmsh's own files are
      std::stable_sort(order.begin(), order.end(),
                       [&](std::size_t a, std::size_t b) { return node_tags_[a] < node_tags_[b]; });
    NodeIndex index_of(node_tags_);
    for (std::size_t i : order) {
      const std::int64_t tag = node_tags_[i];
      if (const Index known = index_of.find(tag); known != kInvalidIndex) {
        const Point& first = model.points[index_cast<std::size_t>(known)];
        if (first != node_points_[i] && !(first.hasNaN() && node_points_[i].hasNaN()))
          throw InvalidInput(source_ + ": node " + std::to_string(tag) + " is given twice, at " +
                             point_text(first) + " and " + point_text(node_points_[i]));
        continue;
      }
      if (tag <= 0)
        throw InvalidInput(source_ + ": node tag " + std::to_string(tag) + " is not positive");
      if (model.points.size() >= index_cast<std::size_t>(INT32_MAX))
        throw InvalidInput(source_ + ": more nodes than this reader can number");
      index_of.add(tag, index_cast(model.points.size()));
      model.points.push_back(node_points_[i]);
      model.node_ids.push_back(tag);
    }
    auto node = [&](const RawElement& e, std::size_t k) {
      const std::int64_t tag = element_nodes_[e.first + k];
      const Index known = index_of.find(tag);
      if (known == kInvalidIndex)
        throw InvalidInput(source_ + ": element " + std::to_string(e.tag) + ": corner " +
                           std::to_string(k + 1) + " refers to node " + std::to_string(tag) +
                           ", which is not in $Nodes");
      return known;
    };

    // Volume elements, block by block (ascending block id, file order within a block).
    struct Volume {
      int block;
      std::size_t element;
      bool entity;  // its block is its entity's (no physical volume holds it), not a group's
    };
    std::vector<Volume> volumes;
    std::set<int> volume_groups;   // every physical volume holding elements
    std::vector<int> volume_part;  // per element of elements_ that is a volume: 0-based
    std::size_t last_volume = 0;   // the volume element before this one
    int run_block = 0;             // its block before the default (model_entity, block_among)
    bool run_entity = false;       // run_block is an entity's
    merge_group_copies();
    for (std::size_t i = 0; i < elements_.size(); ++i) {
      const RawElement& e = elements_[i];
      const GmshType& type = *gmsh_type(e.type);
      if (type.dim != 3 || (!copy_.empty() && copy_[i])) continue;
      const ElementKind* kind = gmsh_cell_kind(e.type);
      if (!kind)
        throw InvalidInput(source_ + ": element " + std::to_string(e.tag) + ": " + type.name +
                           " (Gmsh type " + std::to_string(e.type) +
                           ") is not supported; only linear cells are (4-node tetrahedra, "
                           "8-node hexahedra, 6-node prisms, 5-node pyramids)");
      // The elements of an entity come together: its block found once per run of them.
      if (volumes.empty() || !same_groups(e, elements_[last_volume])) {
        const std::vector<int> physicals = physicals_of(e, 3);
        run_entity = physicals.empty();
        run_block = run_entity ? model_entity(e, 3) : block_among(physicals);
        volume_groups.insert(physicals.begin(), physicals.end());
      }
      last_volume = i;
      int block = run_block;
      // meshio writes 0 for a missing physical and entity tag: the model's default block.
      if (block == 0) block = default_block(*kind);
      if (block < 0)
        throw InvalidInput(source_ + ": element " + std::to_string(e.tag) +
                           ": block (physical or entity tag) " + std::to_string(block) +
                           " is not positive");
      volumes.push_back({block, i, run_entity});
      if (partitioned_) volume_part.push_back(part_of(e));
    }
    number_entity_blocks(volumes, volume_groups);
    // The partition is usable when every volume element has one part.
    const bool parts_known =
        partitioned_ && std::in_range<int>(partitions_) &&
        std::none_of(volume_part.begin(), volume_part.end(), [](int p) { return p < 0; });
    if (parts_known) check_one_file(volume_part);
    std::vector<std::size_t> volume_order(volumes.size());
    std::iota(volume_order.begin(), volume_order.end(), std::size_t{0});
    // A partitioned file lists the elements partition by partition; their tags are the
    // unpartitioned file's, whose order (ascending tags) they take again.
    auto before = [&](std::size_t a, std::size_t b) {
      if (volumes[a].block != volumes[b].block) return volumes[a].block < volumes[b].block;
      return partitioned_ && elements_[volumes[a].element].tag < elements_[volumes[b].element].tag;
    };
    if (!std::is_sorted(volume_order.begin(), volume_order.end(), before))  // often in order
      std::stable_sort(volume_order.begin(), volume_order.end(), before);
    {
      std::set<int> blocks;
      for (const Volume& v : volumes) blocks.insert(v.block);
      for (int p : volume_groups)
        if (!blocks.count(p)) {
          const auto it = physical_names_.find({3, p});
          read_warning(source_ + ": physical volume " + std::to_string(p) +
                       (it == physical_names_.end() ? std::string()
                                                    : " '" + sanitize_name(it->second) + "'") +
                       " is not a block of its own: each of its entities is also in a physical "
                       "volume over fewer "
                       "entities, which is the block of its elements");
        }
    }
    std::array<std::vector<int>, 4> part_by_kind;
    std::size_t block_run = 0;  // the volume before this one
    for (std::size_t o : volume_order) {
      const Volume& v = volumes[o];
      const RawElement& e = elements_[v.element];
      if (!v.entity && (o == volume_order.front() || v.block != volumes[block_run].block))
        if (auto it = physical_names_.find({3, v.block});  // a physical block's first element
            it != physical_names_.end() && !it->second.empty())
          model.block_names[v.block] = it->second;
      block_run = o;
      const ElementKind kind = *gmsh_cell_kind(e.type);
      const GmshCell& cell = kGmshCells[static_cast<std::size_t>(kind)];
      std::array<Index, 8> c{};
      for (std::size_t k = 0; k < index_cast<std::size_t>(cell.corners); ++k)
        c[k] = node(e, index_cast<std::size_t>(cell.order[k]));
      add_element(model, kind, c, v.block, e.tag);
      if (parts_known) part_by_kind[static_cast<std::size_t>(kind)].push_back(volume_part[o]);
    }
    if (parts_known && partition_) {
      partition_->parts = static_cast<int>(partitions_);
      partition_->part.clear();
      for (const auto& parts : part_by_kind)
        partition_->part.insert(partition_->part.end(), parts.begin(), parts.end());
    }

    // Lower-dimensional physical groups: side sets (dim 2), node sets (dim 0 and 1), in
    // ascending (dim, tag) as Gmsh lists them.
    std::map<std::pair<int, int>, std::vector<std::size_t>> groups;
    for (const auto& [key, physicals] : entity_physicals_)
      if (key.first < 3)
        for (int p : physicals) groups[{key.first, p}];
    for (std::size_t i = 0; i < elements_.size(); ++i) {
      const int dim = gmsh_type(elements_[i].type)->dim;
      if (dim < 3 && !on_partition_boundary(elements_[i], dim))
        for (int p : physicals_of(elements_[i], dim)) groups[{dim, p}].push_back(i);
    }
    // The sets as primal::add_tagged_sets makes them of any file's tagged cells (a node set's
    // points and lines kept as its pieces, so that dicing adds the nodes on these lines only);
    // linear cells only: a higher-order line's middle nodes belong to no linear element.
    std::vector<TaggedCells> tagged;
    for (const auto& [key, members] : groups) {
      const auto [dim, tag] = key;
      TaggedCells t{dim, tag, {}, {}, {}};
      if (auto it = physical_names_.find(key); it != physical_names_.end()) t.name = it->second;
      for (std::size_t i : members) {
        const RawElement& e = elements_[i];
        const bool linear =
            dim == 2 ? e.type == kTri3 || e.type == kQuad4 : e.type == kPoint1 || e.type == kLine2;
        if (!linear)
          throw InvalidInput(
              source_ + (dim == 2 ? ": side set " : ": node set ") + std::to_string(tag) + " '" +
              t.name + "': element " + std::to_string(e.tag) + ": " + gmsh_type(e.type)->name +
              " (Gmsh type " + std::to_string(e.type) + ") is not supported; only " +
              (dim == 2 ? "3-node triangles and 4-node quads are" : "points and 2-node lines are"));
        std::vector<Index> cell;
        for (int k = 0; k < gmsh_type(e.type)->nodes; ++k)
          cell.push_back(node(e, index_cast<std::size_t>(k)));
        t.cells.push_back(std::move(cell));
        t.cell_ids.push_back(e.tag);
      }
      tagged.push_back(std::move(t));
    }
    const auto moved = separate_node_set_ids(tagged, source_);
    warn_moved_node_sets(tagged, moved, source_, "physical curve", "physical point");
    try {
      add_tagged_sets(model, tagged, source_, "element");
    } catch (const InvalidInput& e) {  // a face of no element: say why, where Gmsh left one out
      const std::vector<int> unsaved = unsaved_volumes();
      if (unsaved.empty()) throw;
      throw InvalidInput(std::string(e.what()) + "; " + unsaved_text(unsaved));
    }
    // Gmsh 2.2 gives each element its groups' tags; saved with Mesh.SaveAll=1 it gives every
    // element 0, and $PhysicalNames alone still lists the groups: say they are lost.
    if (version_ == 2) {
      std::set<std::pair<int, int>> carried;
      for (const RawElement& e : elements_)
        if (e.physical != 0) carried.insert({gmsh_type(e.type)->dim, e.physical});
      for (const auto& [key, name] : physical_names_)
        if (!carried.count(key))
          read_warning(source_ + ": physical group '" + sanitize_name(name) + "' (dimension " +
                       std::to_string(key.first) + ", tag " + std::to_string(key.second) +
                       ") in $PhysicalNames holds no element (Gmsh 2.2 saved with "
                       "Mesh.SaveAll=1 writes none): it is not read");
    }
    if (const std::vector<int> unsaved = unsaved_volumes(); !unsaved.empty())
      read_warning(source_ + ": " + unsaved_text(unsaved) + ": the space " +
                   (unsaved.size() == 1 ? "it fills" : "they fill") + " is left empty");
    sanitize_names(model);
    validate(model, source_);
    return model;
  }
};

}  // namespace

Model parse_gmsh(std::string_view content, const std::string& source, const ReadOptions& options,
                 FilePartition* partition) {
  if (partition) *partition = {};
  Model model = MshReader(content, source, partition).read();
  options.check_geometry ? check_geometry(model, source, options.inverted_hint)
                         : check_points(model, source);
  return model;
}

}  // namespace geode::io
