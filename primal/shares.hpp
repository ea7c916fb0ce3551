#pragma once
// Work shared among processes (geode_mpi's ranks) by code that knows nothing of MPI: this
// process is `share` of `shares`, and `exchange` is an all-gather, every process's bytes
// concatenated in share order and returned to each (parallel::rank_shares makes it with
// MPI_Allgatherv). A function taking Shares is collective: every process calls it with the same
// input, and every one returns the same result or throws the same exception.
#include <functional>
#include <vector>

namespace geode::primal {

struct Shares {
  int share = 0, shares = 1;
  std::function<std::vector<char>(const std::vector<char>&)> exchange;
};

}  // namespace geode::primal
