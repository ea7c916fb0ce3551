// Conventions shared by every command (cli/conventions.hpp).
#include "cli/conventions.hpp"

#include <stdio_ext.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string_view>

#include <geode/conform/buffer_layer.hpp>
#include <geode/io/atomic_file.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/validity.hpp>
#include <geode/templates/template_table.hpp>
#include "cli/commands.hpp"

#ifndef GEODE_VERSION
#define GEODE_VERSION "unknown"
#endif

namespace geode::cli {

namespace fs = std::filesystem;

std::string version_text() { return std::string("geode ") + GEODE_VERSION; }

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

namespace {

// Shortest text of a limit for messages ("64", "1e+06").
std::string short_number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// The whole text as a finite double, or nothing.
std::optional<double> finite_number(const std::string& text) {
  double x = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, x);
  if (ec != std::errc() || ptr != end || !std::isfinite(x)) return std::nullopt;
  return x;
}

struct FormatInfo {
  std::string name;
  std::vector<std::string> extensions;
  bool mesh;
  bool file_only = false;  // not written to standard output (a mesh's is binary or too large)
};

// The mesh formats that write (io/formats.hpp), then the text formats of the commands.
const std::vector<FormatInfo>& formats() {
  static const std::vector<FormatInfo> table = [] {
    std::vector<FormatInfo> t;
    for (const io::MeshFormat& f : io::mesh_formats())
      if (f.write)
        t.push_back({std::string(f.name), {f.extensions.begin(), f.extensions.end()}, true, true});
    for (FormatInfo text : std::vector<FormatInfo>{{"json", {".json"}, false},
                                                   {"spec", {".json"}, false},
                                                   {"csv", {".csv"}, false},
                                                   {"appendix", {".txt"}, false},
                                                   {"text", {".txt"}, false},
                                                   {"html", {".html", ".htm"}, false, true}})
      t.push_back(std::move(text));
    return t;
  }();
  return table;
}

const FormatInfo* find_format(const std::string& name) {
  for (const auto& f : formats())
    if (name == f.name) return &f;
  return nullptr;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

}  // namespace

CLI::Validator number_check(double lo, double hi, bool integer) {
  return CLI::Validator(
      [lo, hi, integer](std::string& text) -> std::string {
        const auto x = finite_number(text);
        if (!x) return "'" + text + "' is not a finite number";
        if (integer && *x != std::floor(*x)) return "'" + text + "' is not a whole number";
        if (*x < lo || *x > hi)
          return text + " is out of range [" + short_number(lo) + ", " + short_number(hi) + "]";
        return {};
      },
      integer ? "INT" : "NUMBER");
}

void check_buffer_thickness(double thickness, const std::string& side) {
  if (const double most = conform::max_buffer_thickness(
          side.empty() ? conform::BufferSide::kHex : conform::parse_buffer_side(side));
      thickness > most) {
    std::ostringstream m;
    m << "--buffer-thickness " << thickness << " with --buffer-side "
      << (side.empty() ? "hex" : side) << ": at most " << most;
    throw InvalidInput(m.str());
  }
}

std::array<double, 3> parse_box(const std::string& option, const std::string& text, int dim) {
  const std::string expected =
      dim == 3 ? "WIDTHxHEIGHTxDEPTH such as 24x14x24" : "WIDTHxHEIGHT such as 24x14";
  std::vector<std::string> parts;
  std::string part;
  for (char c : text) {
    if (c == 'x' || c == 'X') {
      parts.push_back(part);
      part.clear();
    } else {
      part += c;
    }
  }
  parts.push_back(part);
  if (primal::index_cast<int>(parts.size()) != dim)
    throw InvalidInput(option + " '" + text + "': " + std::to_string(parts.size()) + " number" +
                       (parts.size() == 1 ? "" : "s") + " for a " + std::to_string(dim) +
                       "D template; expected " + expected);
  std::array<double, 3> box{};
  for (int a = 0; a < dim; ++a) {
    const auto x = finite_number(parts[primal::index_cast<std::size_t>(a)]);
    if (!x)
      throw InvalidInput(option + " '" + text + "': '" + parts[primal::index_cast<std::size_t>(a)] +
                         "' is not a finite number; expected " + expected);
    box[primal::index_cast<std::size_t>(a)] = *x;
  }
  if (const std::string why =
          templates::box_problem(std::span(box.data(), primal::index_cast<std::size_t>(dim)));
      !why.empty())
    throw InvalidInput(option + " '" + text + "': " + why);
  if (dim == 2) box[2] = box[0];
  return box;
}

bool is_mesh_format(const std::string& format) {
  const FormatInfo* f = find_format(format);
  return f && f->mesh;
}

std::string output_format(const std::string& path, const std::string& format,
                          const std::vector<std::string>& allowed, const std::string& fallback) {
  if (!format.empty() && std::find(allowed.begin(), allowed.end(), format) == allowed.end())
    throw InvalidInput("--format " + format + ": expected one of " + join(allowed));
  if (path.empty() || path == "-") {
    const std::string f = format.empty() ? fallback : format;
    const FormatInfo* info = find_format(f);
    if (path == "-" && (!info || info->file_only))  // no fallback: a mesh
      throw InvalidInput("'-': " + (f.empty() ? std::string("a mesh") : "--format " + f) +
                         " is written to a file, not to standard output");
    if (is_mesh_format(f)) throw InvalidInput("--format " + f + " needs -o FILE");
    return f;
  }
  const std::string e = file_extension(path);
  std::vector<std::string> by_extension, extensions;
  for (const auto& name : allowed) {
    const FormatInfo* f = find_format(name);
    if (!f) continue;
    for (const auto& x : f->extensions) {
      if (std::find(extensions.begin(), extensions.end(), x) == extensions.end())
        extensions.push_back(x);
      if (x == e) by_extension.push_back(name);
    }
  }
  if (by_extension.empty()) {
    // A text format may go to a file of any other name (report.out); a mesh needs its extension.
    bool known_elsewhere = false;
    for (const auto& f : formats())
      known_elsewhere |=
          std::find(f.extensions.begin(), f.extensions.end(), e) != f.extensions.end();
    if (!format.empty() && !is_mesh_format(format) && !known_elsewhere) return format;
    if (e.empty())  // /dev/stdout, a name without extension: say how to get there
      throw InvalidInput(path + ": no extension, which tells the output format (expected " +
                         join(extensions) +
                         "; to write to standard output, give a link to /dev/stdout such as "
                         "out.vtk)");
    throw InvalidInput(path + ": unknown output format '" + e + "' (expected " + join(extensions) +
                       ")");
  }
  if (format.empty()) return by_extension.front();  // .msh: msh (4.1) before msh22
  if (std::find(by_extension.begin(), by_extension.end(), format) == by_extension.end())
    throw InvalidInput(path + ": --format " + format + " contradicts the extension '" + e + "' (" +
                       join(by_extension) + ")");
  return format;
}

void check_output_path(const std::string& path) {
  if (path.empty() || path == "-") return;
  const fs::path p(path);
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw InvalidInput(path + ": is a directory, not an output file");
  // A device or FIFO (/dev/null; /dev/stdout, a link to "pipe:[N]" when it is a pipe) gets the
  // finished file copied into it (io/atomic_file.hpp): its own permission is what counts, and
  // the temporary's directory, probed below.
  const fs::file_status st = fs::status(p, ec);
  const bool device = !ec && fs::exists(st) && !fs::is_regular_file(st);
  if (device && ::access(p.c_str(), W_OK) != 0)
    throw InvalidInput(path + ": exists and is not writable");
  // A symbolic link is written through (its temporary beside the file it names): that file's
  // directory is the one to check (a dangling link into a missing one failed after the work).
  fs::path real = p;
  for (int hops = 0; hops < 40 && fs::is_symlink(real, ec); ++hops) {  // 40: Linux's own bound
    const fs::path target = fs::read_symlink(real, ec);
    if (ec) break;
    real = target.is_absolute() ? target : real.parent_path() / target;
  }
  if (fs::is_symlink(real, ec))  // a loop: refused now, not after the work
    throw InvalidInput(path + ": too many levels of symbolic links");
  if (device) {
    io::remove_temporary(io::create_temporary(io::resolve_output(p), p.extension().string()));
    return;
  }
  const fs::path dir = real.parent_path().empty() ? fs::path(".") : real.parent_path();
  if (!fs::is_directory(dir, ec))
    throw InvalidInput(path + ": directory " + dir.string() +
                       (ec && ec != std::errc::no_such_file_or_directory ? ": " + ec.message()
                                                                         : " does not exist"));
  // A name longer than the file system takes failed only when the temporary was renamed.
  const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  if (const auto n = real.filename().native().size();
      name_max > 0 && n > static_cast<std::size_t>(name_max))
    throw InvalidInput(path + ": file name too long (" + std::to_string(n) + " bytes, at most " +
                       std::to_string(name_max) + " here)");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw InvalidInput(path + ": directory " + dir.string() + " is not writable");
  if (fs::exists(p, ec) && ::access(p.c_str(), W_OK) != 0)
    throw InvalidInput(path + ": exists and is not writable");
  // The rest the write needs (the temporary's path within PATH_MAX too, a file system that takes
  // new files): a temporary made and removed now, not found after the work.
  io::remove_temporary(io::create_temporary(io::resolve_output(p), p.extension().string()));
}

namespace {

void refuse_input_as_output(const std::string& output, const std::string& input, const char* hint) {
  if (output.empty() || output == "-" || input.empty()) return;
  std::error_code ec;
  if (fs::equivalent(output, input, ec) && !ec)
    throw InvalidInput(output + ": is the input file " + input +
                       "; writing it would destroy the input" + hint);
}

}  // namespace

void check_not_input(const std::string& output, const std::string& input, bool force) {
  if (!force) refuse_input_as_output(output, input, " (--force overwrites it)");
}

void check_not_input(const std::string& output, const std::string& input) {
  refuse_input_as_output(output, input, "");
}

namespace {
// "5,6,7" as block ids; empty when it is not two or more positive integers.
std::vector<int> block_ids(const std::string& text) {
  std::vector<int> ids;
  for (std::size_t at = 0; at <= text.size();) {
    const std::size_t end = std::min(text.find(',', at), text.size());
    int id = 0;
    const auto [ptr, ec] = std::from_chars(text.data() + at, text.data() + end, id);
    if (ec != std::errc() || ptr != text.data() + end || id < 1) return {};
    ids.push_back(id);
    at = end + 1;
  }
  return ids.size() >= 2 ? ids : std::vector<int>{};
}

// "2 tets and 1 pyramid", "1 tet", "0 tets": cells counted by kind (tets and pyramids).
std::string counted_cells(const std::vector<primal::ElementRef>& cells) {
  std::size_t tets = 0, pyramids = 0;
  for (const primal::ElementRef& e : cells)
    ++(e.kind == primal::ElementKind::kPyramid ? pyramids : tets);
  const auto counted = [](std::size_t n, const char* what) {
    return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
  };
  if (pyramids == 0) return counted(tets, "tet");
  return tets == 0 ? counted(pyramids, "pyramid")
                   : counted(tets, "tet") + " and " + counted(pyramids, "pyramid");
}

}  // namespace

CLI::Option* add_unfold_option(CLI::App* app, bool& unfold) {
  return app->add_flag(
      "--unfold", unfold,
      "turn back tets and pyramids a mesher folded over their neighbours (Gmsh 4.8 near its\n"
      "pyramids: a cell written positive lying on the same side of its faces as every\n"
      "neighbour) and move one free node of each (a pyramid's apex) into its cells; tets and\n"
      "pyramids written inverted get a node moved the same way (the geometry check runs\n"
      "after); only where that mends every one; warns naming the nodes moved");
}

std::string unfold_stage(const primal::UnfoldResult& result) {
  if (!result.unfolded())
    return result.covered_once ? "unfold: nothing to mend"
                               : "unfold: not every fault can be mended: the model left as read";
  return "unfold: " + counted_cells(result.turned) + " turned back, " +
         counted_cells(result.inverted) + " read inverted mended";
}

std::string unfold_warning(const primal::Model& model, const primal::UnfoldResult& result) {
  std::string what;
  if (!result.turned.empty())
    what = counted_cells(result.turned) + " folded over " +
           (result.turned.size() == 1 ? "its" : "their") + " neighbours turned back";
  if (!result.inverted.empty())
    what += (what.empty() ? "" : ", ") + counted_cells(result.inverted) + " read inverted";
  if (result.moved.empty()) return "--unfold: " + what;  // node orders only
  std::string ids;
  for (std::size_t i = 0; i < result.moved.size() && i < 10; ++i)
    ids += (i ? " " : "") + std::to_string(primal::node_id(model, result.moved[i]));
  const bool one = result.moved.size() == 1;
  return "--unfold: " + what + ", node" + (one ? " " : "s ") + ids +
         (result.moved.size() > 10 ? " ..." : "") + " moved into " + (one ? "its" : "their") +
         " cells (by at most " + primal::number_text(result.farthest) + ")";
}

CLI::Option* add_join_blocks_option(CLI::App* app, std::vector<std::string>& lists) {
  return app
      ->add_option(
          "--join-blocks", lists,
          "A,B[,...]: input blocks that are one material, joined into block A (which keeps its\n"
          "name) before conforming, so that smoothing moves the faces between them; for files\n"
          "that keep a volume's element types apart, such as Cubit's Exodus blocks of tets and\n"
          "of pyramids (repeat the option for several materials; geode's own Exodus files are\n"
          "joined by themselves)")
      ->check(CLI::Validator(
          [](std::string& text) {
            return block_ids(text).empty()
                       ? "'" + text + "' is not two or more block ids separated by commas"
                       : std::string();
          },
          "A,B[,...]"))
      // One list per occurrence, so that `--join-blocks 5,6 in.exo` leaves in.exo the input.
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

void join_block_lists(primal::Model& model, const std::vector<std::string>& lists,
                      const std::string& source) {
  // A block an earlier list joined away has no element left: named as joined, not as missing.
  std::map<int, std::string> joined;  // block -> the list that joined it into another
  for (const std::string& list : lists) {
    const std::vector<int> ids = block_ids(list);
    for (int id : ids)
      if (const auto it = joined.find(id); it != joined.end())
        throw InvalidInput(source + ": joining blocks " + list + ": block " + std::to_string(id) +
                           " was joined into block " + it->second.substr(0, it->second.find(',')) +
                           " by --join-blocks " + it->second +
                           " before; give one list for one material");
    primal::join_blocks(model, ids, source);
    for (std::size_t i = 1; i < ids.size(); ++i) joined.emplace(ids[i], list);
  }
}

// An empty argument (-o "", --report=) was taken as the option not given: a path or name
// computed by a script that came out empty wrote nothing, or the default, with exit 0. Refused
// before parsing, as CLI11's usage errors are.
void refuse_empty_arguments(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (!arg.empty() && !(arg.starts_with("--") && arg.ends_with("=") && arg.size() > 3)) continue;
    const std::string option = !arg.empty() ? std::string(arg.substr(0, arg.size() - 1))
                               : i > 1 && argv[i - 1][0] == '-'
                                   ? std::string(argv[i - 1])
                                   : std::string("argument ") + std::to_string(i);
    throw CLI::ValidationError(option + ": an empty value (leave the option out instead)");
  }
}

void check_distinct_outputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i)
    for (std::size_t j = i + 1; j < outputs.size(); ++j) {
      const auto& [a, p] = outputs[i];
      const auto& [b, q] = outputs[j];
      if (p.empty() || q.empty() || p == "-" || q == "-") continue;
      std::error_code ec, ed;  // a path that cannot be resolved is left to the writer
      if (fs::weakly_canonical(p, ec) == fs::weakly_canonical(q, ed) && !ec && !ed)
        throw InvalidInput(q + ": given to both " + a + " and " + b +
                           ": one would overwrite the other");
    }
}

