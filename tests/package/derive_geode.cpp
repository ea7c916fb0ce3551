// Downstream use of the installed package: derive the geode and check its size.
#include <geode/templates/geode.hpp>
#include <iostream>

int main() {
  const geode::templates::Template t = geode::templates::build_geode3d({});
  std::cout << t.hex.hexes.size() << " hexes, " << t.hex.points.size() << " nodes\n";
  return t.hex.hexes.size() == 26 && t.hex.points.size() == 48 ? 0 : 1;
}
