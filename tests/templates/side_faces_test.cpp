// Templates whose four side faces carry one mirror-symmetric mesh (templates/side_faces.hpp),
// so that neighbouring buffer hexes share their side nodes in any orientation. Checked from the
// positions alone: every side face, read in its own frame, holds the same points as the others
// and as its mirror image.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <vector>

#include <geode/primal/quality.hpp>
#include <geode/templates/geode.hpp>
#include <geode/templates/side_faces.hpp>

using namespace geode;

namespace {

// (u, v) of the nodes on one side face: u along the face seen from outside (x-: +z, x+: -z,
// z-: -x, z+: +x), scaled to [-1, 1]; v the height. Sorted.
std::vector<std::array<double, 2>> face_points(const templates::Template& t, int axis, bool high,
                                               const Eigen::Vector3d& box, bool mirror) {
  std::vector<std::array<double, 2>> out;
  const double plane = (high ? 0.5 : -0.5) * box[axis];
  for (const auto& p : t.hex.points) {
    if (std::abs(p[axis] - plane) > 1e-9) continue;
    double u = axis == 0 ? (high ? -p.z() : p.z()) / (0.5 * box.z())
                         : (high ? p.x() : -p.x()) / (0.5 * box.x());
    if (mirror) u = -u;
    out.push_back({u, p.y()});
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE(
    "smooth_template_shared_sides: four side faces, one symmetric mesh; top and bottom kept") {
  for (auto diagonal : {templates::Diagonal::kMain, templates::Diagonal::kAnti}) {
    for (const Eigen::Vector3d& box : {Eigen::Vector3d(24, 8, 24), Eigen::Vector3d(24, 14, 24)}) {
      CAPTURE(static_cast<int>(diagonal));
      CAPTURE(box.y());
      templates::GeodeOptions o;
      o.box = box;
      o.diagonal = diagonal;
      templates::Template t = templates::build_geode3d(o);
      const templates::Template before = t;
      // Unsmoothed, the x- and z-faces differ (the two tunnels' roofs are at different heights).
      CHECK(face_points(t, 0, false, box, false) != face_points(t, 2, false, box, false));
      const auto r = templates::smooth_template_shared_sides(t);
      CHECK(r.untangled);
      CHECK(primal::min_scaled_jacobian(t.hex) == doctest::Approx(r.final_min_scaled_jacobian));
      CHECK(r.final_min_scaled_jacobian > (box.y() < 10 ? 0.2 : 0.3));
      const auto ref = face_points(t, 0, false, box, false);
      CHECK(ref.size() >= 9);
      for (int axis : {0, 2})
        for (bool high : {false, true})
          for (bool mirror : {false, true}) {
            const auto f = face_points(t, axis, high, box, mirror);
            REQUIRE(f.size() == ref.size());
            for (std::size_t i = 0; i < f.size(); ++i) {
              CHECK(f[i][0] == doctest::Approx(ref[i][0]).epsilon(1e-9));
              CHECK(f[i][1] == doctest::Approx(ref[i][1]).epsilon(1e-9));
            }
          }
      for (std::size_t n = 0; n < t.hex.points.size(); ++n)
        if (std::abs(std::abs(before.hex.points[n].y()) - 0.5 * box.y()) < 1e-9)
          CHECK((t.hex.points[n] - before.hex.points[n]).norm() == 0.0);
    }
  }
}
