#pragma once
// hex_scaled_jacobian's and hex_scaled_jacobian_bounded's implementations (quality.cpp): the
// fastest this processor runs (AVX2 where it has it, chosen at run time) and the portable ones
// (SSE2 on x86-64; the bounded one a corner at a time), for the test that they give the same
// bits (below the bound: each some value at or below it).
#include <geode/primal/quality.hpp>

namespace geode::primal::detail {

struct ScaledJacobianPaths {
  double (*fastest)(const HexCorners&);
  double (*fastest_bounded)(const HexCorners&, double bound);
  double (*portable)(const HexCorners&);
  double (*portable_bounded)(const HexCorners&, double bound);
};

ScaledJacobianPaths scaled_jacobian_paths();

}  // namespace geode::primal::detail
