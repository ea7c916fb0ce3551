#pragma once
// The dual chords of a closed quad surface: the curves a sheet leaves on the boundary of any hex
// mesh that has this surface as its boundary (stc/mesh_dual.hpp reads the same off a hex mesh).
// Inside every quad the chord through edges 0 and 2 (corners 0-1 and 2-3) is one, the chord
// through edges 1 and 3 another; chords are joined across shared edges (union-find on edges).
// A chord crosses itself where both chords of a quad are the same chord.
//
// Why it matters to the arrangement engine: a sheet there is the zero set of a field with a
// nonzero gradient (stc/sheet.hpp), an embedded surface, whose trace on the boundary never
// crosses itself; two sheets cross on the boundary only as two different traces. So a surface
// whose chord crosses itself is the boundary of no arrangement of such sheets: it needs a
// self-intersecting (immersed) sheet.
#include <array>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::stc {

struct SurfaceChord {
  std::vector<primal::Index> quads;           // quads it passes, one entry per pass, ascending
  std::vector<primal::Index> self_crossings;  // quads it passes twice, ascending
  int edges = 0;                              // surface edges it crosses
};

// Throws TopologyError when an edge is not shared by exactly two quads (the surface is not
// closed and manifold along it), naming the edge's nodes.
std::vector<SurfaceChord> surface_chords(const std::vector<std::array<primal::Index, 4>>& quads);

}  // namespace geode::stc
