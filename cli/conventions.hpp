#pragma once
// What every `geode` command shares, so that all of them speak one way (cli/commands.hpp):
//
// - Exit codes: 0 done, 2 usage or input error, 3 topology refusal, 4 invalid result (main.cpp
//   maps InvalidInput, TopologyError and InvalidResult). Every error is one line on stderr.
// - Numbers: number_check() for every numeric option (finite, in range, one-line message);
//   parse_box() for WIDTHxHEIGHT[xDEPTH] with the dimension count the command needs.
// - Outputs: output_format() picks the format from the extension (a --format that contradicts
//   it is refused), check_output_path() refuses a missing or unwritable directory before any
//   work, OutputFiles writes several outputs as one (all or none); io::write_model writes a
//   model in any mesh format of the format table (io/formats.hpp).
//
// Output formats: the mesh formats of io/formats.hpp (mesh_format_names(), their extensions
// there), and the text formats a command may add: json .json, spec .json, csv .csv, appendix
// .txt, text .txt, html .html .htm.
#include <CLI/CLI.hpp>
#include <array>
#include <filesystem>
#include <functional>
#include <limits>
#include <nlohmann/json_fwd.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <geode/io/atomic_file.hpp>
#include <geode/io/formats.hpp>
#include <geode/primal/mesh.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/unfold.hpp>

