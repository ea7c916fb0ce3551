#include <geode/conform/conform.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <limits>
#include <map>
#include <numeric>
#include <span>
#include <sstream>
#include <system_error>
#include <thread>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <geode/conform/reference_template.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/dice.hpp>
#include <geode/primal/dice_model.hpp>
#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/interface.hpp>
#include <geode/primal/multilinear.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/quality_report.hpp>
#include <geode/primal/relax_tets.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/smooth.hpp>
#include <geode/primal/split_pyramids.hpp>
#include <geode/primal/split_wedges.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity_local.hpp>

namespace geode::conform {
namespace {

using primal::FaceKey;
using primal::Index;
using primal::kInvalidIndex;
using primal::kNoOrigin;
using primal::Point;
namespace topo = primal::topology;

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The output's block ids and names: the input's, plus the geode block when it has a name.
struct OutputBlocks {
  int geode_id = 0;  // 0: geode hexes join the block of the element they were carved from
  std::map<int, std::string> names;
};

OutputBlocks output_blocks(const primal::Model& input, const std::string& geode_block) {
  OutputBlocks o;
  o.names = input.block_names;
  if (geode_block.empty()) return o;
  int top = 0;
  for (primal::ElementKind kind : primal::kElementKinds)
    for (std::size_t e = 0; e < primal::element_count(input, kind); ++e)
      top = std::max(top, primal::block_of(input, {kind, primal::index_cast(e)}));
  o.geode_id = top + 1;
  o.names[o.geode_id] = geode_block;
  return o;
}

// A four-triangle top (a centre node, `centre`, at (r, s) = (1/2, 1/2)) at (r, s): linear over
// each of its four triangles, as buffer_map's two-triangle tops are.
Point four_triangle_top(const std::array<Point, 8>& P, const Point& centre, double r, double s) {
  // Top corners 4..7 at (r, s) = (0,0), (1,0), (1,1), (0,1); triangle i is (4+i, 4+(i+1)%4,
  // centre), the one whose side of the square is nearest to (r, s).
  const std::array<double, 4> side_distance{s, 1 - r, 1 - s, r};
  const int i = static_cast<int>(std::min_element(side_distance.begin(), side_distance.end()) -
                                 side_distance.begin());
  constexpr std::array<std::array<double, 2>, 4> kAt{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
  const auto& a = kAt[i];
  const auto& b = kAt[(i + 1) % 4];
  // Barycentric coordinates of (r, s) in (a, b, (1/2, 1/2)).
  const double ux = b[0] - a[0], uy = b[1] - a[1], vx = 0.5 - a[0], vy = 0.5 - a[1];
  const double px = r - a[0], py = s - a[1], det = ux * vy - uy * vx;
  const double lb = (px * vy - py * vx) / det, lc = (ux * py - uy * px) / det;
  return (1 - lb - lc) * P[4 + i] + lb * P[4 + (i + 1) % 4] + lc * centre;
}

// The map of the reference cell into a buffer hex: bilinear on the bottom (the hex side's
// quad), piecewise linear over the two triangles of the top (so the tet side's diced nodes,
// edge midpoints and triangle centroids, are images of the template's), linear in t between
// them. The trilinear map would instead follow a twisted top's bilinear surface, whose
// diagonal midpoint passes the template nodes under it; this one keeps every template hex
// positive wherever the buffer hex is valid. With `centre`, the top is four_triangle_top.
Point buffer_map(const std::array<Point, 8>& P, const std::array<int, 2>& diagonal,
                 const Point& rst, const Point* centre = nullptr) {
  const double r = rst.x(), s = rst.y(), t = rst.z();
  const Point bottom = primal::multilinear_point(P, Point(r, s, 0.0), 2);
  // Top corners 4..7 at (r, s) = (0,0), (1,0), (1,1), (0,1).
  Point top;
  if (centre) {
    top = four_triangle_top(P, *centre, r, s);
  } else if (diagonal[0] == 4) {  // split 4-6: the line r = s
    top = r >= s ? P[4] + r * (P[5] - P[4]) + s * (P[6] - P[5])
                 : P[4] + s * (P[7] - P[4]) + r * (P[6] - P[7]);
  } else {  // split 5-7: the line r + s = 1
    top = r + s <= 1 ? P[4] + r * (P[5] - P[4]) + s * (P[7] - P[4])
                     : P[6] + (1 - r) * (P[7] - P[6]) + (1 - s) * (P[5] - P[6]);
  }
  return (1 - t) * bottom + t * top;
}

// conform()'s stages, in the order run() calls them; each reads what the previous ones left.
class Conformer {
 public:
  // `given`: the input's points as the caller gave them, when conform moved some before
  // (ConformRelax): the yardsticks reported are the input's own cells; what smoothing aims at
  // follows the cells as they are diced.
  // `disposable`: the input itself when conform may change it (its own copy, with relaxed tets
  // or split pyramids, or the caller's given up), which run() trims to its blocks, and `given`
  // frees, once the buffer layer holds the model.
  Conformer(const primal::Model& input, const ConformOptions& options,
            std::vector<primal::Point>* given = nullptr, primal::Model* disposable = nullptr)
      : input_(input),
        options_(options),
        given_(given ? *given : input.points),
        given_copy_(given),
        disposable_(disposable) {}

  // The wedges run() found joining the two sides of the interface, where it stopped.
  const std::vector<Index>& joining() const { return joining_; }

  ConformResult run() {
    const auto t_start = Clock::now();
    find_interface();
    if (!joining_.empty()) return {};  // conform() splits their wedge pieces and starts again
    insert_buffer();
    trim_input();
    build_references();
    dice_and_merge();
    place_templates();
    match_sides();
    assemble();
    settle_templates();
    smooth();
    invert_for_test();
    verify_and_output();
    res_.seconds = since(t_start);
    return std::move(res_);
  }

 private:
  void say(const std::string& line) const {
    if (options_.progress) options_.progress(line);
  }
  std::string took() const { return " (" + std::to_string(since(t0_)) + " s)"; }
  const RefTemplate& ref(std::size_t b) const {
    if (layer_.hexes[b].centre != kInvalidIndex) return *refs_[2];
    return layer_.hexes[b].diagonal[0] == 5 ? *refs_[1] : *refs_[0];
  }

  void find_interface();
  void measure_near_interface();
  std::vector<double> local_minima(const std::vector<double>& tet) const;
  void insert_buffer();
  void thicker_from_tets();
  void measure_changed();
  void trim_input();
  void build_references();
  void dice_and_merge();
  void place_templates();
  void match_sides();
  void assemble();
  void diced_alone_from_children(std::size_t tet_first);
  void settle_templates();
  std::vector<std::pair<Index, Point>> settled(std::size_t b) const;
  void untangle();
  void add_smoothing(const primal::LocalSmoothResult& r);
  void smooth();
  void smooth_defects(primal::LocalSmoothOptions o);
  // aim: aims(); within: the hexes whose defects count (ascending; empty: all); start: the
  // floors, measured now if empty and a defect is found.
  void smooth_defect_passes(primal::LocalSmoothOptions o, const std::vector<double>& aim,
                            primal::SmoothStart& start, std::span<const Index> within);
  std::vector<double> aims() const;
  double measure();                            // every hex, then scan()
  void measure(std::span<const Index> hexes);  // these only, the others unchanged since
  double scan();                               // inverted_ and the minimum from sj_
  void check_dicing();
  bool verify_locally() const;
  void invert_for_test();
  void check(std::span<const Point> points, std::span<const std::array<Index, 8>> hexes);
  void ceilings(const std::vector<int>& block);
  void report(const std::vector<int>& block);
  void announce(double seconds) const;
  void output();
  void verify_and_output();

  const primal::Model& input_;
  const ConformOptions& options_;
  const std::vector<primal::Point>& given_;
  std::vector<primal::Point>* given_copy_;
  primal::Model* disposable_;
  ConformResult res_;
  Clock::time_point t0_;
  primal::Interface interface_;
  std::vector<Index> joining_;  // wedges joining the two sides of the interface (none: go on)
  BufferLayer layer_;
  primal::DicedModel diced_;
  std::array<const RefTemplate*, 3> refs_{};  // diagonal {4, 6}, {5, 7}, four triangles
  // Per buffer hex and template node: its global node, or (side-face nodes, until
  // match_sides) a disjoint-sets item at side_pos_.
  std::vector<std::vector<Index>> inst_global_, inst_side_;
  primal::DisjointSets side_sets_uf_;
  std::vector<Point> side_pos_;
  primal::HexMesh mesh_;
  std::vector<primal::NodeSet> node_sets_;
  std::vector<primal::SideSet> side_sets_;
  // Every output hex's scaled Jacobian (kept current by assemble, settling and smoothing) and
  // the hexes at or below 0 as of the last scan(); verification reads them.
  std::vector<double> sj_;
  std::vector<Index> inverted_;
  OutputBlocks blocks_;
  // Per buffer hex: the input element it was carved from (the hex under it or the tet above it,
  // by BufferLayerOptions::side), whose block its geode hexes join by default: they fill space
  // that part had.
  std::vector<primal::ElementRef> carved_from_;
  std::vector<double> hex_diced_, tet_diced_, wedge_diced_;  // per input cell: diced alone
  std::vector<double> tet_given_;  // per input tet: diced alone where the caller gave it
  // Per input hex and tet: 0, its figures are measured; kLater, read off its children; a tet
  // kLaterGiven, its figure as diced read off its children, as given measured apart (relaxed).
  // See measure_near_interface.
  static constexpr char kLater = 1, kLaterGiven = 2;
  std::vector<char> hex_later_, tet_later_;
  // What aims() reads: the yardstick, and per interface quad the higher of its local yardsticks
  // with the tets as diced (relaxed) and as given (reported).
  double aim_yardstick_ = 0.0;
  std::vector<double> aim_local_;
  std::vector<Eigen::Vector3d> proportion_;  // per buffer hex: buffer_proportions, as placed
  std::vector<Index> diced_parent_;          // per output diced hex (the first ones): its input hex
  std::vector<Index> geode_first_;  // per buffer hex: its first output hex (then one past the last)
  // The hexes whose nodes smoothing or untangling could move (their regions), for check().
  std::vector<Index> moved_;
  double dicing_check_seconds_ = 0.0;  // check_dicing, run while the dicing data exist
  std::vector<char> positive_;         // per output hex: its scaled Jacobian was above 0 (check())
};

void Conformer::find_interface() {
  res_.input_hexes = primal::index_cast(input_.hexes.size());
  res_.input_tets = primal::index_cast(input_.tets.size());
  res_.input_wedges = primal::index_cast(input_.wedges.size());
  if (primal::element_count(input_) == 0) throw InvalidInput("conform: the model has no elements");
  t0_ = Clock::now();
  // A model without tets, or without hexes and wedges, has no transition to make: it is simply
  // diced. Wedges are the hex part's where their quads meet tet triangles (a pyramid on a
  // wedge, split), and find_interface refuses a wedge joining the two sides around a node.
  if ((!input_.hexes.empty() || !input_.wedges.empty()) && !input_.tets.empty())
    interface_ = primal::find_interface(input_, options_.interface_tolerance, &joining_);
  if (!joining_.empty()) return;
  // Both parts but no shared quad: the parts were meshed apart (unmerged nodes, a gap).
  if (!input_.hexes.empty() && !input_.tets.empty() && interface_.quads.empty())
    throw InvalidInput("conform: the hex part and the tet part share no interface quad");
  measure_near_interface();
  wedge_diced_.reserve(input_.wedges.size());
  for (std::size_t w = 0; w < input_.wedges.size(); ++w)
    wedge_diced_.push_back(
        primal::diced_wedge_min_scaled_jacobian(input_.points, std::span(&input_.wedges[w], 1)));
  if (!wedge_diced_.empty())
    res_.input_diced_wedge_min_scaled_jacobian =
        *std::min_element(wedge_diced_.begin(), wedge_diced_.end());
  res_.local_yardstick = local_minima(tet_given_);
  aim_local_ = local_minima(tet_diced_);
  // Aims at least the reported local yardstick: relaxing the tets lowers a few quads' minima.
  for (std::size_t q = 0; q < aim_local_.size(); ++q)
    aim_local_[q] = std::max(aim_local_[q], res_.local_yardstick[q]);
  res_.interface_quads = primal::index_cast(interface_.quads.size());
  say("interface: " + std::to_string(interface_.quads.size()) + " quads" + took());
}

// The local yardstick per interface quad, with the tets diced as `tet` gives: per interface
// node the lowest element around it (hexes, tets and wedges diced alone), per quad over its
// nodes.
std::vector<double> Conformer::local_minima(const std::vector<double>& tet) const {
  std::vector<double> node_min(input_.points.size(), 1.0);
  for (std::size_t h = 0; h < input_.hexes.size(); ++h)
    if (!hex_later_[h])  // a cell left for later touches no interface node
      for (Index v : input_.hexes[h])
        node_min[primal::index_cast<std::size_t>(v)] =
            std::min(node_min[primal::index_cast<std::size_t>(v)], hex_diced_[h]);
  for (std::size_t t = 0; t < input_.tets.size(); ++t)
    if (!tet_later_[t])
      for (Index v : input_.tets[t])
        node_min[primal::index_cast<std::size_t>(v)] =
            std::min(node_min[primal::index_cast<std::size_t>(v)], tet[t]);
  for (std::size_t w = 0; w < input_.wedges.size(); ++w)
    for (Index v : input_.wedges[w])
      node_min[primal::index_cast<std::size_t>(v)] =
          std::min(node_min[primal::index_cast<std::size_t>(v)], wedge_diced_[w]);
  std::vector<double> local;
  local.reserve(interface_.quads.size());
  for (const primal::InterfaceQuad& q : interface_.quads) {
    double m = 1.0;
    for (Index v : q.corners) m = std::min(m, node_min[primal::index_cast<std::size_t>(v)]);
    if (q.centre != kInvalidIndex)
      m = std::min(m, node_min[primal::index_cast<std::size_t>(q.centre)]);
    local.push_back(m);
  }
  return local;
}

namespace {

// Each listed cell diced alone, on `points`, into out[cell].
template <std::size_t N>
void measure_cells(std::span<const Point> points, const std::vector<std::array<Index, N>>& cells,
                   const std::vector<std::size_t>& which, std::vector<double>& out) {
  std::vector<std::array<Index, N>> picked;
  picked.reserve(which.size());
  for (std::size_t c : which) picked.push_back(cells[c]);
  const std::vector<double> figures = primal::diced_scaled_jacobian_per_cell(points, picked);
  for (std::size_t i = 0; i < which.size(); ++i) out[which[i]] = figures[i];
}

}  // namespace

// The input's hexes and tets diced alone (the yardsticks): now, the cells at an interface node
// (the local yardsticks read them), and the relaxed tets as the caller gave them. Every other
// figure is of a cell diced as it stands, read off its children once the output is measured
// (diced_alone_from_children), not computed a second time: measuring every input cell here was
// a tenth of a default run's CPU (the n = 36 bench).
void Conformer::measure_near_interface() {
  std::vector<char> at(input_.points.size(), 0);
  for (const primal::InterfaceQuad& q : interface_.quads) {
    for (Index v : q.corners) at[primal::index_cast<std::size_t>(v)] = 1;
    if (q.centre != kInvalidIndex) at[primal::index_cast<std::size_t>(q.centre)] = 1;
  }
  auto touches = [&](std::span<const Index> cell) {
    return std::any_of(cell.begin(), cell.end(),
                       [&](Index v) { return at[primal::index_cast<std::size_t>(v)] != 0; });
  };
  const bool relaxed = &given_ != &input_.points;
  auto moved = [&](std::span<const Index> cell) {
    return relaxed && std::any_of(cell.begin(), cell.end(), [&](Index v) {
             const auto i = primal::index_cast<std::size_t>(v);
             return given_[i] != input_.points[i];
           });
  };
  // Classified in parallel (each cell its own slot), then listed in order.
  auto classify = [](std::size_t n, std::vector<char>& later, auto&& kind) {
    later.resize(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t c = r.begin(); c != r.end(); ++c) later[c] = kind(c);
                      });
  };
  constexpr char kNowMoved = 3;  // a relaxed tet at the interface: measured now, both ways
  classify(input_.hexes.size(), hex_later_,
           [&](std::size_t h) { return touches(input_.hexes[h]) ? char{0} : kLater; });
  classify(input_.tets.size(), tet_later_, [&](std::size_t t) {
    const bool m = moved(input_.tets[t]);
    if (touches(input_.tets[t])) return m ? kNowMoved : char{0};
    return m ? kLaterGiven : kLater;
  });
  std::vector<std::size_t> now, given;
  for (std::size_t h = 0; h < hex_later_.size(); ++h)
    if (!hex_later_[h]) now.push_back(h);
  hex_diced_.assign(input_.hexes.size(), 1.0);
  measure_cells(input_.points, input_.hexes, now, hex_diced_);
  now.clear();
  for (std::size_t t = 0; t < tet_later_.size(); ++t) {
    if (tet_later_[t] == 0 || tet_later_[t] == kNowMoved) now.push_back(t);
    if (tet_later_[t] == kNowMoved || tet_later_[t] == kLaterGiven) given.push_back(t);
    if (tet_later_[t] == kNowMoved) tet_later_[t] = 0;
  }
  tet_diced_.assign(input_.tets.size(), 1.0);
  measure_cells(input_.points, input_.tets, now, tet_diced_);
  // The tets as given differ only where a node moved: those measured again (the same function,
  // so that an unmoved tet's figure is the one --relax none reports).
  tet_given_ = tet_diced_;
  measure_cells(given_, input_.tets, given, tet_given_);
}

// The cells left for later whose children will not be the input's (the buffer layer moved or
// renumbered a node of theirs): measured now, on the input, before trim_input frees it. None on
// today's layers, which change only cells at interface nodes; checked rather than assumed.
void Conformer::measure_changed() {
  if (layer_.hexes.empty()) return;  // no interface: the layer's model is the input itself
  const primal::Model& lm = layer_.model;
  auto same = [&](std::span<const Index> a, std::span<const Index> b) {
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i] != b[i] || input_.points[primal::index_cast<std::size_t>(a[i])] !=
                              lm.points[primal::index_cast<std::size_t>(b[i])])
        return false;
    return true;
  };
  // Flagged in parallel (each cell its own slot), then listed in order and measured now.
  auto changed = [&](const auto& cells, const auto& layer_cells, const std::vector<char>& later) {
    const bool all = cells.size() != layer_cells.size();
    std::vector<char> flag(cells.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t c = r.begin(); c != r.end(); ++c)
                          flag[c] = later[c] && (all || !same(cells[c], layer_cells[c]));
                      });
    std::vector<std::size_t> which;
    for (std::size_t c = 0; c < cells.size(); ++c)
      if (flag[c]) which.push_back(c);
    return which;
  };
  const std::vector<std::size_t> hexes = changed(input_.hexes, lm.hexes, hex_later_);
  measure_cells(input_.points, input_.hexes, hexes, hex_diced_);
  for (std::size_t h : hexes) hex_later_[h] = 0;
  const std::vector<std::size_t> tets = changed(input_.tets, lm.tets, tet_later_);
  measure_cells(input_.points, input_.tets, tets, tet_diced_);
  for (std::size_t t : tets) {
    if (tet_later_[t] == kLater) tet_given_[t] = tet_diced_[t];  // not relaxed
    tet_later_[t] = 0;
  }
}

