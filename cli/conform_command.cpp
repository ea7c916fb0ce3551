// geode conform INPUT: the geode algorithm on a whole hex + tet model; geode demo: the same on
// a demo model built with Gmsh (demo/demo_models).
#include <tbb/global_control.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <geode/conform/conform.hpp>
#include <geode/conform/reference_template.hpp>
#include <geode/conform/report.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/quality_report.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/unfold.hpp>
#include "cli/commands.hpp"
#include "cli/conventions.hpp"
#include "cli/demo_module.hpp"
#include "cli/progress.hpp"

namespace geode::cli {
namespace {

namespace fs = std::filesystem;

struct ConformArgs {
  std::string input;
  std::string output;
  std::string format;
  EncodingArgs encoding;  // --vtk-encoding, --msh-encoding
  std::string report;
  std::string smooth = "local";
  std::string quality = "sj";
  std::string verify = "local";
  std::string geode_block;
  std::string model = "half";
  std::string save_input;
  double merge_tolerance = -1;  // < 0: no merging
  bool unfold = false;          // --unfold: tets and pyramids a mesher folded turned back
  double buffer_thickness = 0;  // 0: the side's default
  double feature_thickness = conform::BufferLayerOptions{}.feature_thickness;
  std::string buffer_side;  // empty: automatic (conform::set_buffer_side)
  std::string pyramids = "split";
  std::string relax = "interface";
  double smooth_target = 0.0;
  std::string template_box;
  std::vector<std::string> join_blocks;  // --join-blocks lists
  int n = 4;
  bool quiet = false;
  bool write_invalid = false;
  bool force = false;
};

void print_summary(const conform::ConformResult& r, std::ostream& os, bool tables) {
  os << "input: " << r.input_hexes << " hexes, ";
  if (r.hexes_split) os << r.hexes_split << " of them split into tets, ";
  os << r.input_tets << " tets, ";
  if (r.input_pyramids) os << r.input_pyramids << " pyramids (split), ";
  if (r.input_wedges) os << r.input_wedges << " wedges, ";
  if (r.wedges_split) os << r.wedges_split << " of them split into tets, ";
  os << r.interface_quads << " interface quads\n";
  if (r.relaxation.nodes_moved)
    os << "tets relaxed near the hex part: " << r.relaxation.nodes_moved
       << " nodes moved, their tets' diced minimum " << r.relaxation.min_before << " -> "
       << r.relaxation.min_after << "\n";
  os << "output: " << r.model.hexes.size() << " hexes (" << r.diced_hexes << " diced hex, "
     << r.geode_hexes << " geode, " << r.diced_tet_hexes << " diced tet";
  if (r.diced_wedge_hexes) os << ", " << r.diced_wedge_hexes << " diced wedge";
  os << "), " << r.model.points.size() << " nodes, "
     << (conform::result_valid(r) ? "valid" : "INVALID") << ", " << r.seconds << " s\n";
  for (const auto& b : r.quality) {
    os << "block " << b.block;
    if (!b.name.empty()) os << " \"" << b.name << "\"";
    os << ": " << b.report.num_hexes << " hexes, min scaled Jacobian "
       << conform::block_min_scaled_jacobian(b.report) << " (diced alone "
       << b.input_diced_min_scaled_jacobian << ")";
    // Its geode hexes against the input cells around their buffer hexes (the local yardstick).
    if (b.geode_hexes > 0)
      os << "; " << b.geode_hexes << " geode hexes, min " << b.geode_min_scaled_jacobian
         << ", local yardstick " << b.local_yardstick << ", >= " << b.local_ratio << " x their own";
    os << "\n";
    if (tables) os << primal::format_quality_table(b.report) << "\n";
  }
  // The transition against the input's own elements diced alone (the yardstick).
  const double yardstick = r.yardstick();
  const double output = conform::output_min_scaled_jacobian(r);
  // Only the kinds the input holds, and the geode hexes where there are some: a kind without
  // elements has no minimum (the result's 1 is a placeholder).
  std::vector<std::string> kinds;
  auto add = [&](double value, const std::string& what) {
    std::ostringstream k;
    k << value << " (" << what << ")";
    kinds.push_back(k.str());
  };
  const conform::DicedAloneKinds has = conform::diced_alone_kinds(r);
  if (has.hexes) add(r.input_diced_hex_min_scaled_jacobian, "hexes");
  std::string tets;  // what the tets' minimum is over
  for (const auto& [count, what] :
       {std::pair{r.input_tets, "tets"}, std::pair{r.input_pyramids, "pyramids as their two tets"},
        std::pair{r.wedges_split, "split wedges as their three"},
        std::pair{r.hexes_split, "split hexes as their tets"}})
    if (count > 0) tets += (tets.empty() ? "" : ", ") + std::string(what);
  if (has.tets) add(r.input_diced_tet_min_scaled_jacobian, tets);
  if (has.wedges) add(r.input_diced_wedge_min_scaled_jacobian, "wedges");
  os << "input diced alone: min scaled Jacobian ";
  for (std::size_t i = 0; i < kinds.size(); ++i) os << (i ? ", " : "") << kinds[i];
  os << "; output " << output;
  if (yardstick > 0) os << " = " << output / yardstick << " x the lower";
  if (r.geode_hexes > 0)
    os << "; geode hexes >= " << r.local_yardstick_ratio << " x their local yardstick ("
       << r.capped_local_ratio
       << " x it capped by the template's own minimum at its buffer hex's proportions)";
  os << "\n";
}

// --template-box: three sizes, checked as template --box checks its box.
Eigen::Vector3d template_box(const std::string& text) {
  const auto b = parse_box("--template-box", text, 3);
  return {b[0], b[1], b[2]};
}

// The covering check's options: a fold's refusal points at --unfold unless it was given.
primal::InputCheckOptions fold_hint(const ConformArgs& a) {
  primal::InputCheckOptions o;
  if (!a.unfold) o.fold_hint = primal::fold_hint("--unfold");
  return o;
}

// The output paths and format, checked before any work: names, directories, format agreement.
std::string check_outputs(const ConformArgs& a) {
  if (!a.template_box.empty()) template_box(a.template_box);  // a usage error, before the work
  check_buffer_thickness(a.buffer_thickness, a.buffer_side);
  std::string format;
  if (!a.output.empty()) {
    if (a.output == "-")
      throw InvalidInput("-o -: a mesh is written to a file, not to standard output");
    check_output_path(a.output);
    format = output_format(a.output, a.format, mesh_format_names(), "");
  } else if (!a.format.empty()) {
    throw InvalidInput("--format " + a.format + " needs -o FILE");
  }
  if (a.report == "-" && !a.output.empty()) {
    // stat, not fs::equivalent: libstdc++'s refuses a pipe ("operation not supported").
    struct stat out {
    }, std_out{};
    if (::stat(a.output.c_str(), &out) == 0 && ::fstat(STDOUT_FILENO, &std_out) == 0 &&
        out.st_dev == std_out.st_dev && out.st_ino == std_out.st_ino)
      throw InvalidInput(a.output + ": is standard output, where --report - prints the report");
  }
  if (!a.report.empty() && a.report != "-") {  // "-": standard output, after the mesh
    if (file_extension(a.report) != ".json")
      throw InvalidInput(a.report + ": the report is JSON; name it *.json");
    check_output_path(a.report);
    // Resolved without throwing: a link to /dev/stdout on a pipe resolves to nothing, and
    // fs::weakly_canonical's exception ended the run with exit 1 (found by a fault hunt).
    check_distinct_outputs({{"-o", a.output}, {"--report", a.report}});
  }
  for (const std::string* out : {&a.output, &a.report, &a.save_input})
    check_not_input(*out, a.input, a.force);
  return format;
}

// `source` names the input file in the model's own errors (no tet part, no interface, a face
// that does not conform: they name elements and nodes, not the file); empty for demos.
// `together`: outputs written already (demo's --save-input), published with the mesh and
// report, or removed with them; `together_lines` what to print for them.
void run(primal::Model model, const ConformArgs& a, const std::string& format, bool tables,
         const std::string& source = {}, OutputFiles* together = nullptr,
         const std::string& together_lines = {}) {
  const std::string prefix = source.empty() ? "" : source + ": ";
  Progress progress = Progress::for_stderr(a.quiet);
  if (a.merge_tolerance >= 0) {
    try {
      primal::check_merge_tolerance(model, a.merge_tolerance, "--merge-tolerance");
    } catch (const InvalidInput& e) {
      throw InvalidInput(prefix + e.what());
    }
    const primal::Index merged = primal::merge_coincident_nodes(model, a.merge_tolerance);
    progress.stage("merged " + std::to_string(merged) + " coincident nodes");
  }
  bool covered_once = false;  // checked already, by unfold
  if (a.unfold) {
    const auto started = std::chrono::steady_clock::now();
    const primal::UnfoldResult u = primal::unfold(model);
    covered_once = u.covered_once;
    progress.stage(stage_line(
        unfold_stage(u),
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()));
    // The analyst's mesh changed: said whatever --quiet says.
    if (u.unfolded()) std::cerr << "geode: warning: " << prefix << unfold_warning(model, u) << "\n";
    // Read without the geometry check (inverted tets and pyramids are unfold's to mend): run
    // here, naming what is left.
    if (!source.empty()) primal::check_geometry(model, source);
  }
  // Read without the covering check where nodes are merged (duplicated interface nodes look
  // like a gap) or folds mended: run here.
  if (!source.empty() && (a.merge_tolerance >= 0 || a.unfold) && !covered_once)
    primal::require_single_covering(model, source, fold_hint(a));
  conform::ConformOptions opts;
  opts.smooth = conform::parse_conform_smooth(a.smooth);
  opts.pyramids = conform::parse_conform_pyramids(a.pyramids);
  opts.relax = conform::parse_conform_relax(a.relax);
  opts.quality = conform::parse_conform_quality(a.quality);
  opts.verify = conform::parse_conform_verify(a.verify);
  opts.geode_block = a.geode_block;
  conform::set_buffer_side(opts, a.buffer_side);
  opts.buffer.thickness = std::max(a.buffer_thickness, 0.0);  // 0: the side's default
  opts.buffer.feature_thickness = a.feature_thickness;
  opts.smooth_target = a.smooth_target;
  if (!a.template_box.empty()) opts.template_box = template_box(a.template_box);
  opts.progress = [&progress](const std::string& line) { progress.stage(line); };
  opts.smoothing_progress = [&progress](std::size_t done, std::size_t total) {
    progress.step("seed hexes settled", done, total);
  };
  opts.verification_progress = [&progress](std::size_t done, std::size_t total) {
    progress.share("of the output verified", done, total);
  };
  // The mesh is written to its temporary while conform verifies it (ConformOptions::write_ahead),
  // and published (with the report) only if it is valid or --write-invalid asks for it.
  OutputFiles own;
  OutputFiles& files = together ? *together : own;
  const primal::Model* written = nullptr;
  std::span<const double> written_sj;  // the hexes' scaled Jacobians, while conform keeps them
  std::exception_ptr write_failed;
  if (!a.output.empty()) {
    const std::size_t mesh_file = files.add(a.output, [&](const fs::path& temp) {
      io::WriteOptions o = write_options(a.encoding);
      o.scaled_jacobians = written_sj;
      io::write_model(*written, temp, format, o);
    });
    // A format that writes each cell's scaled Jacobian takes conform's (the same values).
    opts.write_ahead_scaled_jacobians = io::output_format(a.output, format).writes_scaled_jacobians;
    opts.output_numbering = io::element_numbering(io::output_format(a.output, format));
    opts.write_ahead = [&, mesh_file](const primal::Model& m, std::span<const double> sj) {
      written = &m;
      written_sj = sj;
      try {
        files.write(mesh_file);
      } catch (...) {  // reported after the run: not as the input's fault
        write_failed = std::current_exception();
      }
      written_sj = {};
    };
  }
  conform::ConformResult r;
  try {
    r = conform::conform(std::move(model), opts);  // the hints below read what is left
  } catch (const InvalidInput& e) {
    throw InvalidInput(prefix + e.what() +
                       conform::duplicate_node_hint(model, "--merge-tolerance"));
  } catch (const TopologyError& e) {
    throw TopologyError(prefix + e.what() +
                        conform::duplicate_node_hint(model, "--merge-tolerance"));
  }
  const bool valid = conform::result_valid(r);
  written = &r.model;
  const bool publish = valid || a.write_invalid;
  // --report -: standard output carries the JSON report alone (for a pipe into jq), once the
  // files are published; the summary goes to stderr.
  const bool report_out = a.report == "-";
  std::ostream& said = report_out ? std::cerr : std::cout;
  if (publish) {
    if (write_failed) std::rethrow_exception(write_failed);
    if (!a.report.empty() && !report_out) {
      files.add(a.report, [text = json_text(conform::report_json(r), 2)](const fs::path& temp) {
        write_or_print(temp.string(), [&](std::ostream& os) { os << text; });
      });
    }
  }
  // Everything for stdout before the files: commit() publishes nothing if it was lost (and
  // says so if the publishing fails after these lines).
  if (!a.quiet) print_summary(r, said, tables);
  if (!a.quiet && publish) {
    if (!a.output.empty()) said << "wrote " << a.output << "\n";
    if (!a.report.empty() && !report_out) said << "wrote " << a.report << "\n";
    said << together_lines;
  }
  if (publish) files.commit();
  if (publish && report_out) std::cout << json_text(conform::report_json(r), 2) << std::flush;
  // Warnings of a valid result go to stderr, --quiet or not (an invalid one's are in its error).
  if (valid)
    for (const auto& w : r.warnings) std::cerr << "geode: warning: " << w << "\n";
  if (!valid) {
    throw InvalidResult(prefix + conform::invalid_reason(r) +
                        (a.write_invalid ? " (written anyway: --write-invalid)"
                                         : " (nothing written; --write-invalid writes it anyway)"));
  }
}

// Options conform and demo share: where to write, the report, smoothing, quiet.
void add_run_options(CLI::App* c, ConformArgs& a) {
  c->add_option(
      "-o,--output", a.output,
      "output mesh; the format follows the extension (" + mesh_formats_help() +
          ");\nwritten only if the result is valid (see --write-invalid), together with --report\n"
          "(both or neither)");
  c->add_option("--format", a.format,
                "mesh format, when it must be named (msh22 for Gmsh 2.2 in a .msh); one that\n"
                "contradicts the extension of -o is refused")
      ->check(CLI::IsMember(mesh_format_names()));
  add_encoding_options(c, a.encoding);
  c->add_option("--report", a.report,
                "write a JSON report (counts, validity, quality per output block) to FILE.json;\n"
                "- prints it on standard output once the mesh is written (the summary then goes\n"
                "to stderr)");
  c->add_option(
       "--smooth", a.smooth,
       "worst-first smoothing; materials never move: nodes on the model boundary and between\n"
       "blocks slide only in their plane or along their straight edge, and are fixed on curved\n"
       "surfaces and at corners, so every block keeps its volume; local (default): near the\n"
       "geode hexes (see --smooth-target); global: every hex below min(0.5, 3 x the input diced\n"
       "alone), then what local runs where a hex is still below its aim; none: only hexes the\n"
       "placement inverted are untangled (the report counts them)")
      ->check(CLI::IsMember({"local", "global", "none"}))
      ->capture_default_str();
  c->add_option(
       "--smooth-target", a.smooth_target,
       "local smoothing: 0 (default) works where a hex is below its aim: the input's own hexes\n"
       "and tets diced alone (the yardstick); for a geode hex 0.9 x its local yardstick (the\n"
       "input cells around its buffer hex, diced alone; capped by the template's own minimum);\n"
       "for a diced hex 0.5 x its input hex diced alone; on hexes below 1.1 x their aim around\n"
       "those until none is below it, again where they remain (up to 8 passes); a value > 0\n"
       "works on every geode hex and neighbour below it (e.g. 0.35: more time, most hexes\n"
       "higher, but the lowest may end lower: the potting demo at n = 3 0.039 -> 0.110 overall,\n"
       "a cylinder's geode hexes 0.155 -> 0.110)")
      ->check(number_check(0, 1))
      ->capture_default_str();
  c->add_option("--quality", a.quality,
                "sj: validity and the scaled Jacobian per block (default, cheap); full: every "
                "metric of the paper's Table 1 per block")
      ->check(CLI::IsMember({"sj", "full"}))
      ->capture_default_str();
  c->add_option(
       "--verify", a.verify,
       "local (default): the validity check on the geode hexes, what smoothing moved and\n"
       "two rings around them, the diced parts against the dicing tables and every hex's\n"
       "corner Jacobians (the diced parts of an input the read-time check passed are valid\n"
       "by construction); full: that check on the whole output (about twice the CPU;\n"
       "--smooth global is always verified whole)")
      ->check(CLI::IsMember({"local", "full"}))
      ->capture_default_str();
  c->add_option(
      "--geode-block", a.geode_block,
      "put the geode hexes in a block of their own with this name (id one above every\n"
      "input block); by default each goes to the block of the element its buffer hex was carved\n"
      "from (the hex under it; with --buffer-side tet, the tet above it). A label only:\n"
      "smoothing moves them as that block's, so the mesh is the one without the option\n"
      "(but where a side set on the interface follows the geode block's face)");
  c->add_option("--merge-tolerance", a.merge_tolerance,
                "first merge nodes closer than this distance (model units), for parts meshed\n"
                "separately whose interface nodes are duplicated")
      ->check(number_check(0, 1e300));
  add_unfold_option(c, a.unfold);
  c->add_option(
       "--pyramids", a.pyramids,
       "what pyramids of a hybrid mesh become: split (default): two tets along the base diagonal\n"
       "giving the better tets, the base quad then getting the geode transition")
      ->capture_default_str();
  c->add_option(
       "--relax", a.relax,
       "interface (default): before the buffer layer, move the tet mesher's nodes within\n"
       "two rings of tets of the hex part, each where its tets diced are best (never worse;\n"
       "nodes on the boundary, between blocks, in a node set or on a side set's faces stay;\n"
       "the yardsticks are measured after); none: every input node stays where it is")
      ->check(CLI::IsMember({"interface", "none"}))
      ->capture_default_str();
  c->add_option(
       "--buffer-side", a.buffer_side,
       "the part the buffer layer is carved from: hex (the tets stay as meshed, the hexes at\n"
       "the interface are squashed) or tet (the hexes stay, the tets shrink off the interface);\n"
       "not given: hex, or tet with a warning where the hex cells at some piece of the\n"
       "interface are thin (flatter than 2.5 : 1, a boundary layer's) and the tets give a\n"
       "thicker layer there; where they are nearly so (flatter than 2 : 1), or the hex part\n"
       "is convex at some interface corner (its buffer hexes taper there), and the geode\n"
       "hexes from the hex part fall short of 0.9 x their capped local yardstick or leave a\n"
       "block below 0.5 x its own elements diced alone, both parts are tried and the better\n"
       "kept (the higher minimum; on a tie, the better transition; the tet part's where only\n"
       "the hex part's leaves a block so spoilt and its minimum is at least 0.9 x the hex\n"
       "part's), with a warning. hex given on nearly thin cells and the output invalid: the\n"
       "tet part's, with a warning")
      ->check(CLI::IsMember({"hex", "tet"}));
  c->add_option(
       "--buffer-thickness", a.buffer_thickness,
       "how far that part shrinks off the interface (the buffer layer's thickness), as a fraction\n"
       "of the shortest edge at each interface node; default 0.5 with --buffer-side hex (at most "
       "0.9),\n"
       "0.3 with tet (at most 0.45)")
      ->check(number_check(0.01, conform::max_buffer_thickness(conform::BufferSide::kHex)));
  c->add_option(
       "--feature-thickness", a.feature_thickness,
       "at convex interface corners (faces in three directions more than 30 degrees apart) the\n"
       "layer is this fraction of its thickness: buffer hexes there taper by their height in two\n"
       "directions, a thinner layer keeps the geode nearer a box (1: as thick as elsewhere)")
      ->check(number_check(0.1, 1))
      ->capture_default_str();
  c->add_option(
      "--template-box", a.template_box,
      "proportions WxHxD of the box the reference geode template is smoothed in once per\n"
      "run (H: the buffer hex's thickness direction; default 24x12x24, near the buffer hexes' "
      "own;\n"
      "24x10x24 suits --buffer-side tet)");
  c->add_flag("--write-invalid", a.write_invalid,
              "write the mesh and report even when verification fails (the exit code is still 4)");
  add_force_flag(c, a.force);
  c->add_flag("-q,--quiet", a.quiet,
              "no progress and no summary (errors and the invalid-result message still print)");
}

}  // namespace

void add_conform_commands(CLI::App& app) {
  auto args = std::make_shared<ConformArgs>();
  CLI::App* c = app.add_subcommand(
      "conform",
      "Conform the hex part of a model to its tet part with geode templates: buffer layer, dicing\n"
      "(8 per hex, 4 per tet), 26 geode hexes per interface quad split into two triangles (44 "
      "hexes of\n"
      "the superquadric-dome four-triangle template where the tet side splits a quad into four "
      "triangles\n"
      "around a centre node), smoothing where the result is below the input's own diced elements.\n"
      "Input element blocks, node sets and side sets are carried to the output. Exit 4 when the "
      "result\n"
      "fails verification.");
  c->add_option("INPUT", args->input, "input model (" + input_extensions_help() + ")")->required();
  add_run_options(c, *args);
  add_join_blocks_option(c, args->join_blocks);
  c->callback([args] {
    const std::string format = check_outputs(*args);  // before the long run, not after it
    // The templates depend on the options alone: built while the file is read, on a thread of
    // their own, unless the reader forks (no thread of ours may be at work then;
    // io/read_model.hpp) or --threads 1 asks for one thread.
    std::jthread templates;
    if (!io::read_forks(args->input) &&
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1)
      templates = conform::build_reference_templates_ahead(
          args->template_box.empty() ? conform::ConformOptions{}.template_box
                                     : template_box(args->template_box));
    // With --unfold neither the geometry nor the covering check at read: run after unfold.
    primal::ReadOptions read;
    read.check_geometry = !args->unfold;
    if (!args->unfold)  // with it, the geometry is checked after unfold
      read.inverted_hint = primal::inverted_hint("--unfold");
    primal::Model model = io::read_model(
        args->input, read, args->merge_tolerance < 0 && !args->unfold, nullptr, fold_hint(*args));
    join_block_lists(model, args->join_blocks, args->input);
    run(std::move(model), *args, format, false, args->input);
  });

  auto dargs = std::make_shared<ConformArgs>();
  CLI::App* d = app.add_subcommand(
      "demo",
      "Build a demo model with the Gmsh API (--model) and conform it, printing the quality\n"
      "report per block; --save-input writes the model itself.");
  d->add_option(
       "--model", dargs->model,
       "half: structured hexes beside Kuhn-split transfinite tets (default); delaunay,\n"
       "delaunay-random: beside a Delaunay tet box, interface diagonals alternating or\n"
       "random; cylinder: a swept hex cylinder with unstructured quad caps in a tet box\n"
       "(n >= 2); lshape: a hex block in the notch of an L-shaped tet part (concave interface);\n"
       "nugget: a Delaunay tet cube in 26 structured blocks; fulcher: the same with circles\n"
       "imprinted on three nugget faces, those blocks swept from unstructured quads; fourtri:\n"
       "beside a Delaunay tet box whose interface quads are split into two or four triangles\n"
       "(at random); fourtri-cylinder: the cylinder with half its interface quads in four\n"
       "triangles (n >= 2);\n"
       "hybrid meshes Gmsh makes in one generate(3), with its pyramids: hybrid (a transfinite hex\n"
       "box beside a Delaunay tet box), hybrid-cylinder (a swept hex cylinder in a Delaunay box;\n"
       "n >= 2),\n"
       "boundary-layer (wedge layers extruded on a tet box), hexdominant (hexes, tets, pyramids\n"
       "and wedges side by side), layer-side (a wedge layer whose side quads meet tets, with\n"
       "Gmsh's pyramids), layer-interface (a wedge layer at the hex/tet interface's edge),\n"
       "layer-mixed (hexes and wedges side by side in one layer on tets: the wedges are split);\n"
       "potting: six hex parts (boxes, swept cylinders, a tilted box, an\n"
       "L bracket), each its own block, in a Delaunay tet potting (n >= 2)")
      // Checked against the module's names when given (loading libgmsh then, not at startup).
      ->check(CLI::Validator(
          [](std::string& name) {
            const auto& names = demo_module().names();
            if (std::find(names.begin(), names.end(), name) != names.end()) return std::string();
            std::string list;
            for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
            return name + " not in {" + list + "}";
          },
          "NAME"))
      ->capture_default_str();
  d->add_option(
       "-n,--size", dargs->n,
       "cells per unit length (1 to 64; default 4; nugget, fulcher round up to even;\n"
       "boundary-layer, layer-side and layer-mixed cap Gmsh's own sizes, about 5 cells per\n"
       "unit, so that n below 4 or 5 gives the same mesh as there)")
      ->check(number_check(1, 64, true));
  d->add_option("--save-input", dargs->save_input,
                "write the demo's input model (" +
                    io::extension_list(io::FormatRole::kWrite, ", ", ", ") +
                    ") to try `geode conform` on it;\nwithout -o or --report nothing is conformed");
  add_run_options(d, *dargs);
  d->callback([dargs] {
    const std::string format = check_outputs(*dargs);
    std::string save_format;
    if (!dargs->save_input.empty()) {
      check_output_path(dargs->save_input);
      save_format = output_format(dargs->save_input, "", mesh_format_names(), "");
    }
    check_distinct_outputs(
        {{"-o", dargs->output}, {"--report", dargs->report}, {"--save-input", dargs->save_input}});
    primal::Model model = demo_module().model(dargs->model, dargs->n);
    // The read-time check, as on a file: --verify local (the default) takes the diced parts of a
    // checked input as valid by construction.
    primal::require_single_covering(model, "demo model " + dargs->model);
    // The input saved to its temporary now (conform consumes the model), published with the
    // mesh and report: a run that fails writes none of them.
    OutputFiles files;
    std::ostringstream saved;
    if (!dargs->save_input.empty()) {
      files.write(files.add(dargs->save_input, [&](const fs::path& temp) {
        io::write_model(model, temp, save_format, write_options(dargs->encoding));
      }));
      saved << "wrote " << dargs->save_input << " (" << model.hexes.size() << " hexes, "
            << model.tets.size() << " tets, " << model.pyramids.size() << " pyramids, "
            << model.wedges.size() << " wedges)\n";
    }
    // The line before the files: commit() publishes nothing if it was lost.
    const std::string lines = dargs->quiet ? std::string() : saved.str();
    // --save-input alone: the input is what was asked for; nothing given at all: the demo is
    // conformed and its report printed, as --help says (it did nothing, exit 0; a hunt's).
    if (dargs->output.empty() && dargs->report.empty() && !dargs->save_input.empty()) {
      std::cout << lines;
      files.commit();
    } else {
      run(std::move(model), *dargs, format, true, {}, &files, lines);
    }
  });
}

}  // namespace geode::cli
