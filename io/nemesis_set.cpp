#include <geode/io/nemesis_set.hpp>

#include <algorithm>
#include <charconv>
#include <map>
#include <set>
#include <string>
#include <string_view>

#include <geode/io/exodus.hpp>
#include <geode/io/names.hpp>
#include <geode/primal/errors.hpp>

namespace geode::io {

using namespace primal;
namespace fs = std::filesystem;

namespace {

// A decimal number of 1..9 digits without a sign, else nullopt.
std::optional<int> decimal(std::string_view s) {
  int v = 0;
  if (s.empty() || s.size() > 9) return std::nullopt;
  const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
  if (res.ec != std::errc() || res.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

// "NAME.N.r" -> (N, r) when r < N and r is zero-padded to N's digits (the set's naming).
std::optional<std::pair<int, int>> piece_suffix(std::string_view name, std::string_view base) {
  if (name.size() <= base.size() + 1 || name.substr(0, base.size()) != base ||
      name[base.size()] != '.')
    return std::nullopt;
  const std::string_view rest = name.substr(base.size() + 1);
  const auto dot = rest.find('.');
  if (dot == std::string_view::npos) return std::nullopt;
  const auto n = decimal(rest.substr(0, dot)), r = decimal(rest.substr(dot + 1));
  if (!n || !r || *n < 1 || *r >= *n || rest.size() - dot - 1 != rest.substr(0, dot).size())
    return std::nullopt;
  return std::pair{*n, *r};
}

fs::path piece_path(const fs::path& base, int pieces, int piece) {
  const std::string n = std::to_string(pieces);
  std::string r = std::to_string(piece);
  r.insert(0, n.size() - r.size(), '0');
  return base.string() + "." + n + "." + r;
}

NemesisSet make_set(const fs::path& base, int pieces) {
  if (pieces > kMaxNemesisPieces)
    throw InvalidInput(base.string() + "." + std::to_string(pieces) + ".*: a Nemesis set of " +
                       std::to_string(pieces) + " pieces, more than " +
                       std::to_string(kMaxNemesisPieces) + " are not read");
  NemesisSet set{base, {}};
  for (int r = 0; r < pieces; ++r) {
    set.files.push_back(piece_path(base, pieces, r));
    std::error_code ec;
    if (!fs::is_regular_file(set.files.back(), ec))
      throw InvalidInput(set.files.back().string() + ": missing (piece " + std::to_string(r) +
                         " of the Nemesis set " + base.string() + "." + std::to_string(pieces) +
                         ".*, " + std::to_string(pieces) + " pieces)");
  }
  return set;
}

// What each piece gives the joined model.
struct Slot {
  int piece = -1;
  ElementRef element;
};

class SetReader {
 public:
  SetReader(const NemesisSet& set, FilePartition* partition) : set_(set), partition_(partition) {}

  Model read() {
    const int n = index_cast<int>(set_.files.size());
    pieces_.resize(set_.files.size());
    std::vector<NemesisInfo> info(set_.files.size());
    std::int64_t local_nodes = 0, local_elements = 0;
    for (std::size_t p = 0; p < set_.files.size(); ++p) {
      // Geometry is checked once, on the joined model.
      pieces_[p] = read_exodus_piece(set_.files[p], {.check_geometry = false, .inverted_hint = {}},
                                     &info[p]);
      const std::string file = set_.files[p].string();
      if (info[p].processors == 0)
        throw InvalidInput(file + ": no Nemesis I counts (not a piece of a partitioned set)");
      if (info[p].processors != n)
        throw InvalidInput(file + ": a piece of " + std::to_string(info[p].processors) +
                           " processors in a set of " + std::to_string(n) + " files");
      if (info[p].global_nodes != info[0].global_nodes ||
          info[p].global_elements != info[0].global_elements)
        throw InvalidInput(file + ": global counts " + std::to_string(info[p].global_nodes) +
                           " nodes, " + std::to_string(info[p].global_elements) +
                           " elements differ from " + set_.files[0].string() + "'s " +
                           std::to_string(info[0].global_nodes) + " and " +
                           std::to_string(info[0].global_elements));
      local_nodes += index_cast<std::int64_t>(pieces_[p].points.size());
      local_elements += index_cast<std::int64_t>(element_count(pieces_[p]));
    }
    // Every global node and element is in a piece: the global counts are bounded by what the
    // pieces hold before anything of that size is allocated.
    if (info[0].global_nodes < 0 || info[0].global_nodes > local_nodes ||
        info[0].global_elements < 0 || info[0].global_elements > local_elements ||
        info[0].global_nodes >= INT32_MAX || info[0].global_elements >= INT32_MAX)
      throw InvalidInput(
          set_.files[0].string() + ": global counts " + std::to_string(info[0].global_nodes) +
          " nodes, " + std::to_string(info[0].global_elements) +
          " elements, more than the set's pieces hold (" + std::to_string(local_nodes) +
          " nodes, " + std::to_string(local_elements) + " elements)");
    Model model;
    join_nodes(model, index_cast<std::size_t>(info[0].global_nodes));
    join_elements(model, index_cast<std::size_t>(info[0].global_elements));
    join_sets(model);
    sanitize_names(model);
    validate(model, set_.name());
    return model;
  }

 private:
  std::string file(std::size_t p) const { return set_.files[p].string(); }

  void join_nodes(Model& model, std::size_t count) {
    model.points.resize(count);
    std::vector<int> from(count, -1);  // the first piece giving each node
    node_index_.resize(pieces_.size());
    for (std::size_t p = 0; p < pieces_.size(); ++p) {
      const Model& m = pieces_[p];
      for (std::size_t i = 0; i < m.points.size(); ++i) {
        const std::int64_t gid = node_id(m, index_cast<Index>(i));
        if (gid < 1 || gid > index_cast<std::int64_t>(count))
          throw InvalidInput(file(p) + ": node " + std::to_string(i + 1) + ": global id " +
                             std::to_string(gid) + " out of range [1, " + std::to_string(count) +
                             "]");
        const auto g = index_cast<std::size_t>(gid - 1);
        if (from[g] < 0) {
          from[g] = static_cast<int>(p);
          model.points[g] = m.points[i];
        } else if (model.points[g] != m.points[i]) {
          throw InvalidInput(file(p) + ": global node " + std::to_string(gid) + " is at " +
                             point_text(m.points[i]) + ", in " +
                             file(index_cast<std::size_t>(from[g])) + " at " +
                             point_text(model.points[g]));
        }
        node_index_[p].push_back(index_cast<Index>(g));
      }
    }
    const auto missing = std::find(from.begin(), from.end(), -1);
    if (missing != from.end())
      throw InvalidInput(set_.name() + ": global node " +
                         std::to_string(missing - from.begin() + 1) + " is in no piece of " +
                         std::to_string(pieces_.size()));
    model.node_ids.resize(count);
    for (std::size_t g = 0; g < count; ++g) model.node_ids[g] = index_cast<std::int64_t>(g + 1);
  }

  void join_elements(Model& model, std::size_t count) {
    std::vector<Slot> slot(count);
    for (std::size_t p = 0; p < pieces_.size(); ++p)
      for (ElementKind kind : kElementKinds)
        for (std::size_t e = 0; e < element_count(pieces_[p], kind); ++e) {
          const ElementRef ref{kind, index_cast<Index>(e)};
          const std::int64_t gid = element_id(pieces_[p], ref);
          if (gid < 1 || gid > index_cast<std::int64_t>(count))
            throw InvalidInput(file(p) + ": element " + std::to_string(gid) +
                               ": global id out of range [1, " + std::to_string(count) + "]");
          Slot& s = slot[index_cast<std::size_t>(gid - 1)];
          if (s.piece >= 0)
            throw InvalidInput(file(p) + ": element " + std::to_string(gid) + " is also in " +
                               file(index_cast<std::size_t>(s.piece)));
          s = {static_cast<int>(p), ref};
        }
    for (std::size_t g = 0; g < count; ++g)
      if (slot[g].piece < 0)
        throw InvalidInput(set_.name() + ": global element " + std::to_string(g + 1) +
                           " is in no piece of " + std::to_string(pieces_.size()));
    // By kind, then ascending global id.
    element_index_.resize(pieces_.size());
    for (std::size_t p = 0; p < pieces_.size(); ++p)
      for (ElementKind kind : kElementKinds)
        element_index_[p][static_cast<std::size_t>(kind)].resize(element_count(pieces_[p], kind));
    if (partition_) *partition_ = {index_cast<int>(pieces_.size()), {}};
    for (ElementKind kind : kElementKinds)
      for (std::size_t g = 0; g < count; ++g) {
        const Slot& s = slot[g];
        if (s.element.kind != kind) continue;
        const auto p = index_cast<std::size_t>(s.piece);
        const Model& m = pieces_[p];
        std::array<Index, 8> corners{};
        const auto local = element_corners(m, s.element);
        for (std::size_t k = 0; k < local.size(); ++k)
          corners[k] = node_index_[p][index_cast<std::size_t>(local[k])];
        const int block = element_blocks(m, kind).empty()
                              ? default_block(kind)
                              : element_blocks(m, kind)[index_cast<std::size_t>(s.element.index)];
        element_index_[p][static_cast<std::size_t>(kind)]
                      [index_cast<std::size_t>(s.element.index)] =
                          index_cast<Index>(element_count(model, kind));
        add_element(model, kind, corners, block, index_cast<std::int64_t>(g + 1));
        if (partition_) partition_->part.push_back(s.piece);
      }
    for (std::size_t p = 0; p < pieces_.size(); ++p)
      for (const auto& [id, name] : pieces_[p].block_names) agree(kBlock, id, name, p);
    for (const auto& [id, name] : names_[kBlock]) model.block_names[id] = name;
  }

  // Two pieces naming one block or set differently: an inconsistent set.
  enum Named : std::size_t { kBlock, kNodeSet, kSideSet };
  void agree(Named k, int id, const std::string& name, std::size_t p) {
    static constexpr std::array<const char*, 3> kWhat{"element block", "node set", "side set"};
    const auto [it, fresh] = names_[k].emplace(id, name);
    if (fresh) {
      named_by_[k][id] = p;
    } else if (it->second != name) {
      throw InvalidInput(file(p) + ": " + kWhat[k] + " " + std::to_string(id) + " is named '" +
                         name + "', in " + file(named_by_[k][id]) + " '" + it->second + "'");
    }
  }

  void join_sets(Model& model) {
    std::map<int, NodeSet> node_sets;
    std::map<int, SideSet> side_sets;
    for (std::size_t p = 0; p < pieces_.size(); ++p) {
      for (const NodeSet& s : pieces_[p].node_sets) {
        agree(kNodeSet, s.id, s.name, p);
        NodeSet& out = node_sets[s.id];
        out.id = s.id, out.name = s.name;
        for (Index v : s.nodes) out.nodes.push_back(node_index_[p][index_cast<std::size_t>(v)]);
      }
      for (const SideSet& s : pieces_[p].side_sets) {
        agree(kSideSet, s.id, s.name, p);
        SideSet& out = side_sets[s.id];
        out.id = s.id, out.name = s.name;
        for (const Side& side : s.sides) {
          const ElementRef e{side.element.kind,
                             element_index_[p][static_cast<std::size_t>(side.element.kind)]
                                           [index_cast<std::size_t>(side.element.index)]};
          out.sides.push_back({e, side.face});
        }
      }
    }
    for (auto& [id, s] : node_sets) {
      std::sort(s.nodes.begin(), s.nodes.end());
      s.nodes.erase(std::unique(s.nodes.begin(), s.nodes.end()), s.nodes.end());
      model.node_sets.push_back(std::move(s));
    }
    for (auto& [id, s] : side_sets) {
      std::sort(s.sides.begin(), s.sides.end());
      s.sides.erase(std::unique(s.sides.begin(), s.sides.end()), s.sides.end());
      model.side_sets.push_back(std::move(s));
    }
  }

  const NemesisSet& set_;
  FilePartition* partition_;
  std::vector<Model> pieces_;
  std::vector<std::vector<Index>> node_index_;                    // per piece: node -> joined
  std::vector<std::array<std::vector<Index>, 4>> element_index_;  // per piece and kind
  std::array<std::map<int, std::string>, 3> names_;  // blocks, node sets, side sets by id
  std::array<std::map<int, std::size_t>, 3> named_by_;
};

}  // namespace

std::optional<NemesisSet> find_nemesis_set(const fs::path& path) {
  const std::string name = path.filename().string();
  // A piece named: IN.exo.N.r.
  const auto last = name.rfind('.');
  if (last != std::string::npos && last > 0) {
    const auto second = name.rfind('.', last - 1);
    if (second != std::string::npos && second > 0) {
      const std::string base = name.substr(0, second);
      if (const auto nr = piece_suffix(name, base))
        return make_set(path.parent_path() / base, nr->first);
    }
  }
  std::error_code ec;
  if (fs::exists(path, ec) || name.empty()) return std::nullopt;
  // IN.exo absent: the pieces beside it.
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  std::set<int> counts;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (const auto nr = piece_suffix(it->path().filename().string(), name))
      counts.insert(nr->first);
  if (counts.empty()) return std::nullopt;
  if (counts.size() > 1)
    throw InvalidInput(path.string() + ": missing, and pieces of " + std::to_string(counts.size()) +
                       " Nemesis sets lie beside it (" + path.string() + "." +
                       std::to_string(*counts.begin()) + ".*, " + path.string() + "." +
                       std::to_string(*counts.rbegin()) + ".*): name one piece of the set to read");
  return make_set(path, *counts.begin());
}

Model read_nemesis_set(const NemesisSet& set, const ReadOptions& options,
                       FilePartition* partition) {
  Model model = SetReader(set, partition).read();
  options.check_geometry ? check_geometry(model, set.name(), options.inverted_hint)
                         : check_points(model, set.name());
  return model;
}

}  // namespace geode::io