// The cells left for later, diced alone: the lowest of their children as measured (sj_),
// bit for bit what diced_scaled_jacobian_per_cell gives (its nodes placed as dicing places
// them, the same corner order); dice_model makes each part's children in parent order, 8 per
// hex and 4 per tet. Then the yardsticks over all cells.
void Conformer::diced_alone_from_children(std::size_t tet_first) {
  auto from_children = [&](std::vector<double>& figure, const std::vector<char>& later,
                           std::size_t first, std::size_t per) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, figure.size(), 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t c = r.begin(); c != r.end(); ++c) {
                          if (!later[c]) continue;
                          double lowest = 1.0;  // as diced_scaled_jacobian_per_cell starts
                          for (std::size_t k = first + per * c; k < first + per * (c + 1); ++k)
                            lowest = std::min(lowest, sj_[k]);
                          figure[c] = lowest;
                        }
                      });
  };
  from_children(hex_diced_, hex_later_, 0, 8);
  from_children(tet_diced_, tet_later_, tet_first, 4);
  for (std::size_t t = 0; t < tet_given_.size(); ++t)
    if (tet_later_[t] == kLater) tet_given_[t] = tet_diced_[t];  // not relaxed
  primal::release(hex_later_, tet_later_);
  if (!hex_diced_.empty())
    res_.input_diced_hex_min_scaled_jacobian =
        *std::min_element(hex_diced_.begin(), hex_diced_.end());
  if (!tet_given_.empty())
    res_.input_diced_tet_min_scaled_jacobian =
        *std::min_element(tet_given_.begin(), tet_given_.end());
  aim_yardstick_ = std::min(
      {res_.input_diced_hex_min_scaled_jacobian, res_.input_diced_wedge_min_scaled_jacobian,
       tet_diced_.empty() ? 1.0 : *std::min_element(tet_diced_.begin(), tet_diced_.end())});
}

