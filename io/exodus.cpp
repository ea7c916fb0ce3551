#include <geode/io/exodus.hpp>

#include <geode/io/atomic_file.hpp>

#include <exodusII.h>
#include <netcdf.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <geode/io/file_format.hpp>
#include <geode/io/names.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::io {

using namespace primal;

namespace {

// Longer names than Exodus's default 32 characters.
constexpr int kNameLength = 80;

// Owns an open Exodus file id.
class ExodusFile {
 public:
  explicit ExodusFile(int id) : id_(id) {}
  ~ExodusFile() {
    if (id_ >= 0) ex_close(id_);
  }
  ExodusFile(const ExodusFile&) = delete;
  ExodusFile& operator=(const ExodusFile&) = delete;
  int id() const { return id_; }
  int close() {
    const int status = ex_close(id_);
    id_ = -1;
    return status;
  }

 private:
  int id_;
};

// The cause libexodusII recorded for its last error: a system error (ENOSPC on a full disk)
// or a netCDF / Exodus one, in words.
std::string exodus_cause() {
  const char* msg = nullptr;
  const char* func = nullptr;
  int err = 0;
  ex_get_err(&msg, &func, &err);
  if (err > 0)
    return std::string(std::strerror(err)) +
           (err == ENOSPC || err == EDQUOT ? " (the disk is full)" : "");
  if (err < 0) return nc_strerror(err);
  return "Exodus error";
}

// `where` names the file the user gave (never the temporary one a write goes through).
void check(int status, const std::string& where, const std::string& what) {
  if (status < 0) throw InvalidInput(where + ": " + what + " failed: " + exodus_cause());
}

// Names as Exodus wants them: an array of char* to buffers of kNameLength + 1.
struct NameBuffers {
  std::vector<std::vector<char>> storage;
  std::vector<char*> pointers;
  explicit NameBuffers(std::size_t n) : storage(n, std::vector<char>(kNameLength + 1, '\0')) {
    for (auto& s : storage) pointers.push_back(s.data());
  }
  void set(std::size_t i, const std::string& name) {
    const std::string safe = sanitize_name(name);
    std::size_t n = std::min<std::size_t>(safe.size(), kNameLength);
    while (n > 0 && n < safe.size() && (static_cast<unsigned char>(safe[n]) & 0xC0) == 0x80)
      --n;  // whole characters
    std::copy_n(safe.begin(), n, storage[i].begin());
  }
  std::string get(std::size_t i) const { return std::string(storage[i].data()); }
};

// What an Exodus file can hold (see read_exodus).
class ExodusBounds {
 public:
  ExodusBounds(const std::filesystem::path& path, std::string source) : source_(std::move(source)) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    const std::string head = read_file_head(path, 4);
    const bool classic = head.rfind("CDF", 0) == 0;
    size_ = ec ? 0 : size;
    capacity_ = classic ? size_ : size_ * 1032 + 4096;
  }
  void check(std::int64_t count, std::size_t bytes_each, const char* what) const {
    if (count < 0 || static_cast<std::uint64_t>(count) > capacity_ / bytes_each)
      throw InvalidInput(source_ + ": the header announces " + std::to_string(count) + " " + what +
                         ", more than a file of " + std::to_string(size_) +
                         " bytes can hold (corrupt or truncated file?)");
  }

 private:
  std::string source_;
  std::uint64_t size_ = 0, capacity_ = 0;
};

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

