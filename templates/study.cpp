#include <geode/templates/study.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <geode/primal/errors.hpp>
#include <geode/primal/multilinear.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/topology.hpp>

namespace geode::templates {
namespace {

using primal::Index;
using primal::Point;

// FNV-1a over 64-bit words: a fixed, platform-independent hash, so that class keys written to
// CSV files are reproducible.
std::uint64_t fnv(std::uint64_t h, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) {
    h ^= (v >> (8 * i)) & 0xffu;
    h *= 1099511628211ull;
  }
  return h;
}
constexpr std::uint64_t kFnvSeed = 1469598103934665603ull;

std::uint64_t fnv(const std::string& s) {
  std::uint64_t h = kFnvSeed;
  for (unsigned char c : s) h = fnv(h, c);
  return h;
}

// "dome+dome+tunnel" for an element's sheets.
std::string kind_triple(const Template& t, const std::vector<int>& sheets) {
  std::vector<std::string> k;
  for (int s : sheets) k.push_back(t.sheets[primal::index_cast<std::size_t>(s)].kind);
  std::sort(k.begin(), k.end());
  std::string r;
  for (const auto& x : k) r += (r.empty() ? "" : "+") + x;
  return r;
}

// Box-face class of a node: tet side (top), hex side (bottom), on a side face, as bits.
unsigned node_class(unsigned faces) {
  const unsigned top = 1u << 3, bottom = 1u << 2;  // y high / y low (stc::box_face(1, .))
  unsigned sides = faces & ~(top | bottom);
  unsigned side_count = 0;
  for (; sides; sides &= sides - 1) ++side_count;
  return ((faces & top) ? 1u : 0u) | ((faces & bottom) ? 2u : 0u) | (side_count << 2);
}

std::string fmt(double x) {
  std::ostringstream s;
  s << std::setprecision(6) << x;
  return s.str();
}

std::string csv_quote(const std::string& s) {
  std::string r = "\"";
  for (char c : s) r += c == '"' ? std::string("\"\"") : std::string(1, c);
  return r + "\"";
}

// Obstructions and smoothed quality of a valid class's example template.
void measure_class(InterleaveClass& c, const Template& example) {
  c.obstructions = template_obstructions(example);
  Template fixed = example, slide = example;
  const auto f = smooth_template(fixed, false);
  const auto s = smooth_template(slide, true);
  c.min_sj_fixed = f.final_min_scaled_jacobian;
  c.min_sj_slide = s.final_min_scaled_jacobian;
  c.usable = c.obstructions.empty() && f.untangled && c.min_sj_fixed > 0.0;
}

// "doublet:10;pinched-corner:1", kinds in enum order.
std::string obstruction_counts(const std::vector<primal::Obstruction>& obstructions) {
  std::map<primal::ObstructionKind, int> count;
  for (const auto& o : obstructions) ++count[o.kind];
  std::string r;
  for (const auto& [kind, n] : count)
    r += (r.empty() ? "" : ";") + std::string(primal::to_string(kind)) + ":" + std::to_string(n);
  return r;
}

}  // namespace