void Conformer::insert_buffer() {
  t0_ = Clock::now();
  res_.buffer_side = options_.buffer.side;
  if (interface_.quads.empty()) {  // nothing to carve: the model is diced as it is
    layer_.model = input_;
    layer_.top_node.assign(input_.points.size(), kInvalidIndex);
    return;
  }
  try {
    layer_ = insert_buffer_layer(input_, interface_, options_.buffer);
    if (options_.buffer_fallback && options_.buffer.side == BufferSide::kHex &&
        options_.buffer.thickness == 0.0)
      thicker_from_tets();
  } catch (const TopologyError& e) {
    if (!options_.buffer_fallback) throw;
    BufferLayerOptions other = options_.buffer;
    other.side = options_.buffer.side == BufferSide::kHex ? BufferSide::kTet : BufferSide::kHex;
    other.thickness = 0.0;  // that side's default
    const char* first = buffer_side_name(options_.buffer.side);
    const char* second = buffer_side_name(other.side);
    try {
      layer_ = insert_buffer_layer(input_, interface_, other);
    } catch (const TopologyError& e2) {
      throw TopologyError(std::string(e.what()) + "; from the " + second + " part: " + e2.what());
    }
    res_.buffer_side = other.side;
    const std::string thickness =
        options_.buffer.thickness > 0.0
            ? " (its default thickness " + std::to_string(default_buffer_thickness(other.side)) +
                  ", not the " + std::to_string(options_.buffer.thickness) + " given)"
            : "";
    res_.warnings.push_back(std::string("buffer layer carved from the ") + second + " part" +
                            thickness + ", not the " + first + " part: " + e.what());
  }
  carved_from_.reserve(layer_.hexes.size());
  for (const BufferHex& b : layer_.hexes) {
    const primal::InterfaceQuad& q = interface_.quads[b.quad];
    carved_from_.push_back(res_.buffer_side == BufferSide::kHex
                               ? q.owner()
                               : primal::ElementRef{primal::ElementKind::kTet, q.tets[0]});
  }
  interface_ = {};
  proportion_ = buffer_proportions(layer_);
  res_.buffer = layer_.report;
  say("buffer layer: " + std::to_string(layer_.hexes.size()) + " hexes, min scaled Jacobian " +
      std::to_string(layer_.report.min_scaled_jacobian) + took());
}

// Carved from the hex part, the buffer is half the shortest hex edge at each node thick: where the
// hex cells at the interface are a graded boundary layer's thin first cells (hexes beside wedges
// in an extruded layer), the buffer hexes and the diced hexes behind them are squashed flat
// (layer-mixed, n = 3 to 6: 0.43 to 0.79 x the yardstick, against 1.1 to 2.0 x carved from the
// tets). So where the hex part's buffer hexes are on average lower than kThinHexBuffer of their
// quads' edge (hex cells flatter than 2.5 : 1; every other demo's are 0.24 to 0.5), the tet
// part's layer is taken instead if it is thicker.
constexpr double kThinHexBuffer = 0.2;

void Conformer::thicker_from_tets() {
  const double hex = buffer_height_ratio(layer_);
  if (hex >= kThinHexBuffer) return;
  BufferLayerOptions other = options_.buffer;
  other.side = BufferSide::kTet;
  BufferLayer tets;
  try {
    tets = insert_buffer_layer(input_, interface_, other);
  } catch (const TopologyError&) {
    return;
  }
  const double tet = buffer_height_ratio(tets);
  if (tet <= hex) return;
  layer_ = std::move(tets);
  res_.buffer_side = BufferSide::kTet;
  std::ostringstream m;
  m << "buffer layer carved from the tet part, not the hex part: its hexes are " << tet
    << " of their interface quads' edge high on average, against " << hex
    << " from the hex part (thin hex cells at the interface, as a boundary layer's)";
  res_.warnings.push_back(m.str());
}

// After the buffer layer the stages read the input for its blocks only (the layer's model is
// a copy of it): where conform may change the input, the rest is freed before dicing, the
// run's peak (the n = 36 bench: 9.3 MiB where conform copied it to relax its tets, 10.2 MiB
// where the caller gave it up and it was not copied).
void Conformer::trim_input() {
  measure_changed();
  blocks_ = output_blocks(input_, options_.geode_block);
  if (given_copy_) primal::release(*given_copy_);
  if (!disposable_) return;
  primal::Model& m = *disposable_;
  primal::release(m.points, m.hexes, m.tets, m.pyramids, m.wedges, m.node_sets, m.side_sets,
                  m.node_ids, m.hex_ids, m.tet_ids, m.pyramid_ids, m.wedge_ids);
}

// The reference templates the buffer hexes use, built in parallel (each once per process);
// the four-triangle one only when some buffer hex needs it (it costs time). Before dicing, so
// that dicing knows how many hexes the output will hold.
void Conformer::build_references() {
  if (layer_.hexes.empty()) return;  // no interface: no template
  t0_ = Clock::now();
  const bool any_four = std::any_of(layer_.hexes.begin(), layer_.hexes.end(),
                                    [](const BufferHex& b) { return b.centre != kInvalidIndex; });
  tbb::parallel_invoke(
      [&] {
        refs_[0] = &reference_template(options_.template_box, {4, 6});
      },
      [&] {
        refs_[1] = &reference_template(options_.template_box, {5, 7});
      },
      [&] {
        if (any_four) refs_[2] = &reference_template_four_triangles(options_.template_box);
      });
  res_.template_min_scaled_jacobian =
      std::min(refs_[0]->min_scaled_jacobian, refs_[1]->min_scaled_jacobian);
  if (any_four)
    res_.template_min_scaled_jacobian =
        std::min(res_.template_min_scaled_jacobian, refs_[2]->min_scaled_jacobian);
  say("reference templates: min scaled Jacobian " +
      std::to_string(res_.template_min_scaled_jacobian) + took());
}

// Both parts diced over the layer model's point array, nodes merged by origin; the buffer
// hex corners are shareable so that template nodes find their diced nodes by origin. The tet
// children get room for every other output hex: assembly puts the hex children and the
// templates in front of them and the wedge children after, without a copy of the tet
// children (the largest part of most models) beside the output's connectivity.
void Conformer::dice_and_merge() {
  t0_ = Clock::now();
  std::vector<char> shareable(layer_.model.points.size(), 0);
  for (const auto& b : layer_.hexes) {
    for (Index v : b.corners) shareable[v] = 1;
    if (b.centre != kInvalidIndex) shareable[b.centre] = 1;
  }
  std::size_t room = 8 * layer_.model.hexes.size() + 6 * layer_.model.wedges.size();
  for (std::size_t b = 0; b < layer_.hexes.size(); ++b) room += ref(b).tpl.hex.hexes.size();
  diced_ = primal::dice_model(layer_.model, shareable, room);
  res_.diced_hexes = primal::index_cast(diced_.hex_children.size());
  res_.diced_tet_hexes = primal::index_cast(diced_.tet_children.size());
  res_.diced_wedge_hexes = primal::index_cast(diced_.wedge_children.size());
  check_dicing();
  say("dicing: " + std::to_string(res_.diced_hexes) + " hexes from hexes, " +
      std::to_string(res_.diced_tet_hexes) + " from tets, " +
      std::to_string(res_.diced_wedge_hexes) + " from wedges" + took());
}

// Local verification: the diced children against the dicer's tables, now that they exist (the
// dicing data are gone by check()); the children's topology is final here, smoothing moves
// nodes only.
void Conformer::check_dicing() {
  if (!verify_locally()) return;
  const auto t = Clock::now();
  res_.dicing = primal::check_dicing(layer_.model, diced_);
  dicing_check_seconds_ = since(t);
}

bool Conformer::verify_locally() const {
  return options_.verify == ConformVerify::kLocal && options_.smooth != ConformSmooth::kGlobal;
}

// A template in every buffer hex: tet/hex-side nodes become their diced node, interior nodes
// new nodes, side-face nodes disjoint-sets items merged across shared faces by match_sides.
void Conformer::place_templates() {
  t0_ = Clock::now();
  if (layer_.hexes.empty()) return;  // no interface: no template
  const primal::Model& lm = layer_.model;
  const std::size_t nb = layer_.hexes.size();
  inst_global_.assign(nb, {});
  inst_side_.assign(nb, {});
  for (std::size_t b = 0; b < nb; ++b) {
    const BufferHex& bh = layer_.hexes[b];
    const RefTemplate& rt = ref(b);
    std::array<Point, 8> P;
    for (int c = 0; c < 8; ++c) P[c] = lm.points[bh.corners[c]];
    const bool four = bh.centre != kInvalidIndex;
    const Point centre = four ? lm.points[bh.centre] : Point::Zero();
    const std::size_t n = rt.rst.size();
    inst_global_[b].assign(n, kInvalidIndex);
    inst_side_[b].assign(n, kInvalidIndex);
    res_.geode_hexes += primal::index_cast(rt.tpl.hex.hexes.size());
    for (std::size_t i = 0; i < n; ++i) {
      const Point x = buffer_map(P, bh.diagonal, rt.rst[i], four ? &centre : nullptr);
      if (!rt.key_corners[i].empty()) {
        FaceKey key = kNoOrigin;
        for (std::size_t k = 0; k < rt.key_corners[i].size(); ++k) {
          const int c = rt.key_corners[i][k];
          key[k] = c == kCentreCorner ? bh.centre : bh.corners[c];
        }
        const Index g = diced_.find(key);
        if (g == kInvalidIndex)
          throw TopologyError("buffer hex " + std::to_string(b) +
                              ": a template node has no diced node to merge with");
        inst_global_[b][i] = g;
      } else if (rt.interior(i)) {
        inst_global_[b][i] = diced_.add_node(x);
      } else {
        inst_side_[b][i] = side_sets_uf_.add();
        side_pos_.push_back(x);
      }
    }
  }
  diced_.shared = primal::KeyMap<4>();  // every template node is placed
  say("geode templates: " + std::to_string(nb) + " buffer hexes placed" + took());
}

