// The Exodus II reader in two stages: what libexodusII reads from the file (raw arrays, every
// count bounded by the file's size before anything is allocated), then the Model built from
// them with every entry checked. The first stage runs in a child process (isolated.hpp):
// libhdf5 crashes on corrupt netCDF-4 files and libexodusII overruns buffers on some classic
// ones, and nothing short of a process contains that; a classic file's header is screened whole
// by our own parser first (netcdf_screen.hpp), an HDF5 superblock checked.
#include <geode/io/exodus.hpp>
#include <geode/io/read_warnings.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <geode/io/exodus_library.hpp>
#include <geode/io/file_format.hpp>
#include <geode/io/isolated.hpp>
#include <geode/io/netcdf_screen.hpp>
#include <geode/primal/detail/byte_packet.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/shares.hpp>
#include <geode/primal/topology.hpp>

namespace geode::io {

using namespace primal;
using namespace exodus_library;

namespace {

// What an Exodus file can hold: a classic netCDF file stores each value (4 bytes at least), a
// netCDF-4 (HDF5) one may compress them, by at most zlib's 1032:1.
class ExodusBounds {
 public:
  ExodusBounds(std::uint64_t size, bool classic, std::string source)
      : source_(std::move(source)), size_(size), capacity_(classic ? size : size * 1032 + 4096) {}
  void check(std::int64_t count, std::size_t bytes_each, const char* what) const {
    if (count < 0 || static_cast<std::uint64_t>(count) > capacity_ / bytes_each)
      throw InvalidInput(source_ + ": the header announces " + std::to_string(count) + " " + what +
                         ", more than a file of " + std::to_string(size_) +
                         " bytes can hold (corrupt or truncated file?)");
  }
  // The same for data about to be allocated, counted together: many sets each announcing
  // what the file could hold (a netCDF-4 file stores nothing for values never written) are
  // bounded by the file's size in all, not each.
  void take(std::int64_t count, std::size_t bytes_each, const char* what) {
    check(count, bytes_each, what);
    used_ += static_cast<std::uint64_t>(count) * bytes_each;
    if (used_ > capacity_)
      throw InvalidInput(source_ + ": the header announces more data in all (" + what +
                         " the last) than a file of " + std::to_string(size_) +
                         " bytes can hold (corrupt or truncated file?)");
  }
  std::uint64_t capacity() const { return capacity_; }

