#include <geode/io/exodus.hpp>

#include <geode/io/atomic_file.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <map>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include <geode/io/exodus_library.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::io {

using namespace primal;

using namespace exodus_library;

namespace {
// Nodes or elements written per library call: 2^18 hexes are 8 MiB of connectivity.
constexpr std::size_t kSlice = std::size_t{1} << 18;

// An Exodus block's elements: runs of consecutive model elements of one kind (a block's
// elements come in runs: one per block in a conform output), not a reference per element (8 B
// a hex beside the model at a conform run's write).
struct BlockMembers {
  ElementKind kind;
  std::vector<std::pair<std::size_t, std::size_t>> runs;  // first, count
  std::size_t size = 0;
};
// Bytes kept free in the header (ex_put_init's definitions, blocks, sets, names, Nemesis's).
constexpr std::size_t kHeaderRoom = std::size_t{1} << 17;

// netCDF reads every 8 KiB block before writing it, and libexodusII writes small variables
// placed after the coordinates and connectivity while defining them, so the model's data goes
// into a hole that each of those reads finds. Reading holes cost the kernel far more zeroing
// than the file's size: 0.7 to 3.8 s, erratic, for 600 MB that take 0.43 s when the holes are
// first filled with zeros (a fifth of a 10-million-hex Nemesis piece's run). So they are
// filled, in large writes, before the model's data; in the page cache these pages are usually
// rewritten before they reach the disk.
void fill_holes(int exo, const std::filesystem::path& file, const std::string& target) {
  check_netcdf(nc_sync(exo), target, "writing the definitions");
  const int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return;  // netCDF's own reads then find the holes: slower, not wrong
  const off_t end = ::lseek(fd, 0, SEEK_END);
  static const std::vector<char> zeros(std::size_t{1} << 20, 0);
  for (off_t at = 0; at < end;) {
    const off_t hole = ::lseek(fd, at, SEEK_HOLE);
    if (hole < 0 || hole >= end) break;
    off_t data = ::lseek(fd, hole, SEEK_DATA);
    if (data < 0) data = end;
    for (off_t p = hole; p < data;) {
      const auto n = static_cast<std::size_t>(std::min<off_t>(data - p, zeros.size()));
      const ssize_t w = ::pwrite(fd, zeros.data(), n, p);
      if (w <= 0) break;  // as above; a full disk shows at netCDF's own write
      p += w;
    }
    at = data;
  }
  ::close(fd);
}
}  // namespace