CLI::Option* add_force_flag(CLI::App* app, bool& flag) {
  return app->add_flag("--force", flag, "allow an output to overwrite the input file");
}

std::vector<std::string> mesh_format_names(bool quads) {
  return io::format_names(quads ? io::FormatRole::kWriteQuads : io::FormatRole::kWrite);
}

std::vector<std::string> with_mesh_formats(std::vector<std::string> before,
                                           const std::vector<std::string>& after) {
  for (const auto& f : mesh_format_names()) before.push_back(f);
  before.insert(before.end(), after.begin(), after.end());
  return before;
}

std::string mesh_formats_help(bool quads) {
  std::string s;
  for (const io::MeshFormat& f : io::mesh_formats()) {
    if (!(quads ? f.write_quads != nullptr : f.write != nullptr)) continue;
    std::string ext;
    for (std::string_view e : f.extensions) ext += " " + std::string(e);
    s += (s.empty() ? "" : ", ") + std::string(f.name) + " (" + std::string(f.title) + "," + ext +
         ")";
  }
  return s;
}

std::string input_extensions_help() {
  return io::extension_list(io::FormatRole::kRead, ", ", ", ");
}

std::string hex_or_quad_input_help() {
  return "All-hex mesh (" + input_extensions_help() + ") or planar quad mesh in z = 0 (" +
         io::extension_list(io::FormatRole::kReadQuads, ", ", ", ") + ")";
}