namespace geode::cli {

// The result was computed but fails verification (e.g. inverted hexes): exit 4. The message
// is printed even with --quiet.
struct InvalidResult : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "geode 0.1.0" (CMake's project version).
std::string version_text();
// `s` on one line (CLI11's messages may span several): line breaks as spaces, no trailing ones.
std::string one_line(std::string s);
// An empty argument (-o "", --report=) is refused (CLI::ValidationError naming the option):
// CLI11 takes it as the option not given. Call before parsing.
void refuse_empty_arguments(int argc, char** argv);

// ---- Numbers ----------------------------------------------------------------------------------

// A CLI11 check: the text is a finite number in [lo, hi] (an integer when `integer`). The
// message is one line ("-n: 0 is out of range [1, 64]"), unlike CLI11's ranges, which print
// the limits of double.
CLI::Validator number_check(double lo = std::numeric_limits<double>::lowest(),
                            double hi = std::numeric_limits<double>::max(), bool integer = false);

// --buffer-thickness against --buffer-side's maximum (conform::max_buffer_thickness), before
// any work: InvalidInput "--buffer-thickness 0.6 with --buffer-side tet: at most 0.45". `geode
// conform` and `geode_mpi conform` (which compiles this file too) check it alike; an empty side
// (not given) is the hex side's.
void check_buffer_thickness(double thickness, const std::string& side);

// "24x14x24" (dim 3) or "24x14" (dim 2): exactly `dim` finite numbers, each in [1e-6, 1e6] and
// the largest at most 1e4 times the smallest (a flatter box is degenerate for the templates).
// InvalidInput naming `option` otherwise. A 2D box gets depth = width.
std::array<double, 3> parse_box(const std::string& option, const std::string& text, int dim);

// --join-blocks A,B[,...] (conform, geode_mpi; repeatable): input blocks that are one material
// (primal::join_blocks). The option checks each value's form; join_block_lists applies them to
// the model read from `source`, whose messages name it.
CLI::Option* add_join_blocks_option(CLI::App* app, std::vector<std::string>& lists);
void join_block_lists(primal::Model& model, const std::vector<std::string>& lists,
                      const std::string& source);

// --unfold (conform, geode_mpi): tets and pyramids a mesher folded or wrote inverted, mended by
// primal::unfold before the covering check. The stage line ("unfold: 1 pyramid turned back, 0
// tets read inverted mended", or that nothing was) and the warning naming the cells and the
// nodes moved (without "warning: ").
CLI::Option* add_unfold_option(CLI::App* app, bool& unfold);
std::string unfold_stage(const primal::UnfoldResult& result);
std::string unfold_warning(const primal::Model& model, const primal::UnfoldResult& result);

// ---- Outputs ----------------------------------------------------------------------------------

// The format of output `path`: the format its extension names among `allowed` (a given
// `format` must agree), or `format` when the path has no known extension and `format` is a text
// format, or `fallback` for standard output (empty path or "-"). InvalidInput (exit 2) for a
// contradiction, an extension no allowed format has, or a mesh format without a file.
std::string output_format(const std::string& path, const std::string& format,
                          const std::vector<std::string>& allowed, const std::string& fallback);

// Whether a format name is one of the mesh formats (exo, msh, msh22, vtu, vtk).
bool is_mesh_format(const std::string& format);

// The output can be written: not a directory, its directory exists and is writable. Call it
// before any long work; InvalidInput naming the path otherwise. Empty and "-" pass.
void check_output_path(const std::string& path);

// An output that is the input itself (the same file, also through links) would destroy it:
// InvalidInput naming both unless `force` (--force). Paths that do not exist yet pass.
void check_not_input(const std::string& output, const std::string& input, bool force);
// The same for a command without --force (check, view): always refused, the message without
// the --force hint.
void check_not_input(const std::string& output, const std::string& input);
CLI::Option* add_force_flag(CLI::App* app, bool& flag);
// Outputs given as (option, path): two that are the same file (also through links) would
// overwrite one another: InvalidInput naming both options. Empty paths and "-" pass.
void check_distinct_outputs(const std::vector<std::pair<std::string, std::string>>& outputs);

// The mesh formats every command that writes a mesh offers (io/formats.hpp), in table order:
// exo, msh, msh22, vtu, vtk. quads: those that write planar quad meshes.
std::vector<std::string> mesh_format_names(bool quads = false);
// `before`, the mesh formats, then `after`: a command's --format choices.
std::vector<std::string> with_mesh_formats(std::vector<std::string> before,
                                           const std::vector<std::string>& after = {});
// For help texts, from the format table: "exo (Exodus II, .exo .e), msh (Gmsh .msh 4.1 ASCII,
// .msh), ..." and the extensions read ".exo, .e, .msh, .vtu, .vtk".
std::string mesh_formats_help(bool quads = false);
std::string input_extensions_help();
// "All-hex mesh (.exo, .e, .msh, .vtu, .vtk) or planar quad mesh in z = 0 (.vtu, .vtk)".
std::string hex_or_quad_input_help();
// ".vtu or .vtk": where a planar quad mesh can be written.
std::string quad_output_extensions();
// --vtk-encoding and --msh-encoding (binary, ascii), for every command that writes a mesh.
struct EncodingArgs {
  std::string vtk = "binary";
  std::string msh = "ascii";
};
void add_encoding_options(CLI::App* app, EncodingArgs& args);
io::WriteOptions write_options(const EncodingArgs& args);

// ---- Validity before writing -----------------------------------------------------------------

// The one check every derived mesh goes through before it is written (primal/validity.hpp
// check_validity: faces shared by two cells, manifold, closed boundary, positive corners, every
// node covered once): "" when valid, else one line of what is wrong, elements and nodes numbered
// from `base` as the output will number them (1: appendix, csv, json, .msh, .exo; 0: .vtu, .vtk).
std::string invalid_mesh_reason(const primal::HexMesh& mesh, primal::Index base);
std::string invalid_mesh_reason(const primal::QuadMesh& mesh, primal::Index base);
// The numbering base of a format's node and element ids (0 for vtu and vtk, else 1).
primal::Index output_index_base(const std::string& format);

// Before writing `what` (e.g. "the rebuilt mesh"): nothing when `reason` is empty; InvalidResult
// (exit 4, nothing written) unless `write_invalid`, which lets the caller write it and then call
// invalid_written (InvalidResult again: the exit code stays 4, the output is there).
void refuse_invalid(const std::string& what, const std::string& reason, bool write_invalid);
void invalid_written(const std::string& what, const std::string& reason);

// The same --write-invalid flag on every command that writes a mesh.
CLI::Option* add_write_invalid_flag(CLI::App* app, bool& flag);
// --quiet of a command whose output is its report (check, dual, view): no progress lines on
// stderr; the report, errors and warnings still print.
CLI::Option* add_quiet_flag(CLI::App* app, bool& flag);
// JSON as every command writes it (reports, tables): a file name that is not UTF-8 (Linux names
// are bytes) is written with U+FFFD in its place, as JSON text must be UTF-8, instead of the
// library's exception failing the whole run.
std::string json_text(const nlohmann::json& j, int indent);
// Why a std::bad_alloc ended a run: "the input needs more memory than this machine gives", or,
// under an address-space limit (ulimit -v), "... than this process may use (ulimit -v: N MiB)".
std::string out_of_memory_reason();
// A stage's progress line as every command says it when the stage ends: "LINE (S.S s)".
std::string stage_line(const std::string& line, double seconds);

// Standard output flushed: "" when everything printed so far went out, else why not ("writing
// standard output failed: No space left on device"). The failed text is dropped, so that the
// exit path (main.cpp) does not report it a second time.
std::string standard_output_failure();
// InvalidInput (exit 2) with standard_output_failure() when it is not empty. OutputFiles::commit
// calls it before publishing, and a command prints its summary before it publishes: a summary
// lost (stdout closed, a full disk behind `> log`) fails the run with nothing published, instead
// of files left in place by a run that exits 2.
void require_standard_output();

// Several outputs written as one: each goes to a temporary file next to its target (same
// extension, so writers that go by it still work; registered for removal on signals), and only
// when all are written are they renamed over their targets (through symbolic links; copied into
// a target that is not a regular file, e.g. a device). If any write fails, every temporary is
// removed and nothing is written; if a rename fails or a signal comes between two renames, the
// targets already replaced get their former content back (io::publish_together: never half a
// result). commit() publishes nothing when what the command printed before it on standard output
// was lost (require_standard_output).
class OutputFiles {
 public:
  using Writer = std::function<void(const std::filesystem::path& temp)>;
  // Returns the output's number, for write().
  std::size_t add(const std::filesystem::path& target, Writer write);
  // Writes output `i` to its temporary now, once (commit() then publishes it as it is); a
  // failure leaves nothing behind, as commit()'s.
  void write(std::size_t i);
  void commit();
  // Removes the temporaries written so far, as the destructor does (for a process about to end
  // without running destructors: geode_mpi's abort).
  void discard();
  ~OutputFiles();

 private:
  struct Entry {
    std::filesystem::path target;  // as given
    io::OutputTarget resolved;     // symbolic links followed
    std::filesystem::path temp;
    Writer write;
    bool written = false;
  };
  std::vector<Entry> entries_;
  std::vector<std::filesystem::path> pending_;  // temporaries to remove on failure
};

}  // namespace geode::cli