void write_exodus(const Model& model, const std::filesystem::path& path,
                  const std::function<void(int exo)>& define,
                  const std::function<void(int exo)>& write_more) {
  const std::string target = path.string();
  validate(model, target);

  // Blocks in ascending id, each of one element type; global numbering follows.
  // An Exodus block holds one element type. A model block of several kinds (Gmsh puts the
  // pyramids in the tet volume's block) keeps its id for its first kind (kElementKinds order);
  // each further kind gets a block of its own above every model id, named after it.
  std::map<int, BlockMembers> blocks;  // id -> its elements, one kind
  std::map<std::pair<int, ElementKind>, int> exodus_id;
  int top = 0;
  for (ElementKind kind : kElementKinds) {
    const std::vector<int>& ids = element_blocks(model, kind);
    if (!ids.empty()) top = std::max(top, *std::max_element(ids.begin(), ids.end()));
    if (ids.empty() && element_count(model, kind) > 0) top = std::max(top, default_block(kind));
  }
  std::map<int, std::string> names = model.block_names;
  for (ElementKind kind : kElementKinds) {
    // Elements of one block come in runs: the maps are read once per run, not per element
    // (three map operations per element were a third of writing a million hexes).
    BlockMembers* into = nullptr;
    int run_id = 0;
    for (std::size_t e = 0; e < element_count(model, kind); ++e) {
      const int id = block_of(model, {kind, index_cast(e)});
      if (!into || id != run_id) {
        auto [it, inserted] = exodus_id.try_emplace({id, kind}, id);
        if (inserted && blocks.count(id) && blocks.at(id).kind != kind) {
          it->second = ++top;
          const auto name = model.block_names.find(id);
          names[top] =
              (name != model.block_names.end() ? name->second : "block " + std::to_string(id)) +
              " " + element_kind_name(kind) + "s";
        }
        into = &blocks.try_emplace(it->second, BlockMembers{kind, {}, 0}).first->second;
        into->runs.emplace_back(e, 0);
        run_id = id;
      }
      ++into->runs.back().second, ++into->size;
    }
  }

  write_path_atomically(path, "", [&](const std::filesystem::path& temp) {
    ex_opts(0);
    int cpu_word_size = 8, io_word_size = 8;
    ExodusFile file(ex_create(temp.string().c_str(), EX_CLOBBER, &cpu_word_size, &io_word_size));
    if (file.id() < 0) throw InvalidInput(target + ": cannot create the file: " + exodus_cause());
    const int exo = file.id();
    check(ex_set_max_name_length(exo, kNameLength), target, "setting the name length");
    // Room in the header for every later definition: a classic netCDF file moves its whole data
    // region (written or not: netCDF copies the unwritten region as zeros) whenever a definition
    // outgrows the header: once per block, set and Nemesis definition, 0.1 to 0.3 s each on a
    // 5-million-hex piece. Reserving the room after ex_put_init (nc__enddef's h_minfree) moved
    // the coordinates ex_put_init had just placed: 30 MB of zeros copied in 8 KiB steps, 37 ms
    // of a 1.15-million-hex conform output. So the room is held by a placeholder attribute
    // while ex_put_init places the coordinates after it, then given back: netCDF never moves
    // data towards a header that shrank, and later definitions fill the room instead.
    constexpr const char* kRoom = "geode_header_room";
    {
      const std::vector<char> zeros(kHeaderRoom, 0);
      check_netcdf(nc_redef(exo), target, "reserving the header");
      check_netcdf(nc_put_att_text(exo, NC_GLOBAL, kRoom, zeros.size(), zeros.data()), target,
                   "reserving the header");
      check_netcdf(nc_enddef(exo), target, "reserving the header");
    }
    check(ex_put_init(exo, "geode", 3, index_cast<int64_t>(model.points.size()),
                      index_cast<int64_t>(element_count(model)), index_cast<int64_t>(blocks.size()),
                      index_cast<int64_t>(model.node_sets.size()),
                      index_cast<int64_t>(model.side_sets.size())),
          target, "writing the header");
    check_netcdf(nc_redef(exo), target, "reserving the header");
    check_netcdf(nc_del_att(exo, NC_GLOBAL, kRoom), target, "reserving the header");
    check_netcdf(nc_enddef(exo), target, "reserving the header");
    // Definitions first (names, blocks, sets), then the data.
    // Post-processors (ParaView, Cubit) label the axes by these names; empty ones show as blanks.
    char cx[] = "x", cy[] = "y", cz[] = "z";
    char* coordinate_names[] = {cx, cy, cz};
    check(ex_put_coord_names(exo, coordinate_names), target, "writing coordinate names");
    NameBuffers block_names(blocks.size());
    std::size_t b = 0;
    for (const auto& [id, members] : blocks) {
      const ExodusCell& cell = kExodusCells[static_cast<std::size_t>(members.kind)];
      check(ex_put_block(exo, EX_ELEM_BLOCK, id, cell.name, index_cast<int64_t>(members.size),
                         cell.corners, 0, 0, 0),
            target, "writing block " + std::to_string(id));
      if (auto it = names.find(id); it != names.end()) block_names.set(b, it->second);
      ++b;
    }
    if (!blocks.empty())
      check(ex_put_names(exo, EX_ELEM_BLOCK, block_names.pointers.data()), target,
            "writing block names");
    // A split block's parts say whose they are (kBlockProperty), so that reading the file
    // gives the model's block back: one material, whose inner faces smoothing may move.
    if (std::any_of(exodus_id.begin(), exodus_id.end(),
                    [](const auto& e) { return e.first.first != e.second; })) {
      std::string property = kBlockProperty;
      char* properties[] = {property.data()};
      check(ex_put_prop_names(exo, EX_ELEM_BLOCK, 1, properties), target,
            "writing block properties");
      for (const auto& [key, id] : exodus_id)
        check(ex_put_prop(exo, EX_ELEM_BLOCK, id, kBlockProperty, key.first), target,
              "writing block " + std::to_string(id) + "'s properties");
    }
    // Node and side sets alike: each set's size, then their names.
    auto define_sets = [&](ex_entity_type type, const auto& sets, const std::string& what,
                           auto size) {
      NameBuffers set_names(sets.size());
      for (std::size_t s = 0; s < sets.size(); ++s) {
        check(ex_put_set_param(exo, type, sets[s].id, index_cast<int64_t>(size(sets[s])), 0),
              target, "writing " + what + " " + std::to_string(sets[s].id));
        set_names.set(s, sets[s].name);
      }
      if (!sets.empty())
        check(ex_put_names(exo, type, set_names.pointers.data()), target,
              "writing " + what + " names");
    };
    define_sets(EX_NODE_SET, model.node_sets, "node set",
                [](const NodeSet& set) { return set.nodes.size(); });
    define_sets(EX_SIDE_SET, model.side_sets, "side set",
                [](const SideSet& set) { return set.sides.size(); });
    if (define) define(exo);

    fill_holes(exo, temp, target);
    // Coordinates and connectivity in slices, so that writing adds a few MiB beside the model
    // instead of a copy of it (on a conform run the write was the peak); each coordinate whole
    // before the next, in file order.
    std::vector<double> slice(std::min(kSlice, model.points.size()));
    for (int axis = 0; axis < 3; ++axis)
      for (std::size_t first = 0; first < model.points.size(); first += kSlice) {
        const std::size_t n = std::min(kSlice, model.points.size() - first);
        for (std::size_t i = 0; i < n; ++i) slice[i] = model.points[first + i][axis];
        const double* xyz[3] = {nullptr, nullptr, nullptr};
        xyz[axis] = slice.data();  // libexodusII skips a null component
        check(ex_put_partial_coord(exo, index_cast<int64_t>(first + 1), index_cast<int64_t>(n),
                                   xyz[0], xyz[1], xyz[2]),
              target, "writing coordinates");
      }
    for (const auto& entry : blocks) {
      const int id = entry.first;  // named: a lambda below reads them
      const BlockMembers& members = entry.second;
      const ExodusCell& cell = kExodusCells[static_cast<std::size_t>(members.kind)];
      std::vector<int> conn;
      // exodus_corner[order[c]] = model_corner[c]
      auto put = [&](const auto& cells) {
        constexpr std::size_t kCorners = std::tuple_size_v<std::decay_t<decltype(cells[0])>>;
        conn.resize(std::min(kSlice, members.size) * kCorners);
        std::size_t written = 0, n = 0;  // elements written, and in conn
        const auto flush = [&] {
          check(ex_put_partial_elem_conn(exo, id, index_cast<int64_t>(written + 1),
                                         index_cast<int64_t>(n), conn.data()),
                target, "writing block " + std::to_string(id) + " connectivity");
          written += n, n = 0;
        };
        for (const auto& [first, count] : members.runs)
          for (std::size_t e = first; e < first + count; ++e) {
            const auto& corners = cells[e];
            int* out = conn.data() + n * kCorners;
            for (std::size_t c = 0; c < kCorners; ++c) out[cell.order[c]] = corners[c] + 1;
            if (++n == kSlice) flush();
          }
        if (n > 0) flush();
      };
      with_cells(model, members.kind, put);
    }
    // A side's element by its 1-based file number: blocks in ascending id, each its runs in
    // order.
    std::map<std::pair<ElementKind, std::size_t>, std::size_t> run_start;  // (kind, first) -> no.
    if (!model.side_sets.empty()) {
      std::size_t next = 1;
      for (const auto& [id, members] : blocks)
        for (const auto& [first, count] : members.runs)
          run_start[{members.kind, first}] = next, next += count;
    }
    const auto file_number = [&](const ElementRef& e) {
      const auto at = index_cast<std::size_t>(e.index);
      const auto it = std::prev(run_start.upper_bound({e.kind, at}));
      return index_cast<int>(it->second + (at - it->first.second));
    };
    for (const NodeSet& set : model.node_sets) {
      std::vector<int> nodes;
      for (Index v : set.nodes) nodes.push_back(v + 1);
      if (!nodes.empty())
        check(ex_put_set(exo, EX_NODE_SET, set.id, nodes.data(), nullptr), target,
              "writing node set " + std::to_string(set.id));
    }
    for (const SideSet& set : model.side_sets) {
      std::vector<int> elems, sides;
      for (const Side& side : set.sides) {
        elems.push_back(file_number(side.element));
        sides.push_back(side.face + 1);
      }
      if (!elems.empty())
        check(ex_put_set(exo, EX_SIDE_SET, set.id, elems.data(), sides.data()), target,
              "writing side set " + std::to_string(set.id));
    }
    if (write_more) write_more(exo);
    check(file.close(), target, "closing the temporary file");
  });
}

std::string exodus_error_cause() { return exodus_library::exodus_cause(); }

}  // namespace geode::io
