#pragma once
// conform()'s private class, not part of the API: a long algorithm as one public function
// (conform.hpp) whose stages are the methods of Conformer, defined by topic in conform.cpp (the
// interface, the buffer layer, dicing, template placement, assembly), conform_smoothing.cpp
// (settling, untangling, smoothing) and conform_output.cpp (verification, the report, the
// output). conform_model.cpp runs it, after what changes the model first (the tet relaxation,
// pyramids and layers split into tets).
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <geode/conform/buffer_layer.hpp>
#include <geode/conform/conform.hpp>
#include <geode/conform/reference_template.hpp>
#include <geode/primal/dice_model.hpp>
#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/interface.hpp>
#include <geode/primal/local_smooth.hpp>
#include <geode/primal/mesh.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/topology.hpp>

namespace geode::conform::detail {

using primal::FaceKey;
using primal::Index;
using primal::kInvalidIndex;
using primal::kNoOrigin;
using primal::Point;
namespace topo = primal::topology;

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// What smoothing aims a geode hex at, and the report measures it against: this x its local
// yardstick, capped (Conformer::aims, Conformer::ceilings).
inline constexpr double kLocalAim = 0.9;

// The output's block ids and names: the input's, plus the geode block when it has a name.
struct OutputBlocks {
  int geode_id = 0;  // 0: geode hexes join the block of the element they were carved from
  std::map<int, std::string> names;
};

// The map of the reference cell into a buffer hex: bilinear on the bottom (the hex side's
// quad), piecewise linear over the two triangles of the top (so the tet side's diced nodes,
// edge midpoints and triangle centroids, are images of the template's), linear in t between
// them. The trilinear map would instead follow a twisted top's bilinear surface, whose
// diagonal midpoint passes the template nodes under it; this one keeps every template hex
// positive wherever the buffer hex is valid. With `centre`, the top is four_triangle_top.
Point buffer_map(const std::array<Point, 8>& P, const std::array<int, 2>& diagonal,
                 const Point& rst, const Point* centre = nullptr);

// With a named geode block (ConformOptions::geode_block): the per-block quality and the capped
// ratio as without it, every geode hex in the block it was carved from. conform()'s choice of
// the buffer side reads these, so that the option stays a label and the mesh the one without it.
struct AsCarved {
  std::vector<BlockQuality> quality;
  double capped_local_ratio = 1.0;
};

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

  // How many of the input's tets are the caller's own, in front of those conform made of its
  // pyramids and wedges (split_pyramids, split_wedges): those follow a quad's bilinear face.
  void tets_given(Index n) { tets_given_ = n; }

  // The wedges run() found joining the two sides of the interface, where it stopped.
  const std::vector<Index>& joining() const { return joining_; }

  // Where the layer was carved from the hex part (left to conform, or given) although its cells
  // at some piece of the interface are flatter than 2 : 1 (kNearThinHexBuffer;
  // thicker_from_tets did not take the tet part's layer): the thinnest piece's mean buffer
  // height (buffer_height_ratios), else 0. The input is then kept, not trimmed, so that
  // conform() can try the tet part's layer too.
  double near_thin() const { return near_thin_; }
  // Nearly thin (near_thin()) where the tet part's layer is thicker but crosses faces between
  // its blocks (no layer from it keeps them): conform() tries it only where the hex part's output
  // is below the yardstick or invalid, its blocks then not keeping their volumes.
  bool tets_cross() const { return tets_cross_; }
  // Where the layer was carved, automatically, from a hex part convex at some interface corner
  // (BufferLayerReport::convex_corners), not nearly thin: its buffer hexes taper there, and
  // conform() tries the tet part's layer too where the geode hexes fall short or spoil a block.
  // The input is then kept, as for near_thin().
  bool convex_hex_part() const { return convex_hex_part_; }
  // With a named geode block, the report as without it (AsCarved); else nothing.
  const std::optional<AsCarved>& as_carved() const { return as_carved_; }