// Side faces shared by two buffer hexes: their template nodes matched topologically, one node
// per class at the mean of its members.
void Conformer::match_sides() {
  t0_ = Clock::now();
  const std::size_t nb = layer_.hexes.size();
  std::unordered_map<FaceKey, std::vector<std::pair<int, int>>, primal::IndexArrayHash> side_uses;
  for (std::size_t b = 0; b < nb; ++b)
    for (int k = 0; k < 4; ++k) {
      std::array<Index, 4> f{};
      for (int j = 0; j < 4; ++j) f[j] = layer_.hexes[b].corners[topo::kHexFaceCorners[k][j]];
      side_uses[primal::face_key(f)].push_back({static_cast<int>(b), k});
    }
  Index shared_faces = 0;
  for (const auto& [key, uses] : side_uses) {
    if (uses.size() > 2) {
      std::ostringstream m;
      m << "side face (" << key[0] << " " << key[1] << " " << key[2] << " " << key[3]
        << ") of the buffer layer is shared by " << uses.size()
        << " buffer hexes (the interface is non-manifold along edge " << key[0] << "-" << key[1]
        << ")";
      throw TopologyError(m.str());
    }
    if (uses.size() < 2) continue;
    ++shared_faces;
    const auto [ba, ka] = uses[0];
    const auto [bb, kb] = uses[1];
    const auto m = match_side(ref(ba), ka, inst_global_[ba], ref(bb), kb, inst_global_[bb],
                              "buffer hexes " + std::to_string(ba) + " and " + std::to_string(bb));
    for (const auto& [a, b] : m) {
      const Index sa = inst_side_[ba][a], sb = inst_side_[bb][b];
      if ((sa == kInvalidIndex) != (sb == kInvalidIndex))
        throw TopologyError("buffer hexes " + std::to_string(ba) + " and " + std::to_string(bb) +
                            ": a side node matches a tet/hex-side node");
      if (sa != kInvalidIndex) side_sets_uf_.unite(sa, sb);
    }
  }
  auto& uf = side_sets_uf_;
  const Index ns = primal::index_cast(uf.size());
  std::vector<Point> sum(ns, Point::Zero());
  std::vector<int> cnt(ns, 0);
  for (Index s = 0; s < ns; ++s) sum[uf.find(s)] += side_pos_[s], ++cnt[uf.find(s)];
  std::vector<Index> gid(ns, kInvalidIndex);
  for (Index s = 0; s < ns; ++s)
    if (uf.find(s) == s) gid[s] = diced_.add_node(sum[s] / cnt[s]);
  for (std::size_t b = 0; b < nb; ++b)
    for (std::size_t i = 0; i < inst_side_[b].size(); ++i)
      if (inst_side_[b][i] != kInvalidIndex) inst_global_[b][i] = gid[uf.find(inst_side_[b][i])];
  uf = {};
  primal::release(side_pos_, inst_side_);
  say("side faces: " + std::to_string(shared_faces) + " shared by two buffer hexes, merged" +
      took());
}

// The hexes by block in ascending id, unused nodes dropped, node and side sets carried over
// (they depend only on the numbering). Memory: the output is built out of the dicing data,
// not beside them: the tet children's array becomes the output's hex array, each dicing array
// is released as soon as it is consumed, and the nodes are renumbered in place (no second copy
// of the output mesh); the smoothing and verification that follow need room of their own.
void Conformer::assemble() {
  const std::size_t nb = layer_.hexes.size();
  // Each output hex is in the input block of the element it comes from; a geode hex in the
  // block of the element its buffer hex was carved from, or in a block of its own.
  const primal::Model& lm = layer_.model;
  // Side sets read the children in diced numbers: taken before the children move.
  side_sets_ = primal::diced_side_sets(lm, diced_, 0, res_.diced_hexes + res_.geode_hexes);
  // Nodes numbered in order of first use by the output hexes (unused ones dropped), read off
  // the children where they are, so that the node sets (which need the origins) are made and
  // the origins freed before the output's connectivity is built beside the children.
  std::vector<Index> renum(diced_.points.size(), kInvalidIndex);
  Index used = 0;
  auto number = [&](const std::array<Index, 8>& h) {
    for (Index v : h) {
      Index& r = renum[primal::index_cast<std::size_t>(v)];
      if (r == kInvalidIndex) r = used++;
    }
  };
  auto instance = [&](std::size_t b, const std::array<Index, 8>& h) {
    std::array<Index, 8> o{};
    for (int c = 0; c < 8; ++c) o[c] = inst_global_[b][h[c]];
    return o;
  };
  for (const auto& h : diced_.hex_children) number(h);
  for (std::size_t b = 0; b < nb; ++b)
    for (const auto& h : ref(b).tpl.hex.hexes) number(instance(b, h));
  for (const auto& h : diced_.tet_children) number(h);
  for (const auto& h : diced_.wedge_children) number(h);
  diced_.shared = primal::KeyMap<4>();
  // A node set keeps its interface nodes' tet-side duplicates too (the layer model's sets hold
  // the hex-side copies only), so that a set on the boundary loses no node along the interface.
  primal::Model sets;
  sets.points.resize(lm.points.size());
  sets.node_sets = lm.node_sets;
  for (primal::NodeSet& ns : sets.node_sets) {
    const std::size_t n = ns.nodes.size();
    for (std::size_t i = 0; i < n; ++i)
      if (const auto v = primal::index_cast<std::size_t>(ns.nodes[i]);
          v < layer_.top_node.size() && layer_.top_node[v] != kInvalidIndex)
        ns.nodes.push_back(layer_.top_node[v]);
  }
  node_sets_ = primal::diced_node_sets(sets, diced_, renum);
  primal::release(diced_.origin);

  // The output hexes in output numbers: hex children, templates, tet children, wedge children.
  // The tet children are renumbered where they are and the others put around them, in the
  // room dicing left (dice_and_merge), so that no copy of them is made beside the output.
  const std::size_t total = diced_.hex_children.size() +
                            primal::index_cast<std::size_t>(res_.geode_hexes) +
                            diced_.tet_children.size() + diced_.wedge_children.size();
  const std::size_t front =
      diced_.hex_children.size() + primal::index_cast<std::size_t>(res_.geode_hexes);
  auto renumbered = [&](std::array<Index, 8> h) {
    for (Index& v : h) v = renum[primal::index_cast<std::size_t>(v)];
    return h;
  };
  // The children renumbered and their blocks read in parallel (each element its own slot).
  auto each = [](std::size_t n, auto&& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
                      });
  };
  each(diced_.tet_children.size(),
       [&](std::size_t i) { diced_.tet_children[i] = renumbered(diced_.tet_children[i]); });
  std::vector<std::array<Index, 8>> hexes = std::move(diced_.tet_children);
  hexes.reserve(total);                                        // dicing's room: no copy
  hexes.insert(hexes.begin(), front, std::array<Index, 8>{});  // shifted within capacity
  std::vector<int> block(total);
  auto blocks_of = [&](primal::ElementKind kind, const std::vector<Index>& parents,
                       std::size_t first) {
    each(parents.size(), [&](std::size_t i) {
      block[first + i] = primal::block_of(lm, {kind, parents[i]});
    });
  };
  each(diced_.hex_children.size(),
       [&](std::size_t i) { hexes[i] = renumbered(diced_.hex_children[i]); });
  std::size_t at = diced_.hex_children.size();
  primal::release(diced_.hex_children);
  blocks_of(primal::ElementKind::kHex, diced_.hex_parent, 0);
  diced_parent_ = std::move(diced_.hex_parent);  // per output diced hex: its input hex
  primal::release(diced_.hex_parent);
  geode_first_.reserve(nb + 1);
  for (std::size_t b = 0; b < nb; ++b) {
    geode_first_.push_back(primal::index_cast(at));
    const int id = blocks_.geode_id ? blocks_.geode_id : primal::block_of(lm, carved_from_[b]);
    for (const auto& h : ref(b).tpl.hex.hexes) {
      block[at] = id;
      hexes[at++] = renumbered(instance(b, h));
    }
  }
  geode_first_.push_back(primal::index_cast(at));
  primal::release(inst_global_, diced_.tet_children);
  const std::size_t tet_first = at;
  blocks_of(primal::ElementKind::kTet, diced_.tet_parent, at);
  primal::release(diced_.tet_parent);
  for (const auto& h : diced_.wedge_children) hexes.push_back(renumbered(h));
  primal::release(diced_.wedge_children);
  blocks_of(primal::ElementKind::kWedge, diced_.wedge_parent, total - diced_.wedge_parent.size());
  primal::release(diced_.wedge_parent);
  // The points permuted in place, one coordinate at a time through an array of one
  // coordinate per node (gathered in parallel, then put back): following the permutation's
  // cycles, one random access after another, was half of assembly; a second array of points
  // would be the run's peak.
  std::vector<Point>& points = diced_.points;
  {
    std::vector<Index> from(primal::index_cast<std::size_t>(used));  // per output node: its own
    each(renum.size(), [&](std::size_t i) {
      if (const Index r = renum[i]; r != kInvalidIndex)
        from[primal::index_cast<std::size_t>(r)] = primal::index_cast(i);
    });
    primal::release(renum);
    std::vector<double> coordinate(from.size());
    for (int c = 0; c < 3; ++c) {
      each(from.size(), [&](std::size_t r) {
        coordinate[r] = points[primal::index_cast<std::size_t>(from[r])][c];
      });
      each(from.size(), [&](std::size_t r) { points[r][c] = coordinate[r]; });
    }
  }
  // No shrink_to_fit: dice_model reserved about what it made, and a shrinking copy of every
  // point would be the run's peak.
  points.resize(primal::index_cast<std::size_t>(used));
  mesh_.points = std::move(points);
  mesh_.hexes = std::move(hexes);
  mesh_.block = std::move(block);
  diced_ = primal::DicedModel();
  // The stages after this one read the buffer hexes only (their quads), not the layer's model
  // or the interface: freed before smoothing, verification and writing add their own.
  layer_.model = primal::Model();
  primal::release(layer_.top_node);
  interface_ = primal::Interface();
  res_.min_scaled_jacobian_before_smoothing = measure();
  diced_alone_from_children(tet_first);
}

// Settling a template: untangling and shape together, at most this many iterations (a bound:
// the buffer hex's fixed nodes soon cap the minimum).
constexpr int kSettleIterations = 50;

