// geode dual MESH: a hex (or quad) mesh seen as its sheet arrangement (the STC from the primal
// side: stc/mesh_dual), and with --rebuild the same sheets handed to the arrangement engine and
// dualized back (stc/mesh_fields, compute_arrangement, dualize).
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include <geode/io/formats.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/model.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include <geode/stc/mesh_dual.hpp>
#include <geode/stc/mesh_fields.hpp>
#include "cli/commands.hpp"
#include "cli/conventions.hpp"
#include "cli/progress.hpp"

namespace geode::cli {
namespace {

namespace fs = std::filesystem;
using primal::Index;

struct DualArgs {
  std::string input;
  std::string format;  // empty: by the extension of -o, else text
  std::string output;
  std::string rebuild;
  EncodingArgs encoding;  // --vtk-encoding, --msh-encoding
  bool write_invalid = false;
  bool force = false;
  bool quiet = false;
};

template <class Dual>
nlohmann::json dual_json(const Dual& dual, Index nodes, Index cells) {
  nlohmann::json j;
  j["nodes"] = nodes;
  j["cells"] = cells;
  j["sheets"] = nlohmann::json::array();
  for (std::size_t s = 0; s < dual.sheets.size(); ++s) {
    const auto& sh = dual.sheets[s];
    int closed = 0;
    for (const auto& t : sh.trace) closed += t.closed;
    j["sheets"].push_back({{"sheet", s},
                           {"edges", sh.edges.size()},
                           {"crossings", sh.cells.size()},
                           {"self_intersecting", sh.self_intersecting},
                           {"trace_pieces", sh.trace.size()},
                           {"closed_trace_pieces", closed}});
  }
  j["intersections"] = nlohmann::json::array();
  for (const auto& [tuple, count] : dual.intersections)
    j["intersections"].push_back(
        {{"sheets", std::vector<Index>(tuple.begin(), tuple.end())}, {"cells", count}});
  return j;
}

std::string dual_text(const nlohmann::json& j, int dim) {
  std::ostringstream s;
  const char* cell = dim == 3 ? "hexes" : "quads";
  const char* sheet = dim == 3 ? "sheets" : "chords";
  s << j["nodes"].get<Index>() << " nodes, " << j["cells"].get<Index>() << " " << cell << ", "
    << j["sheets"].size() << " " << sheet << "\n\n";
  s << (dim == 3 ? "sheet" : "chord")
    << "\tedges\tcrossings\tself-intersecting\tboundary trace pieces (closed)\n";
  for (const auto& sh : j["sheets"])
    s << sh["sheet"].get<Index>() << "\t" << sh["edges"].get<std::size_t>() << "\t"
      << sh["crossings"].get<std::size_t>() << "\t"
      << (sh["self_intersecting"].get<bool>() ? "yes" : "no") << "\t"
      << sh["trace_pieces"].get<std::size_t>() << " (" << sh["closed_trace_pieces"].get<int>()
      << ")\n";
  s << "\n" << (dim == 3 ? "triple" : "crossing") << "\t" << cell << " where they meet\n";
  for (const auto& t : j["intersections"]) {
    std::string tuple;
    for (Index x : t["sheets"]) tuple += (tuple.empty() ? "" : " ") + std::to_string(x);
    s << tuple << "\t" << t["cells"].get<Index>() << "\n";
  }
  return s.str();
}

// The sorted multiset of cells per sheet tuple: equal for isomorphic meshes (whatever the
// sheet numbering), a cheap cross-check of a rebuild.
template <class Dual>
std::vector<Index> tuple_counts(const Dual& d) {
  std::vector<Index> c;
  for (const auto& [t, n] : d.intersections) c.push_back(n);
  std::sort(c.begin(), c.end());
  return c;
}

void run_dual(const DualArgs& a) {
  // Outputs are checked before the input is read and the engine runs.
  check_output_path(a.output);
  const std::string format = output_format(a.output, a.format, {"text", "json"}, "text");
  std::string rebuild_format;
  if (!a.rebuild.empty()) {
    check_output_path(a.rebuild);
    rebuild_format = output_format(a.rebuild, "", mesh_format_names(), "");
  }
  check_not_input(a.output, a.input, a.force);
  check_not_input(a.rebuild, a.input, a.force);
  const fs::path in(a.input);
  Progress progress = Progress::for_stderr(a.quiet);
  const MeshFile m = read_mesh_file(in);
  progress.stage_done(read_line(a.input, m));
  if (m.dim == 2 && !rebuild_format.empty() && !io::find_mesh_format(rebuild_format)->write_quads)
    throw InvalidInput(a.rebuild + ": " + a.input + " is a quad mesh; rebuild it as " +
                       quad_output_extensions());
  nlohmann::json j;
  std::vector<Index> counts;
  // A mesh of millions of cells takes tens of seconds here: say how far it is.
  stc::MeshDualOptions dual_options;
  dual_options.progress = [&progress, what = dual_step(m.dim)](std::size_t done,
                                                               std::size_t total) {
    progress.step(what, done, total);
  };
  // The library knows cells and nodes by position: the refusal names the file, and says so
  // (it said "edge 1-5 lies on 4 boundary quads" with neither; a hunt's).
  const std::string numbering = std::string(" (") + (m.dim == 3 ? "hexes" : "quads") +
                                " and nodes numbered from 0 in the file's order)";
  try {
    if (m.dim == 3) {
      const auto dual = stc::mesh_dual(m.hex, dual_options);
      progress.stage_done("dual: " + std::to_string(dual.sheets.size()) + " sheets");
      j = dual_json(dual, primal::index_cast(m.hex.points.size()),
                    primal::index_cast(m.hex.hexes.size()));
      counts = tuple_counts(dual);
    } else {
      const auto dual = stc::mesh_dual(m.quad, dual_options);
      progress.stage_done("dual: " + std::to_string(dual.sheets.size()) + " chords");
      j = dual_json(dual, primal::index_cast(m.quad.points.size()),
                    primal::index_cast(m.quad.quads.size()));
      counts = tuple_counts(dual);
    }
  } catch (const InvalidInput& x) {
    throw InvalidInput(a.input + ": " + x.what() + numbering);
  } catch (const TopologyError& x) {
    throw TopologyError(a.input + ": " + x.what() + numbering);
  }
  j["input"] = a.input;
  j["dimension"] = m.dim;

  stc::DualMesh D;
  if (!a.rebuild.empty()) {
    // Name the input in what the engine reports (it only knows hexes and sheets by number).
    try {
      const stc::MeshArrangementInput fields =
          m.dim == 3 ? stc::sheet_fields(m.hex) : stc::sheet_fields(m.quad);
      progress.stage_done("sheet fields");
      // A large mesh has many sheets and the engine meets every pair: say how far it is.
      stc::ArrangementOptions options;
      options.progress =
          [&progress, what = std::string(m.dim == 3 ? "sheet pairs traced" : "chords traced")](
              std::size_t done, std::size_t total) { progress.step(what, done, total); };
      D = stc::dualize(stc::compute_arrangement(fields.sheets, fields.domain, options));
    } catch (const InvalidInput& x) {
      throw InvalidInput(a.input + ": cannot rebuild: " + x.what() + numbering);
    } catch (const TopologyError& x) {
      throw TopologyError(a.input + ": cannot rebuild: " + x.what() + numbering);
    }
    nlohmann::json r;
    r["file"] = a.rebuild;
    r["nodes"] = m.dim == 3 ? D.hex.points.size() : D.quad.points.size();
    r["cells"] = m.dim == 3 ? D.hex.hexes.size() : D.quad.quads.size();
    const std::vector<Index> rebuilt =
        m.dim == 3 ? tuple_counts(stc::mesh_dual(D.hex)) : tuple_counts(stc::mesh_dual(D.quad));
    r["same_counts"] = rebuilt == counts && r["nodes"] == j["nodes"] && r["cells"] == j["cells"];
    j["rebuild"] = r;
    progress.stage_done("rebuilt: " + std::to_string(r["cells"].get<std::size_t>()) +
                        (m.dim == 3 ? " hexes" : " quads"));
  }

  std::string text;
  if (format == "json") {
    text = json_text(j, 2);
  } else {
    text = dual_text(j, m.dim);
    if (j.contains("rebuild")) {
      const auto& r = j["rebuild"];
      text += "\nrebuilt through the arrangement engine: " +
              std::to_string(r["nodes"].get<std::size_t>()) + " nodes, " +
              std::to_string(r["cells"].get<std::size_t>()) + (m.dim == 3 ? " hexes" : " quads") +
              " -> " + a.rebuild + "\n  same node, cell and intersection counts as the input: " +
              (r["same_counts"].get<bool>() ? "yes" : "NO") + "\n";
    }
  }
  progress.stage_done("report: " + std::to_string(j["intersections"].size()) +
                      (m.dim == 3 ? " sheet triples" : " chord crossings"));
  // The rebuilt mesh passes the one validity check before anything is written (its ids as the
  // rebuilt file numbers them); the report and the mesh are written as one (both or neither).
  std::string invalid;
  const std::string what = a.input + ": the rebuilt mesh " + a.rebuild;
  if (!a.rebuild.empty()) {
    const primal::Index base = output_index_base(rebuild_format);
    invalid = m.dim == 3 ? invalid_mesh_reason(D.hex, base) : invalid_mesh_reason(D.quad, base);
    progress.stage_done(std::string("validity of the rebuilt mesh: ") +
                        (invalid.empty() ? "valid" : "invalid"));
    refuse_invalid(what, invalid, a.write_invalid);
  }
  OutputFiles files;
  if (!a.rebuild.empty())
    files.add(a.rebuild, [&](const fs::path& temp) {
      const io::WriteOptions options = write_options(a.encoding);
      if (m.dim == 2) {
        io::write_quad_mesh(D.quad, temp, rebuild_format, options);
      } else {
        primal::Model model;
        model.points = D.hex.points;
        model.hexes = D.hex.hexes;
        io::write_model(model, temp, rebuild_format, options);
      }
    });
  const bool to_file = !a.output.empty() && a.output != "-";
  if (to_file)
    files.add(a.output, [&](const fs::path& temp) {
      write_or_print(temp.string(), [&](std::ostream& os) { os << text; });
    });
  if (!to_file) std::cout << text;  // first: commit() publishes nothing if it was lost
  files.commit();
  invalid_written(what, invalid);
}

}  // namespace

void add_dual_command(CLI::App& app) {
  auto a = std::make_shared<DualArgs>();
  CLI::App* d = app.add_subcommand("dual",
                                   "A mesh's dual: its sheets (chords in 2D), each sheet's "
                                   "crossings and boundary trace, and how many\n"
                                   "hexes each triple of sheets meets in. --rebuild realizes those "
                                   "sheets as fields, computes their\n"
                                   "arrangement and dualizes it back (stc/mesh_fields.hpp): for a "
                                   "mesh that fills a box with positively\n"
                                   "oriented cells and sheets that do not cross themselves, the "
                                   "result is the same mesh up to numbering.");
  d->add_option("mesh", a->input, hex_or_quad_input_help())->required();
  d->add_option(
       "--format", a->format,
       "report format: text (tables; default) or json; without it the extension of -o decides\n"
       "(.txt, .json); one that contradicts the extension is refused")
      ->check(CLI::IsMember({"text", "json"}));
  d->add_option("-o,--output", a->output, "Write the report here instead of standard output");
  d->add_option(
      "--rebuild", a->rebuild,
      "Rebuild the mesh from its sheets through the arrangement engine; write it here, the\n"
      "format by the extension: " +
          io::extension_list(io::FormatRole::kWrite, ", ", ", ") +
          " (hexes; quads: " + io::extension_list(io::FormatRole::kWriteQuads, ", ", ", ") + ")");
  add_write_invalid_flag(d, a->write_invalid);
  add_force_flag(d, a->force);
  add_encoding_options(d, a->encoding);
  add_quiet_flag(d, a->quiet);
  d->callback([a] { run_dual(*a); });
}

}  // namespace geode::cli