std::string quad_output_extensions() { return io::extension_list(io::FormatRole::kWriteQuads); }

void add_encoding_options(CLI::App* app, EncodingArgs& args) {
  app->add_option("--vtk-encoding,--vtu-encoding", args.vtk,
                  "binary (default) or ascii values in VTK files: .vtu DataArrays (base64), "
                  "legacy .vtk data (BINARY, big-endian)")
      ->check(CLI::IsMember({"binary", "ascii"}))
      ->capture_default_str();
  app->add_option("--msh-encoding", args.msh,
                  "ascii (default, as Gmsh saves; some solvers read only that) or binary .msh "
                  "(4.1 or 2.2;\nsmaller, and faster to write and read)")
      ->check(CLI::IsMember({"ascii", "binary"}))
      ->capture_default_str();
}

io::WriteOptions write_options(const EncodingArgs& args) {
  io::WriteOptions o;
  o.vtk_encoding = args.vtk == "ascii" ? io::VtkEncoding::kAscii : io::VtkEncoding::kBinary;
  o.msh_encoding = args.msh == "binary" ? io::GmshFormat::kBinary : io::GmshFormat::kAscii;
  return o;
}

std::string invalid_mesh_reason(const primal::HexMesh& mesh, primal::Index base) {
  const auto number = [base](primal::Index i) { return std::int64_t{i} + base; };
  return primal::findings(primal::check_validity(mesh), number, number);
}

