#pragma once
// A pass over items [0, n) cut into pieces that run in parallel (TBB), each piece keeping what
// it finds apart, handed back in piece order: what one pass in order finds, for any thread
// count. The checks use it where their findings are lists (validity.cpp's per-node pass,
// validity_local.cpp's rings, input_check.cpp's face pairing).
#include <cstddef>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace geode::primal::detail {

// f(piece, begin, end, out) for each piece [cut[p], cut[p + 1]) of an ascending `cut`, pieces in
// parallel, each with its own default-made `Out`; the outs in piece order.
template <class Out, class F>
std::vector<Out> in_ordered_pieces(std::span<const std::size_t> cut, F&& f) {
  std::vector<Out> out(cut.empty() ? 0 : cut.size() - 1);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t p = range.begin(); p != range.end(); ++p)
                        f(p, cut[p], cut[p + 1], out[p]);
                    });
  return out;
}

// The same over pieces of `piece` items each (the last one shorter).
template <class Out, class F>
std::vector<Out> in_ordered_chunks(std::size_t n, std::size_t piece, F&& f) {
  std::vector<std::size_t> cut;
  cut.reserve(n / piece + 2);
  for (std::size_t at = 0; at < n; at += piece) cut.push_back(at);
  cut.push_back(n);
  return in_ordered_pieces<Out>(std::span<const std::size_t>(cut), std::forward<F>(f));
}

}  // namespace geode::primal::detail
