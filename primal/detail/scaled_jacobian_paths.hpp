#pragma once
// hex_scaled_jacobian's implementations (quality.cpp): the fastest this processor runs (AVX2
// where it has it, chosen at run time) and the portable one (SSE2 on x86-64), for the test that
// they give the same bits.
#include <geode/primal/quality.hpp>

namespace geode::primal::detail {

struct ScaledJacobianPaths {
  double (*fastest)(const HexCorners&);
  double (*portable)(const HexCorners&);
};

ScaledJacobianPaths scaled_jacobian_paths();

}  // namespace geode::primal::detail
