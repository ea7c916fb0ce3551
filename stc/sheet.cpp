#include <geode/stc/sheet.hpp>

#include <algorithm>

namespace geode::stc {

Point gradient(const Field& f, const Point& x, double h, int dim) {
  Point g = Point::Zero();
  for (int i = 0; i < dim; ++i) {
    Point a = x, b = x;
    a[i] += h;
    b[i] -= h;
    g[i] = (f(a) - f(b)) / (2.0 * h);
  }
  return g;
}

Field field_union(Field a, Field b) {
  return [a = std::move(a), b = std::move(b)](const Point& x) { return std::min(a(x), b(x)); };
}
Field field_intersection(Field a, Field b) {
  return [a = std::move(a), b = std::move(b)](const Point& x) { return std::max(a(x), b(x)); };
}
Field field_offset(Field a, double d) {
  return [a = std::move(a), d](const Point& x) { return a(x) - d; };
}
Field field_scaled(Field a, double s) {
  return [a = std::move(a), s](const Point& x) { return s * a(x); };
}

}  // namespace geode::stc
