#pragma once
// Fix-up of a template whose dual is a valid complex that no positive-Jacobian placement can
// realise (primal/realizability.hpp): the paper's answer for such arrangements (Section 5,
// after Mitchell and Folwell) is to modify the mesh. The driver pillows small shrink sets
// (primal/pillow.hpp) taken from the obstructions until none is left. Pillowing keeps the
// mesh boundary's quads and nodes, so the template's faces (tet side, hex side, sides) stay
// exactly the prescribed ones.
#include <string>
#include <vector>

#include <geode/primal/pillow.hpp>
#include <geode/templates/geode.hpp>

namespace geode::templates {

struct FixupOptions {
  int max_steps = 16;  // pillowings at most
  // An obstruction with up to this many hexes has every subset of them tried as shrink set.
  int max_subset_hexes = 6;
  primal::PillowOptions pillow;
};

struct FixupResult {
  int obstructions_before = 0;
  int obstructions_after = 0;
  std::vector<std::string> steps;  // one line per pillowing: which hexes, what it removed
};

// Repeatedly: for each obstruction in turn, try subsets of its hexes as shrink sets
// (FixupOptions), skip those whose pillowing is not a valid complex (a set whose surface is
// not manifold), and apply the one leaving the fewest obstructions, smallest set first, if
// that is fewer than before; stop when no obstruction can be reduced. An obstruction of the
// boundary itself (a two-quad boundary node) cannot be: the boundary is kept. The template's
// mesh, node faces and node signs (a new sheet per pillowing, negative inside), sheets and
// element sheets are updated; new nodes are interior.
FixupResult fix_up(Template& t, const FixupOptions& options = {});

}  // namespace geode::templates
