// conform() itself: the stages before and around Conformer (detail/conformer.hpp) that change
// the model it is given: the tet relaxation, pyramids split, and the layers of hexes and wedges
// that join the two sides of the interface, split into tets (all of a thin layer, or its wedges
// alone, leaving holes), the run started again after each.
#include <geode/conform/conform.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <iterator>
#include <numeric>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <geode/conform/detail/conformer.hpp>
#include <geode/conform/report.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/relax_tets.hpp>
#include <geode/primal/split_hexes.hpp>
#include <geode/primal/split_pyramids.hpp>
#include <geode/primal/split_wedges.hpp>
#include <geode/primal/topology.hpp>

namespace geode::conform {

namespace {

using primal::Index;

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

// A layer through which wedges join tets on its two sides is split into tets where its wedge
// columns' cells are lower than this of their width: flatter than 2.5 : 1, the hex cells whose
// buffer hexes Conformer::thicker_from_tets finds too flat (kThinHexBuffer: half the cell's
// height below 0.2 of its width), and at the holes there is no thicker side to carve from.
constexpr double kThinLayerCells = 0.4;
// ... and where every hex of it is flatter than this (hex_flatness): a layer's, not a thick
// part's (cube-like, near 1). Gmsh's layers 0.1 thick reach 0.53 at their narrowest quads.
constexpr double kLayerHex = 2.0 / 3.0;
// A thicker layer keeps its hexes, its wedges alone split: holes through it whose walls get
// buffer hexes. Where the output is then below this x the yardstick (worse than the input's own
// elements diced alone), the layer is split into tets as a thin one is and conformed again, and
// the better output kept. The walls of triangular holes meet at 60 degrees: cylinder layers in 2
// cells 0.2 and 0.3 thick (cells 0.6 and 0.9 of their width high) gave 0.025 and 0.0066 with the
// holes (0.57 x and 0.15 x), 0.145 and 0.118 split.
constexpr double kPoorHoles = 1.0;
// Where the layer was carved from the hex part's near-thin cells (Conformer::near_thin), the
// tet part's layer is tried too when the geode hexes fall below this x their local yardstick
// capped by the template's ceiling (issue 22's aim for the transition; capped_local_ratio) or
// the output is invalid (only then where the hex side was given: a graded quads-only layer,
// cylinder 6 out 0.1 quads cells=3 ratio=1.5, left 67 hexes inverted with --buffer-side hex),
// and the output with the higher minimum kept (the first on a tie). The
// layer's cells' height alone does not tell which side is better: Gmsh's quads-only cylinder
// layers 0.15 thick outward have a tets' layer thinner than the hexes' (0.195 against 0.228 of
// the quads' edge) and give 0.073 from it against 0.029 from the hexes; a sphere's quads-only
// layer 0.1 thick gives the same minimum (0.126) from both, and keeps the hexes'.
// So too where conform carved the layer from a hex part convex at some interface corner
// (Conformer::convex_hex_part): its buffer hexes taper there by their height in two directions,
// while from the tets they widen. On demo_wedge (n = 3) the tets' layer took the geode hexes
// from 0.60-0.86 x to above 1 x at 60 to 270 degrees, its output's minimum as high or higher;
// at 300 degrees it gave 0.1623 against 0.1631, and the hex part's is kept. On a tie of the
// minimum (the same element lowest in both, away from the transition) the higher capped ratio
// is kept.
constexpr double kPoorTransition = 0.9;
// A block below this x its own elements diced alone has been spoilt by the transition it
// received (issue 22's target for each part's block). Carved from a hex part, the geode hexes
// join the part's block and reach the template's own minimum at best (0.33), so a part diced
// near 1 falls short wherever it is convex at some interface corner; there the tet part's layer
// is tried too, and kept where it spoils no block while its output's minimum is at least
// kPartTrade x the hex part's. The potting demo: n = 3, parts 0.197-0.36 x -> 0.79-0.92 x, the
// output's minimum 0.0392 -> 0.0688 (higher anyway); n = 5, 0.19-0.40 x -> 0.80-0.96 x for
// 0.0718 -> 0.0688 (0.96 x); demo_wedge at 300 degrees, its part 0.18 x -> 0.84 x for 0.1631 ->
// 0.1623.
constexpr double kPartKept = 0.5;
constexpr double kPartTrade = 0.9;

// The block lowest against its own elements diced alone, and that ratio (none: 1).
std::pair<const BlockQuality*, double> lowest_block(const std::vector<BlockQuality>& quality) {
  std::pair<const BlockQuality*, double> low{nullptr, 1.0};
  for (const BlockQuality& q : quality)
    if (q.report.num_hexes > 0 && q.input_diced_min_scaled_jacobian > 0.0) {
      const double ratio = block_min_scaled_jacobian(q.report) / q.input_diced_min_scaled_jacobian;
      if (ratio < low.second) low = {&q, ratio};
    }
  return low;
}

// "block 3 'pin_x' at 0.2 x its own elements diced alone", of lowest_block's result.
std::string lowest_block_text(const std::pair<const BlockQuality*, double>& low) {
  const auto [q, ratio] = low;
  if (!q) return "every block at 1 x its own elements diced alone";
  std::ostringstream m;
  m << "block " << q->block << (q->name.empty() ? "" : " '" + q->name + "'") << " at " << ratio
    << " x its own elements diced alone";
  return m.str();
}

// How flat a hex is: the mean length of its edges along its flattest direction over that along
// its longest.
double hex_flatness(const primal::Model& m, const std::array<Index, 8>& h) {
  std::array<double, 3> mean{};
  for (std::size_t e = 0; e < primal::topology::kHexEdgeCorners.size(); ++e) {
    const auto& c = primal::topology::kHexEdgeCorners[e];
    mean[e / 4] += (m.points[primal::index_cast<std::size_t>(h[static_cast<std::size_t>(c[1])])] -
                    m.points[primal::index_cast<std::size_t>(h[static_cast<std::size_t>(c[0])])])
                       .norm();
  }
  return *std::min_element(mean.begin(), mean.end()) / *std::max_element(mean.begin(), mean.end());
}

// The indices in [0, n) not in `split` (ascending): where the current model's cells come from.
std::vector<Index> remaining(std::size_t n, const std::vector<Index>& split) {
  std::vector<Index> out;
  for (std::size_t i = 0; i < n; ++i)
    if (!std::binary_search(split.begin(), split.end(), primal::index_cast(i)))
      out.push_back(primal::index_cast(i));
  return out;
}

// `a` and `b` (ascending) merged, ascending, without repeats.
std::vector<Index> merged(const std::vector<Index>& a, const std::vector<Index>& b) {
  std::vector<Index> out;
  std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

// conform() on `input`; `spare`: the same model when the caller gives it up (the Model&&
// overload), then relaxed in place instead of copied, and trimmed once the buffer layer holds
// the model. Each pass of run() conforms the current model; a pass that finds a layer of wedges
// joining the two sides of the interface changes the model and starts again.
class ModelConformer {
 public:
  ModelConformer(const primal::Model& input, primal::Model* spare, ConformOptions options)
      : input_(input),
        options_(std::move(options)),
        owned_(spare),
        model_(&input),
        wedge_origin_(input.wedges.size()),
        hex_origin_(input.hexes.size()),
        write_ahead_(std::move(options_.write_ahead)) {
    std::iota(wedge_origin_.begin(), wedge_origin_.end(), Index{0});
    std::iota(hex_origin_.begin(), hex_origin_.end(), Index{0});
    // A pass whose result may yet be compared with another's does not write it: the caller's
    // writer writes once, and the result returned is written after the comparison instead.
    if (write_ahead_)
      options_.write_ahead = [this](const primal::Model& m, std::span<const double> sj) {
        if (compared_ || (!holes_.hexes.empty() && !layer_kept_) ||
            (conformer_ && (conformer_->near_thin() > 0.0 || conformer_->convex_hex_part()))) {
          deferred_ = true;
          return;
        }
        write_ahead_(m, sj);
      };
  }
  ModelConformer(const ModelConformer&) = delete;  // options_.write_ahead holds `this`
  ModelConformer& operator=(const ModelConformer&) = delete;

  // The passes, then the result's output written where its pass deferred it.
  ConformResult run();

 private:
  // The input's split pyramids (kSplit, the only pyramid treatment so far: each pyramid as its
  // better two tets; a pyramid template, a ConformPyramids value of its own, would fill them in
  // place), or the input.
  primal::Model without_pyramids() const {
    return input_.pyramids.empty() ? input_ : primal::split_pyramids(input_).model;
  }
  // One pass: the tets near the hex part relaxed (given_: their points before), then Conformer.
  ConformResult pass(std::vector<Index>& joining);
  // The points as given back in place of the last pass's relaxed ones, for another pass.
  void restore_given() {
    if (!given_.empty()) owned_->points = std::move(given_);
  }
  // A thin layer joining the two sides: its whole pieces become tets; false where a hex of it has
  // no split (it keeps its hexes, as a thick layer does).
  bool split_layer(const primal::CellPieces& layer, const std::string& where,
                   const std::string& why);
  // Only the wedges of the pieces: holes through the layer.
  void split_wedges_alone(const std::vector<Index>& pieces, Index first);
  // The layers whose wedges alone were split (holes_), split into tets for another pass, `why`
  // said in the warning; the holes' warnings dropped but where the split fails.
  bool split_holes(const std::string& why);
  // The result's counts of what was split, the warnings in front of its own after its findings.
  void finish(ConformResult& r) const;
  ConformResult passes();
  // `r`, or the tet part's layer's result where that is better (kPoorTransition).
  ConformResult from_tets(ConformResult r);

  const primal::Model& input_;
  ConformOptions options_;              // the caller's; the buffer side changed by from_tets
  primal::Model own_;                   // the input as conform changes it, when it copies it
  primal::Model* owned_;                // the model conform may change: the caller's, or own_
  const primal::Model* model_;          // what the next pass conforms
  std::vector<primal::Point> given_;    // the points before this pass's relaxation
  primal::RelaxTetsResult relaxation_;  // this pass's
  // What was split, by the input's own wedge and hex numbers, and where the current model's
  // wedges and hexes come from in the input (splitting renumbers the rest).
  std::vector<Index> wedges_split_, hexes_split_;
  Index hex_tets_ = 0;  // the tets the split hexes became
  std::vector<Index> wedge_origin_, hex_origin_;
  std::vector<std::string> warnings_;
  bool layer_kept_ = false;                    // a thin layer that could not be split into tets
  double near_thin_ = 0.0;                     // the last pass's Conformer::near_thin()
  bool tets_cross_ = false;                    // ... its Conformer::tets_cross()
  bool convex_hex_part_ = false;               // ... and its Conformer::convex_hex_part()
  std::optional<detail::AsCarved> as_carved_;  // ... and its Conformer::as_carved()
  // The caller's writer; the pass running (its near_thin() says whether from_tets may follow);
  // whether the pass running will be compared with an earlier one; whether a pass deferred its
  // writing.
  std::function<void(const primal::Model&, std::span<const double>)> write_ahead_;
  const detail::Conformer* conformer_ = nullptr;
  bool compared_ = false, deferred_ = false;
  // The layers whose wedges alone were split (kPoorHoles), by the input's numbers, and where the
  // warnings stood before the first of them.
  primal::CellPieces holes_;
  bool holes_split_ = false;  // ... and split into tets since (split_holes): not again
  std::size_t warnings_before_holes_ = 0;
  std::string holes_where_;  // the first of them, named
};

ConformResult ModelConformer::pass(std::vector<Index>& joining) {
  relaxation_ = {};
  given_.clear();
  if (options_.relax == ConformRelax::kInterface &&
      (!model_->hexes.empty() || !model_->wedges.empty() || !hexes_split_.empty()) &&
      !model_->tets.empty()) {
    // Where a hex layer was split into tets, its cells' corners seed the rings too: the
    // pyramids Gmsh put on its quads are tets beside it still.
    std::vector<Index> seeds;
    for (Index h : hexes_split_)
      for (Index v : input_.hexes[primal::index_cast<std::size_t>(h)]) seeds.push_back(v);
    const std::vector<Index> nodes = primal::tet_nodes_to_relax(*model_, kRelaxRings, seeds);
    if (!nodes.empty()) {
      if (!owned_) {
        own_ = input_;
        model_ = owned_ = &own_;
      }
      given_ = owned_->points;
      relaxation_ = primal::relax_tet_nodes(owned_->points, owned_->tets, nodes, kRelax);
      if (options_.progress)
        options_.progress("tet relaxation: " + std::to_string(relaxation_.nodes_moved) + " of " +
                          std::to_string(nodes.size()) + " free tet nodes moved, their tets' " +
                          "diced minimum " + std::to_string(relaxation_.min_before) + " -> " +
                          std::to_string(relaxation_.min_after) + " (" +
                          std::to_string(relaxation_.seconds) + " s)");
    }
  }
  detail::Conformer conformer(*model_, options_, relaxation_.nodes_moved ? &given_ : nullptr,
                              model_ == owned_ ? owned_ : nullptr);
  conformer.tets_given(std::min(options_.split_tets_from, primal::index_cast(input_.tets.size())));
  conformer_ = &conformer;
  // Not left pointing at the conformer when its run throws.
  struct Unset {
    const detail::Conformer*& conformer;
    ~Unset() { conformer = nullptr; }
  } unset{conformer_};
  ConformResult r = conformer.run();
  joining = conformer.joining();
  near_thin_ = conformer.near_thin();
  tets_cross_ = conformer.tets_cross();
  convex_hex_part_ = conformer.convex_hex_part();
  as_carved_ = conformer.as_carved();
  return r;
}

bool ModelConformer::split_layer(const primal::CellPieces& layer, const std::string& where,
                                 const std::string& why) {
  // Split again from the input as given, in the order above (pyramids, wedges, then the hexes
  // on the diagonals those give them), as geode_mpi's zone, whose pyramids come split, does.
  std::vector<Index> wedges_now = wedges_split_, hexes_now = hexes_split_;
  for (Index w : layer.wedges) wedges_now.push_back(w);
  for (Index h : layer.hexes) hexes_now.push_back(h);
  std::sort(wedges_now.begin(), wedges_now.end());
  std::sort(hexes_now.begin(), hexes_now.end());
  wedges_now.erase(std::unique(wedges_now.begin(), wedges_now.end()), wedges_now.end());
  hexes_now.erase(std::unique(hexes_now.begin(), hexes_now.end()), hexes_now.end());
  const primal::Model wedges = primal::split_wedges(without_pyramids(), wedges_now);
  try {
    own_ = primal::split_hexes(wedges, hexes_now);  // untouched when it throws
  } catch (const TopologyError& e) {
    // A hex with no positive split on the diagonals the tets on its faces force, or a face
    // under four tet triangles (which no split follows). Its wedges alone are split, as a
    // thicker layer's are: buffer hexes at the holes, valid where they are, rather than no mesh.
    layer_kept_ = true;
    warnings_.push_back(where + ", but its hexes stay hexes: " + e.what());
    return false;
  }
  wedges_split_ = std::move(wedges_now);
  hexes_split_ = std::move(hexes_now);
  std::ostringstream m;
  m << layer.hexes.size() << " hexes and " << layer.wedges.size()
    << " wedges split into tets: " << where << ", and " << why;
  warnings_.push_back(m.str());
  if (options_.progress)
    options_.progress("layer: " + std::to_string(layer.hexes.size()) + " hexes and " +
                      std::to_string(layer.wedges.size()) +
                      " wedges split into tets (wedges through a layer between tets)");
  hex_tets_ = primal::index_cast(own_.tets.size() - wedges.tets.size());
  model_ = owned_ = &own_;
  wedge_origin_ = remaining(input_.wedges.size(), wedges_split_);
  hex_origin_ = remaining(input_.hexes.size(), hexes_split_);
  return true;
}

void ModelConformer::split_wedges_alone(const std::vector<Index>& pieces, Index first) {
  warnings_.push_back(std::to_string(pieces.size()) +
                      " wedges split into three tets each: the layer of " +
                      primal::describe_element(*model_, {primal::ElementKind::kWedge, first}) +
                      " joins the two sides of the hex/tet interface (hexes and wedges side "
                      "by side in a layer against tets), where no buffer layer can end");
  own_ = primal::split_wedges(*model_, pieces);
  model_ = owned_ = &own_;
  for (Index w : pieces) wedges_split_.push_back(wedge_origin_[primal::index_cast<std::size_t>(w)]);
  std::sort(wedges_split_.begin(), wedges_split_.end());
  wedge_origin_ = remaining(input_.wedges.size(), wedges_split_);
  if (options_.progress)
    options_.progress("wedges: " + std::to_string(pieces.size()) +
                      " split into tets (a wedge layer joined the two sides of the interface)");
}

void ModelConformer::finish(ConformResult& r) const {
  r.relaxation = relaxation_;
  r.input_pyramids = primal::index_cast(input_.pyramids.size());
  r.wedges_split = primal::index_cast(wedges_split_.size());
  r.hexes_split = primal::index_cast(hexes_split_.size());
  r.warnings.insert(r.warnings.begin() + static_cast<std::ptrdiff_t>(r.findings), warnings_.begin(),
                    warnings_.end());
  r.input_wedges += r.wedges_split;
  r.input_hexes += r.hexes_split;
  r.input_tets -= 2 * r.input_pyramids + 3 * r.wedges_split + hex_tets_;
}

ConformResult ModelConformer::run() {
  const auto start = std::chrono::steady_clock::now();
  ConformResult r = passes();
  if (deferred_ && write_ahead_) {
    std::vector<double> sj;
    if (options_.write_ahead_scaled_jacobians) {
      // primal's per-hex pass over the output's arrays, lent to a HexMesh and given back.
      primal::HexMesh mesh{std::move(r.model.points), std::move(r.model.hexes), {}};
      sj = primal::scaled_jacobian_per_hex(mesh);
      r.model.points = std::move(mesh.points);
      r.model.hexes = std::move(mesh.hexes);
    }
    write_ahead_(r.model, sj);
  }
  // Every pass's, the results not kept too.
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

ConformResult ModelConformer::passes() {
  if (!input_.pyramids.empty()) {
    own_ = without_pyramids();
    model_ = owned_ = &own_;
  }
  std::optional<ConformResult> with_holes;  // kPoorHoles: the holes' result, while split is tried
  for (;;) {
    std::vector<Index> joining;
    ConformResult r;
    try {
      r = pass(joining);
    } catch (const TopologyError& e) {
      if (with_holes) return std::move(*with_holes);  // the layers split failed: the holes
      // No buffer layer at a hole's wall (where the wall meets the layer's face, the interface
      // faces at a node can all turn away from every direction: the sphere's layer 0.15 to 0.2
      // thick in tests/conform/layer_model.py at n = 6): the layers split into tets instead.
      if (holes_.hexes.empty() || layer_kept_ || holes_split_) throw;
      if (!split_holes("with its wedges alone split, the holes they leave take no buffer layer (" +
                       std::string(e.what()) + ")"))
        throw;
      continue;
    }
    if (!joining.empty()) {
      // A wedge layer joins the two sides of the interface: its pieces become tets (from the
      // points as given: the relaxation runs again on the split model), and the run starts
      // again; a hex quad they covered may join another piece to the sides, hence the loop.
      restore_given();
      const std::vector<Index> pieces = primal::wedge_pieces(*model_, joining);
      const primal::WedgeColumns columns = primal::wedge_columns(*model_, pieces);
      const primal::CellPieces layer =
          columns.through ? primal::cell_pieces(*model_, pieces) : primal::CellPieces{};
      primal::CellPieces as_input;  // the layer by the input's numbers
      for (Index w : layer.wedges)
        as_input.wedges.push_back(wedge_origin_[primal::index_cast<std::size_t>(w)]);
      for (Index h : layer.hexes)
        as_input.hexes.push_back(hex_origin_[primal::index_cast<std::size_t>(h)]);
      const std::string where =
          "wedges go through the layer of " +
          primal::describe_element(*model_, {primal::ElementKind::kWedge, pieces.front()}) +
          " from tets on one side to tets on the other";
      // Only a layer: one joined to a thick part would take it along; it keeps the holes (and
      // their buffer hexes) instead, unless they turn out poor (kPoorHoles).
      const bool thin =
          columns.height_ratio < kThinLayerCells && !layer.hexes.empty() &&
          std::all_of(layer.hexes.begin(), layer.hexes.end(), [&](Index h) {
            return hex_flatness(*model_, model_->hexes[primal::index_cast<std::size_t>(h)]) <
                   kLayerHex;
          });
      if (thin && !layer_kept_) {
        // Wedges go through a thin layer from tets on one side to tets on the other: split,
        // they would leave holes whose walls are interface quads as high as the layer's cells
        // (buffer hexes there inverted or flat, or two layer hexes meeting along an edge only).
        // The layer's whole pieces of hexes and wedges become tets, diced with the tets around
        // them.
        std::ostringstream why;
        why << "its cells are " << columns.height_ratio
            << " of their width high, too thin for buffer hexes at the holes split wedges leave";
        if (split_layer(as_input, where, why.str())) continue;
      } else if (!layer.hexes.empty()) {
        if (holes_.hexes.empty()) warnings_before_holes_ = warnings_.size(), holes_where_ = where;
        std::sort(as_input.wedges.begin(), as_input.wedges.end());
        std::sort(as_input.hexes.begin(), as_input.hexes.end());
        holes_.wedges = merged(holes_.wedges, as_input.wedges);
        holes_.hexes = merged(holes_.hexes, as_input.hexes);
      }
      split_wedges_alone(pieces, joining.front());
      continue;
    }
    finish(r);
    if (with_holes) {  // the layers split: the better of the two
      if (result_valid(r) &&
          output_min_scaled_jacobian(r) > output_min_scaled_jacobian(*with_holes))
        return r;
      return std::move(*with_holes);
    }
    const double holes_min = output_min_scaled_jacobian(r);
    if (holes_.hexes.empty() || layer_kept_ || holes_split_ ||
        holes_min >= kPoorHoles * r.yardstick())
      return from_tets(std::move(r));
    // The holes gave a poor transition: the layers split into tets instead, conformed again.
    std::ostringstream why;
    why << "with its wedges alone split, the buffer hexes at the holes they leave gave "
        << holes_min << " (" << holes_min / r.yardstick() << " x the input's elements diced alone)";
    with_holes = std::move(r);
    compared_ = true;
    if (!split_holes(why.str())) return std::move(*with_holes);
  }
}

bool ModelConformer::split_holes(const std::string& why) {
  const std::vector<std::string> kept = warnings_;
  warnings_.resize(warnings_before_holes_);
  const primal::CellPieces layers = holes_;
  holes_split_ = split_layer(layers, holes_where_, why);
  if (!holes_split_) warnings_ = kept;
  return holes_split_;
}

ConformResult ModelConformer::from_tets(ConformResult r) {
  // The side given (or a thickness for it): only an invalid output is not taken as it is.
  const bool automatic = buffer_side_automatic(options_);
  const bool valid = result_valid(r);
  // The blocks and the capped ratio as without a named geode block, a label only (AsCarved).
  const std::optional<detail::AsCarved> hex_carved = as_carved_;
  const auto& hex_quality = hex_carved ? hex_carved->quality : r.quality;
  const double hex_capped = hex_carved ? hex_carved->capped_local_ratio : r.capped_local_ratio;
  const bool short_of_aim = hex_capped < kPoorTransition;
  const double hex_min = output_min_scaled_jacobian(r), height = near_thin_;
  // Nearly thin hex cells at the interface, or (chosen by conform) a hex part convex at some
  // interface corner, where its buffer hexes taper.
  // Where the tets' layer would cross faces between their blocks (tets_cross_), only an output
  // worse than the input's own elements diced alone justifies that.
  const bool thin =
      near_thin_ > 0.0 &&
      (!valid || (automatic && (tets_cross_ ? hex_min < r.yardstick() : short_of_aim)));
  const auto hex_low = lowest_block(hex_quality);
  const bool spoilt = valid && hex_low.second < kPartKept;  // some block below it
  const bool convex = convex_hex_part_ && valid && (short_of_aim || spoilt);
  if (!thin && !convex) return r;
  if (options_.progress)
    options_.progress(
        !valid ? std::string("buffer layer: from the hex part's thin cells the output is "
                             "invalid; the tet part's layer tried")
               : std::string("buffer layer: from the hex part's ") +
                     (thin ? "thin cells" : "convex corners") + " the geode hexes reach " +
                     std::to_string(hex_capped) + " x their capped local yardstick" +
                     (spoilt ? ", " + lowest_block_text(hex_low) : std::string()) +
                     "; the tet part's layer tried too");
  // The same pass from the tet part (at its default thickness): the tets relaxed again from the
  // points as given.
  restore_given();
  options_.buffer.side = BufferSide::kTet;
  options_.buffer.thickness = 0.0;
  options_.buffer_side_chosen = true;
  const bool crossing = tets_cross_;
  if (crossing) options_.buffer.keep_block_faces = false;
  compared_ = true;
  std::vector<Index> joining;
  ConformResult t;
  try {
    t = pass(joining);
  } catch (const TopologyError&) {
    return r;
  }
  // The higher minimum; on a tie (the same element lowest in both, away from the interface)
  // the transition nearer its aim. The first on a tie of both. A block the hex part's spoils
  // and the tet part's does not is worth kPartTrade of the minimum.
  const double tet_min = output_min_scaled_jacobian(t);
  const auto& tet_quality = as_carved_ ? as_carved_->quality : t.quality;
  const double tet_capped = as_carved_ ? as_carved_->capped_local_ratio : t.capped_local_ratio;
  const auto tet_low = lowest_block(tet_quality);
  const bool keeps_parts = convex && !crossing && spoilt && result_valid(t) &&
                           tet_low.second >= kPartKept && tet_min >= kPartTrade * hex_min;
  const bool better =
      !valid || tet_min > hex_min || keeps_parts || (tet_min == hex_min && tet_capped > hex_capped);
  if (!joining.empty() || t.buffer_side != BufferSide::kTet || !result_valid(t) || !better) {
    if (options_.progress) options_.progress("buffer layer: the hex part's kept");
    return r;
  }
  finish(t);
  std::ostringstream m;
  m << "buffer layer carved from the tet part, not the hex part"
    << (automatic ? "" : " given (--buffer-side hex, or a thickness for it)") << ": ";
  if (thin)
    m << "from the hex part's thin cells at the interface (its buffer hexes " << height
      << " of their interface quads' edge high on average on the thinnest piece) ";
  else
    m << "at the hex part's convex corners its buffer hexes taper, and from it ";
  if (valid)
    m << "the output's minimum scaled Jacobian was " << hex_min << ", its geode hexes "
      << hex_capped << " x their capped local yardstick"
      << (spoilt ? ", " + lowest_block_text(hex_low) : std::string()) << "; from the tet part "
      << tet_min << " and " << tet_capped << " x"
      << (spoilt ? ", " + lowest_block_text(tet_low) : std::string());
  else
    m << "the output was invalid (" << invalid_reason(r) << "); from the tet part " << tet_min;
  if (crossing)
    m << "; across faces between the tet part's blocks, so blocks there do not keep their "
         "volumes, nor side sets on those faces their place: no layer from the tet part keeps "
         "them";
  t.warnings.insert(t.warnings.begin() + static_cast<std::ptrdiff_t>(t.findings), m.str());
  return t;
}

}  // namespace

ConformResult conform(const primal::Model& input, const ConformOptions& options) {
  return ModelConformer(input, nullptr, options).run();
}

ConformResult conform(primal::Model&& input, const ConformOptions& options) {
  return ModelConformer(input, &input, options).run();
}

}  // namespace geode::conform