// One template settled: its interior nodes with their new positions, or nothing when the
// smoother did not raise the template's minimum.
std::vector<std::pair<Index, Point>> Conformer::settled(std::size_t b) const {
  const RefTemplate& rt = ref(b);
  const auto& local = rt.tpl.hex.hexes;
  const Index first = geode_first_[b];
  std::vector<Index> global(rt.rst.size(), kInvalidIndex);
  for (std::size_t k = 0; k < local.size(); ++k)
    for (int c = 0; c < 8; ++c) global[local[k][c]] = mesh_.hexes[first + k][c];
  primal::HexMesh m;
  m.hexes = local;
  std::vector<primal::NodeConstraint> constraints;
  for (std::size_t i = 0; i < global.size(); ++i) {
    m.points.push_back(mesh_.points[global[i]]);
    constraints.push_back(rt.interior(i) ? primal::NodeConstraint::free()
                                         : primal::NodeConstraint::fixed());
  }
  primal::SmoothOptions so;
  so.max_iterations = kSettleIterations;
  const auto r = primal::smooth_hex_mesh(m, constraints, so);
  std::vector<std::pair<Index, Point>> moved;
  if (r.final_min_scaled_jacobian <= r.initial_min_scaled_jacobian) return moved;
  for (std::size_t i = 0; i < global.size(); ++i)
    if (constraints[i].kind == primal::NodeConstraint::Kind::kFree)
      moved.emplace_back(global[i], m.points[i]);
  return moved;
}

// The map can invert a template hex where a buffer hex is far from the template's box (a
// trapezoidal interface quad at a model corner squeezes one side of the template). Such a
// template is put right inside its own buffer hex: its interior nodes (used by none of the
// template's neighbours) are untangled and smoothed with every other node fixed (the template
// smoother, primal/smooth.hpp), so the placement hands a valid mesh to smoothing wherever
// that can be done inside the buffer hex, and the diced elements stay exactly as diced.
void Conformer::settle_templates() {
  t0_ = Clock::now();
  std::vector<std::size_t> buffer_hexes;  // those with an inverted geode hex, ascending
  for (Index h : inverted_) {
    if (h < geode_first_.front() || h >= geode_first_.back()) continue;
    const auto b = primal::index_cast<std::size_t>(
        std::upper_bound(geode_first_.begin(), geode_first_.end(), h) - geode_first_.begin() - 1);
    if (buffer_hexes.empty() || buffer_hexes.back() != b) buffer_hexes.push_back(b);
  }
  if (buffer_hexes.empty()) {
    res_.placement_inverted = primal::index_cast(inverted_.size());
    return;
  }
  // Templates share no interior node: settled in parallel (TBB), written back in order.
  std::vector<std::vector<std::pair<Index, Point>>> moved(buffer_hexes.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, buffer_hexes.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t j = range.begin(); j != range.end(); ++j)
                        moved[j] = settled(buffer_hexes[j]);
                    });
  for (std::size_t j = 0; j < buffer_hexes.size(); ++j) {
    if (moved[j].empty()) continue;
    ++res_.templates_settled;
    for (const auto& [v, x] : moved[j]) mesh_.points[v] = x;
    const std::size_t b = buffer_hexes[j];
    std::vector<Index> hexes(
        primal::index_cast<std::size_t>(geode_first_[b + 1] - geode_first_[b]));
    std::iota(hexes.begin(), hexes.end(), geode_first_[b]);
    measure(hexes);
  }
  res_.min_scaled_jacobian_before_smoothing = scan();
  res_.placement_inverted = primal::index_cast(inverted_.size());
  say("settling: " + std::to_string(buffer_hexes.size()) + " templates with an inverted hex, " +
      std::to_string(res_.templates_settled) + " settled, " +
      std::to_string(res_.placement_inverted) + " hexes left inverted" + took());
}

// A hex is untangled by moving its neighbours too: the patches start on it and on the hexes
// within this many rings of it.
constexpr int kUntangleRings = 2;

// A hex still inverted (one whose buffer hex leaves its template no valid placement, or one the
// smoothing could not lift) is untangled with the hexes within kUntangleRings of it, at
// local_smooth_options' own target, so that even --smooth none gives a usable mesh. Reads
// inverted_ as the last measure() or scan() left it.
void Conformer::untangle() {
  if (inverted_.empty()) return;
  const std::size_t before = inverted_.size();
  std::vector<Index> seeds = inverted_;
  for (int ring = 0; ring < kUntangleRings; ++ring) seeds = primal::hexes_around(mesh_, seeds);
  const auto r = primal::smooth_hexes_around(mesh_, seeds, options_.local_smooth_options);
  add_smoothing(r);
  measure(r.region);
  res_.smoothing.final_min_scaled_jacobian = scan();
  res_.smoothing.final_inverted = primal::index_cast(inverted_.size());
  say("untangling: " + std::to_string(before) + " inverted hexes, " +
      std::to_string(inverted_.size()) + " left" + took());
}

// Several smoothing calls report as one: their work adds up; the minima and inverted counts
// are the whole mesh's (set in smooth() and untangle()).
void Conformer::add_smoothing(const primal::LocalSmoothResult& r) {
  moved_.insert(moved_.end(), r.region.begin(), r.region.end());
  auto& s = res_.smoothing;
  s.patches += r.patches, s.rounds += r.rounds, s.iterations += r.iterations;
  s.seconds += r.seconds, s.cpu_seconds += r.cpu_seconds;
}

// The worst-first smoother (primal/local_smooth.hpp); nodes on the model boundary and between
// blocks slide only where that keeps every block's volume. Local: patches seeded near the geode
// hexes, on the submesh around the seeds, so the cost follows the interface (or, with the automatic
// target, its defects); global: every hex, then the automatic passes wherever a hex is still below
// the yardstick.
void Conformer::smooth() {
  t0_ = Clock::now();
  res_.smoothing.initial_min_scaled_jacobian = res_.min_scaled_jacobian_before_smoothing;
  res_.smoothing.final_min_scaled_jacobian = res_.min_scaled_jacobian_before_smoothing;
  res_.smoothing.initial_inverted = res_.smoothing.final_inverted = res_.placement_inverted;
  if (options_.smooth == ConformSmooth::kNone) return untangle();
  const bool local = options_.smooth == ConformSmooth::kLocal;
  primal::LocalSmoothOptions o =
      local ? options_.local_smooth_options : options_.global_smooth_options;
  auto last = Clock::now();
  o.progress = [&](std::size_t settled, std::size_t total) {
    if (options_.smoothing_progress) {
      options_.smoothing_progress(settled, total);
    } else if (since(last) > 5.0) {
      last = Clock::now();
      say("smoothing: " + std::to_string(settled) + " / " + std::to_string(total) +
          " seed hexes settled" + took());
    }
  };
  if (local && options_.smooth_target > 0.0) {
    std::vector<Index> geode(primal::index_cast<std::size_t>(res_.geode_hexes));
    std::iota(geode.begin(), geode.end(), res_.diced_hexes);
    o.target = options_.smooth_target;
    const auto r = primal::smooth_hexes_around(mesh_, primal::hexes_around(mesh_, geode), o);
    add_smoothing(r);
    measure(r.region);
  } else if (local) {
    smooth_defects(o);
  } else {
    const auto constraints = primal::boundary_slide_constraints(mesh_);
    o.target = std::min(o.target, options_.global_target_factor * aim_yardstick_);
    add_smoothing(primal::smooth_hexes_local(mesh_, constraints, nullptr, {}, o));
    sj_ = primal::scaled_jacobian_per_hex(mesh_);
    // The global target lifts the whole mesh a little, not a defect to the yardstick: the
    // local passes follow wherever a hex is still below it. Their floors are measured on the
    // globally smoothed mesh: from before it, the edges the global pass shortened would leave
    // the defects no room. So the bounds add up over the two: a hex may lose `loss` in each,
    // an edge shrink to half of half its length.
    primal::LocalSmoothOptions d = options_.local_smooth_options;
    d.progress = o.progress;
    // With the neighbourhood lift, as the local mode: the passes' floors hold the neighbours of
    // the defects they leave here too. Over the 17 demos at n = 3, 5, 6, against the passes
    // alone: the whole output's minimum up in 8 runs, down in none, block minima up in 29 of
    // the 132 and down in 5, runs below 0.9 x the capped local yardstick 2 -> 0, the
    // smoothing's CPU 26.1 -> 32.3 s.
    smooth_defects(d);
  }
  res_.smoothing.final_min_scaled_jacobian = scan();
  res_.smoothing.final_inverted = primal::index_cast(inverted_.size());
  untangle();
  const Index patches = res_.smoothing.patches;
  say("smoothing (" + std::string(local ? "local" : "global") + "): " + std::to_string(patches) +
      " patches, min scaled Jacobian " +
      std::to_string(res_.smoothing.initial_min_scaled_jacobian) + " -> " +
      std::to_string(res_.smoothing.final_min_scaled_jacobian) + took());
}

// Automatic target. The defects are the hexes below their aim (aims(): the yardstick, the
// input's own hexes and tets diced alone, which every hex the transition did not touch is
// above; for a geode hex also 0.9 x its local yardstick, so that a transition next to good
// cells is not measured against the worst tet far away). Patches start on them
// and on the hexes sharing a node with them (a defect is lifted by moving its neighbours too),
// at hexes below a target a little above their aim, so that the smoother works only where
// the transition is worse than dicing makes anyway and its cost follows the defects; a pass
// ends as soon as no seed is below its aim (the target only gives room to get there). A
// defect whose neighbours are above that target has no room to rise: where defects remain, the
// pass is repeated around them with a slightly higher target (small steps: a pass costs what
// lies below its target around the defects). Within a pass each hex seeds one patch: a second
// one, after a neighbour moved its nodes, mostly repeats work, while the next pass seeds afresh
// where defects are left. The passes after the first seed only around the defects within
// kDefectBand of the lowest one of their output block: after the first pass most defects are
// geode hexes a little under kGeodeFloor, and passes around all of them again cost as much as
// the first for little (hexdominant n = 28: 38,000 seeds a pass, the lowest 0.0962 -> 0.0974,
// as much as about 600 patches around the lowest give). Where the whole transition rises
// together (the n = 2 nugget) the lowest are most of it.
constexpr int kDefectRings = 1;
constexpr double kDefectBand = 0.05;
constexpr double kDefectTarget = 1.1;       // x the aim, first pass
constexpr double kDefectTargetStep = 0.02;  // added to it by each further pass
constexpr int kDefectPasses = 8;
// After kDefectMinPasses, further passes only while one removes at least kDefectProgress of
// the defects it seeds around or lifts the worst of them by kDefectRise: where geode hexes at
// hex-part corners stay below kGeodeFloor, repeating the passes around all of them cost 8 x their
// patches (the potting demo: 66,747 patches, 7.7 s of CPU) for little; where the whole
// transition rises together (the n = 2 nugget) it took 3 passes.
constexpr int kDefectMinPasses = 3;
constexpr double kDefectProgress = 0.05;
constexpr double kDefectRise = 0.002;
constexpr int kDefectVisits = 1;   // patches seeded by one hex in one pass
constexpr double kLocalAim = 0.9;  // x a geode hex's local yardstick (capped), see aims()
constexpr double kPartAim = 0.5;   // x a diced hex's input hex diced alone, see aims()
// Every geode hex's aim is at least this (capped by kLocalAim x the template's own minimum):
// where a diced tet of the mesher's lies next to a hex part's edge or corner, the local
// yardstick says nothing about how good the transition can be there (issue 22's 0.25 target).
// 0.30 (so 0.297, the cap, with the default template) and three rings of lift below raised the
// nugget's concave corners at n = 3 0.227 -> 0.255 and its geode hexes at n = 5 and 6 0.227 ->
// 0.258, but took the n = 2 nugget's 0.263 to 0.259 (0.226 with two rings), and without the
// lift the higher aim lowered 19 block minima of 51 global runs: more defects, each patch
// taking its neighbours' room from the lower ones.
constexpr double kGeodeFloor = 0.28;