std::string invalid_mesh_reason(const primal::QuadMesh& mesh, primal::Index base) {
  const auto number = [base](primal::Index i) { return std::int64_t{i} + base; };
  return primal::findings(primal::check_validity(mesh), number, number);
}

primal::Index output_index_base(const std::string& format) {
  return format == "vtu" || format == "vtk" ? 0 : 1;
}

void refuse_invalid(const std::string& what, const std::string& reason, bool write_invalid) {
  if (reason.empty() || write_invalid) return;
  throw InvalidResult(what + " is invalid: " + reason +
                      " (nothing written; --write-invalid writes it anyway)");
}

void invalid_written(const std::string& what, const std::string& reason) {
  if (reason.empty()) return;
  throw InvalidResult(what + " is invalid: " + reason + " (written anyway: --write-invalid)");
}

CLI::Option* add_quiet_flag(CLI::App* app, bool& flag) {
  return app->add_flag("-q,--quiet", flag,
                       "no progress on stderr (the output, errors and warnings still print)");
}

std::string json_text(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string out_of_memory_reason() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    return "the input needs more memory than this process may use (ulimit -v: " +
           std::to_string(limit.rlim_cur >> 20) + " MiB)";
  return "the input needs more memory than this machine gives";
}

std::string stage_line(const std::string& line, double seconds) {
  char tenths[32];
  std::snprintf(tenths, sizeof tenths, "%.1f", seconds);
  return line + " (" + tenths + " s)";
}