std::string template_class_key(const Template& t) {
  const bool d3 = t.dim == 3;
  const std::size_t elements = d3 ? t.hex.hexes.size() : t.quad.quads.size();
  const std::size_t nodes = d3 ? t.hex.points.size() : t.quad.points.size();
  std::map<std::string, int> triples;
  std::vector<std::string> element_kind(elements);
  for (std::size_t e = 0; e < elements; ++e) {
    element_kind[e] = kind_triple(t, t.element_sheets[e]);
    ++triples[element_kind[e]];
  }
  // Bipartite incidence graph: nodes 0..nodes-1, elements after them.
  std::vector<std::vector<std::size_t>> adj(nodes + elements);
  for (std::size_t e = 0; e < elements; ++e) {
    const std::size_t k = d3 ? 8 : 4;
    for (std::size_t c = 0; c < k; ++c) {
      const auto n = primal::index_cast<std::size_t>(d3 ? t.hex.hexes[e][c] : t.quad.quads[e][c]);
      adj[n].push_back(nodes + e);
      adj[nodes + e].push_back(n);
    }
  }
  std::vector<std::uint64_t> colour(nodes + elements);
  for (std::size_t n = 0; n < nodes; ++n)
    colour[n] = fnv(fnv(kFnvSeed, 1), node_class(t.node_faces[n]));
  for (std::size_t e = 0; e < elements; ++e)
    colour[nodes + e] = fnv(fnv(kFnvSeed, 2), fnv(element_kind[e]));
  // Refine until the number of colour classes stops growing (an isomorphism-invariant stop).
  auto classes = [](const std::vector<std::uint64_t>& c) {
    return std::set<std::uint64_t>(c.begin(), c.end()).size();
  };
  std::size_t count = classes(colour);
  for (std::size_t round = 0; round < adj.size(); ++round) {
    std::vector<std::uint64_t> next(colour.size());
    for (std::size_t v = 0; v < adj.size(); ++v) {
      std::vector<std::uint64_t> nb;
      for (std::size_t w : adj[v]) nb.push_back(colour[w]);
      std::sort(nb.begin(), nb.end());
      std::uint64_t h = fnv(kFnvSeed, colour[v]);
      for (auto x : nb) h = fnv(h, x);
      next[v] = h;
    }
    colour.swap(next);
    const std::size_t c = classes(colour);
    if (c == count) break;
    count = c;
  }
  std::sort(colour.begin(), colour.end());
  std::uint64_t h = kFnvSeed;
  for (auto c : colour) h = fnv(h, c);
  std::ostringstream key;
  key << elements << (d3 ? "h" : "q") << "|";
  bool first = true;
  for (const auto& [k, n] : triples) key << (first ? "" : ",") << k << ":" << n, first = false;
  key << "|" << std::hex << std::setw(16) << std::setfill('0') << h;
  return key.str();
}

std::string strip_numbers(const std::string& message) {
  // Numbers that name a thing rather than measure it stay: "condition 1", "a 1-cell".
  static const std::regex number(R"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)");
  static const std::regex tuple(R"(\(\s*#(?:\s*,\s*#)*\s*\))");
  std::string s;
  std::size_t last = 0;
  for (auto it = std::sregex_iterator(message.begin(), message.end(), number);
       it != std::sregex_iterator(); ++it) {
    const auto pos = primal::index_cast<std::size_t>(it->position()),
               len = primal::index_cast<std::size_t>(it->length());
    const bool names = message.compare(pos + len, 5, "-cell") == 0 ||
                       (pos >= 10 && message.compare(pos - 10, 10, "condition ") == 0);
    s += message.substr(last, pos - last) + (names ? it->str() : "#");
    last = pos + len;
  }
  s += message.substr(last);
  return std::regex_replace(s, tuple, "(#)");
}

InterleaveStudy interleave_study(const GeodeOptions& base, const PushGrid& grid,
                                 const std::string& template_name, const StudyProgress& progress) {
  std::vector<InterleaveCase> cases;
  for (double high : grid.high_roof)
    for (double low : grid.low_roof) {
      if (!(0 < low && low < high && high < 1)) continue;
      for (double depth : grid.dome_depth)
        for (double radius : grid.dome_radius) {
          GeodeOptions o = base;
          o.push = {high, low, depth, radius};
          cases.push_back({o.push, {}, [o] { return build_geode3d(o); }});
        }
    }
  return interleave_study(cases, template_name, {}, progress);
}

void check_sweep_size(const std::vector<std::size_t>& counts, const std::string& where) {
  double product = 1;
  for (std::size_t c : counts) product *= static_cast<double>(c);
  if (product > kMaxSweepPoints) {
    std::string f;
    for (std::size_t c : counts) f += (f.empty() ? "" : " x ") + std::to_string(c);
    std::ostringstream m;
    m << where << ": " << f << " = " << product << " sweep points; at most " << kMaxSweepPoints
      << " (sweep fewer values, or split the study)";
    throw InvalidInput(m.str());
  }
}

