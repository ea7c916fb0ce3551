#pragma once
// Test fixtures: the paper's Appendix A geode read from notebooks-data (tests only: the guide
// forbids typing its tables into the library), structured grids, and boundary-face extraction.
#include <functional>
#include <string>

#include <geode/primal/mesh.hpp>
#include <geode/primal/model.hpp>

namespace geode::test {

// Reads a hex mesh from two CSV files with a header line each: `node,x,y,z` rows numbered
// 1..N in order, and `hex,n1,...,n8` rows with 1-based node numbers. Throws
// geode::InvalidInput naming the file, the line and the reason on any malformed row.
//
// Corner order: the paper lists n1..n4 as a face cycle and n5..n8 as the opposite face with
// n5 over n1. That is already the VTK/Exodus order of primal/topology.hpp (bottom 0-1-2-3,
// top 4-7 with 4 above 0), and for Appendix A the handedness agrees too: every interior face
// is seen in opposite cyclic orders by its two hexes and the corner frames of
// kHexCornerNeighbors are right-handed (apart from rounding in the printed positions), which
// tests/stc/mesh_dual_test.cpp checks. So the only conversion is 1-based -> 0-based.
primal::HexMesh read_hex_csv(const std::string& nodes_csv, const std::string& hexes_csv);

// The Appendix A geode: 48 nodes, 26 hexes, box [-12,12] x [-7,7] x [-12,12], y up, the
// diced-tet side at y = +7 and the diced-hex side at y = -7.
primal::HexMesh appendix_a_geode();

// nx * ny * nz unit cubes on [0,nx] x [0,ny] x [0,nz]; node (i,j,k) has number
// i + (nx+1) * (j + (ny+1) * k) and hexes are positively oriented (VTK order).
primal::HexMesh structured_hex_grid(int nx, int ny, int nz);

// nx * ny unit squares in the plane z = 0; node (i,j) has number i + (nx+1) * j; quads are
// counter-clockwise seen from +z.
primal::QuadMesh structured_quad_grid(int nx, int ny);

// The boundary quads of a hex mesh (faces used by exactly one hex) whose four corners all
// satisfy `keep`, as a quad mesh of their own with nodes renumbered in first-use order and
// quads counter-clockwise seen from outside the volume. E.g. one face of a box.
primal::QuadMesh boundary_quads(const primal::HexMesh& mesh,
                                const std::function<bool(const primal::Point&)>& keep);

// 4 x 2 x 2 unit cells, cells with i >= 2 split into 6 tets: 8 hexes, 48 tets, 4 interface quads.
primal::Model small_hybrid_model();

// One unit hex (primal::grid_model, block 1) whose top face, nodes 4 5 7 6 counter-clockwise
// seen from above, is split into four triangles around node 8 at `centre`, each under a tet
// (block 2) with apex node 9 at `apex`: the smallest four-triangle interface.
primal::Model four_tet_fan(const primal::Point& centre, const primal::Point& apex);

// A tet cell (primal::grid_model's six tets, block 2) standing alone on the top of a 2 x 2 x 1
// hex block (block 1): the one interface quad lies on the hex block's flat top, so no buffer
// layer can be carved from the hex part there.
primal::Model tet_cell_on_hex_top();

// primal::grid_model(cells) with hexes (block 1) in the first half of x and tets (block 2) in the
// second, the tets on copies of every node: parts meshed apart and not merged, each tet face at
// the interface against a hex face without sharing its nodes.
primal::Model unmerged_parts(std::array<int, 3> cells);

}  // namespace geode::test
