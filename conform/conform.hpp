#pragma once
// The geode algorithm on a whole model (the paper's Sections 1 and 4): find the hex/tet
// interface, shrink one part off it (buffer layer; the hex part by default), dice the hex part (8
// per hex) and the tet part (4 hexes per tet), fill every buffer hex with the 26-hex geode template
// (or, where the interface quad is split into four triangles around a centre node, the 44-hex
// four-triangle template) mapped into it (a template the map inverts is settled inside its
// buffer hex), merge, smooth locally and verify. The result is all-hex.
//
// Merging. Tet- and hex-side template nodes are identified with diced nodes by their origin
// (corner, edge midpoint, quad centre, triangle centroid, a four-triangle top's centre node:
// the keys of primal/dice's node-origin map), never by position, and take the diced position.
// Side-face nodes of two buffer hexes sharing a side face are matched topologically (the side
// face's quad mesh, propagated from the shared top/bottom nodes across quad edges) and merged. The
// reference template's four side faces carry one mirror-symmetric mesh (templates/side_faces.hpp)
// and a side face is mapped bilinearly from its four corners by both buffer hexes, so both place a
// merged node at the same point: no position is reconciled, and a placement valid in each buffer
// hex stays valid.
#include <algorithm>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <geode/conform/buffer_layer.hpp>
#include <geode/primal/dice_model.hpp>
#include <geode/primal/element_numbers.hpp>
#include <geode/primal/local_smooth.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/quality_report.hpp>
#include <geode/primal/relax_tets.hpp>
#include <geode/primal/validity.hpp>