InterleaveStudy interleave_study(const nlohmann::json& spec, const std::string& source,
                                 const std::vector<SweepAxis>& axes,
                                 const std::string& template_name, const StudyProgress& progress) {
  // Here, not in the command alone: geode.study_interleave ran a 200 x 200 sweep unbounded.
  std::vector<std::size_t> counts;
  for (const auto& x : axes) counts.push_back(x.values.size());
  check_sweep_size(counts, source);
  std::vector<InterleaveCase> cases;
  std::vector<std::string> names;
  for (const auto& a : axes) names.push_back(a.path);
  int skipped = 0;
  std::vector<std::size_t> at(axes.size(), 0);
  for (bool more = true; more;) {
    nlohmann::json j = spec;
    InterleaveCase c;
    for (std::size_t i = 0; i < axes.size(); ++i) {
      c.parameters.push_back(axes[i].values[at[i]]);
      set_spec_number(j, axes[i].path, c.parameters.back(), source);
    }
    try {
      const ArrangementSpec s = parse_spec(j, source);
      if (s.completion) c.push = s.completion->push;
      c.build = [s] { return build_template(s); };
      cases.push_back(c);
    } catch (const InvalidInput&) {
      ++skipped;
    }
    // Odometer over the axes, the last fastest.
    more = false;
    for (std::size_t i = axes.size(); i-- > 0;) {
      if (++at[i] < axes[i].values.size()) {
        more = true;
        break;
      }
      at[i] = 0;
    }
  }
  InterleaveStudy study = interleave_study(cases, template_name, names, progress);
  study.skipped = skipped;
  return study;
}

InterleaveStudy interleave_study(const std::vector<InterleaveCase>& cases,
                                 const std::string& template_name,
                                 const std::vector<std::string>& parameter_names,
                                 const StudyProgress& progress) {
  InterleaveStudy study;
  study.template_name = template_name;
  study.parameter_names = parameter_names;
  struct Outcome {
    bool valid;
    std::string key;
    int hexes = 0;
    int count = 0;
    int ok = 0;
    PushParameters example;
    std::vector<double> example_parameters;
    Template example_template;  // valid classes
  };
  // Every push is built on its own (TBB, one case per task: a push takes tens of milliseconds
  // to seconds) into its own slot; the runs are then grouped into classes in case order, so the
  // tables are the same for any thread count.
  struct Built {
    InterleaveRun run;
    std::string key;
    Template t;
  };
  std::vector<Built> built(cases.size());
  std::atomic<std::size_t> done{0};
  std::mutex progress_mutex;  // the callback is called from one thread at a time
  auto report = [&](const char* what, std::size_t total) {
    const std::size_t d = ++done;
    if (!progress) return;
    std::lock_guard lock(progress_mutex);
    progress(what, d, total);
  };
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, cases.size(), 1),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const InterleaveCase& cs = cases[i];
          InterleaveRun& run = built[i].run;
          run.push = cs.push;
          run.parameters = cs.parameters;
          const auto t0 = std::chrono::steady_clock::now();
          try {
            Template& t = built[i].t;
            t = cs.build();
            run.valid = true;
            run.hexes = static_cast<int>(t.dim == 3 ? t.hex.hexes.size() : t.quad.quads.size());
            run.conditions_ok = t.checks.ok();
            std::set<std::string> failed;
            for (const auto& f : t.checks.failures) failed.insert(strip_numbers(f));
            for (const auto& f : failed) run.conditions += (run.conditions.empty() ? "" : "; ") + f;
            built[i].key = template_class_key(t);
          } catch (const TopologyError& e) {
            run.diagnosis = strip_numbers(e.what());
            built[i].key = run.diagnosis;
          }
          run.seconds =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          report("pushes", cases.size());
        }
      });
  std::map<std::pair<bool, std::string>, Outcome> outcomes;
  std::vector<std::string> keys;  // per run
  for (Built& b : built) {
    InterleaveRun& run = b.run;
    auto& oc = outcomes[{run.valid, b.key}];
    if (oc.count == 0)
      oc = {run.valid, b.key, run.hexes, 0, 0, run.push, run.parameters, std::move(b.t)};
    ++oc.count;
    oc.ok += run.conditions_ok ? 1 : 0;
    keys.push_back(std::move(b.key));
    study.runs.push_back(std::move(run));
    b.t = Template();  // only the first of a class is kept
  }
  primal::release(built);
  std::vector<const Outcome*> order;
  for (const auto& [k, oc] : outcomes) order.push_back(&oc);
  std::stable_sort(order.begin(), order.end(), [](const Outcome* a, const Outcome* b) {
    if (a->valid != b->valid) return a->valid;
    if (a->count != b->count) return a->count > b->count;
    return a->key < b->key;
  });
  std::map<std::pair<bool, std::string>, std::string> label;
  int nv = 0, ne = 0;
  for (const Outcome* oc : order) {
    InterleaveClass c;
    c.valid = oc->valid;
    c.label = oc->valid ? "V" + std::to_string(++nv) : "E" + std::to_string(++ne);
    c.key = oc->key;
    c.hexes = oc->hexes;
    c.count = oc->count;
    c.conditions_ok = oc->ok;
    c.example = oc->example;
    c.example_parameters = oc->example_parameters;
    label[{c.valid, c.key}] = c.label;
    study.classes.push_back(c);
  }
  // Each valid class's example smoothed (twice) on its own, in parallel, into its own slot.
  done = 0;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        if (study.classes[i].valid)
                          measure_class(study.classes[i], order[i]->example_template);
                        report("classes", order.size());
                      }
                    });
  for (std::size_t r = 0; r < study.runs.size(); ++r)
    study.runs[r].class_label = label.at({study.runs[r].valid, keys[r]});
  return study;
}

