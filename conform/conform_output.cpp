// conform()'s last stages (detail/conformer.hpp): verification, the quality report per block
// with the local yardsticks and template ceilings, and the output handed to the writer.
#include <geode/conform/detail/conformer.hpp>

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <map>
#include <span>
#include <system_error>
#include <thread>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <geode/primal/element_numbers.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/quality_report.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/validity_local.hpp>

namespace geode::conform::detail {

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
void Conformer::check(std::span<const Point> points, std::span<const std::array<Index, 8>> hexes,
                      std::span<const int> block) {
  // What makes the result invalid leads the warnings, so that the refusal's one line (exit 4)
  // says it first, before what the run said on its way (wedges split, volumes moved).
  const auto verdict = [&](std::string why) {
    res_.warnings.insert(res_.warnings.begin() + static_cast<std::ptrdiff_t>(res_.findings++),
                         std::move(why));
  };
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
    if (!res_.dicing.ok()) {
      // A faulty stage, not the input: named in the dicing's own arrays (children, nodes), on
      // one line.
      std::string why = res_.dicing.summary();
      for (std::size_t at; (at = why.find("\n  ")) != std::string::npos;) why.replace(at, 3, "; ");
      while (!why.empty() && why.back() == '\n') why.pop_back();
      verdict("invalid dicing, numbered in the dicing's own arrays: " + why);
    }
  } else {
    res_.validity = primal::check_validity(mesh_, options_.verification_progress);
    res_.verified = ConformVerify::kFull;
    res_.verified_hexes = primal::index_cast(mesh_.hexes.size());
  }
  // Hexes and nodes as the output file numbers them (ConformOptions::output_numbering).
  const primal::ElementNumbering numbering = options_.output_numbering;
  if (!res_.validity.ok()) {
    // The hexes its lists hold, numbered in one pass (findings() names a few of each).
    std::vector<Index> listed;
    for (const auto* list : {&res_.validity.out_of_range_hexes, &res_.validity.repeated_node_hexes,
                             &res_.validity.inverted_hexes})
      listed.insert(listed.end(), list->begin(), list->end());
    std::sort(listed.begin(), listed.end());
    listed.erase(std::unique(listed.begin(), listed.end()), listed.end());
    const std::vector<std::int64_t> numbers = primal::hex_numbers(block, listed, numbering);
    const auto hex = [&](Index h) {
      return numbers[static_cast<std::size_t>(std::lower_bound(listed.begin(), listed.end(), h) -
                                              listed.begin())];
    };
    const auto node = [&](Index v) { return std::int64_t{v} + numbering.base; };
    verdict("invalid mesh: " + primal::findings(res_.validity, hex, node));
  }
  if (!inverted_.empty()) {
    std::ostringstream m;
    m << inverted_.size() << " hexes with scaled Jacobian <= 0:";
    const std::size_t shown = std::min<std::size_t>(inverted_.size(), 20);
    for (std::int64_t n : primal::hex_numbers(block, std::span(inverted_).first(shown), numbering))
      m << " " << n;
    if (inverted_.size() > shown) m << " ...";
    verdict(m.str());
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
    // An unnamed block stays so: the report says what the output file says.
    BlockQuality q{id, name != blocks_.names.end() ? name->second : std::string(),
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
  // Where each metric's extremes are, as the output file numbers its hexes.
  std::vector<Index*> at;
  for (BlockQuality& q : res_.quality)
    for (primal::MetricSummary& m : q.report.metrics) at.insert(at.end(), {&m.min_hex, &m.max_hex});
  std::vector<Index> hexes(at.size());
  std::transform(at.begin(), at.end(), hexes.begin(), [](const Index* h) { return *h; });
  const auto numbers = primal::hex_numbers(block, hexes, options_.output_numbering);
  for (std::size_t i = 0; i < at.size(); ++i) *at[i] = primal::index_cast(numbers[i]);
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

// The report again with the geode hexes in the blocks they were carved from (AsCarved), the
// result's own report (the output's blocks) left as it was.
void Conformer::report_as_carved() {
  if (carved_blocks_.empty()) return;
  std::vector<BlockQuality> labelled = std::move(res_.quality);
  std::vector<double> ceilings = res_.template_ceiling;
  const double local = res_.local_yardstick_ratio, capped = res_.capped_local_ratio;
  res_.quality.clear();
  res_.local_yardstick_ratio = res_.capped_local_ratio = 1.0;
  report(carved_blocks_);
  as_carved_ = AsCarved{std::move(res_.quality), res_.capped_local_ratio};
  res_.quality = std::move(labelled);
  res_.template_ceiling = std::move(ceilings);
  res_.local_yardstick_ratio = local;
  res_.capped_local_ratio = capped;
  primal::release(carved_blocks_);
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
  // A named geode block (--geode-block) labels hexes of the material they were carved from:
  // smoothing moved them as that block's, so the mesh is the one without the option (with it,
  // their faces were block faces the smoothing kept, and quads-only layers came out with
  // inverted hexes, exit 4, where the run without it was valid).
  if (blocks_.geode_id != 0 && geode_first_.size() > 1) {
    carved_blocks_ = mesh_.block;
    std::fill(mesh_.block.begin() + geode_first_.front(), mesh_.block.begin() + geode_first_.back(),
              blocks_.geode_id);
  }
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
    report_as_carved();
    if (!hand_on) primal::release(sj_);
    check(mesh_.points, mesh_.hexes, mesh_.block);
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
    report_as_carved();
    if (!hand_on) primal::release(sj_);
    check(res_.model.points, res_.model.hexes, res_.model.hex_block);
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

}  // namespace geode::conform::detail