// Where defects remain after the passes, their neighbours are often what holds them: diced tets
// above the yardstick (so no defect, and left alone by the passes) but poor, whose nodes a
// defect's patch may not push further down. So the hexes within kNeighbourRings of the lowest
// remaining defects (per block at most kNeighbourSeeds within kDefectBand of its lowest, lowest
// first, and as many lowest by their ratio to their aim: the one that sets the block's ratio to
// its local yardstick may lie above that band) are lifted as the global mode lifts every hex
// (towards min(0.5, 3 x the yardstick), one patch each), and the passes run again there. Their
// floors are measured after the first passes, so a hex may lose `loss` twice, as in the global
// mode, except the diced hexes of hex parts, whose floors stay those from before all passes
// (measured afresh, layer-mixed n = 5's hex layer gave up 0.65 -> 0.51 for 0.006 on the geode
// hexes). Measured, the first passes only -> with this: the lowest geode hexes of the nugget at
// n = 5 0.218 -> 0.227 (0.76 -> 0.79 x the local yardstick), hexdominant n = 5 0.167 -> 0.184 (0.79
// -> 0.94 x), the potting's pin_z and pin_x 0.128 / 0.105 -> 0.154 / 0.119, hexdominant n = 32
// 0.116 -> 0.141 for 1.85 -> 1.93 s of smoothing. Around more defects, or again where the lowest
// rose, cost that model 2.2 to 4 times the smoothing (the band then takes in the bulk of its
// transition) for 0.145 at best. The seeds by ratio: the fulcher at n = 5 and 6 0.755 -> 0.821
// x the local yardstick (capped), the potting at n = 6 0.924 -> 0.952, hybrid-cylinder at n = 5
// 0.907 -> 0.930, hexdominant n = 32's smoothing unchanged (1.7 s).
constexpr int kNeighbourRings = 2;
constexpr std::size_t kNeighbourSeeds = 32;

// Keeps sj_ up to date. A pass changes only the hexes sharing a node with its seeds (its
// region): the defects outside it are left as they were.
void Conformer::smooth_defects(primal::LocalSmoothOptions o) {
  const std::vector<double> aim = aims();  // fixed: the yardsticks do not move
  primal::SmoothStart start;               // measured by the passes if they find a defect
  smooth_defect_passes(o, aim, start, {});
  if (start.scaled_jacobian.empty()) return;
  std::map<int, double> lowest;  // per output block, its lowest defect
  for (std::size_t h = 0; h < sj_.size(); ++h)
    if (sj_[h] < aim[h]) {
      auto [it, added] = lowest.try_emplace(mesh_.block[h], sj_[h]);
      if (!added) it->second = std::min(it->second, sj_[h]);
    }
  // Per output block, the kNeighbourSeeds defects lowest by `key` among those `within` says.
  std::vector<Index> seeds;
  const auto take_lowest = [&](auto key, auto within) {
    std::map<int, std::vector<std::pair<double, Index>>> defects;
    for (std::size_t h = 0; h < sj_.size(); ++h)
      if (sj_[h] < aim[h] && within(h))
        defects[mesh_.block[h]].emplace_back(key(h), primal::index_cast(h));
    for (auto& [block, hexes] : defects) {
      const std::size_t n = std::min(hexes.size(), kNeighbourSeeds);
      std::partial_sort(hexes.begin(), hexes.begin() + static_cast<std::ptrdiff_t>(n), hexes.end());
      for (std::size_t k = 0; k < n; ++k) seeds.push_back(hexes[k].second);
    }
  };
  take_lowest([&](std::size_t h) { return sj_[h]; },
              [&](std::size_t h) { return sj_[h] < lowest[mesh_.block[h]] + kDefectBand; });
  take_lowest([&](std::size_t h) { return sj_[h] / aim[h]; }, [](std::size_t) { return true; });
  if (seeds.empty()) return;
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  for (int ring = 0; ring < kNeighbourRings; ++ring) seeds = primal::hexes_around(mesh_, seeds);
  // The floors from now on, but the hex parts' own: `start` updated in place (a second one would
  // be 16 B per output hex more at the peak).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(diced_parent_.size(), sj_.size(), 8192),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t h = range.begin(); h != range.end(); ++h) {
                        start.scaled_jacobian[h] = sj_[h];
                        start.shortest_edge[h] = primal::hex_shortest_edge(
                            primal::hex_corners(mesh_, primal::index_cast(h)));
                      }
                    });
  primal::LocalSmoothOptions lift = options_.global_smooth_options;
  lift.progress = o.progress;
  lift.target = std::min(lift.target, options_.global_target_factor * aim_yardstick_);
  const auto r = primal::smooth_hexes_around(mesh_, seeds, lift, &start);
  add_smoothing(r);
  measure(r.region);
  smooth_defect_passes(o, aim, start, r.region);
}

void Conformer::smooth_defect_passes(primal::LocalSmoothOptions o, const std::vector<double>& aim,
                                     primal::SmoothStart& start, std::span<const Index> within) {
  const auto considered = [&](std::size_t h) {
    return within.empty() || std::binary_search(within.begin(), within.end(), h);
  };
  std::vector<Index> defects;
  double worst = 1.0;  // the lowest defect
  for (std::size_t h = 0; h < sj_.size(); ++h)
    if (sj_[h] < aim[h] && considered(h)) {
      defects.push_back(primal::index_cast(h));
      worst = std::min(worst, sj_[h]);
    }
  if (defects.empty()) return;
  // The floors over all passes, measured only where there is a defect (16 B per output hex).
  if (start.scaled_jacobian.empty()) start = {sj_, primal::shortest_edge_per_hex(mesh_)};
  o.goal = 0.0;
  o.hex_goals = aim;
  o.max_visits = kDefectVisits;
  for (int pass = 0; pass < kDefectPasses && !defects.empty(); ++pass) {
    // The first pass seeds around every defect; the later ones around the lowest of each
    // output block only.
    std::map<int, double> lowest;
    for (Index h : defects) {
      const auto i = primal::index_cast<std::size_t>(h);
      auto [it, added] = lowest.try_emplace(mesh_.block[i], sj_[i]);
      if (!added) it->second = std::min(it->second, sj_[i]);
    }
    std::vector<Index> seeds;
    for (Index h : defects) {
      const auto i = primal::index_cast<std::size_t>(h);
      if (pass == 0 || sj_[i] < lowest[mesh_.block[i]] + kDefectBand) seeds.push_back(h);
    }
    const std::vector<Index> focus = seeds;  // ascending, as defects
    for (int ring = 0; ring < kDefectRings; ++ring) seeds = primal::hexes_around(mesh_, seeds);
    o.hex_targets.resize(aim.size());
    for (std::size_t h = 0; h < aim.size(); ++h)
      o.hex_targets[h] = kDefectTarget * aim[h] + pass * kDefectTargetStep;
    const auto r = primal::smooth_hexes_around(mesh_, seeds, o, &start);
    add_smoothing(r);
    measure(r.region);
    const double worst_before = worst;
    // The defects the pass could not change stay; the region's are measured again.
    std::vector<Index> left;
    for (Index h : defects)
      if (!std::binary_search(r.region.begin(), r.region.end(), h)) left.push_back(h);
    for (Index h : r.region)
      if (sj_[primal::index_cast<std::size_t>(h)] < aim[primal::index_cast<std::size_t>(h)] &&
          considered(primal::index_cast<std::size_t>(h)))
        left.push_back(h);
    std::sort(left.begin(), left.end());
    defects.swap(left);
    worst = 1.0;
    for (Index h : defects) worst = std::min(worst, sj_[primal::index_cast<std::size_t>(h)]);
    // Progress: among the defects the pass seeded around, the ones it lifted to their aim.
    const auto still = std::count_if(focus.begin(), focus.end(), [&](Index h) {
      return sj_[primal::index_cast<std::size_t>(h)] < aim[primal::index_cast<std::size_t>(h)];
    });
    if (pass + 1 >= kDefectMinPasses &&
        static_cast<double>(still) > (1.0 - kDefectProgress) * static_cast<double>(focus.size()) &&
        worst < worst_before + kDefectRise)
      break;
  }
}

// Per output hex, what the automatic passes aim at: the yardstick; for a geode hex kLocalAim x
// the lower of its buffer hex's local yardstick and the template's own minimum (what it
// reaches in an undistorted cell), and at least kGeodeFloor (within that cap); for a diced hex
// kPartAim x its input hex diced alone (the hexes the buffer layer squashed); each only where
// higher than the yardstick.
std::vector<double> Conformer::aims() const {
  const double yardstick = aim_yardstick_;
  std::vector<double> aim(sj_.size(), yardstick);
  // A diced hex squashed by the buffer layer: at least kPartAim x its input hex diced alone,
  // so that the part keeps its own quality behind the layer.
  for (std::size_t k = 0; k < diced_parent_.size(); ++k)
    aim[k] = std::max(yardstick,
                      kPartAim * hex_diced_[primal::index_cast<std::size_t>(diced_parent_[k])]);
  for (std::size_t b = 0; b + 1 < geode_first_.size(); ++b) {
    const double local = aim_local_[primal::index_cast<std::size_t>(layer_.hexes[b].quad)];
    const double tpl = res_.template_min_scaled_jacobian;
    const double a = std::max(
        {yardstick, kLocalAim * std::min(local, tpl), std::min(kGeodeFloor, kLocalAim * tpl)});
    for (Index h = geode_first_[b]; h < geode_first_[b + 1]; ++h)
      aim[primal::index_cast<std::size_t>(h)] = a;
  }
  return aim;
}