 private:
  std::string source_;
  std::uint64_t size_ = 0, capacity_ = 0, used_ = 0;
};

// The file's content as libexodusII gives it.
struct BlockData {
  int id = 0;
  std::string name, type;
  int per_elem = 0;
  std::int64_t count = 0;  // the block's elements in the file
  int model_block = 0;     // kBlockProperty: the model block it is a part of (0: none given)
  std::vector<int> conn;   // its run of them (all of them but in a shared read) x per_elem
};
struct SetData {
  int id = 0;
  std::string name;
  std::vector<int> entries, sides;  // nodes, or elements and sides
};
struct Contents {
  int num_dim = 0, num_nodes = 0, num_elem = 0;
  NemesisInfo nemesis;
  std::vector<double> x, y, z;
  std::vector<std::int64_t> node_map, element_map;  // 64-bit: Cubit's ids pass 2^31
  std::vector<BlockData> blocks;
  std::vector<SetData> node_sets, side_sets;
};

std::vector<std::string> names_of(int exo, ex_entity_type type, std::size_t n) {
  NameBuffers names(n);
  std::vector<std::string> out(n);
  if (ex_get_names(exo, type, names.pointers.data()) >= 0)
    for (std::size_t i = 0; i < n; ++i) out[i] = names.get(i);
  return out;
}

// Which part of the file a process reads: its run [first, last) of every n things, the runs of
// `shares` processes one after another (Shares in read_exodus_shared; 0 of 1 reads the file).
struct Slice {
  int share = 0, shares = 1;
  std::pair<std::int64_t, std::int64_t> run(std::int64_t n) const {
    return {n * share / shares, n * (share + 1) / shares};
  }
};

// Stage one: the library's reads; counts bounded before each allocation.
Contents read_contents(const std::string& source, ExodusBounds bound, Slice slice) {
  ex_opts(0);  // we report errors ourselves, through exceptions
  int cpu_word_size = 8, io_word_size = 0;
  float version = 0.0f;
  ExodusFile file(ex_open(source.c_str(), EX_READ, &cpu_word_size, &io_word_size, &version));
  if (file.id() < 0)
    throw InvalidInput(source + ": not a readable Exodus II file (truncated or corrupt?)");
  const int exo = file.id();
  // The number maps through the 64-bit API whatever the file stores: ids of 2^31 and more
  // (64-bit files) do not fit the 32-bit one, which refuses them.
  ex_set_int64_status(exo, EX_MAPS_INT64_API);
  const int64_t used_name_length = ex_inquire_int(exo, EX_INQ_DB_MAX_USED_NAME_LENGTH);
  ex_set_max_name_length(exo,
                         static_cast<int>(std::clamp<int64_t>(used_name_length, 32, kNameLength)));

  Contents c;
  char title[MAX_LINE_LENGTH + 1] = {};
  int num_blocks = 0, num_node_sets = 0, num_side_sets = 0;
  check(ex_get_init(exo, title, &c.num_dim, &c.num_nodes, &c.num_elem, &num_blocks, &num_node_sets,
                    &num_side_sets),
        source, "reading the header");
  if (c.num_dim < 2 || c.num_dim > 3)
    throw InvalidInput(source + ": " + std::to_string(c.num_dim) +
                       "-dimensional model; expected 3 (or 2)");
  bound.take(c.num_nodes, index_cast<std::size_t>(c.num_dim) * 4, "nodes");
  bound.check(c.num_elem, 4, "elements");
  bound.check(num_blocks, 4, "element blocks");
  bound.check(num_node_sets, 4, "node sets");
  bound.check(num_side_sets, 4, "side sets");

  const bool whole = slice.shares == 1;
  const auto [first_node, last_node] = slice.run(c.num_nodes);
  const auto nodes = index_cast<std::size_t>(last_node - first_node);
  c.x.resize(nodes);
  c.y.resize(nodes);
  c.z.assign(nodes, 0.0);
  if (nodes > 0) {
    double* z = c.num_dim == 3 ? c.z.data() : nullptr;
    check(whole ? ex_get_coord(exo, c.x.data(), c.y.data(), z)
                : ex_get_partial_coord(exo, first_node + 1, last_node - first_node, c.x.data(),
                                       c.y.data(), z),
          source, "reading coordinates");
    // Node and element number maps (Cubit's ids); without maps in the file, 1..n.
    c.node_map.resize(nodes);
    check(whole ? ex_get_id_map(exo, EX_NODE_MAP, c.node_map.data())
                : ex_get_partial_id_map(exo, EX_NODE_MAP, first_node + 1, last_node - first_node,
                                        c.node_map.data()),
          source, "reading the node number map");
  }
  const auto [first_element, last_element] = slice.run(c.num_elem);
  if (last_element > first_element) {
    c.element_map.resize(index_cast<std::size_t>(last_element - first_element));
    check(whole ? ex_get_id_map(exo, EX_ELEM_MAP, c.element_map.data())
                : ex_get_partial_id_map(exo, EX_ELEM_MAP, first_element + 1,
                                        last_element - first_element, c.element_map.data()),
          source, "reading the element number map");
  }

  std::int64_t elements = 0;
  if (num_blocks > 0) {
    std::vector<int> ids(index_cast<std::size_t>(num_blocks));
    check(ex_get_ids(exo, EX_ELEM_BLOCK, ids.data()), source, "reading element block ids");
    const std::vector<std::string> names = names_of(exo, EX_ELEM_BLOCK, ids.size());
    for (std::size_t b = 0; b < ids.size(); ++b) {
      BlockData block;
      block.id = ids[b];
      block.name = names[b];
      const std::string where = source + ": element block " + std::to_string(block.id);
      char type_buffer[MAX_STR_LENGTH + 1] = {};
      int count = 0, edges = 0, faces = 0, attributes = 0;
      check(ex_get_block(exo, EX_ELEM_BLOCK, block.id, type_buffer, &count, &block.per_elem, &edges,
                         &faces, &attributes),
            where, "reading the block header");
      block.type.assign(type_buffer, strnlen(type_buffer, MAX_STR_LENGTH));
      if (block.per_elem < 0 || block.per_elem > 64)
        throw InvalidInput(where + ": " + std::to_string(block.per_elem) + " nodes per element");
      bound.take(count, 4 * index_cast<std::size_t>(std::max(block.per_elem, 1)),
                 "elements in the block");
      if (elements + count > c.num_elem)
        throw InvalidInput(where + ": more elements in the blocks than the header's " +
                           std::to_string(c.num_elem));
      elements += count;
      block.count = count;
      const auto [first, last] = slice.run(count);
      block.conn.resize(index_cast<std::size_t>(last - first) *
                        index_cast<std::size_t>(block.per_elem));
      if (!block.conn.empty())
        check(whole ? ex_get_conn(exo, EX_ELEM_BLOCK, block.id, block.conn.data(), nullptr, nullptr)
                    : ex_get_partial_conn(exo, EX_ELEM_BLOCK, block.id, first + 1, last - first,
                                          block.conn.data(), nullptr, nullptr),
              where, "reading connectivity");
      c.blocks.push_back(std::move(block));
    }
    // Properties are named per file; ours (kBlockProperty) only where the writer split a block.
    const int64_t properties = ex_inquire_int(exo, EX_INQ_EB_PROP);
    bound.check(properties, 4, "element block properties");
    if (properties > 1) {
      NameBuffers property_names(index_cast<std::size_t>(properties));
      check(ex_get_prop_names(exo, EX_ELEM_BLOCK, property_names.pointers.data()), source,
            "reading element block property names");
      for (std::size_t p = 0; p < property_names.storage.size(); ++p)
        if (property_names.get(p) == kBlockProperty)
          for (BlockData& block : c.blocks)
            check(ex_get_prop(exo, EX_ELEM_BLOCK, block.id, kBlockProperty, &block.model_block),
                  source + ": element block " + std::to_string(block.id), "reading its properties");
    }
  }

  const auto read_sets = [&](ex_entity_type type, int n, const char* what, std::size_t each,
                             std::vector<SetData>& out) {
    if (n <= 0) return;
    std::vector<int> ids(index_cast<std::size_t>(n));
    check(ex_get_ids(exo, type, ids.data()), source, std::string("reading ") + what + " ids");
    const std::vector<std::string> names = names_of(exo, type, ids.size());
    for (std::size_t s = 0; s < ids.size(); ++s) {
      SetData set{ids[s], names[s], {}, {}};
      const std::string where = source + ": " + what + " " + std::to_string(ids[s]);
      int count = 0, factors = 0;
      check(ex_get_set_param(exo, type, ids[s], &count, &factors), where, "reading the set header");
      bound.take(count, each, type == EX_NODE_SET ? "node set entries" : "side set entries");
      set.entries.resize(index_cast<std::size_t>(count));
      if (type == EX_SIDE_SET) set.sides.resize(set.entries.size());
      if (count > 0)
        check(ex_get_set(exo, type, ids[s], set.entries.data(),
                         type == EX_SIDE_SET ? set.sides.data() : nullptr),
              where, "reading entries");
      out.push_back(std::move(set));
    }
  };
  if (slice.share == 0) {  // the sets are the first share's to read
    read_sets(EX_NODE_SET, num_node_sets, "node set", 4, c.node_sets);
    read_sets(EX_SIDE_SET, num_side_sets, "side set", 8, c.side_sets);
  }
  // Nemesis I (a piece of a partitioned set): absent from a plain file, which the library
  // reports as an error.
  int processors = 0, in_file = 0;
  char ftype[2] = {};
  int global_nodes = 0, global_elems = 0, global_blocks = 0, global_node_sets = 0,
      global_side_sets = 0;
  if (ex_get_init_info(exo, &processors, &in_file, ftype) >= 0 && processors > 0 &&
      ex_get_init_global(exo, &global_nodes, &global_elems, &global_blocks, &global_node_sets,
                         &global_side_sets) >= 0)
    c.nemesis = {processors, global_nodes, global_elems};
  return c;
}

// The child's answer: the contents as length-prefixed little-endian arrays (both ends are
// this build, so the layout is ours alone); read back with every length bounded.
class Packer {
 public:
  void i64(std::int64_t v) { raw(&v, sizeof v); }
  template <typename T>
  void array(const std::vector<T>& v) {
    i64(index_cast<std::int64_t>(v.size()));
    raw(v.data(), v.size() * sizeof(T));
  }
  void text(const std::string& s) {
    i64(index_cast<std::int64_t>(s.size()));
    raw(s.data(), s.size());
  }
  std::string out;