void write_interleave_csv(std::ostream& out, const InterleaveStudy& study) {
  out << "high_roof,low_roof,dome_depth,dome_radius,outcome,hexes,class,conditions_ok,diagnosis";
  for (const auto& p : study.parameter_names) out << "," << csv_quote(p);
  out << "\n";
  for (const auto& r : study.runs) {
    out << fmt(r.push.high_roof) << "," << fmt(r.push.low_roof) << "," << fmt(r.push.dome_depth)
        << "," << fmt(r.push.dome_radius) << "," << (r.valid ? "valid" : "error") << "," << r.hexes
        << "," << r.class_label << "," << (r.valid ? (r.conditions_ok ? "1" : "0") : "") << ","
        << csv_quote(r.valid ? r.conditions : r.diagnosis);
    for (double p : r.parameters) out << "," << fmt(p);
    out << "\n";
  }
}

void write_interleave_summary(std::ostream& out, const InterleaveStudy& study) {
  out << "class,outcome,count,hexes,conditions_ok,example_high_roof,example_low_roof,example_dome_"
         "depth,"
         "example_dome_radius,key,obstructions,min_sj_fixed,min_sj_slide,usable";
  for (const auto& p : study.parameter_names) out << "," << csv_quote("example_" + p);
  out << "\n";
  for (const auto& c : study.classes) {
    out << c.label << "," << (c.valid ? "valid" : "error") << "," << c.count << "," << c.hexes
        << "," << c.conditions_ok << "," << fmt(c.example.high_roof) << ","
        << fmt(c.example.low_roof) << "," << fmt(c.example.dome_depth) << ","
        << fmt(c.example.dome_radius) << "," << csv_quote(c.key) << ",";
    if (c.valid)
      out << obstruction_counts(c.obstructions) << "," << fmt(c.min_sj_fixed) << ","
          << fmt(c.min_sj_slide) << "," << (c.usable ? 1 : 0);
    else
      out << ",,,";
    for (double p : c.example_parameters) out << "," << fmt(p);
    out << "\n";
  }
}

// ---- Shape study ---------------------------------------------------------------------------

CellCorners box_cell(const Eigen::Vector3d& box) {
  CellCorners c;
  for (int i = 0; i < 8; ++i)
    c[primal::index_cast<std::size_t>(i)] =
        Point((i & 1 ? 0.5 : -0.5) * box.x(), (i & 2 ? 0.5 : -0.5) * box.y(),
              (i & 4 ? 0.5 : -0.5) * box.z());
  return c;
}

CellCorners sheared_cell(const Eigen::Vector3d& box, double angle_degrees) {
  CellCorners c = box_cell(box);
  const double shift = box.y() * std::tan(angle_degrees * M_PI / 180.0);
  for (int i = 0; i < 8; ++i)
    if (i & 2) c[primal::index_cast<std::size_t>(i)].x() += shift;
  return c;
}

CellCorners tapered_cell(const Eigen::Vector3d& box, double ratio) {
  CellCorners c = box_cell(box);
  for (int i = 0; i < 8; ++i)
    if (i & 2)
      c[primal::index_cast<std::size_t>(i)].x() *= ratio,
          c[primal::index_cast<std::size_t>(i)].z() *= ratio;
  return c;
}

