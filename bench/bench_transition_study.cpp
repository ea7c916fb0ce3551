// The transition at hex-part edges and corners (conform/corner_study.hpp): per dihedral angle
// and corner kind, the minimum scaled Jacobian of the geode hexes before smoothing (--smooth
// none) and after it (the defaults), and their ratio to the local yardstick, on the demo models
// with edges and corners (nugget, lshape, potting, cylinder) and on demo_wedge at dihedral
// angles from 60 to 300 degrees. `geode study corners` runs the same study.
//
// Usage: bench_transition_study [n] [csv]   (defaults 3, notebooks-data/transition-corners.csv)
// Prints a table and writes the CSV that notebooks-data/plot.py draws.
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include <geode/conform/corner_study.hpp>
#include <geode/demo/demo_models.hpp>

int main(int argc, char** argv) {
  using namespace geode;
  const int n = argc > 1 ? std::atoi(argv[1]) : 3;
  const std::string csv =
      argc > 2 ? argv[2] : std::string(GEODE_SOURCE_DIR) + "/notebooks-data/transition-corners.csv";
  const conform::CornerStudy study = conform::corner_study(demo::corner_study_models(n), n);
  conform::write_corner_table(std::cout, study);
  std::ofstream out(csv);
  conform::write_corner_csv(out, study);
  std::cout << "wrote " << csv << "\n";
  return 0;
}
