#include <geode/templates/pyramid.hpp>

#include <sstream>

#include <geode/stc/arrangement.hpp>

namespace geode::templates {

using primal::Index;
using primal::Point;
using N = PyramidSurfaceNodes;

primal::QuadMesh schneiders_surface(const std::array<Point, 5>& c) {
  stc::Domain::pyramid(c);  // the same checks as the engine's domain
  primal::QuadMesh s;
  s.points.assign(c.begin(), c.end());
  for (int i = 0; i < 4; ++i)
    s.points.push_back(0.5 * (c[primal::index_cast<std::size_t>(i)] +
                              c[primal::index_cast<std::size_t>((i + 1) % 4)]));
  for (int i = 0; i < 4; ++i)
    s.points.push_back(0.5 * (c[primal::index_cast<std::size_t>(i)] + c[4]));
  s.points.push_back(0.25 * (c[0] + c[1] + c[2] + c[3]));
  for (int i = 0; i < 4; ++i)
    s.points.push_back((c[primal::index_cast<std::size_t>(i)] +
                        c[primal::index_cast<std::size_t>((i + 1) % 4)] + c[4]) /
                       3.0);
  // Base: counter-clockwise seen from below (outside).
  for (int i = 0; i < 4; ++i)
    s.quads.push_back({i, N::base_midpoint((i + 3) % 4), N::kBaseCentre, N::base_midpoint(i)});
  // Triangle (i, i+1, apex) is counter-clockwise seen from outside; its quads at i, i+1, apex.
  for (int i = 0; i < 4; ++i) {
    const Index j = (i + 1) % 4, m = N::base_midpoint(i), g = N::centroid(i);
    s.quads.push_back({i, m, g, N::lateral_midpoint(i)});
    s.quads.push_back({j, N::lateral_midpoint(j), g, m});
    s.quads.push_back({N::kApex, N::lateral_midpoint(i), g, N::lateral_midpoint(j)});
  }
  return s;
}

PyramidCertificate pyramid_certificate(const std::array<Point, 5>& corners) {
  PyramidCertificate c;
  c.chords = stc::surface_chords(schneiders_surface(corners).quads);
  std::ostringstream s;
  s << "the 16-quad surface's dual has " << c.chords.size() << " chords (";
  for (std::size_t k = 0; k < c.chords.size(); ++k) {
    const auto& ch = c.chords[k];
    s << (k ? "; " : "") << ch.quads.size() << " passes through "
      << ch.quads.size() - ch.self_crossings.size() << " quads, " << ch.self_crossings.size()
      << " self-crossings";
    c.self_crossing_chords += !ch.self_crossings.empty();
  }
  s << ")";
  if (c.self_crossing_chords > 0)
    s << ": a chord that crosses itself is the trace of a self-intersecting sheet, and every sheet "
         "of the "
         "arrangement engine is a field's zero set (embedded), so no arrangement of its sheets has "
         "this boundary";
  c.statement = s.str();
  return c;
}

}  // namespace geode::templates