primal::SmoothResult smooth_in_cell(Template& t, const Eigen::Vector3d& box_of_t,
                                    const CellCorners& cell, bool slide) {
  if (t.dim != 3) throw InvalidInput("smooth_in_cell: needs a 3D template");
  // Face planes: face 2*axis + high holds the corners whose bit `axis` equals high.
  std::array<Point, 6> origin, normal;
  for (int axis = 0; axis < 3; ++axis)
    for (int high = 0; high < 2; ++high) {
      std::vector<Point> q;
      for (int i = 0; i < 8; ++i)
        if (((i >> axis) & 1) == high) q.push_back(cell[primal::index_cast<std::size_t>(i)]);
      // q is ordered as the two remaining bits; its diagonals are q0-q3 and q1-q2.
      Point n = (q[3] - q[0]).cross(q[2] - q[1]);
      const Point centre = 0.25 * (q[0] + q[1] + q[2] + q[3]);
      for (const auto& p : q)
        if (std::abs(n.normalized().dot(p - centre)) > 1e-9 * (q[3] - q[0]).norm())
          throw InvalidInput("smooth_in_cell: face " + std::to_string(2 * axis + high) +
                             " of the cell is not planar");
      origin[primal::index_cast<std::size_t>(2 * axis + high)] = centre;
      normal[primal::index_cast<std::size_t>(2 * axis + high)] = n.normalized();
    }
  // Trilinear map (primal/multilinear.hpp) of the reference position in [0, 1]^3; the cell's
  // corners are numbered bitwise here (bx + 2 by + 4 bz), VTK corner c is the one at
  // kHexCornerCoords[c].
  std::array<Point, 8> vtk;
  for (int c = 0; c < 8; ++c) {
    const auto& rc = primal::topology::kHexCornerCoords[primal::index_cast<std::size_t>(c)];
    vtk[primal::index_cast<std::size_t>(c)] =
        cell[primal::index_cast<std::size_t>(rc[0] + 2 * rc[1] + 4 * rc[2])];
  }
  for (auto& p : t.hex.points)
    p = primal::multilinear_point(
        vtk,
        Point(p.x() / box_of_t.x() + 0.5, p.y() / box_of_t.y() + 0.5, p.z() / box_of_t.z() + 0.5),
        3);
  std::vector<primal::NodeConstraint> c;
  for (std::size_t n = 0; n < t.hex.points.size(); ++n) {
    std::vector<int> faces;
    for (int f = 0; f < 6; ++f)
      if ((t.node_faces[n] >> f) & 1u) faces.push_back(f);
    const bool tet_or_hex_side =
        std::any_of(faces.begin(), faces.end(), [](int f) { return f / 2 == 1; });
    if (faces.size() >= 3 || (tet_or_hex_side && !slide)) {
      c.push_back(primal::NodeConstraint::fixed());
    } else if (faces.size() == 2) {
      const Point d = normal[primal::index_cast<std::size_t>(faces[0])].cross(
          normal[primal::index_cast<std::size_t>(faces[1])]);
      c.push_back(primal::NodeConstraint::line(t.hex.points[n], d));
    } else if (faces.size() == 1) {
      const auto f = primal::index_cast<std::size_t>(faces[0]);
      c.push_back(primal::NodeConstraint::plane(origin[f], normal[f]));
    } else {
      c.push_back(primal::NodeConstraint::free());
    }
  }
  return primal::smooth_hex_mesh(t.hex, c);
}

namespace {

ShapeRow shape_row(const std::string& cell, double parameter, bool slide,
                   const primal::SmoothResult& r) {
  ShapeRow row;
  row.cell = cell;
  row.parameter = parameter;
  row.mode = slide ? "slide" : "fixed";
  row.initial_min_sj = r.initial_min_scaled_jacobian;
  row.final_min_sj = r.final_min_scaled_jacobian;
  row.final_max_sj = r.final_max_scaled_jacobian;
  row.untangled = r.untangled;
  row.iterations = r.iterations;
  row.seconds = r.seconds;
  return row;
}

}  // namespace