 private:
  void raw(const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); }
};

class Unpacker {
 public:
  Unpacker(std::string_view b, std::string source) : b_(b), source_(std::move(source)) {}
  std::int64_t i64() {
    std::int64_t v = 0;
    raw(&v, sizeof v);
    return v;
  }
  // An array appended to `v` (a shared read joins the shares' runs so).
  template <typename T>
  void array_onto(std::vector<T>& v) {
    const std::uint64_t n = length(sizeof(T));
    const std::size_t at = v.size();
    v.resize(at + n);
    raw(v.data() + at, n * sizeof(T));
  }
  std::string text() {
    std::string s(length(1), '\0');
    raw(s.data(), s.size());
    return s;
  }
  bool done() const { return pos_ == b_.size(); }

 private:
  std::uint64_t length(std::size_t each) {
    const auto n = static_cast<std::uint64_t>(i64());
    if (n > (b_.size() - pos_) / each) bad();
    return n;
  }
  void raw(void* p, std::size_t n) {
    if (n > b_.size() - pos_) bad();
    if (n > 0) std::memcpy(p, b_.data() + pos_, n);
    pos_ += n;
  }
  [[noreturn]] void bad() const {
    throw std::runtime_error(source_ + ": the Exodus reader process's answer is malformed");
  }
  std::string_view b_;
  std::string source_;
  std::size_t pos_ = 0;
};

std::string pack(const Contents& c) {
  Packer p;
  for (int v : {c.num_dim, c.num_nodes, c.num_elem, c.nemesis.processors}) p.i64(v);
  p.i64(c.nemesis.global_nodes);
  p.i64(c.nemesis.global_elements);
  p.array(c.x);
  p.array(c.y);
  p.array(c.z);
  p.array(c.node_map);
  p.array(c.element_map);
  p.i64(index_cast<std::int64_t>(c.blocks.size()));
  for (const BlockData& b : c.blocks) {
    p.i64(b.id);
    p.text(b.name);
    p.text(b.type);
    p.i64(b.per_elem);
    p.i64(b.count);
    p.i64(b.model_block);
    p.array(b.conn);
  }
  for (const auto* sets : {&c.node_sets, &c.side_sets}) {
    p.i64(index_cast<std::int64_t>(sets->size()));
    for (const SetData& s : *sets) {
      p.i64(s.id);
      p.text(s.name);
      p.array(s.entries);
      p.array(s.sides);
    }
  }
  return std::move(p.out);
}

// The child's answer appended to `c`: onto empty contents, or (a shared read, `later`) onto the
// runs of the shares before it, whose header it must repeat.
void unpack_onto(Contents& c, std::string_view bytes, const std::string& source, bool later) {
  Unpacker u(bytes, source);
  const auto changed = [&] {
    return InvalidInput(source +
                        ": the file changed while it was read (the processes sharing "
                        "the read found different headers)");
  };
  const auto header = [&](auto& field) {
    const auto v = static_cast<std::remove_reference_t<decltype(field)>>(u.i64());
    if (later && v != field) throw changed();
    field = v;
  };
  for (int* field : {&c.num_dim, &c.num_nodes, &c.num_elem, &c.nemesis.processors}) header(*field);
  header(c.nemesis.global_nodes);
  header(c.nemesis.global_elements);
  for (auto* v : {&c.x, &c.y, &c.z}) u.array_onto(*v);
  u.array_onto(c.node_map);
  u.array_onto(c.element_map);
  const auto count = [&](std::size_t least) {
    const std::int64_t n = u.i64();
    if (n < 0 || static_cast<std::uint64_t>(n) > bytes.size() / least)
      throw std::runtime_error(source + ": the Exodus reader process's answer is malformed");
    return index_cast<std::size_t>(n);
  };
  const std::size_t blocks = count(40);
  if (later && blocks != c.blocks.size()) throw changed();
  c.blocks.resize(blocks);
  for (BlockData& block : c.blocks) {
    header(block.id);
    std::string name = u.text(), type = u.text();
    if (later && (name != block.name || type != block.type)) throw changed();
    block.name = std::move(name), block.type = std::move(type);
    header(block.per_elem);
    header(block.count);
    header(block.model_block);
    u.array_onto(block.conn);
  }
  for (auto* sets : {&c.node_sets, &c.side_sets})
    for (std::size_t s = count(32); s-- > 0;) {
      if (later)  // only the first share reads the sets
        throw std::runtime_error(source + ": the Exodus reader process's answer is malformed");
      SetData set;
      set.id = static_cast<int>(u.i64());
      set.name = u.text();
      u.array_onto(set.entries);
      u.array_onto(set.sides);
      sets->push_back(std::move(set));
    }
  if (!u.done())
    throw std::runtime_error(source + ": the Exodus reader process's answer is malformed");
}

// Whether contents hold every node and element the header announces (a shared read's joined).
void check_whole(const Contents& c, const std::string& source) {
  bool whole = c.x.size() == index_cast<std::size_t>(c.num_nodes) && c.y.size() == c.x.size() &&
               c.z.size() == c.x.size() && c.node_map.size() == c.x.size() &&
               c.element_map.size() == index_cast<std::size_t>(c.num_elem);
  for (const BlockData& b : c.blocks)
    whole = whole &&
            b.conn.size() == index_cast<std::size_t>(b.count) * index_cast<std::size_t>(b.per_elem);
  if (!whole)
    throw std::runtime_error(source + ": the Exodus reader process's answer is malformed");
}

std::string upper(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return s;
}

// Element types of points, lines and faces (Exodus's SPHERE, BAR, BEAM, TRUSS, TRI, SHELL, QUAD
// and their numbered forms): what meshio writes of a Gmsh mesh's physical points, curves and
// surfaces, and shell or beam blocks beside a solid model. No volume cell: such a block is left
// out (one warning names them all), its elements keeping their numbers.
bool lower_dimensional_type(const std::string& upper_type) {
  for (const char* prefix :
       {"SPHERE", "CIRCLE", "BAR", "BEAM", "TRUSS", "ROD", "EDGE", "TRI", "SHELL", "QUAD", "POINT"})
    if (upper_type.rfind(prefix, 0) == 0) return true;
  return false;
}

// meshio numbers blocks and sets from 0: a file with any id <= 0 gets them numbered by
// position (1, 2, ...), which keeps every id positive and distinct, and the reader says so:
// the output, and options naming blocks (--join-blocks), use the new ids.
template <typename T>
bool renumbered(const std::vector<T>& items, const std::string& source, const char* what) {
  if (std::none_of(items.begin(), items.end(), [](const T& i) { return i.id <= 0; })) return false;
  std::string from, to;  // the first few, on one line
  constexpr std::size_t kListed = 6;
  for (std::size_t k = 0; k < std::min(items.size(), kListed); ++k) {
    from += (k ? ", " : "") + std::to_string(items[k].id);
    to += (k ? ", " : "") + std::to_string(k + 1);
  }
  if (items.size() > kListed) from += ", ...", to += ", ...";
  read_warning(source + ": " + what + " ids " + from + " are not all positive: read as " + to +
               ", in the file's order (the output and options naming them use these)");
  return true;
}

// Stage two: the model, every entry checked (the file's ids in messages).
Model build_model(const Contents& c, const std::string& source) {
  Model model;
  model.points.reserve(c.x.size());
  for (std::size_t i = 0; i < c.x.size(); ++i) model.points.emplace_back(c.x[i], c.y[i], c.z[i]);
  model.node_ids.assign(c.node_map.begin(), c.node_map.end());
  const auto element_file_id = [&](std::size_t global_index) {
    return global_index < c.element_map.size() ? c.element_map[global_index]
                                               : static_cast<int64_t>(global_index) + 1;
  };
  // An element named by the file's id (its number map), at its place in the global order.
  const auto element_named = [&](std::size_t global_index) {
    return "element " + std::to_string(element_file_id(global_index));
  };

  // A block's cell, its index in kExodusCells by its type and node count; the table's size for
  // another.
  const auto cell_of = [](const BlockData& block) -> std::size_t {
    const std::string type = upper(block.type);
    for (std::size_t k = 0; k < kExodusCells.size(); ++k)
      for (const char* alias : kExodusCells[k].aliases)
        if (alias && type == alias && block.per_elem == kExodusCells[k].corners) return k;
    return kExodusCells.size();
  };
  // Room for every element first: pushed one by one, the arrays would be copied as they grow.
  std::array<std::size_t, kExodusCells.size() + 1> per_kind{};
  for (const BlockData& block : c.blocks)
    per_kind[cell_of(block)] += block.conn.size() / std::max(block.per_elem, 1);
  for (std::size_t k = 0; k < kExodusCells.size(); ++k) {
    with_cells(model, kElementKinds[k], [&](auto& cells) { cells.reserve(per_kind[k]); });
    element_blocks(model, kElementKinds[k]).reserve(per_kind[k]);
    element_ids(model, kElementKinds[k]).reserve(per_kind[k]);
  }
  std::vector<ElementRef> global;  // global element number (1-based) - 1 -> element
  global.reserve(index_cast<std::size_t>(std::max(c.num_elem, 0)));
  const bool renumber_blocks = renumbered(c.blocks, source, "element block");
  std::string left_out;  // blocks of points, lines or faces: "3 (QUAD4, 96), ..."
  for (std::size_t b = 0; b < c.blocks.size(); ++b) {
    const BlockData& block = c.blocks[b];
    const int block_id = renumber_blocks ? static_cast<int>(b) + 1 : block.id;
    // An empty block (libexodus writes one as type NULL, no connectivity): nothing to read.
    if (block.count == 0) continue;
    if (!block.name.empty()) model.block_names[block_id] = block.name;
    const std::string where = source + ": element block " + std::to_string(block.id);
    const std::size_t k = cell_of(block);
    if (k == kExodusCells.size() && lower_dimensional_type(upper(block.type))) {
      left_out += (left_out.empty() ? "" : ", ") + std::to_string(block.id) + " (" + block.type +
                  ", " + std::to_string(block.count) + ")";
      global.insert(global.end(), index_cast<std::size_t>(block.count),
                    ElementRef{ElementKind::kHex, kInvalidIndex});
      continue;
    }
    const ExodusCell* cell = k < kExodusCells.size() ? &kExodusCells[k] : nullptr;
    const ElementKind kind = cell ? kElementKinds[k] : ElementKind::kHex;
    if (!cell)
      throw InvalidInput(where + ": " + element_named(global.size()) + ": element type '" +
                         block.type + "' with " + std::to_string(block.per_elem) +
                         " nodes is not supported; only HEX8, TETRA4, PYRAMID5 and WEDGE6 are");
    const auto per_elem = index_cast<std::size_t>(block.per_elem);
    for (std::size_t base = 0; base + per_elem <= block.conn.size(); base += per_elem) {
      auto node = [&](int corner) {
        const int n = block.conn[base + index_cast<std::size_t>(corner)];
        if (n < 1 || n > c.num_nodes)
          throw InvalidInput(where + ": " + element_named(global.size()) + ": corner " +
                             std::to_string(corner + 1) + " refers to node number " +
                             std::to_string(n) + ", out of range [1, " +
                             std::to_string(c.num_nodes) + "]");
        return index_cast(n - 1);
      };
      std::array<Index, 8> corners{};
      for (std::size_t k = 0; k < index_cast<std::size_t>(cell->corners); ++k)
        corners[k] = node(cell->order[k]);
      global.push_back({kind, static_cast<Index>(element_count(model, kind))});
      add_element(model, kind, corners, block_id, element_file_id(global.size() - 1));
    }
  }

  if (!left_out.empty())
    read_warning(source +
                 ": element blocks of points, lines or faces, not volume cells, are not "
                 "read (block id, type, elements): " +
                 left_out);

  // Parts of a block our writer split by element type (kBlockProperty) join it again
  // (primal::join_blocks): a block whose property names another block, one that names itself;
  // blocks with elements only.
  if (!renumber_blocks) {
    std::map<int, std::vector<int>> parts;  // block -> itself, then its parts
    for (const BlockData& block : c.blocks)
      if (block.model_block == block.id && block.count > 0) parts[block.id].push_back(block.id);
    for (const BlockData& block : c.blocks)
      if (block.model_block != block.id && block.count > 0)
        if (const auto it = parts.find(block.model_block); it != parts.end())
          it->second.push_back(block.id);
    for (const auto& [id, ids] : parts)
      if (ids.size() > 1) join_blocks(model, ids, source);
  }

  const bool renumber_node_sets = renumbered(c.node_sets, source, "node set");
  for (std::size_t s = 0; s < c.node_sets.size(); ++s) {
    const SetData& in = c.node_sets[s];
    NodeSet set{renumber_node_sets ? static_cast<int>(s) + 1 : in.id, in.name, {}};
    const std::string where = source + ": node set " + std::to_string(in.id);
    for (std::size_t i = 0; i < in.entries.size(); ++i) {
      if (in.entries[i] < 1 || in.entries[i] > c.num_nodes)
        throw InvalidInput(where + ": entry " + std::to_string(i + 1) + " refers to node " +
                           std::to_string(in.entries[i]) + ", out of range");
      set.nodes.push_back(index_cast(in.entries[i] - 1));
    }
    model.node_sets.push_back(std::move(set));
  }

  const bool renumber_side_sets = renumbered(c.side_sets, source, "side set");
  for (std::size_t s = 0; s < c.side_sets.size(); ++s) {
    const SetData& in = c.side_sets[s];
    SideSet set{renumber_side_sets ? static_cast<int>(s) + 1 : in.id, in.name, {}};
    const std::string where = source + ": side set " + std::to_string(in.id);
    for (std::size_t i = 0; i < in.entries.size() && i < in.sides.size(); ++i) {
      const std::string entry = where + ": entry " + std::to_string(i + 1);
      const int element_number = in.entries[i], side = in.sides[i];
      if (element_number < 1 || index_cast<std::size_t>(element_number) > global.size())
        throw InvalidInput(entry + " refers to element number " + std::to_string(element_number) +
                           ", out of range [1, " + std::to_string(global.size()) + "]");
      const ElementRef element = global[index_cast<std::size_t>(element_number - 1)];
      if (element.index == kInvalidIndex)
        throw InvalidInput(entry + ": " +
                           element_named(index_cast<std::size_t>(element_number - 1)) +
                           " is in a block of points, lines or faces, not a volume cell");
      const int faces = cell_topology(element.kind).faces;
      if (side < 1 || side > faces)
        throw InvalidInput(
            entry + ": " + element_named(index_cast<std::size_t>(element_number - 1)) + ": side " +
            std::to_string(side) + " out of range [1, " + std::to_string(faces) + "]");
      set.sides.push_back({element, side - 1});
    }
    model.side_sets.push_back(std::move(set));
  }
  return model;
}

// Stage one in a child: the answer (pack()) for `slice` of the file.
std::string read_answer(const std::filesystem::path& path, const std::string& source, Slice slice) {
  check_mesh_format(path, MeshFileFormat::kExodus);
  const NetcdfKind kind = screen_netcdf(path, source);
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  const ExodusBounds bound(ec ? 0 : size, kind == NetcdfKind::kClassic, source);
  // Both kinds are read in the child: libexodusII itself overruns its callers' buffers on some
  // classic files that pass the screen (tests/fuzz/regressions/exo-classic-stack-smash.exo:
  // "stack smashing detected" in main's reader), and libhdf5 crashes on corrupt netCDF-4 ones.
  // The child may use what the data it returns needs, several times over, and not the
  // machine: 2 GiB, or 64 times the file's size for larger files.
  // Its time is bounded by the file's size too: 3 s of CPU and 1 s more per MiB (libhdf5 reads
  // hundreds of MiB a second), twice that and 2 s of wall-clock time; so a corrupt file that
  // sends the library into a loop, or a child that never answers, ends in seconds.
  IsolationLimits limits;
  limits.memory_bytes = std::max<std::uint64_t>(limits.memory_bytes, 64 * size);
  limits.cpu_seconds = static_cast<unsigned>(std::min<std::uint64_t>(3 + (size >> 20), 1u << 20));
  limits.wall_seconds = 2 * limits.cpu_seconds + 2;
  limits.max_result_bytes = 8 * bound.capacity() + 4096;
  return run_isolated(
      [&] { return pack(read_contents(source, bound, slice)); }, source,
      kind == NetcdfKind::kClassic ? "reading the netCDF file" : "reading the netCDF-4 (HDF5) file",
      limits);
}

// Stage two on the whole contents.
Model model_of(const Contents& contents, const std::string& source, const ReadOptions& options) {
  check_whole(contents, source);
  Model model = build_model(contents, source);
  sanitize_names(model);
  validate(model, source);
  options.check_geometry ? check_geometry(model, source, options.inverted_hint)
                         : check_points(model, source);
  return model;
}

// What a share of a shared read sends the others: its answer, or why it has none.
enum class ShareOutcome : char { kRead, kInvalidInput, kOutOfMemory, kFault };

}  // namespace