double Conformer::measure() {
  sj_ = primal::scaled_jacobian_per_hex(mesh_);
  return scan();
}

void Conformer::measure(std::span<const Index> hexes) {
  for (Index h : hexes)
    sj_[primal::index_cast<std::size_t>(h)] =
        primal::hex_scaled_jacobian(primal::hex_corners(mesh_, h));
}

double Conformer::scan() {
  inverted_.clear();
  double lowest = 1.0;
  for (std::size_t h = 0; h < sj_.size(); ++h) {
    lowest = std::min(lowest, sj_[h]);
    if (sj_[h] <= 0.0) inverted_.push_back(primal::index_cast(h));
  }
  return lowest;
}

// Test hook (docs/cli.md): GEODE_TEST_INVERT_OUTPUT_HEX=N moves the first corner of output hex
// N (1-based) through the hex's centre before verification, then measures the hexes at that node
// again and counts them as moved, as smoothing does: a faulty stage on a valid input, which both
// --verify modes must find (tests/cli/conventions_test.cpp's exit 4).
void Conformer::invert_for_test() {
  const char* text = std::getenv("GEODE_TEST_INVERT_OUTPUT_HEX");
  if (!text || !*text) return;
  const long n = std::strtol(text, nullptr, 10);
  if (n < 1 || primal::index_cast<std::size_t>(n) > mesh_.hexes.size()) return;
  const auto& h = mesh_.hexes[primal::index_cast<std::size_t>(n - 1)];
  Point centre = Point::Zero();
  for (Index v : h) centre += mesh_.points[primal::index_cast<std::size_t>(v)];
  const Index corner = h[0];
  Point& p = mesh_.points[primal::index_cast<std::size_t>(corner)];
  p = 2.0 * (centre / 8.0) - p;
  std::vector<Index> at;
  for (std::size_t k = 0; k < mesh_.hexes.size(); ++k)
    if (std::find(mesh_.hexes[k].begin(), mesh_.hexes[k].end(), corner) != mesh_.hexes[k].end())
      at.push_back(primal::index_cast(k));
  measure(at);
  scan();
  moved_.insert(moved_.end(), at.begin(), at.end());
}

// The output's validity (verify_locally(): around what was not diced) on the output's arrays,
// where they are (mesh_, or the result's model once output() has moved them); the whole-mesh
// check reads mesh_.
void Conformer::check(std::span<const Point> points, std::span<const std::array<Index, 8>> hexes) {
  if (verify_locally()) {
    // Seeds: the geode hexes and whatever smoothing could move; the rest is diced, checked
    // against the dicing tables in check_dicing().
    std::vector<Index> seeds = std::move(moved_);
    primal::release(moved_);
    if (!geode_first_.empty())
      for (Index h = geode_first_.front(); h < geode_first_.back(); ++h) seeds.push_back(h);
    primal::RegionValidityOptions o;
    o.positive = positive_;
    res_.validity = primal::check_validity_around(points, hexes, seeds, o);
    primal::release(positive_);
    res_.verified = ConformVerify::kLocal;
    res_.verified_hexes = res_.validity.num_cells;
    if (!res_.dicing.ok()) res_.warnings.push_back("invalid dicing: " + res_.dicing.summary());
  } else {
    res_.validity = primal::check_validity(mesh_);
    res_.verified = ConformVerify::kFull;
    res_.verified_hexes = primal::index_cast(mesh_.hexes.size());
  }
  if (!res_.validity.ok()) res_.warnings.push_back("invalid mesh: " + res_.validity.summary());
  if (!inverted_.empty()) {
    std::ostringstream m;
    // 1-based in the result model's element order (writers keep it when blocks ascend).
    m << inverted_.size() << " hexes with scaled Jacobian <= 0 (1-based output elements):";
    for (std::size_t i = 0; i < std::min<std::size_t>(inverted_.size(), 20); ++i)
      m << " " << inverted_[i] + 1;
    if (inverted_.size() > 20) m << " ...";
    res_.warnings.push_back(m.str());
  }
}

// What each buffer hex's template reaches in an undistorted cell of the buffer hex's proportions
// (template_ceiling), where it matters: where its geode hexes fall short of kLocalAim x
// min(local yardstick, the templates' own minimum). A buffer hex in a thin first cell of a
// boundary layer is flatter than the template box, and there the template's minimum, not the
// placement, is what stops the geode (layer-mixed, n = 7: 0.144 in a buffer hex 0.17 as high as
// wide, where the template reaches 0.135). Only those buffer hexes are measured, and of them
// only as many as can set their block's capped ratio (ConformOptions::all_template_ceilings:
// all), the templates of their distinct proportions built in parallel (about 0.13 s each): a
// run that meets its aims pays nothing, and one with --smooth none not a template per
// proportion (the potting demo at n = 3: 6.1 -> 1.9 s of CPU).
void Conformer::ceilings(const std::vector<int>& block) {
  const double tpl = res_.template_min_scaled_jacobian;
  res_.template_ceiling.assign(res_.local_yardstick.size(), tpl);
  // The short buffer hexes: their lowest geode hex against min(local yardstick, tpl), which
  // their ratio to min(local yardstick, their ceiling) is never below (a ceiling <= tpl).
  struct Short {
    double bound;  // the lowest geode hex / min(local, tpl)
    std::size_t b;
    double lowest, local;
    int block;
  };
  std::vector<Short> short_of;
  std::map<int, double> best;  // per output block, its lowest capped ratio found so far
  const auto lower = [](std::map<int, double>& m, int id, double x) {
    const auto [it, added] = m.try_emplace(id, x);
    if (!added) it->second = std::min(it->second, x);
  };
  for (std::size_t b = 0; b + 1 < geode_first_.size(); ++b) {
    const double local =
        res_.local_yardstick[primal::index_cast<std::size_t>(layer_.hexes[b].quad)];
    const auto first = sj_.begin() + geode_first_[b], last = sj_.begin() + geode_first_[b + 1];
    const double lowest = *std::min_element(first, last);
    const int id = block[primal::index_cast<std::size_t>(geode_first_[b])];
    const double bound = lowest / std::min(local, tpl);
    // Four triangles: its own box, no ceiling.
    if (lowest < kLocalAim * std::min(local, tpl) && layer_.hexes[b].centre == kInvalidIndex)
      short_of.push_back({bound, b, lowest, local, id});
    else
      lower(best, id, bound);
  }
  std::sort(short_of.begin(), short_of.end(), [](const Short& x, const Short& y) {
    return std::tie(x.bound, x.b) < std::tie(y.bound, y.b);
  });
  // Lowest bound first, a few at a time (in parallel): a hex whose bound is not below its
  // block's best so far cannot lower it, nor later (the best only falls), so it is passed for
  // good.
  constexpr std::size_t kBatch = 8;
  for (std::size_t k = 0; k < short_of.size();) {
    std::vector<std::size_t> batch;
    for (; k < short_of.size() && batch.size() < kBatch; ++k) {
      const auto it = best.find(short_of[k].block);
      if (options_.all_template_ceilings || it == best.end() || short_of[k].bound < it->second)
        batch.push_back(k);
    }
    std::vector<double> found(batch.size(), tpl);
    tbb::parallel_for(std::size_t{0}, batch.size(), [&](std::size_t i) {
      const Short& s = short_of[batch[i]];
      try {
        found[i] = std::min(tpl, template_ceiling(options_.template_box, layer_.hexes[s.b].diagonal,
                                                  proportion_[s.b]));
      } catch (const std::exception&) {  // no template in that box: the box's own figure
      }
    });
    for (std::size_t i = 0; i < batch.size(); ++i) {
      const Short& s = short_of[batch[i]];
      res_.template_ceiling[primal::index_cast<std::size_t>(layer_.hexes[s.b].quad)] = found[i];
      lower(best, s.block, s.lowest / std::min(s.local, found[i]));
    }
  }
}

// The quality per output block.
// `block`: the output's hex blocks, where they are (mesh_, or the result's model).
void Conformer::report(const std::vector<int>& block) {
  std::map<int, std::vector<Index>> members;    // output block -> its hexes, ascending id
  for (std::size_t h = 0; h < block.size();) {  // a block's hexes come in runs: a run at a time
    std::size_t end = h + 1;
    while (end < block.size() && block[end] == block[h]) ++end;
    std::vector<Index>& list = members[block[h]];
    const std::size_t at = list.size();
    list.resize(at + end - h);
    std::iota(list.begin() + static_cast<std::ptrdiff_t>(at), list.end(), primal::index_cast(h));
    h = end;
  }
  for (const auto& [id, sel] : members) {
    const auto name = blocks_.names.find(id);
    primal::QualityReport report;
    if (options_.quality == ConformQuality::kFull) {
      report = primal::hex_quality_report(mesh_, sel);
    } else {  // the scaled Jacobians measured after smoothing
      std::vector<double> values;
      values.reserve(sel.size());
      for (Index h : sel) values.push_back(sj_[primal::index_cast<std::size_t>(h)]);
      report.num_hexes = primal::index_cast(sel.size());
      report.metrics.push_back(
          primal::summarize_metric(primal::HexMetric::kScaledJacobian, values, sel));
    }
    BlockQuality q{id, name != blocks_.names.end() ? name->second : "block " + std::to_string(id),
                   std::move(report)};
    // The input's elements by their diced-alone figures (trim_input kept their blocks only).
    for (std::size_t h = 0; h < hex_diced_.size(); ++h)
      if (primal::block_of(input_, {primal::ElementKind::kHex, primal::index_cast(h)}) == id)
        q.input_diced_min_scaled_jacobian =
            std::min(q.input_diced_min_scaled_jacobian, hex_diced_[h]);
    for (std::size_t t = 0; t < tet_given_.size(); ++t)
      if (primal::block_of(input_, {primal::ElementKind::kTet, primal::index_cast(t)}) == id)
        q.input_diced_min_scaled_jacobian =
            std::min(q.input_diced_min_scaled_jacobian, tet_given_[t]);
    for (std::size_t w = 0; w < wedge_diced_.size(); ++w)
      if (primal::block_of(input_, {primal::ElementKind::kWedge, primal::index_cast(w)}) == id)
        q.input_diced_min_scaled_jacobian =
            std::min(q.input_diced_min_scaled_jacobian, wedge_diced_[w]);
    res_.quality.push_back(std::move(q));
  }
  // The geode hexes against their local yardsticks, per block and over all.
  ceilings(block);
  for (std::size_t b = 0; b + 1 < geode_first_.size(); ++b) {
    const auto quad = primal::index_cast<std::size_t>(layer_.hexes[b].quad);
    const double local = res_.local_yardstick[quad];
    const double capped = std::min(local, res_.template_ceiling[quad]);
    for (Index h = geode_first_[b]; h < geode_first_[b + 1]; ++h) {
      const int id = block[primal::index_cast<std::size_t>(h)];
      auto it = std::find_if(res_.quality.begin(), res_.quality.end(),
                             [&](const BlockQuality& q) { return q.block == id; });
      const double sj = sj_[primal::index_cast<std::size_t>(h)];
      ++it->geode_hexes;
      it->geode_min_scaled_jacobian = std::min(it->geode_min_scaled_jacobian, sj);
      it->local_yardstick = std::min(it->local_yardstick, local);
      it->local_ratio = std::min(it->local_ratio, sj / local);
      it->capped_local_ratio = std::min(it->capped_local_ratio, sj / capped);
      res_.local_yardstick_ratio = std::min(res_.local_yardstick_ratio, sj / local);
      res_.capped_local_ratio = std::min(res_.capped_local_ratio, sj / capped);
    }
  }
}