Model read_exodus(const std::filesystem::path& path, const ReadOptions& options) {
  const std::string source = path.string();
  check_mesh_format(path, MeshFileFormat::kExodus);
  ex_opts(0);  // we report errors ourselves, through exceptions
  int cpu_word_size = 8, io_word_size = 0;
  float version = 0.0f;
  ExodusFile file(ex_open(source.c_str(), EX_READ, &cpu_word_size, &io_word_size, &version));
  if (file.id() < 0)
    throw InvalidInput(source + ": not a readable Exodus II file (truncated or corrupt?)");
  const int exo = file.id();
  const int64_t used_name_length = ex_inquire_int(exo, EX_INQ_DB_MAX_USED_NAME_LENGTH);
  ex_set_max_name_length(exo,
                         static_cast<int>(std::clamp<int64_t>(used_name_length, 32, kNameLength)));

  char title[MAX_LINE_LENGTH + 1] = {};
  int num_dim = 0, num_nodes = 0, num_elem = 0, num_blocks = 0, num_node_sets = 0,
      num_side_sets = 0;
  check(ex_get_init(exo, title, &num_dim, &num_nodes, &num_elem, &num_blocks, &num_node_sets,
                    &num_side_sets),
        source, "reading the header");
  if (num_dim < 2 || num_dim > 3)
    throw InvalidInput(source + ": " + std::to_string(num_dim) +
                       "-dimensional model; expected 3 (or 2)");
  // Every count is bounded by what the file can hold before anything of its size is read or
  // allocated: a classic netCDF file stores each value (4 bytes at least), a netCDF-4 (HDF5)
  // one may compress them, by at most zlib's 1032:1.
  const ExodusBounds bound(path, source);
  bound.check(num_nodes, static_cast<std::size_t>(num_dim) * 4, "nodes");
  bound.check(num_elem, 4, "elements");
  bound.check(num_blocks, 4, "element blocks");
  bound.check(num_node_sets, 4, "node sets");
  bound.check(num_side_sets, 4, "side sets");

  Model model;
  {
    std::vector<double> x(static_cast<std::size_t>(num_nodes)), y(x.size()), z(x.size(), 0.0);
    if (num_nodes > 0)
      check(ex_get_coord(exo, x.data(), y.data(), num_dim == 3 ? z.data() : nullptr), source,
            "reading coordinates");
    for (std::size_t i = 0; i < x.size(); ++i) model.points.emplace_back(x[i], y[i], z[i]);
  }
  // Node and element number maps (Cubit's ids): the file ids in messages. Without maps in the
  // file, libexodusII gives 1..n.
  std::vector<int64_t> element_map;
  if (num_nodes > 0) {
    std::vector<int> ids(static_cast<std::size_t>(num_nodes));
    check(ex_get_id_map(exo, EX_NODE_MAP, ids.data()), source, "reading the node number map");
    model.node_ids.assign(ids.begin(), ids.end());
  }
  if (num_elem > 0) {
    std::vector<int> ids(static_cast<std::size_t>(num_elem));
    check(ex_get_id_map(exo, EX_ELEM_MAP, ids.data()), source, "reading the element number map");
    element_map.assign(ids.begin(), ids.end());
  }
  auto element_file_id = [&](std::size_t global_index) {
    return global_index < element_map.size() ? element_map[global_index]
                                             : static_cast<int64_t>(global_index) + 1;
  };

  // Element blocks in file order; global element number (1-based) -> element.
  std::vector<ElementRef> global;
  if (num_blocks > 0) {
    std::vector<int> ids(static_cast<std::size_t>(num_blocks));
    check(ex_get_ids(exo, EX_ELEM_BLOCK, ids.data()), source, "reading element block ids");
    NameBuffers names(ids.size());
    const bool named = ex_get_names(exo, EX_ELEM_BLOCK, names.pointers.data()) >= 0;
    // meshio numbers blocks from 0: a file with any id <= 0 gets its blocks numbered by
    // position (1, 2, ...), which keeps every id positive and distinct.
    const bool renumber = std::any_of(ids.begin(), ids.end(), [](int id) { return id <= 0; });
    for (std::size_t b = 0; b < ids.size(); ++b) {
      const int id = ids[b];
      const int block_id = renumber ? static_cast<int>(b) + 1 : id;
      if (named && !names.get(b).empty()) model.block_names[block_id] = names.get(b);
      const std::string where = source + ": element block " + std::to_string(id);
      char type_buffer[MAX_STR_LENGTH + 1] = {};
      int count = 0, per_elem = 0, edges = 0, faces = 0, attributes = 0;
      check(ex_get_block(exo, EX_ELEM_BLOCK, id, type_buffer, &count, &per_elem, &edges, &faces,
                         &attributes),
            where, "reading the block header");
      if (per_elem < 0 || per_elem > 64)
        throw InvalidInput(where + ": " + std::to_string(per_elem) + " nodes per element");
      bound.check(count, 4 * static_cast<std::size_t>(std::max(per_elem, 1)),
                  "elements in the block");
      if (static_cast<std::int64_t>(global.size()) + count > num_elem)
        throw InvalidInput(where + ": more elements in the blocks than the header's " +
                           std::to_string(num_elem));
      const std::string type = upper(type_buffer);
      const ExodusCell* cell = nullptr;
      ElementKind kind = ElementKind::Hex;
      for (std::size_t k = 0; k < kExodusCells.size() && !cell; ++k)
        for (const char* alias : kExodusCells[k].aliases)
          if (alias && type == alias && per_elem == kExodusCells[k].corners) {
            cell = &kExodusCells[k];
            kind = kElementKinds[k];
            break;
          }
      if (!cell)
        throw InvalidInput(where + ": element " + std::to_string(global.size() + 1) +
                           ": element type '" + std::string(type_buffer) + "' with " +
                           std::to_string(per_elem) +
                           " nodes is not supported; only HEX8, TETRA4, PYRAMID5 and WEDGE6 are");
      std::vector<int> conn(static_cast<std::size_t>(count) * static_cast<std::size_t>(per_elem));
      if (count > 0)
        check(ex_get_conn(exo, EX_ELEM_BLOCK, id, conn.data(), nullptr, nullptr), where,
              "reading connectivity");
      for (int e = 0; e < count; ++e) {
        const std::size_t base = static_cast<std::size_t>(e) * static_cast<std::size_t>(per_elem);
        auto node = [&](int corner) {
          const int n = conn[base + static_cast<std::size_t>(corner)];
          if (n < 1 || n > num_nodes)
            throw InvalidInput(where + ": element " + std::to_string(global.size() + 1) +
                               ": corner " + std::to_string(corner + 1) + " refers to node " +
                               std::to_string(n) + ", out of range [1, " +
                               std::to_string(num_nodes) + "]");
          return static_cast<Index>(n - 1);
        };
        std::array<Index, 8> c{};
        for (std::size_t k = 0; k < static_cast<std::size_t>(cell->corners); ++k)
          c[k] = node(cell->order[k]);
        global.push_back({kind, static_cast<Index>(element_count(model, kind))});
        add_element(model, kind, c, block_id, element_file_id(global.size() - 1));
      }
    }
  }

  if (num_node_sets > 0) {
    std::vector<int> ids(static_cast<std::size_t>(num_node_sets));
    check(ex_get_ids(exo, EX_NODE_SET, ids.data()), source, "reading node set ids");
    NameBuffers names(ids.size());
    const bool named = ex_get_names(exo, EX_NODE_SET, names.pointers.data()) >= 0;
    // As for blocks: meshio numbers sets from 0, and a file with any id <= 0 gets its node
    // sets numbered by position (1, 2, ...).
    const bool renumber = std::any_of(ids.begin(), ids.end(), [](int id) { return id <= 0; });
    for (std::size_t s = 0; s < ids.size(); ++s) {
      NodeSet set{
          renumber ? static_cast<int>(s) + 1 : ids[s], named ? names.get(s) : std::string(), {}};
      const std::string where = source + ": node set " + std::to_string(ids[s]);
      int count = 0, factors = 0;
      check(ex_get_set_param(exo, EX_NODE_SET, ids[s], &count, &factors), where,
            "reading the set header");
      bound.check(count, 4, "node set entries");
      std::vector<int> nodes(static_cast<std::size_t>(count));
      if (count > 0)
        check(ex_get_set(exo, EX_NODE_SET, ids[s], nodes.data(), nullptr), where,
              "reading entries");
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (nodes[i] < 1 || nodes[i] > num_nodes)
          throw InvalidInput(where + ": entry " + std::to_string(i + 1) + " refers to node " +
                             std::to_string(nodes[i]) + ", out of range");
        set.nodes.push_back(static_cast<Index>(nodes[i] - 1));
      }
      model.node_sets.push_back(std::move(set));
    }
  }

  if (num_side_sets > 0) {
    std::vector<int> ids(static_cast<std::size_t>(num_side_sets));
    check(ex_get_ids(exo, EX_SIDE_SET, ids.data()), source, "reading side set ids");
    NameBuffers names(ids.size());
    const bool named = ex_get_names(exo, EX_SIDE_SET, names.pointers.data()) >= 0;
    const bool renumber = std::any_of(ids.begin(), ids.end(), [](int id) { return id <= 0; });
    for (std::size_t s = 0; s < ids.size(); ++s) {
      SideSet set{
          renumber ? static_cast<int>(s) + 1 : ids[s], named ? names.get(s) : std::string(), {}};
      const std::string where = source + ": side set " + std::to_string(ids[s]);
      int count = 0, factors = 0;
      check(ex_get_set_param(exo, EX_SIDE_SET, ids[s], &count, &factors), where,
            "reading the set header");
      bound.check(count, 8, "side set entries");
      std::vector<int> elems(static_cast<std::size_t>(count)), sides(elems.size());
      if (count > 0)
        check(ex_get_set(exo, EX_SIDE_SET, ids[s], elems.data(), sides.data()), where,
              "reading entries");
      for (std::size_t i = 0; i < elems.size(); ++i) {
        const std::string entry = where + ": entry " + std::to_string(i + 1);
        if (elems[i] < 1 || static_cast<std::size_t>(elems[i]) > global.size())
          throw InvalidInput(entry + " refers to element " + std::to_string(elems[i]) +
                             ", out of range");
        const ElementRef element = global[static_cast<std::size_t>(elems[i] - 1)];
        const int faces = cell_topology(element.kind).faces;
        if (sides[i] < 1 || sides[i] > faces)
          throw InvalidInput(entry + ": element " + std::to_string(elems[i]) + ": side " +
                             std::to_string(sides[i]) + " out of range [1, " +
                             std::to_string(faces) + "]");
        set.sides.push_back({element, sides[i] - 1});
      }
      model.side_sets.push_back(std::move(set));
    }
  }
  sanitize_names(model);
  validate(model, source);
  options.check_geometry ? check_geometry(model, source) : check_points(model, source);
  return model;
}