  ConformResult run() {
    const auto t_start = Clock::now();
    res_.numbering = options_.output_numbering;
    find_interface();
    if (!joining_.empty()) return {};  // conform() splits their wedge pieces and starts again
    insert_buffer();
    warn_warped();
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
  // The buffer hex whose template output hex `h` is, or kNone when `h` is not a geode hex.
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t buffer_hex_of(Index h) const {
    if (geode_first_.size() < 2 || h < geode_first_.front() || h >= geode_first_.back())
      return kNone;
    return primal::index_cast<std::size_t>(
        std::upper_bound(geode_first_.begin(), geode_first_.end(), h) - geode_first_.begin() - 1);
  }
  const RefTemplate& ref(std::size_t b) const {
    if (layer_.hexes[b].centre != kInvalidIndex) return *refs_[2];
    return layer_.hexes[b].diagonal[0] == 5 ? *refs_[1] : *refs_[0];
  }

  void find_interface();
  void warped_interface();
  void warn_warped();
  void measure_near_interface();
  std::vector<double> local_minima(const std::vector<double>& tet) const;
  void insert_buffer();
  void carved();  // after insert_buffer placed the layer
  // The hex part's layer on its thinnest piece: near_thin_ set where it is nearly thin; where
  // it is thin and `may_switch` (the side left to conform), the tet part's layer taken if
  // clearly thicker there.
  void thicker_from_tets(bool may_switch);
  void measure_changed();
  void trim_input();
  void build_references();
  void dice_and_merge();
  void place_templates();
  void match_sides();
  void assemble();
  void carry_side_sets();
  primal::Model node_set_model() const;
  void keep_sets();
  void diced_alone_from_children(std::size_t tet_first);
  void settle_templates();
  std::vector<std::pair<Index, Point>> settled(std::size_t b) const;
  void untangle();
  void add_smoothing(const primal::LocalSmoothResult& r);
  void smooth();
  void smooth_defects(primal::LocalSmoothOptions o);
  // The global mode's options (its pass over every hex, and the lift), its target at most
  // global_target_factor x the yardstick aimed at, reporting to the caller's options' progress.
  primal::LocalSmoothOptions global_options(const primal::LocalSmoothOptions& caller) const {
    primal::LocalSmoothOptions g = options_.global_smooth_options;
    g.progress = caller.progress;
    g.kept = caller.kept;
    g.target = std::min(g.target, options_.global_target_factor * aim_yardstick_);
    return g;
  }
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
  void check(std::span<const Point> points, std::span<const std::array<Index, 8>> hexes,
             std::span<const int> block);
  void ceilings(const std::vector<int>& block);
  void report(const std::vector<int>& block);
  void report_as_carved();
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
  double near_thin_ = 0.0;      // near_thin()
  bool convex_hex_part_ = false;
  bool tets_cross_ = false;
  // warped_interface: per (hex-side block, tet-side block, the tets split from a pyramid or
  // wedge) the space between the interface quads' bilinear faces and the tets' triangles on
  // them (the hex block's side of the triangles, signed), the quads' scale (their sizes cubed)
  // and how many are not planar.
  Index tets_given_ = std::numeric_limits<Index>::max();
  std::map<std::tuple<int, int, bool>, std::tuple<double, double, std::size_t>> warped_;
  BufferLayer layer_;
  primal::DicedModel diced_;
  std::array<const RefTemplate*, 3> refs_{};  // diagonal {4, 6}, {5, 7}, four triangles
  // Per buffer hex and template node: its global node, or (side-face nodes, until
  // match_sides) a disjoint-sets item at side_pos_.
  std::vector<std::vector<Index>> inst_global_, inst_side_;
  primal::DisjointSets side_sets_uf_;
  std::vector<Point> side_pos_;
  std::vector<primal::FaceKey> side_origin_;  // per item: the buffer hex corners it is made from
  primal::HexMesh mesh_;
  std::vector<primal::NodeSet> node_sets_;
  std::vector<primal::SideSet> side_sets_;
  primal::KeptFeatures kept_;  // the sets in mesh_'s numbers, for smoothing (keep_sets)
  // Every output hex's scaled Jacobian (kept current by assemble, settling and smoothing) and
  // the hexes at or below 0 as of the last scan(); verification reads them.
  std::vector<double> sj_;
  std::vector<Index> inverted_;
  OutputBlocks blocks_;
  // Per buffer hex: the input element it was carved from (the hex under it or the tet above it,
  // by BufferLayerOptions::side), whose block its geode hexes join by default: they fill space
  // that part had.
  std::vector<primal::ElementRef> carved_from_;
  // With a named geode block: mesh_.block before the geode hexes join it (until
  // report_as_carved), and that report.
  std::vector<int> carved_blocks_;
  std::optional<AsCarved> as_carved_;
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

}  // namespace geode::conform::detail