CLI::Option* add_write_invalid_flag(CLI::App* app, bool& flag) {
  return app->add_flag(
      "--write-invalid", flag,
      "write the mesh even when it fails the validity check (inverted or overlapping cells,\n"
      "faces not shared by two cells); the exit code is still 4. Without it an invalid mesh\n"
      "is not written");
}

std::string standard_output_failure() {
  errno = 0;
  std::cout.flush();
  const bool failed = !std::cout || std::fflush(stdout) != 0 || std::ferror(stdout);
  if (!failed) return {};
  const int e = errno;
  std::cout.clear();
  __fpurge(stdout);  // glibc <stdio_ext.h>: the text that could not go out, dropped
  std::clearerr(stdout);
  return std::string("writing standard output failed") +
         (e != 0 ? std::string(": ") + std::strerror(e) : std::string());
}

void require_standard_output() {
  if (std::string failure = standard_output_failure(); !failure.empty())
    throw InvalidInput(failure + " (nothing written)");
}

std::size_t OutputFiles::add(const fs::path& target, Writer write) {
  entries_.push_back({target, io::resolve_output(target), {}, std::move(write)});
  return entries_.size() - 1;
}

void OutputFiles::write(std::size_t i) {
  // Each output to a registered temporary (io/atomic_file.hpp: removed on signals too) with the
  // target's extension, for writers that go by it; a symbolic link is written through.
  Entry& e = entries_.at(i);
  if (e.written) return;
  e.temp = io::create_temporary(e.resolved, e.target.extension().string());
  pending_.push_back(e.temp);
  try {
    e.write(e.temp);
  } catch (const InvalidInput& error) {
    // Writers name the file they were given; the user gave the target, not our temporary.
    std::string what = error.what();
    const std::string temp = e.temp.string();
    for (auto at = what.find(temp); at != std::string::npos;
         at = what.find(temp, at + e.target.string().size()))
      what.replace(at, temp.size(), e.target.string());
    throw InvalidInput(what);
  }
  e.written = true;
}

void OutputFiles::commit() {
  for (std::size_t i = 0; i < entries_.size(); ++i) write(i);
  require_standard_output();
  // All renamed as one (io/atomic_file.hpp): a failure or a signal between two renames puts
  // back what the targets held, so a mesh never stands without its report.
  std::vector<io::Publication> items;
  for (const Entry& e : entries_) items.push_back({e.temp, e.resolved, e.target});
  io::publish_together(items);
  pending_.clear();
}

void OutputFiles::discard() {
  for (const auto& p : pending_) io::remove_temporary(p);
  pending_.clear();
}

OutputFiles::~OutputFiles() { discard(); }

}  // namespace geode::cli
