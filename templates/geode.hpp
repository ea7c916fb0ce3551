#pragma once
// Geode transition templates derived from completed dual sheet arrangements (the paper's
// Section 2). Nothing here is typed in: each template is the dual of its arrangement.
#include <Eigen/Core>
#include "primal/mesh.hpp"

namespace geode::templates {

// Which diagonal splits the tet-side (top) quad into two triangles. Box corners are named in
// (x, z) at the top face y = +h/2: Main joins (-x, +z) to (+x, -z) (as in the paper's
// Appendix A, nodes 1 and 2); Anti joins (+x, +z) to (-x, -z).
enum class Diagonal { Main, Anti };

// Which tunnel's roof is higher where the two tunnels cross: the tunnel running along x (its
// feet are the two dual chords of the diced bottom quad parallel to x) or along z.
enum class Higher { X, Z };

// The buffer cell: an axis-aligned box centred at the origin, y up; the tet side (diced
// triangles) on top (y = +box.y/2), the hex side (diced quad) at the bottom.
struct GeodeOptions {
  Eigen::Vector3d box{24.0, 14.0, 24.0};
  Diagonal diagonal = Diagonal::Main;
  Higher higher = Higher::X;
};

}  // namespace geode::templates