namespace geode::conform {

enum class ConformSmooth { kNone, kLocal, kGlobal };

// "local", "global" or "none"; InvalidInput naming the word otherwise.
ConformSmooth parse_conform_smooth(const std::string& word);

// What the verification reports per block besides validity: the scaled Jacobian alone
// (cheap), or every metric of the paper's Table 1 (primal/quality_report.hpp).
enum class ConformQuality { kScaledJacobian, kFull };

// "sj" or "full"; InvalidInput naming the word otherwise.
ConformQuality parse_conform_quality(const std::string& word);

// How much of the output the verification checks. kLocal: check_validity's full check on the
// geode hexes, the hexes smoothing could move and two rings around them
// (primal/validity_local.hpp), the diced parts through the dicer's tables
// (primal::check_dicing: children as their tables make them, no node made twice) and every
// hex's corner Jacobians; the diced parts of a valid input are then valid by construction.
// kFull: check_validity on the whole output (the cost of several dicings).
enum class ConformVerify { kLocal, kFull };

// "local" or "full"; InvalidInput naming the word otherwise.
ConformVerify parse_conform_verify(const std::string& word);

// What becomes of the pyramids of a hybrid mesh: kSplit, each pyramid as two tets along the
// base diagonal giving the better tets (primal/split_pyramids.hpp), its base quad then getting
// the transition as any two-triangle interface quad does. (A pyramid template is the place for
// a second value.)
enum class ConformPyramids { kSplit };

// "split"; InvalidInput naming the word otherwise.
ConformPyramids parse_conform_pyramids(const std::string& word);

// Whether the tet mesher's nodes near the hex part move before the buffer layer is carved
// (primal/relax_tets.hpp): kInterface (default) relaxes the tet nodes within two rings of tets
// of the hex part (hexes and wedges) that lie inside one tet block (no boundary, material interface
// or node set moves), raising the lowest diced scaled Jacobian of their tets; kNone keeps every
// input node where it is.
enum class ConformRelax { kNone, kInterface };

// "none" or "interface"; InvalidInput naming the word otherwise.
ConformRelax parse_conform_relax(const std::string& word);

struct ConformOptions {
  ConformPyramids pyramids = ConformPyramids::kSplit;
  ConformRelax relax = ConformRelax::kInterface;
  BufferLayerOptions buffer;
  // When no buffer layer can be carved from buffer.side (a node where that part's copy cannot
  // move off the interface, e.g. on the hex part's flat boundary where a tet part covers only
  // part of a hex face), carve it from the other part (at that side's default thickness) and say
  // so in ConformResult::warnings; false: refuse.
  bool buffer_fallback = true;
  // False (automatic, with no thickness given: buffer_side_automatic): where the hex part's
  // buffer hexes on some piece of the interface are flat (a graded boundary layer's thin first
  // cells), the tet part's layer is taken if it is thicker there, with a warning (conform.cpp,
  // kThinHexBuffer), and where they are nearly so or taper at convex corners the tet part's is
  // tried too (conform_model.cpp, kPoorTransition). True: buffer.side as the caller chose it
  // (buffer_fallback still applies where that part gives no layer at all).
  bool buffer_side_chosen = false;
  // The model's tets from this index on are pyramids (or wedges) the caller split, as geode_mpi's
  // zone is cut from a model whose pyramids it split: on an interface quad that is not planar
  // their triangles stand for the quad's bilinear face, which bounded the pyramid (the volume
  // warning of conform.cpp's warped_interface). conform itself so counts the pyramids it splits.
  primal::Index split_tets_from = std::numeric_limits<primal::Index>::max();
  double interface_tolerance = 1e-6;  // find_interface: relative to the local edge length
  // Box of the reference template (x, y, z as in templates/geode.hpp: y is the buffer hex's
  // thickness direction). It is smoothed once per diagonal, top and bottom fixed and its four
  // side faces one shared mesh (templates/side_faces.hpp); only its proportions matter. Near
  // the buffer hexes' own (half the shortest edge thick by default), a template mapped into
  // them keeps most of its quality (the paper's is 24 x 14 x 24; 24 x 10 x 24 suits the tet
  // side's default thickness).
  Eigen::Vector3d template_box{24.0, 12.0, 24.0};
  // ConformResult::template_ceiling for every buffer hex whose geode hexes fall short (each a
  // template smoothed in a box of its proportions: with --smooth none, seconds on the potting
  // demo), not only where it can set a block's capped_local_ratio (the default).
  bool all_template_ceilings = false;
  // The worst-first smoother (primal/local_smooth.hpp); materials never move: nodes on the
  // model boundary and on the faces between output blocks slide in their plane or along their
  // straight edge where those are flat, and stay fixed elsewhere (curved surfaces, corners), so
  // every block keeps its volume (primal::boundary_slide_constraints). kLocal: patches
  // seeded near the geode hexes (see smooth_target), on the submesh around them; kGlobal: by
  // every hex, with a higher target so that the diced parts are improved too, then kLocal's
  // automatic passes wherever a hex is still below the yardstick; kNone: nothing but
  // untangling the hexes the placement inverted, if any (ConformResult::placement_inverted).
  ConformSmooth smooth = ConformSmooth::kLocal;
  // kLocal. 0 (automatic): the defects are the hexes below the yardstick (the input's own hexes
  // and tets diced alone, ConformResult); patches start on them and the hexes sharing a node
  // with them (one patch each), at hexes below 1.1 x the yardstick, until none is below the
  // yardstick, and up to seven times more around the defects left, each time 0.02 higher. The
  // smoother works only where the transition is worse than dicing the input makes anyway, and
  // its cost follows the defects, not the interface. > 0: every geode hex and its neighbours
  // below this scaled Jacobian seed patches.
  double smooth_target = 0.0;
  ConformQuality quality = ConformQuality::kScaledJacobian;
  // kLocal takes the diced parts as valid by construction, so it is sound on an input that passed
  // primal::check_input (faces shared by at most two cells, covered once, a manifold boundary):
  // io::read_model runs it, and so do the demo command and the Python module on the models they
  // build; a caller handing conform() a model of its own runs primal::require_single_covering
  // first or asks for kFull. kGlobal smoothing moves every node: its output is verified whole
  // whatever this says.
  ConformVerify verify = ConformVerify::kLocal;
  // kLocal, kGlobal's automatic passes, and the untangling of hexes still inverted (with any
  // mode); the automatic target replaces its target, goal and max_visits. A narrower margin and
  // a larger loss than the primal defaults: hexes near the worst of a patch must give a little
  // for it to rise (where every hex around a defect is within the margin of it, no patch can
  // move), and the hexes around it may give up 0.2 (over all passes) so that it reaches the
  // yardstick. More visits per hex (4) for untangling and an explicit smooth_target, each a
  // single call: there a hex is lifted by its neighbours' moves within it.
  primal::LocalSmoothOptions local_smooth_options = [] {
    primal::LocalSmoothOptions o;
    o.max_visits = 4;
    o.margin = 0.03;
    o.loss = 0.2;
    return o;
  }();
  // kGlobal's pass over every hex: hexes below min(target, global_target_factor x the
  // yardstick) seed one patch each. Relative to the yardstick so that the pass lifts the worst
  // hexes of the model, not nearly all diced tets of a poor tet mesh (on the potting demo, n =
  // 3, a fixed 0.5 seeded 39,000 patches, 53 s).
  primal::LocalSmoothOptions global_smooth_options = [] {
    primal::LocalSmoothOptions o;
    o.target = 0.5;
    o.max_visits = 1;
    return o;
  }();
  double global_target_factor = 3.0;
  // Empty: geode hexes go to the block of the element their buffer hex was carved from (the
  // hex under it, or the tet above it with BufferSide::kTet): the material of that space.
  // A name: they get a block of their own with that name, id one above every input block id.
  std::string geode_block;
  // Called with one line per stage (for the command line's progress output); may be empty.
  std::function<void(const std::string&)> progress;
  // Called after each round of smoothing with (seed hexes settled, seed hexes), for a progress
  // bar; when empty, `progress` gets a line every few seconds instead.
  std::function<void(std::size_t done, std::size_t total)> smoothing_progress;
  // Called during the whole-output check (ConformVerify::kFull, and `--smooth global`) with its
  // (work done, all the work), as primal::ValidityProgress says; may be empty.
  primal::ValidityProgress verification_progress;
  // Called once with the output model (ConformResult::model, before it is returned) when it is
  // final: on a thread of its own while the default verification (ConformVerify::kLocal, the
  // scaled Jacobian report) runs, else after verification, so that a caller writing it (to a
  // temporary file: the result may yet be found invalid) waits for no write of its own. An
  // exception it throws is rethrown once verification is done. May be empty. With
  // write_ahead_scaled_jacobians, its second argument is each output hex's scaled Jacobian
  // (primal::hex_scaled_jacobian, the same doubles), which conform has measured anyway, for a
  // writer that writes them (io::WriteOptions::scaled_jacobians); they are then kept, 8 bytes
  // a hex, until it returns. Else it is empty.
  std::function<void(const primal::Model&, std::span<const double> scaled_jacobians)> write_ahead;
  bool write_ahead_scaled_jacobians = false;
  // How the output's file numbers its hexes and nodes (io::element_numbering of its format): the
  // report's min_hex / max_hex and verification's findings name them so. The output model's
  // own order is not the blocks' (ConformResult::model).
  primal::ElementNumbering output_numbering;
};

// The buffer side as the command line and Python spell it: "" (automatic: the hex part, or the
// tet part where the hex part's cells at the interface are thin), "hex" or "tet" (that part, as
// chosen); sets buffer.side and buffer_side_chosen. InvalidInput naming any other word.
void set_buffer_side(ConformOptions& options, const std::string& word);
// Whether the buffer side is conform's to choose: neither a side nor a thickness given.
inline bool buffer_side_automatic(const ConformOptions& options) {
  return !options.buffer_side_chosen && options.buffer.thickness == 0.0;
}

struct BlockQuality {
  int block = 0;
  std::string name;  // the block's name; empty where it has none (as in the output file)
  primal::QualityReport report;
  // The block's input elements each diced alone (1 when it has none): what the part gives
  // without any transition.
  double input_diced_min_scaled_jacobian = 1.0;
  // The geode hexes the block holds (none: the figures stay 1): their lowest scaled Jacobian,
  // the lowest local yardstick of their buffer hexes (ConformResult::local_yardstick), and the
  // lowest ratio of a geode hex's scaled Jacobian to its own buffer hex's local yardstick, and
  // to that capped by what its template reaches (ConformResult::capped_local_ratio).
  primal::Index geode_hexes = 0;
  double geode_min_scaled_jacobian = 1.0, local_yardstick = 1.0, local_ratio = 1.0;
  double capped_local_ratio = 1.0;
};

struct ConformResult {
  // All-hex model: hexes by origin (diced_hexes diced hexes, geode_hexes geode hexes, 26 per
  // two-triangle interface quad and the four-triangle template's count per four-triangle one,
  // in Interface order, diced_tet_hexes diced tets), each in an input block:
  // a diced hex or tet in its parent's, a geode hex in that of the hex (or, carved from the tet
  // part, the tet) its buffer hex was carved from (or ConformOptions::geode_block); input block
  // names kept. Node sets: every input node of the set plus the diced edge / face nodes whose
  // origin nodes are all in the set. Side sets: every input side becomes the diced children's faces
  // lying on it (4 per hex face, 3 per tet face).
  primal::Model model;
  // input_tets: the input's own; its pyramids are split into two tets each before the rest.
  // wedges_split: of input_wedges, those split into three tets each where a wedge layer joined
  // the two sides of the interface (primal/split_wedges.hpp), the whole pieces of wedges they
  // belong to. hexes_split: of input_hexes, those split into tets (5, 6 or 12 each) where
  // wedges went through a thin layer of hexes from tets on one side to tets on the other
  // (primal/split_hexes.hpp): the layer's whole pieces of hexes and wedges.
  primal::Index input_hexes = 0, input_tets = 0, input_pyramids = 0, input_wedges = 0,
                interface_quads = 0, wedges_split = 0, hexes_split = 0;
  primal::Index diced_hexes = 0, geode_hexes = 0, diced_tet_hexes = 0, diced_wedge_hexes = 0;
  BufferLayerReport buffer;
  BufferSide buffer_side = BufferSide::kHex;  // the part the buffer layer was carved from
  double template_min_scaled_jacobian = 0.0;  // the reference templates used, after smoothing
  // The yardstick for the transition: the input's hexes and tets each diced alone
  // (primal::diced_min_scaled_jacobian), before the buffer layer moves anything.
  // Pyramids count as their two tets (the tet figure), wedges diced alone as their own (a split
  // wedge as its three tets, the tet figure).
  double input_diced_hex_min_scaled_jacobian = 1.0, input_diced_tet_min_scaled_jacobian = 1.0;
  double input_diced_wedge_min_scaled_jacobian = 1.0;
  double yardstick() const {
    return std::min({input_diced_hex_min_scaled_jacobian, input_diced_tet_min_scaled_jacobian,
                     input_diced_wedge_min_scaled_jacobian});
  }
  // ConformRelax::kInterface: the tet nodes moved and the lowest diced scaled Jacobian of their
  // tets before and after. The yardsticks (above and local_yardstick) stay the input's own cells
  // as given; what smoothing aims at follows the cells as relaxed.
  primal::RelaxTetsResult relaxation;
  // The local yardstick, per buffer hex (Interface order): the lowest of the input hexes and tets
  // touching its interface quad (sharing a node with it), each diced alone. A transition next
  // to good cells is measured against them, not against the worst tet of the model. Smoothing
  // aims every geode hex at 0.9 x min(its local yardstick, template_min_scaled_jacobian) (what
  // the template reaches in an undistorted cell), and at least the yardstick.
  std::vector<double> local_yardstick;
  // Per buffer hex (Interface order): what its template reaches in an undistorted cell of the
  // buffer hex's proportions (conform::template_ceiling of its buffer_proportions), where its geode
  // hexes fall below 0.9 x min(local yardstick, template_min_scaled_jacobian) and can set their
  // block's capped_local_ratio (taken lowest ratio first, until the rest cannot go below it;
  // every such hex with ConformOptions::all_template_ceilings); elsewhere
  // template_min_scaled_jacobian (the template in --template-box), which it never exceeds.
  std::vector<double> template_ceiling;
  // The lowest ratio of a geode hex's scaled Jacobian to its local yardstick (after smoothing),
  // and to min(its local yardstick, its buffer hex's template_ceiling). Below 0.9 the first can
  // be the template's ceiling (a local yardstick above 0.330 / 0.9, or a buffer hex flatter
  // than the template box: a thin first cell of a boundary layer); the second says how far
  // placement fell short.
  double local_yardstick_ratio = 1.0, capped_local_ratio = 1.0;
  double min_scaled_jacobian_before_smoothing = 0.0;
  // Buffer hexes whose template the map inverted, re-smoothed inside the buffer hex (interior
  // template nodes only, every other node fixed) before any smoothing.
  primal::Index templates_settled = 0;
  // Hexes the placement (the map, then that settling) left with scaled Jacobian <= 0; every mode
  // untangles those still inverted (patches seeded within two rings of them); ConformSmooth::kNone
  // does that and nothing else.
  primal::Index placement_inverted = 0;
  // The smoothing and untangling calls added up; the minima and inverted counts are the whole
  // mesh's before and after (kNone: no patches when nothing was inverted).
  primal::LocalSmoothResult smoothing;
  // The validity check (of the region ConformVerify::kLocal names, or of the whole output) and,
  // kLocal, the dicing against its tables; result_valid (report.hpp) needs both ok().
  primal::HexValidityReport validity;
  primal::DicingCheck dicing;
  ConformVerify verified = ConformVerify::kFull;
  primal::Index verified_hexes = 0;  // hexes check_validity read
  std::vector<BlockQuality>
      quality;  // one per output block, ascending id ("block N" unnamed); ConformOptions::quality
  std::vector<std::string>
      warnings;  // e.g. "3 hexes with scaled Jacobian <= 0: 12 40 ..." (output_numbering)
  // How many of the warnings, first, are verification's findings (what makes the result invalid:
  // invalid dicing, invalid mesh, inverted hexes); the run's own come after them.
  std::size_t findings = 0;
  // How the report and the findings number hexes and nodes (ConformOptions::output_numbering).
  primal::ElementNumbering numbering;
  double seconds = 0.0;
};

// Pyramids first become tets (ConformOptions::pyramids), then the tets near the transition are
// relaxed (ConformOptions::relax); wedges are diced in place, 6 hexes each, after the diced tets
// in the output, and a wedge quad meeting tet triangles gets the transition as a hex quad does.
// A model without tets, or without hexes and wedges, has no interface and is simply diced.
// Throws TopologyError from find_interface / insert_buffer_layer (named by them: e.g. a wedge
// joining the two sides around an interface node), when a side face is shared by more than two
// buffer hexes or when the side faces of two buffer hexes do not match; InvalidInput when the
// model is empty. A model with both parts but no interface quad is diced, with a warning. A
// result whose validity is not ok() is still returned (with warnings) so that it can be
// inspected.
ConformResult conform(const primal::Model& input, const ConformOptions& options = {});
// The same on a model the caller gives up, changed in place rather than copied: its tets
// relaxed, and once the buffer layer holds the model (a copy of it) its arrays freed but the
// blocks, so that the run's peak holds one model less (the n = 36 Delaunay bench: 138.5 ->
// 128.3 MiB). Afterwards, or after an exception, the model may have been changed or emptied.
ConformResult conform(primal::Model&& input, const ConformOptions& options = {});

}  // namespace geode::conform