std::vector<ShapeRow> height_study(const std::vector<double>& heights, double base) {
  std::vector<ShapeRow> rows;
  for (double h : heights) {
    GeodeOptions o;
    o.box = Eigen::Vector3d(base, h, base);
    const Template ref = build_geode3d(o);
    for (bool slide : {false, true}) {
      Template t = ref;
      rows.push_back(shape_row("box", h, slide, smooth_template(t, slide)));
    }
  }
  return rows;
}

std::vector<ShapeRow> distorted_study(const std::vector<double>& shear_degrees,
                                      const std::vector<double>& taper_ratios) {
  std::vector<ShapeRow> rows;
  GeodeOptions o;
  const Eigen::Vector3d box = o.box;
  const Template reference = build_geode3d(o);
  for (double a : shear_degrees)
    for (bool slide : {false, true}) {
      Template t = reference;
      rows.push_back(
          shape_row("shear", a, slide, smooth_in_cell(t, box, sheared_cell(box, a), slide)));
    }
  for (double r : taper_ratios)
    for (bool slide : {false, true}) {
      Template t = reference;
      rows.push_back(
          shape_row("taper", r, slide, smooth_in_cell(t, box, tapered_cell(box, r), slide)));
    }
  return rows;
}

void write_shape_csv(std::ostream& out, const std::vector<ShapeRow>& rows) {
  out << "cell,parameter,mode,initial_min_sj,final_min_sj,final_max_sj,untangled,iterations,"
         "seconds\n";
  for (const auto& r : rows)
    out << r.cell << "," << fmt(r.parameter) << "," << r.mode << "," << fmt(r.initial_min_sj) << ","
        << fmt(r.final_min_sj) << "," << fmt(r.final_max_sj) << "," << (r.untangled ? 1 : 0) << ","
        << r.iterations << "," << fmt(r.seconds) << "\n";
}

const std::vector<PaperRow>& paper_table1() {
  // The paper's Table 1, "CUBIT quality report for a 24 x 14 x 24 geode-template".
  using M = primal::HexMetric;
  static const std::vector<PaperRow> rows = {
      {M::kAspectRatio, 1.75, 0.55, 1.07, 3.07},   {M::kSkew, 0.54, 0.16, 0.17, 0.76},
      {M::kTaper, 0.30, 0.13, 0.038, 0.76},        {M::kVolume, 300, 223, 97, 786},
      {M::kStretch, 0.41, 0.13, 0.25, 0.63},       {M::kDiagonal, 0.53, 0.09, 0.38, 0.74},
      {M::kDimension, 3.19, 0.94, 1.97, 5.00},     {M::kJacobian, 69.9, 44, 26, 164},
      {M::kScaledJacobian, 0.34, 0.09, 0.26, 0.53}};
  return rows;
}

void write_geode_quality(std::ostream& report_csv, std::ostream* per_hex_csv) {
  report_csv << "metric,key,mode,average,std_dev,min,max,paper_average,paper_std_dev,paper_min,"
                "paper_max\n";
  if (per_hex_csv) *per_hex_csv << "mode,hex,scaled_jacobian\n";
  std::vector<primal::HexMetric> metrics;
  for (const auto& p : paper_table1()) metrics.push_back(p.metric);
  const Template ref = build_geode3d(GeodeOptions{});
  for (bool slide : {false, true}) {
    Template t = ref;
    smooth_template(t, slide);
    const auto report = primal::hex_quality_report(t.hex, {}, metrics);
    const char* mode = slide ? "slide" : "fixed";
    for (std::size_t i = 0; i < metrics.size(); ++i) {
      const auto& m = report.metrics[i];
      const auto& p = paper_table1()[i];
      const auto& info = primal::hex_metric_info(m.metric);
      report_csv << info.name << "," << info.key << "," << mode << "," << fmt(m.average) << ","
                 << fmt(m.std_dev) << "," << fmt(m.minimum) << "," << fmt(m.maximum) << ","
                 << fmt(p.average) << "," << fmt(p.std_dev) << "," << fmt(p.minimum) << ","
                 << fmt(p.maximum) << "\n";
    }
    if (per_hex_csv)
      for (std::size_t h = 0; h < t.hex.hexes.size(); ++h)
        *per_hex_csv << mode << "," << h + 1 << ","
                     << fmt(primal::hex_scaled_jacobian(
                            primal::hex_corners(t.hex, primal::index_cast(h))))
                     << "\n";
  }
}

}  // namespace geode::templates
