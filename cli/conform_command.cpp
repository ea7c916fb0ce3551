// geode conform INPUT: the geode algorithm on a whole hex + tet model; geode demo: the same on
// a demo model built with Gmsh (primal/demo_models).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "primal/atomic_file.hpp"
#include "conform/demo_models.hpp"
#include "primal/errors.hpp"
#include "primal/io_exodus.hpp"
#include "primal/io_gmsh.hpp"
#include "primal/io_vtk.hpp"
#include "primal/quality.hpp"
#include "primal/quality_report.hpp"
#include "conform/conform.hpp"

namespace geode::cli {
namespace {

namespace fs = std::filesystem;

void check_output_extension(const fs::path& path) {
  const std::string e = file_extension(path);
  if (e != ".exo" && e != ".e" && e != ".msh" && e != ".vtu")
    throw InvalidInput(path.string() + ": unknown output format '" + e +
                       "' (expected .exo, .e, .msh or .vtu)");
}

void write_model(const primal::Model& model, const fs::path& path) {
  const std::string e = file_extension(path);
  if (e == ".exo" || e == ".e") return primal::write_exodus(model, path);
  if (e == ".msh") return primal::write_gmsh(model, path);
  if (e == ".vtu") return primal::write_vtu(path, primal::hex_part(model));
  check_output_extension(path);
}

struct ConformArgs {
  std::string input;
  std::string output;
  std::string report;
  std::string smooth = "local";
  std::string quality = "sj";
  std::string model = "half";
  std::string save_input;
  int n = 4;
  bool quiet = false;
};

nlohmann::json result_json(const conform::ConformResult& r) {
  nlohmann::json j;
  j["input"] = {{"hexes", r.input_hexes}, {"tets", r.input_tets},
                {"interface_quads", r.interface_quads}};
  j["output"] = {{"hexes", r.model.hexes.size()},    {"nodes", r.model.points.size()},
                 {"diced_hexes", r.diced_hexes},     {"geode_hexes", r.geode_hexes},
                 {"diced_tet_hexes", r.diced_tet_hexes}};
  j["valid"] = r.validity.ok();
  j["template_min_scaled_jacobian"] = r.template_min_scaled_jacobian;
  j["min_scaled_jacobian_before_smoothing"] = r.min_scaled_jacobian_before_smoothing;
  j["min_scaled_jacobian_after_smoothing"] = r.smoothing.final_min_scaled_jacobian;
  j["buffer_layer_min_scaled_jacobian"] = r.buffer.min_scaled_jacobian;
  j["seconds"] = r.seconds;
  j["warnings"] = r.warnings;
  j["blocks"] = nlohmann::json::array();
  for (const auto& b : r.quality)
    j["blocks"].push_back({{"id", b.block}, {"name", b.name},
                           {"quality", primal::quality_report_json(b.report)}});
  return j;
}

double min_sj(const primal::QualityReport& q) {
  for (const auto& m : q.metrics)
    if (m.metric == primal::HexMetric::kScaledJacobian) return m.minimum;
  return 0.0;
}

void print_summary(const conform::ConformResult& r, std::ostream& os, bool tables) {
  os << "input: " << r.input_hexes << " hexes, " << r.input_tets << " tets, "
     << r.interface_quads << " interface quads\n";
  os << "output: " << r.model.hexes.size() << " hexes (" << r.diced_hexes << " diced hex, "
     << r.geode_hexes << " geode, " << r.diced_tet_hexes << " diced tet), "
     << r.model.points.size() << " nodes, " << (r.validity.ok() ? "valid" : "INVALID") << ", "
     << r.seconds << " s\n";
  for (const auto& b : r.quality) {
    os << "block " << b.block << " \"" << b.name << "\": " << b.report.num_hexes
       << " hexes, min scaled Jacobian " << min_sj(b.report) << "\n";
    if (tables) os << primal::format_quality_table(b.report) << "\n";
  }
  for (const auto& w : r.warnings) os << "warning: " << w << "\n";
}

// `source` names the input file in the model's own errors (no tet part, no interface, a face
// that does not conform: they name elements and nodes, not the file); empty for demos.
void run(const primal::Model& model, const ConformArgs& a, bool tables,
         const std::string& source = {}) {
  conform::ConformOptions opts;
  opts.smooth = conform::parse_conform_smooth(a.smooth);
  opts.quality = conform::parse_conform_quality(a.quality);
  if (!a.quiet && isatty(STDERR_FILENO)) {
    opts.progress = [](const std::string& line) { std::cerr << "geode: " << line << "\n"; };
    // Local smoothing is the long step: a bar redrawn in place, at most ten times a second.
    auto last = std::make_shared<std::chrono::steady_clock::time_point>();
    opts.smoothing_progress = [last](std::size_t done, std::size_t total) {
      const auto now = std::chrono::steady_clock::now();
      if (done < total && now - *last < std::chrono::milliseconds(100)) return;
      *last = now;
      const std::size_t width = 30, filled = total ? width * done / total : width;
      std::cerr << "\rgeode: smoothing [" << std::string(filled, '#') << std::string(width - filled, '.') << "] "
                << done << " / " << total << " buffer hexes" << (done == total ? "\n" : "") << std::flush;
    };
  }
  const std::string prefix = source.empty() ? "" : source + ": ";
  conform::ConformResult r;
  try {
    r = conform::conform(model, opts);
  } catch (const InvalidInput& e) {
    throw InvalidInput(prefix + e.what());
  } catch (const TopologyError& e) {
    throw TopologyError(prefix + e.what());
  }
  if (!a.output.empty()) write_model(r.model, a.output);
  if (!a.report.empty()) {
    const std::string text = result_json(r).dump(2) + "\n";
    primal::write_file_atomically(a.report, [&](std::ostream& os) { os << text; });
  }
  if (!a.quiet) print_summary(r, std::cout, tables);
  if (!a.output.empty() && !a.quiet) std::cout << "wrote " << a.output << "\n";
}

}  // namespace

// Options conform and demo share: where to write, the report, smoothing, quiet.
void add_run_options(CLI::App* c, ConformArgs& a) {
  c->add_option("-o,--output", a.output, "output model (.exo, .e, .msh, .vtu)");
  c->add_option("--report", a.report, "write a JSON report (counts, quality per block)");
  c->add_option("--smooth", a.smooth,
                "worst-first smoothing, model boundary nodes sliding on the boundary; local: hexes below "
                "0.35 among the geode hexes and those touching them (default); global: every hex "
                "below 0.5; none")
      ->check(CLI::IsMember({"local", "global", "none"}))
      ->capture_default_str();
  c->add_option("--quality", a.quality,
                "sj: validity and the scaled Jacobian per block (default, cheap); full: every "
                "metric of the paper's Table 1 per block")
      ->check(CLI::IsMember({"sj", "full"}))
      ->capture_default_str();
  c->add_flag("--quiet", a.quiet, "no progress and no summary");
}

void add_conform_commands(CLI::App& app) {
  auto args = std::make_shared<ConformArgs>();
  CLI::App* c = app.add_subcommand(
      "conform",
      "Conform the hex part of a model to its tet part with geode templates: buffer layer, "
      "dicing (8 per hex, 4 per tet), 26 geode hexes per interface quad.");
  c->add_option("INPUT", args->input, "input model (.msh, .exo, .e, .vtu, .vtk)")->required();
  add_run_options(c, *args);
  c->callback([args] {
    // Check the output name before the long run, not after it.
    if (!args->output.empty()) check_output_extension(args->output);
    run(read_model(args->input), *args, false, args->input);
  });

  auto dargs = std::make_shared<ConformArgs>();
  CLI::App* d = app.add_subcommand(
      "demo", "Build a demo model with the Gmsh API (--model) and conform it, printing the quality "
              "report per block; --save-input writes the model itself.");
  d->add_option("--model", dargs->model,
                 "half: structured hexes beside Kuhn-split transfinite tets (default); delaunay, "
                 "delaunay-random: beside a Delaunay tet box, interface diagonals alternating or "
                 "random; cylinder: a swept hex cylinder with unstructured quad caps in a tet box; "
                 "lshape: a hex block in the notch of an L-shaped tet part (concave interface); "
                 "nugget: a Delaunay tet cube in 26 structured blocks")
      ->check(CLI::IsMember(conform::demo_model_names()))
      ->capture_default_str();
  d->add_option("-n,--size", dargs->n, "cells per unit length (default 4; nugget rounds up to even)")
      ->check(CLI::PositiveNumber);
  d->add_option("--save-input", dargs->save_input,
                "write the demo's input model (.msh, .exo, .e) to try `geode conform` on it; "
                "without -o or --report nothing is conformed");
  add_run_options(d, *dargs);
  d->callback([dargs] {
    if (!dargs->output.empty()) check_output_extension(dargs->output);
    const primal::Model model = conform::demo_model(dargs->model, dargs->n);
    if (!dargs->save_input.empty()) {
      const std::string e = file_extension(dargs->save_input);
      if (e == ".vtu") throw InvalidInput(dargs->save_input + ": --save-input needs .msh, .exo or .e (a .vtu holds no tets)");
      write_model(model, dargs->save_input);
      if (!dargs->quiet)
        std::cout << "wrote " << dargs->save_input << " (" << model.hexes.size() << " hexes, "
                  << model.tets.size() << " tets)\n";
      if (dargs->output.empty() && dargs->report.empty()) return;
    }
    run(model, *dargs, true);
  });
}

}  // namespace geode::cli
