// conform()'s smoothing stages (detail/conformer.hpp): the templates settled in their buffer
// hexes, inverted hexes untangled, and the worst-first smoothing with its aims.
#include <geode/conform/detail/conformer.hpp>

#include <algorithm>
#include <map>
#include <numeric>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <geode/primal/boundary.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/smooth.hpp>

namespace geode::conform::detail {

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
  for (Index h : inverted_)
    if (const std::size_t b = buffer_hex_of(h); b != kNone)
      if (buffer_hexes.empty() || buffer_hexes.back() != b) buffer_hexes.push_back(b);
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
// within this many rings of it, and where some are still inverted after that, again within
// kUntangleRings more, up to kUntangleTries times. With --smooth none, two templates inverted in
// a quads-only layer's buffer hexes (cylinder layers 0.1 thick inwards and 0.15 outwards, warped
// interface quads) were left at 4 and 2 inverted hexes by two rings, none by four.
constexpr int kUntangleRings = 2;
constexpr int kUntangleTries = 3;

// A hex still inverted (one whose buffer hex leaves its template no valid placement, or one the
// smoothing could not lift) is untangled with the hexes within kUntangleRings of it (or more), at
// local_smooth_options' own target, so that even --smooth none gives a usable mesh. Reads
// inverted_ as the last measure() or scan() left it.
void Conformer::untangle() {
  if (inverted_.empty()) return;
  const std::size_t before = inverted_.size();
  primal::LocalSmoothOptions o = options_.local_smooth_options;
  o.kept = &kept_;
  for (int attempt = 1; attempt <= kUntangleTries && !inverted_.empty(); ++attempt) {
    std::vector<Index> seeds = inverted_;
    for (int ring = 0; ring < attempt * kUntangleRings; ++ring)
      seeds = primal::hexes_around(mesh_, seeds);
    const auto r = primal::smooth_hexes_around(mesh_, seeds, o);
    add_smoothing(r);
    measure(r.region);
    res_.smoothing.final_min_scaled_jacobian = scan();
    res_.smoothing.final_inverted = primal::index_cast(inverted_.size());
  }
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

// The worst-first smoother (primal/local_smooth.hpp); nodes on the model boundary, between
// blocks and on the user's side sets slide only where that keeps every block's volume and the
// sets' surfaces, and a node set's nodes only within their set (keep_sets). Local: patches
// seeded near the geode hexes, on the submesh around the seeds, so the cost follows the
// interface (or, with the automatic target, its defects); global: every hex, then the automatic
// passes wherever a hex is still below the yardstick. Hexes the placement left inverted are
// untangled first, as with --smooth none: the smoother's floors hold the worst hex of a patch
// only where it is not inverted, and starting from the inverted hexes the passes (one visit a
// seed) ended below --smooth none's result (quads-only cylinder layers with 32 and 50 hexes
// inverted by placement: 0.029 and 0.011 against 0.033 and 0.018; untangled first, 0.069 and
// 0.029). From a valid mesh they only raise its minimum.
void Conformer::smooth() {
  t0_ = Clock::now();
  res_.smoothing.initial_min_scaled_jacobian = res_.min_scaled_jacobian_before_smoothing;
  res_.smoothing.final_min_scaled_jacobian = res_.min_scaled_jacobian_before_smoothing;
  res_.smoothing.initial_inverted = res_.smoothing.final_inverted = res_.placement_inverted;
  keep_sets();
  untangle();
  if (options_.smooth == ConformSmooth::kNone) {
    kept_ = {};
    return;
  }
  const bool local = options_.smooth == ConformSmooth::kLocal;
  primal::LocalSmoothOptions o = options_.local_smooth_options;
  o.kept = &kept_;
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
    const auto constraints = primal::kept_slide_constraints(mesh_, kept_);
    add_smoothing(primal::smooth_hexes_local(mesh_, constraints, nullptr, {}, global_options(o)));
    sj_ = primal::scaled_jacobian_per_hex(mesh_);
    // The global target lifts the whole mesh a little, not a defect to the yardstick: the
    // local passes follow wherever a hex is still below it. Their floors are measured on the
    // globally smoothed mesh: from before it, the edges the global pass shortened would leave
    // the defects no room. So the bounds add up over the two: a hex may lose `loss` in each,
    // an edge shrink to half of half its length.
    // With the neighbourhood lift, as the local mode: the passes' floors hold the neighbours of
    // the defects they leave here too. Over the 17 demos at n = 3, 5, 6, against the passes
    // alone: the whole output's minimum up in 8 runs, down in none, block minima up in 29 of
    // the 132 and down in 6, runs below 0.9 x the capped local yardstick 2 -> 0, the
    // smoothing's CPU 26.1 -> 32.9 s.
    smooth_defects(o);
  }
  res_.smoothing.final_min_scaled_jacobian = scan();
  res_.smoothing.final_inverted = primal::index_cast(inverted_.size());
  untangle();
  kept_ = {};
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
constexpr int kDefectVisits = 1;  // patches seeded by one hex in one pass
constexpr double kPartAim = 0.5;  // x a diced hex's input hex diced alone, see aims()
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
// first, and its kRatioSeeds lowest against what the report measures them by: the one that sets
// the block's ratio to its local yardstick may lie above that band) are lifted as the global mode
// lifts every hex (towards min(0.5, 3 x the yardstick), one patch each), and the passes run again
// there. Their floors are measured after the first passes, so a hex may lose `loss` twice, as in
// the global mode, except the diced hexes of hex parts, whose floors stay those from before all
// passes (measured afresh, layer-mixed n = 5's hex layer gave up 0.65 -> 0.51 for 0.006 on the
// geode hexes). Measured, the first passes only -> with this: the lowest geode hexes of the nugget
// at n = 5 0.218 -> 0.227 (0.76 -> 0.79 x the local yardstick), hexdominant n = 5 0.167 -> 0.184
// (0.79 -> 0.94 x), the potting's pin_z and pin_x 0.128 / 0.105 -> 0.154 / 0.119, hexdominant
// n = 32 0.116 -> 0.141 for 1.85 -> 1.93 s of smoothing. Around more defects, or again where the
// lowest rose, cost that model 2.2 to 4 times the smoothing (the band then takes in the bulk of
// its transition) for 0.145 at best. The seeds by ratio: the fulcher at n = 5 and 6 0.690 -> 0.821
// x the local yardstick (capped 0.755 -> 0.821), the potting's 90-degree convex edges at n = 3
// 0.214 -> 0.242, hexdominant n = 32 0.558 -> 0.578 (capped 0.761 both) for 1.37 -> 1.49 s of
// smoothing (30,074 -> 32,508 patches); 32 of them instead of 8 gave the fulcher 0.903 capped
// but hexdominant n = 32 2.1 s, and the 32 lowest by their ratio to the aim (0.28 for most geode
// hexes, so nearly their scaled Jacobian) 0.821 capped for 1.70 s.
constexpr int kNeighbourRings = 2;
constexpr std::size_t kNeighbourSeeds = 32;
constexpr std::size_t kRatioSeeds = 8;

// Keeps sj_ up to date. A pass changes only the hexes sharing a node with its seeds (its
// region): the defects outside it are left as they were.
void Conformer::smooth_defects(primal::LocalSmoothOptions o) {
  const std::vector<double> aim = aims();  // fixed: the yardsticks do not move
  primal::SmoothStart start;               // measured by the passes if they find a defect
  smooth_defect_passes(o, aim, start, {});
  if (start.scaled_jacobian.empty()) return;
  std::vector<std::size_t> defects;  // what the passes left below its aim
  std::map<int, double> lowest;      // per output block, its lowest defect
  for (std::size_t h = 0; h < sj_.size(); ++h)
    if (sj_[h] < aim[h]) {
      defects.push_back(h);
      auto [it, added] = lowest.try_emplace(mesh_.block[h], sj_[h]);
      if (!added) it->second = std::min(it->second, sj_[h]);
    }
  // Per output block, the `count` defects lowest by `key` among those `within` says.
  std::vector<Index> seeds;
  const auto take_lowest = [&](std::size_t count, auto key, auto within) {
    std::map<int, std::vector<std::pair<double, Index>>> by_block;
    for (std::size_t h : defects)
      if (within(h)) by_block[mesh_.block[h]].emplace_back(key(h), primal::index_cast(h));
    for (auto& [block, hexes] : by_block) {
      const std::size_t n = std::min(hexes.size(), count);
      std::partial_sort(hexes.begin(), hexes.begin() + static_cast<std::ptrdiff_t>(n), hexes.end());
      for (std::size_t k = 0; k < n; ++k) seeds.push_back(hexes[k].second);
    }
  };
  take_lowest(
      kNeighbourSeeds, [&](std::size_t h) { return sj_[h]; },
      [&](std::size_t h) { return sj_[h] < lowest[mesh_.block[h]] + kDefectBand; });
  // What the report divides a geode hex by, as far as it is known before the report: its local
  // yardstick capped by the template's own minimum (the report's cap, the template's ceiling at
  // the buffer hex's proportions, is measured after smoothing and only lower); any other hex:
  // its aim.
  const auto reported = [&](std::size_t h) {
    const std::size_t b = buffer_hex_of(primal::index_cast(h));
    if (b == kNone) return aim[h];
    return std::min(res_.local_yardstick[primal::index_cast<std::size_t>(layer_.hexes[b].quad)],
                    res_.template_min_scaled_jacobian);
  };
  take_lowest(
      kRatioSeeds, [&](std::size_t h) { return sj_[h] / reported(h); },
      [](std::size_t) { return true; });
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
  const auto r = primal::smooth_hexes_around(mesh_, seeds, global_options(o), &start);
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

}  // namespace geode::conform::detail
