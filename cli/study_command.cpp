// geode study interleave | shape | corners: parameter studies of the geode templates
// (templates/study.hpp) and of the transition at hex-part edges and corners
// (conform/corner_study.hpp).
#include <algorithm>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#include <geode/conform/corner_study.hpp>
#include <geode/primal/errors.hpp>
#include <geode/templates/spec.hpp>
#include <geode/templates/study.hpp>
#include <geode/templates/template_table.hpp>
#include "cli/commands.hpp"
#include "cli/conventions.hpp"
#include "cli/demo_module.hpp"
#include "cli/progress.hpp"

namespace geode::cli {
namespace {

struct InterleaveArgs {
  std::string name = "geode3d";
  std::string output;
  std::string summary;
  std::vector<double> high, low, depth, radius;
  std::string spec;
  std::vector<std::string> sweep;
  bool quiet = false;
};

// The spec's sweep block, then --sweep options (replacing an axis of the same path).
templates::InterleaveStudy spec_study(const InterleaveArgs& a) {
  const nlohmann::json spec = templates::read_spec_json(a.spec);
  const std::string source = std::filesystem::path(a.spec).filename().string();
  templates::parse_spec(spec, source);  // the unswept spec must be valid too
  std::vector<templates::SweepAxis> axes = templates::spec_sweep(spec, source);
  for (const auto& text : a.sweep) {
    templates::SweepAxis axis = templates::parse_sweep_option(text);
    nlohmann::json probe = spec;
    templates::set_spec_number(probe, axis.path, axis.values.front(), source);
    auto same =
        std::find_if(axes.begin(), axes.end(), [&](const auto& x) { return x.path == axis.path; });
    if (same != axes.end())
      *same = axis;
    else
      axes.push_back(axis);
  }
  if (axes.empty())
    throw InvalidInput(source +
                       ": nothing to sweep (give --sweep PATH=FROM:TO:COUNT or a sweep block)");
  Progress progress = Progress::for_stderr(a.quiet);
  auto study =
      templates::interleave_study(spec, source, axes, std::filesystem::path(a.spec).stem().string(),
                                  [&](const std::string& what, std::size_t done,
                                      std::size_t total) { progress.step(what, done, total); });
  if (study.runs.empty())
    throw InvalidInput(source + ": every sweep point is invalid input (e.g. low roof above high)");
  return study;
}

// A study's outputs written as one (OutputFiles: all or none); an output named `-`, or one
// left unnamed that goes to standard output, is printed first: the files are published only
// if it went out (OutputFiles::commit).
class StudyOutputs {
 public:
  using Write = std::function<void(std::ostream&)>;
  void add(const std::string& path, Write write) {
    if (path.empty() || path == "-") {
      printed_.push_back(std::move(write));
      return;
    }
    files_.add(path, [write = std::move(write)](const std::filesystem::path& temp) {
      write_or_print(temp.string(), write);
    });
  }
  void commit() {
    for (const Write& write : printed_) write(std::cout);
    files_.commit();
  }