// Verification's verdict, as a progress line; `seconds`: the report and the check (not the
// writing beside them).
void Conformer::announce(double seconds) const {
  const bool valid = res_.validity.ok() && res_.dicing.ok();
  say("verification (" + std::string(res_.verified == ConformVerify::kLocal ? "local" : "full") +
      ", " + std::to_string(res_.verified_hexes) +
      " hexes checked whole): " + (valid ? "valid" : "INVALID") + " (" +
      std::to_string(seconds + dicing_check_seconds_) + " s)");
}

void Conformer::output() {
  primal::Model& out = res_.model;
  // The names of the blocks the output has (a block's hexes come in runs).
  for (std::size_t h = 0; h < mesh_.block.size(); ++h)
    if (h == 0 || mesh_.block[h] != mesh_.block[h - 1])
      if (auto it = blocks_.names.find(mesh_.block[h]); it != blocks_.names.end())
        out.block_names.insert(*it);
  out.hex_block = std::move(mesh_.block);
  out.hexes = std::move(mesh_.hexes);
  out.points = std::move(mesh_.points);
  out.node_sets = std::move(node_sets_);
  out.side_sets = std::move(side_sets_);
}

// Verification, and the output written (options_.write_ahead) while the per-block report and
// the default validity check run: they read the output's arrays only. The whole-mesh checks
// (check_validity, the full quality report) read mesh_: those run before the writer.
void Conformer::verify_and_output() {
  t0_ = Clock::now();
  if (verify_locally()) {  // what the local check reads of the scaled Jacobians
    positive_.resize(sj_.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sj_.size(), 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t h = r.begin(); h != r.end(); ++h)
                          positive_[h] = sj_[h] > 0.0;  // all 9 determinants above 0
                      });
  }
  // The scaled Jacobians for the writer, when it asked for them (kept until it is done; else
  // freed before the check allocates, which keeps the peak where dicing puts it).
  const bool hand_on = options_.write_ahead && options_.write_ahead_scaled_jacobians;
  auto write = [&] {
    options_.write_ahead(res_.model,
                         hand_on ? std::span<const double>(sj_) : std::span<const double>());
  };
  const bool ahead =
      options_.write_ahead && verify_locally() &&
      options_.quality == ConformQuality::kScaledJacobian &&
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1;
  if (!ahead) {
    report(mesh_.block);
    if (!hand_on) primal::release(sj_);
    check(mesh_.points, mesh_.hexes);
    announce(since(t0_));
    output();
    if (options_.write_ahead) write();
    primal::release(sj_);
    return;
  }
  output();
  std::exception_ptr failed;
  double seconds = 0.0;  // the report and the check
  auto write_caught = [&] {
    try {
      write();
    } catch (...) {
      failed = std::current_exception();
    }
  };
  {
    // A thread of its own, not a TBB task: while the writer waits for the disk (its sync), the
    // check's parallel loops have every TBB thread (a task would hold one, idle).
    std::jthread writer;
    try {
      writer = std::jthread(write_caught);
    } catch (const std::system_error&) {  // no thread to be had: one after the other
    }
    // The report first (on this thread, beside the writer), its lists (and the scaled
    // Jacobians, unless the writer reads them) freed before the check allocates its own.
    report(res_.model.hex_block);
    if (!hand_on) primal::release(sj_);
    check(res_.model.points, res_.model.hexes);
    seconds = since(t0_);
    if (writer.joinable())
      writer.join();
    else
      write_caught();
  }
  primal::release(sj_);
  announce(seconds);
  if (failed) std::rethrow_exception(failed);
}

}  // namespace

ConformSmooth parse_conform_smooth(const std::string& word) {
  if (word == "local") return ConformSmooth::kLocal;
  if (word == "global") return ConformSmooth::kGlobal;
  if (word == "none") return ConformSmooth::kNone;
  throw InvalidInput("smoothing mode '" + word + "': expected local, global or none");
}

ConformQuality parse_conform_quality(const std::string& word) {
  if (word == "sj") return ConformQuality::kScaledJacobian;
  if (word == "full") return ConformQuality::kFull;
  throw InvalidInput("quality report '" + word + "': expected sj or full");
}

ConformVerify parse_conform_verify(const std::string& word) {
  if (word == "local") return ConformVerify::kLocal;
  if (word == "full") return ConformVerify::kFull;
  throw InvalidInput("verification '" + word + "': expected local or full");
}

ConformPyramids parse_conform_pyramids(const std::string& word) {
  if (word == "split") return ConformPyramids::kSplit;
  throw InvalidInput("pyramid treatment '" + word + "': expected split");
}

ConformRelax parse_conform_relax(const std::string& word) {
  if (word == "interface") return ConformRelax::kInterface;
  if (word == "none") return ConformRelax::kNone;
  throw InvalidInput("tet relaxation '" + word + "': expected interface or none");
}

// Rings of tets out from the covered quads that relax_tet_nodes moves: two take in a pyramid's
// apex and the tets around it (on the hexdominant demo, n = 8, the lowest diced tet among them
// 0.060 -> 0.184); on the nugget (n = 3) one, two or three rings give the same output.
constexpr int kRelaxRings = 2;
// Only nodes with a tet diced below 0.3 (the geode template's own minimum is 0.33: a tet diced
// at that level does not limit the transition), each step halved at most 3 times, 2 sweeps:
// on the hexdominant demo at n = 28 (2,918 free nodes; load 0.5) 0.97 s instead of 1.85 s for
// every node and 5 halvings, and the lowest diced tet there 0.175 instead of 0.167.
constexpr primal::RelaxTetsOptions kRelax{
    .sweeps = 2, .halvings = 3, .initial_step = 0.25, .good = 0.3};

namespace {

// conform() on `input`; `spare`: the same model when the caller gives it up (the Model&&
// overload), then relaxed in place instead of copied, and trimmed once the buffer layer holds
// the model.
ConformResult conform_model(const primal::Model& input, primal::Model* spare,
                            const ConformOptions& options) {
  const auto input_pyramids = primal::index_cast(input.pyramids.size());
  // kSplit, the only pyramid treatment so far: each pyramid as its better two tets
  // (split_pyramids); a pyramid template (a ConformPyramids value of its own) would fill the
  // pyramids in place.
  primal::Model own;             // the input as conform changes it, when it copies it
  primal::Model* owned = spare;  // the model conform may change: the caller's, or own
  const primal::Model* model = &input;
  if (!input.pyramids.empty()) {
    own = primal::split_pyramids(input).model;
    model = owned = &own;
  }
  Index wedges_split = 0;
  std::vector<std::string> warnings;
  for (;;) {
    primal::RelaxTetsResult relaxation;
    std::vector<primal::Point> given;  // the points before relaxation
    if (options.relax == ConformRelax::kInterface &&
        (!model->hexes.empty() || !model->wedges.empty()) && !model->tets.empty()) {
      const std::vector<Index> nodes = primal::tet_nodes_to_relax(*model, kRelaxRings);
      if (!nodes.empty()) {
        if (!owned) {
          own = input;
          model = owned = &own;
        }
        given = owned->points;
        relaxation = primal::relax_tet_nodes(owned->points, owned->tets, nodes, kRelax);
        if (options.progress)
          options.progress("tet relaxation: " + std::to_string(relaxation.nodes_moved) + " of " +
                           std::to_string(nodes.size()) + " free tet nodes moved, their tets' " +
                           "diced minimum " + std::to_string(relaxation.min_before) + " -> " +
                           std::to_string(relaxation.min_after) + " (" +
                           std::to_string(relaxation.seconds) + " s)");
      }
    }
    Conformer conformer(*model, options, relaxation.nodes_moved ? &given : nullptr,
                        model == owned ? owned : nullptr);
    ConformResult r = conformer.run();
    if (const auto& joining = conformer.joining(); !joining.empty()) {
      // A wedge layer joins the two sides of the interface: its pieces become tets (from the
      // points as given: the relaxation runs again on the split model), and the run starts
      // again; a hex quad they covered may join another piece to the sides, hence the loop.
      if (!given.empty()) owned->points = std::move(given);
      const std::vector<Index> pieces = primal::wedge_pieces(*model, joining);
      warnings.push_back(
          std::to_string(pieces.size()) + " wedges split into three tets each: the layer of " +
          primal::describe_element(*model, {primal::ElementKind::kWedge, joining.front()}) +
          " joins the two sides of the hex/tet interface (hexes and wedges side "
          "by side in a layer against tets), where no buffer layer can end");
      own = primal::split_wedges(*model, pieces);
      model = owned = &own;
      wedges_split += primal::index_cast(pieces.size());
      if (options.progress)
        options.progress("wedges: " + std::to_string(pieces.size()) +
                         " split into tets (a wedge layer joined the two sides of the interface)");
      continue;
    }
    r.relaxation = relaxation;
    r.seconds += relaxation.seconds;
    r.input_pyramids = input_pyramids;
    r.wedges_split = wedges_split;
    r.warnings.insert(r.warnings.begin(), warnings.begin(), warnings.end());
    r.input_wedges += wedges_split;
    r.input_tets -= 2 * r.input_pyramids + 3 * wedges_split;
    return r;
  }
}

}  // namespace

ConformResult conform(const primal::Model& input, const ConformOptions& options) {
  return conform_model(input, nullptr, options);
}

ConformResult conform(primal::Model&& input, const ConformOptions& options) {
  return conform_model(input, &input, options);
}

}  // namespace geode::conform