void write_exodus(const Model& model, const std::filesystem::path& path) {
  const std::string target = path.string();
  validate(model, target);

  // Blocks in ascending id, each of one element type; global numbering follows.
  // An Exodus block holds one element type. A model block of several kinds (Gmsh puts the
  // pyramids in the tet volume's block) keeps its id for its first kind (kElementKinds order);
  // each further kind gets a block of its own above every model id, named after it.
  std::map<int, std::vector<ElementRef>> blocks;  // id -> its elements, one kind
  std::map<std::pair<int, ElementKind>, int> exodus_id;
  int top = 0;
  for (ElementKind kind : kElementKinds)
    for (std::size_t e = 0; e < element_count(model, kind); ++e)
      top = std::max(top, block_of(model, {kind, static_cast<Index>(e)}));
  std::map<int, std::string> names = model.block_names;
  for (ElementKind kind : kElementKinds)
    for (std::size_t e = 0; e < element_count(model, kind); ++e) {
      const ElementRef ref{kind, static_cast<Index>(e)};
      const int id = block_of(model, ref);
      auto [it, inserted] = exodus_id.try_emplace({id, kind}, id);
      if (inserted && blocks.count(id) && blocks[id].front().kind != kind) {
        it->second = ++top;
        const auto name = model.block_names.find(id);
        names[top] =
            (name != model.block_names.end() ? name->second : "block " + std::to_string(id)) + " " +
            element_kind_name(kind) + "s";
      }
      blocks[it->second].push_back(ref);
    }
  std::array<std::vector<int>, 4> global;  // per kind and element: its 1-based file number
  for (ElementKind kind : kElementKinds)
    global[static_cast<std::size_t>(kind)].resize(element_count(model, kind));
  int next = 1;
  for (const auto& [id, members] : blocks)
    for (const ElementRef& e : members)
      global[static_cast<std::size_t>(e.kind)][static_cast<std::size_t>(e.index)] = next++;

  write_path_atomically(path, "", [&](const std::filesystem::path& temp) {
    ex_opts(0);
    int cpu_word_size = 8, io_word_size = 8;
    ExodusFile file(ex_create(temp.string().c_str(), EX_CLOBBER, &cpu_word_size, &io_word_size));
    if (file.id() < 0) throw InvalidInput(target + ": cannot create the file: " + exodus_cause());
    const int exo = file.id();
    check(ex_set_max_name_length(exo, kNameLength), target, "setting the name length");
    check(
        ex_put_init(exo, "geode", 3, static_cast<int64_t>(model.points.size()),
                    static_cast<int64_t>(element_count(model)), static_cast<int64_t>(blocks.size()),
                    static_cast<int64_t>(model.node_sets.size()),
                    static_cast<int64_t>(model.side_sets.size())),
        target, "writing the header");
    if (!model.points.empty()) {
      std::vector<double> x, y, z;
      for (const Point& p : model.points) {
        x.push_back(p.x());
        y.push_back(p.y());
        z.push_back(p.z());
      }
      check(ex_put_coord(exo, x.data(), y.data(), z.data()), target, "writing coordinates");
    }
    // Post-processors (ParaView, Cubit) label the axes by these names; empty ones show as blanks.
    char cx[] = "x", cy[] = "y", cz[] = "z";
    char* coordinate_names[] = {cx, cy, cz};
    check(ex_put_coord_names(exo, coordinate_names), target, "writing coordinate names");
    NameBuffers block_names(blocks.size());
    std::size_t b = 0;
    for (const auto& [id, members] : blocks) {
      const ExodusCell& cell = kExodusCells[static_cast<std::size_t>(members.front().kind)];
      const int per_elem = cell.corners;
      check(ex_put_block(exo, EX_ELEM_BLOCK, id, cell.name, static_cast<int64_t>(members.size()),
                         per_elem, 0, 0, 0),
            target, "writing block " + std::to_string(id));
      std::vector<int> conn(members.size() * static_cast<std::size_t>(per_elem));
      for (std::size_t i = 0; i < members.size(); ++i) {
        const auto corners = element_corners(model, members[i]);
        const std::size_t base = i * static_cast<std::size_t>(per_elem);
        // exodus_corner[order[c]] = model_corner[c]
        for (std::size_t c = 0; c < static_cast<std::size_t>(per_elem); ++c)
          conn[base + static_cast<std::size_t>(cell.order[c])] = corners[c] + 1;
      }
      if (!conn.empty())
        check(ex_put_conn(exo, EX_ELEM_BLOCK, id, conn.data(), nullptr, nullptr), target,
              "writing block " + std::to_string(id) + " connectivity");
      if (auto it = names.find(id); it != names.end()) block_names.set(b, it->second);
      ++b;
    }
    if (!blocks.empty())
      check(ex_put_names(exo, EX_ELEM_BLOCK, block_names.pointers.data()), target,
            "writing block names");

    NameBuffers node_set_names(model.node_sets.size());
    for (std::size_t s = 0; s < model.node_sets.size(); ++s) {
      const NodeSet& set = model.node_sets[s];
      check(ex_put_set_param(exo, EX_NODE_SET, set.id, static_cast<int64_t>(set.nodes.size()), 0),
            target, "writing node set " + std::to_string(set.id));
      std::vector<int> nodes;
      for (Index v : set.nodes) nodes.push_back(v + 1);
      if (!nodes.empty())
        check(ex_put_set(exo, EX_NODE_SET, set.id, nodes.data(), nullptr), target,
              "writing node set " + std::to_string(set.id));
      node_set_names.set(s, set.name);
    }
    if (!model.node_sets.empty())
      check(ex_put_names(exo, EX_NODE_SET, node_set_names.pointers.data()), target,
            "writing node set names");

    NameBuffers side_set_names(model.side_sets.size());
    for (std::size_t s = 0; s < model.side_sets.size(); ++s) {
      const SideSet& set = model.side_sets[s];
      check(ex_put_set_param(exo, EX_SIDE_SET, set.id, static_cast<int64_t>(set.sides.size()), 0),
            target, "writing side set " + std::to_string(set.id));
      std::vector<int> elems, sides;
      for (const Side& side : set.sides) {
        elems.push_back(global[static_cast<std::size_t>(side.element.kind)]
                              [static_cast<std::size_t>(side.element.index)]);
        sides.push_back(side.face + 1);
      }
      if (!elems.empty())
        check(ex_put_set(exo, EX_SIDE_SET, set.id, elems.data(), sides.data()), target,
              "writing side set " + std::to_string(set.id));
      side_set_names.set(s, set.name);
    }
    if (!model.side_sets.empty())
      check(ex_put_names(exo, EX_SIDE_SET, side_set_names.pointers.data()), target,
            "writing side set names");
    check(file.close(), target, "closing the temporary file");
  });
}

}  // namespace geode::io
