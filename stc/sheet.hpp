#pragma once
// A sheet of a Spatial Twist Continuum arrangement, given as the zero set of a smooth scalar
// field. The sign of the field tells the two sides of the sheet apart; that sign vector is
// what the arrangement engine works with. In 2D (curves in a rectangle) the field is
// evaluated at points with z = 0 and its z-derivative is ignored.
#include <functional>
#include <string>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::stc {

using primal::Point;
using Field = std::function<double(const Point&)>;

struct Sheet {
  std::string name;
  Field field;
  // A label for reports ("tunnel", "dome", ...). Not used by the engine.
  std::string kind;
};

// Central-difference gradient; h is an absolute step (a small fraction of the domain size).
Point gradient(const Field& f, const Point& x, double h, int dim);

// --- Field algebra, so that sheets can be composed from simple pieces ----------------------
// Union and intersection of the negative sides (min / max are not smooth along the seam; a
// seam crossing another sheet is reported by the engine as a failure to trace, never hidden).
Field field_union(Field a, Field b);
Field field_intersection(Field a, Field b);
Field field_offset(Field a, double d);  // a - d
Field field_scaled(Field a, double s);  // s * a (flips the sides for s < 0)

}  // namespace geode::stc