 private:
  OutputFiles files_;
  std::vector<Write> printed_;
};

void run_interleave(const InterleaveArgs& a) {
  for (const std::string* path : {&a.output, &a.summary}) {
    output_format(*path, "", {"csv"}, "csv");
    check_output_path(*path);
  }
  check_distinct_outputs({{"-o", a.output}, {"--summary", a.summary}});
  templates::InterleaveStudy study;
  if (!a.spec.empty()) {
    study = spec_study(a);
  } else {
    if (!a.sweep.empty()) throw InvalidInput("study interleave: --sweep needs --spec");
    // The template table says which templates are studied and on what default grid.
    const templates::TemplateEntry* entry = templates::find_template(a.name);
    if (!entry || !entry->study_grid) {
      std::string names;
      for (const auto& n : templates::template_names(true))
        names += (names.empty() ? "" : ", ") + n;
      throw InvalidInput("study interleave: unknown template '" + a.name + "' (" + names + ")");
    }
    templates::PushGrid grid = entry->study_grid();
    if (!a.high.empty()) grid.high_roof = a.high;
    if (!a.low.empty()) grid.low_roof = a.low;
    if (!a.depth.empty()) grid.dome_depth = a.depth;
    if (!a.radius.empty()) grid.dome_radius = a.radius;
    templates::check_sweep_size({grid.high_roof.size(), grid.low_roof.size(),
                                 grid.dome_depth.size(), grid.dome_radius.size()},
                                "study interleave");
    const templates::GeodeOptions o = entry->defaults.geode;
    Progress progress = Progress::for_stderr(a.quiet);
    study = templates::interleave_study(
        o, grid, a.name, [&](const std::string& what, std::size_t done, std::size_t total) {
          progress.step(what, done, total);
        });
    if (study.runs.empty())
      throw InvalidInput("study interleave: no grid point has 0 < low < high < 1");
  }
  // The runs and the summary are written as one (both or neither); the runs to stdout otherwise.
  StudyOutputs outputs;
  outputs.add(a.output, [&](std::ostream& s) { templates::write_interleave_csv(s, study); });
  if (!a.summary.empty())
    outputs.add(a.summary, [&](std::ostream& s) { templates::write_interleave_summary(s, study); });
  double total = 0;
  for (const auto& r : study.runs) total += r.seconds;
  std::ostringstream log;
  log << study.template_name << ": " << study.runs.size() << " runs, " << std::setprecision(3)
      << total << " s, " << study.classes.size() << " outcome classes";
  if (study.skipped) log << ", " << study.skipped << " sweep points skipped as invalid input";
  log << "\n";
  for (const auto& c : study.classes) {
    log << "  " << c.label << "  " << std::setw(4) << c.count << " runs  ";
    if (c.valid)
      log << c.hexes << " hexes, conditions ok in " << c.conditions_ok << "/" << c.count << ", "
          << (c.obstructions.empty() ? std::string("no obstruction")
                                     : std::to_string(c.obstructions.size()) + " obstructions")
          << ", smoothed min SJ " << c.min_sj_fixed << " fixed / " << c.min_sj_slide << " sliding"
          << (c.usable ? ": usable" : ": not usable");
    else
      log << "error";
    log << "  e.g. push " << c.example.high_roof << " " << c.example.low_roof << " "
        << c.example.dome_depth << " " << c.example.dome_radius;
    for (std::size_t i = 0; i < c.example_parameters.size(); ++i)
      log << (i ? ", " : "; ") << study.parameter_names[i] << " " << c.example_parameters[i];
    log << "\n      " << c.key << "\n";
  }
  // The classes on stdout when the runs go to a file, printed before the files are published
  // (commit() publishes nothing if they were lost); else on stderr, after the runs' CSV.
  const bool runs_on_stdout = a.output.empty() || a.output == "-";
  if (!runs_on_stdout) std::cout << log.str();
  outputs.commit();
  if (runs_on_stdout) std::cerr << log.str();
}

struct ShapeArgs {
  std::string height_csv, distorted_csv, quality_csv, sj_csv;
  std::vector<double> heights, shears, tapers;
};

void run_shape(const ShapeArgs& a) {
  for (const std::string* path : {&a.height_csv, &a.distorted_csv, &a.quality_csv, &a.sj_csv}) {
    output_format(*path, "", {"csv"}, "csv");
    check_output_path(*path);
  }
  check_distinct_outputs({{"-o", a.height_csv},
                          {"--distorted-csv", a.distorted_csv},
                          {"--quality-csv", a.quality_csv},
                          {"--sj-csv", a.sj_csv}});
  const bool any = !a.height_csv.empty() || !a.distorted_csv.empty() || !a.quality_csv.empty() ||
                   !a.sj_csv.empty();
  // The CSVs are written as one (all or none: a fourth that failed left the first three
  // replaced); `-`, or no output named, prints the table.
  StudyOutputs outputs;
  if (!a.height_csv.empty() || !any) {
    std::vector<double> h = a.heights;
    if (h.empty())
      for (int x = 6; x <= 30; x += 2) h.push_back(x);
    const auto rows = templates::height_study(h);
    outputs.add(a.height_csv, [rows](std::ostream& s) { templates::write_shape_csv(s, rows); });
  }
  if (!a.distorted_csv.empty()) {
    const std::vector<double> shears =
        a.shears.empty() ? std::vector<double>{0, 10, 20, 30, 40} : a.shears;
    const std::vector<double> tapers =
        a.tapers.empty() ? std::vector<double>{0.4, 0.6, 0.8, 1.0, 1.25, 1.5} : a.tapers;
    const auto rows = templates::distorted_study(shears, tapers);
    outputs.add(a.distorted_csv, [rows](std::ostream& s) { templates::write_shape_csv(s, rows); });
  }
  if (!a.quality_csv.empty() || !a.sj_csv.empty()) {
    std::ostringstream report, per_hex;
    templates::write_geode_quality(report, &per_hex);
    if (!a.quality_csv.empty())
      outputs.add(a.quality_csv, [text = report.str()](std::ostream& s) { s << text; });
    if (!a.sj_csv.empty())
      outputs.add(a.sj_csv, [text = per_hex.str()](std::ostream& s) { s << text; });
  }
  outputs.commit();
}

struct CornersArgs {
  int n = 3;
  std::string output, buffer_side;
  bool quiet = false;
};

void run_corners(const CornersArgs& a) {
  output_format(a.output, "", {"csv"}, "csv");
  check_output_path(a.output);
  const auto study = conform::corner_study(
      demo_module().corner_study_models(a.n), a.n,
      [&](const conform::CornerStudyModelSummary& s) {
        if (!a.quiet) std::cerr << "study corners: " << s.name << " done\n";
      },
      a.buffer_side);
  if (a.output.empty()) {
    conform::write_corner_table(std::cout, study);
  } else {
    write_or_print(a.output, [&](std::ostream& s) { conform::write_corner_csv(s, study); });
    if (!a.quiet) conform::write_corner_table(std::cerr, study);
  }
}

}  // namespace

void add_study_commands(CLI::App& app) {
  auto* study =
      app.add_subcommand("study", "Parameter studies of the geode templates (CSV output)");
  study->require_subcommand(1);

  auto ia = std::make_shared<InterleaveArgs>();
  auto* inter = study->add_subcommand(
      "interleave",
      "Sweep the push parameters (high roof, low roof, dome depth, dome radius) and classify what "
      "each push "
      "dualizes to: a template class (hex count, sheet-kind triples, colour-refinement hash) with "
      "the paper's "
      "two conditions, or the TopologyError's diagnosis with numbers stripped");
  inter
      ->add_option("--template", ia->name,
                   "the template to sweep (default geode3d): " + templates::template_help(true))
      ->check(CLI::IsMember(templates::template_names(true)));
  inter->add_option("-o,--output", ia->output, "per-run CSV (default: stdout)");
  inter->add_option("--summary", ia->summary, "per-class summary CSV");
  inter->add_option("--high", ia->high, "high roof values (default grid if omitted)")
      ->check(number_check(0, 1));
  inter->add_option("--low", ia->low, "low roof values")->check(number_check(0, 1));
  inter->add_option("--depth", ia->depth, "dome depth values")->check(number_check(0, 1));
  inter->add_option("--radius", ia->radius, "dome radius blend values")->check(number_check(0, 1));
  inter
      ->add_option(
          "--spec", ia->spec,
          "sweep an arrangement spec (geode arrange's format) instead of a built-in template;\n"
          "its \"sweep\" block and --sweep say what to sweep")
      ->excludes("--template")
      ->excludes("--high")
      ->excludes("--low")
      ->excludes("--depth")
      ->excludes("--radius");
  inter->add_option(
      "--sweep", ia->sweep,
      "with --spec: PATH=FROM:TO:COUNT or PATH=V1,V2,... for a number in the spec, e.g.\n"
      "push.high_roof=0.55:0.95:5 or sheets[3].sphere.radius=0.2,0.3 (repeat for a grid)");
  inter->add_flag("-q,--quiet", ia->quiet,
                  "no progress lines (a bar on a terminal, a line every few seconds in a log)");
  inter->callback([ia] { run_interleave(*ia); });

  auto sa = std::make_shared<ShapeArgs>();
  auto* shape = study->add_subcommand(
      "shape",
      "Min scaled Jacobian of the smoothed geode (tet/hex-side nodes fixed or sliding) against the "
      "box height "
      "(24 x h x 24), in sheared and tapered 24 x 14 x 24 cells, and the Table 1 report");
  shape->add_option("-o,--output,--height-csv", sa->height_csv,
                    "height study CSV (default when no other output is asked: stdout)");
  shape->add_option("--distorted-csv", sa->distorted_csv, "sheared/tapered cell study CSV");
  shape->add_option("--quality-csv", sa->quality_csv,
                    "Table 1 report of the smoothed geode with the paper's values");
  shape->add_option("--sj-csv", sa->sj_csv,
                    "per-hex scaled Jacobians of the smoothed geode (both modes)");
  shape->add_option("--heights", sa->heights, "box heights (default 6, 8, ..., 30), in [0.1, 2400]")
      ->check(number_check(0.1, 2400));
  shape
      ->add_option("--shears", sa->shears,
                   "shear angles in degrees (default 0 10 20 30 40), in [0, 80]")
      ->check(number_check(0, 80));
  shape
      ->add_option("--tapers", sa->tapers,
                   "top/bottom taper ratios (default 0.4 0.6 0.8 1 1.25 1.5), in [0.01, 100]")
      ->check(number_check(0.01, 100));
  shape->callback([sa] { run_shape(*sa); });

  auto ca = std::make_shared<CornersArgs>();
  auto* corners = study->add_subcommand(
      "corners",
      "The transition at hex-part edges and corners: per demo model (nugget, lshape, potting,\n"
      "cylinder, wedges of 60 to 300 degrees), dihedral angle and corner kind, the geode hexes'\n"
      "min scaled Jacobian with --smooth none, the defaults and --smooth global, and its ratio\n"
      "to the local yardstick with the defaults (a table; with -o the CSV notebooks-data/plot.py\n"
      "draws)");
  corners->add_option("-n", ca->n, "demo model size (default 3), in [2, 8]")
      ->check(CLI::Range(2, 8));
  corners->add_option("-o,--output", ca->output, "CSV output (default: a table on stdout)");
  corners
      ->add_option("--buffer-side", ca->buffer_side,
                   "the part every model's buffer layer is carved from (as geode conform's "
                   "--buffer-side; not given: as geode conform chooses); the runs with "
                   "--smooth none and global are given the part the defaults' run took")
      ->check(CLI::IsMember({"hex", "tet"}));
  corners->add_flag("-q,--quiet", ca->quiet, "no progress lines or table on stderr");
  corners->callback([ca] { run_corners(*ca); });
}

}  // namespace geode::cli