Model read_exodus(const std::filesystem::path& path, const ReadOptions& options) {
  return read_exodus_piece(path, options, nullptr);
}

Model read_exodus_piece(const std::filesystem::path& path, const ReadOptions& options,
                        NemesisInfo* nemesis) {
  const std::string source = path.string();
  Contents contents;
  unpack_onto(contents, read_answer(path, source, {}), source, false);
  if (nemesis) *nemesis = contents.nemesis;
  return model_of(contents, source, options);
}

Model read_exodus_shared(const std::filesystem::path& path, const ReadOptions& options,
                         const Shares& shares) {
  if (shares.shares <= 1) return read_exodus(path, options);
  if (!shares.exchange || shares.share < 0 || shares.share >= shares.shares)
    throw std::invalid_argument("read_exodus_shared: share " + std::to_string(shares.share) +
                                " of " + std::to_string(shares.shares) + " without an exchange");
  const std::string source = path.string();
  // Every share reaches the exchange, whatever happened to its read: one that threw instead
  // would leave the others waiting there.
  ShareOutcome outcome = ShareOutcome::kRead;
  std::string answer;
  try {
    // Test hook (docs/cli.md): GEODE_TEST_FAIL_READ_SHARE=N refuses share N's read alone.
    if (const char* hook = std::getenv("GEODE_TEST_FAIL_READ_SHARE");
        hook && *hook && std::atoi(hook) == shares.share)
      throw InvalidInput(source + ": GEODE_TEST_FAIL_READ_SHARE is set");
    answer = read_answer(path, source, {shares.share, shares.shares});
  } catch (const InvalidInput& e) {
    outcome = ShareOutcome::kInvalidInput, answer = e.what();
  } catch (const std::bad_alloc&) {
    outcome = ShareOutcome::kOutOfMemory, answer.clear();
  } catch (const std::exception& e) {
    outcome = ShareOutcome::kFault, answer = e.what();
  }
  primal::detail::BytePacket mine;
  mine.put(outcome);
  mine.put(answer);
  std::string().swap(answer);
  primal::detail::BytePacket all(shares.exchange(mine.bytes()));
  mine = {};
  // The shares' answers in share order; the first failure is every process's.
  std::vector<std::string_view> answers;
  for (int s = 0; s < shares.shares; ++s) {
    const auto kind = all.get<ShareOutcome>();
    const std::string_view body = all.get_view();
    switch (kind) {
      case ShareOutcome::kRead:
        answers.push_back(body);
        break;
      case ShareOutcome::kInvalidInput:
        throw InvalidInput(std::string(body));
      case ShareOutcome::kOutOfMemory:
        throw std::bad_alloc();
      default:
        throw std::runtime_error(std::string(body));
    }
  }
  Contents contents;
  for (std::size_t s = 0; s < answers.size(); ++s) unpack_onto(contents, answers[s], source, s > 0);
  return model_of(contents, source, options);
}

}  // namespace geode::io
