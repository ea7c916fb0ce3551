#pragma once
// Schneiders' pyramid: the boundary a pyramid of a hybrid mesh gets once its neighbours are
// diced (its base in 4 quads, each triangle in 3), and why the arrangement engine cannot fill
// it yet.
//
// The surface is the problem's statement, not a template: corners, edge midpoints, the base's
// centre and the triangles' centroids, numbered by role (below). Its dual (stc/surface_chords.hpp)
// has two chords: one around the apex (8 passes, simple) and one through all 16 quads that
// crosses itself 8 times (the paper's Figure 11 centre). Every sheet of stc::compute_arrangement
// is a field's zero set, embedded, and its boundary trace cannot cross itself; so no arrangement
// of such sheets has this boundary, in a pyramid domain or any other. Filling it from a sheet
// arrangement needs self-intersecting (immersed) sheets, which the engine does not represent.
// `pyramid_certificate` computes that statement from the surface, so the claim is measured.
#include <array>
#include <string>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/stc/surface_chords.hpp>

namespace geode::templates {

// Node numbers of the 16-quad surface, by role. Corners 0-3 are the base (counter-clockwise
// seen from the apex), 4 the apex, as stc::Domain::pyramid takes them.
struct PyramidSurfaceNodes {
  static constexpr primal::Index kApex = 4;
  static constexpr primal::Index base_midpoint(int i) { return 5 + i; }     // edge i - (i+1)%4
  static constexpr primal::Index lateral_midpoint(int i) { return 9 + i; }  // edge i - apex
  static constexpr primal::Index kBaseCentre = 13;
  static constexpr primal::Index centroid(int i) { return 14 + i; }  // triangle i, (i+1)%4, apex
};

// 18 nodes at the diced positions (midpoints, the base's bilinear centre, the centroids), 16
// quads counter-clockwise seen from outside: the base's 4 first (quad i at corner i), then
// triangle i's 3 at corners i, (i+1)%4 and the apex. Throws InvalidInput for a pyramid
// stc::Domain::pyramid refuses.
primal::QuadMesh schneiders_surface(const std::array<primal::Point, 5>& corners);

struct PyramidCertificate {
  std::vector<stc::SurfaceChord> chords;  // of schneiders_surface
  int self_crossing_chords = 0;
  // One line: the chords, their passes and self-crossings, and what follows for the engine.
  std::string statement;
};

PyramidCertificate pyramid_certificate(const std::array<primal::Point, 5>& corners);

}  // namespace geode::templates
