#pragma once
// Mixed models (hexes, tets, pyramids, wedges) to exercise the whole-model geode pipeline:
// demo models meshed with the Gmsh API (no input file).
#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::demo {

using primal::Model;

// Demo (a), meshed with the Gmsh API (OpenCASCADE boxes, transfinite meshing): the block
// [0,2] x [0,1] x [0,1]; x < 1 a structured n x n x n hex mesh (block 1 "hex"), x > 1 a
// transfinite tet mesh (block 2 "tet", Gmsh splits each structured cell into 6 tets) whose
// x = 1 face triangulates the same n x n grid, so the parts conform node-wise with every
// interface quad split into two triangles. The two boxes are meshed as separate volumes and
// their coincident interface nodes merged afterwards (Gmsh cannot put quads on one side and
// triangles on the other of one shared surface). Elements Gmsh returns inverted are re-oriented.
Model demo_half_block(int n = 4);

// Demo (b), in the spirit of the paper's Figure 8 (Fulcher's nugget). Simplified: the nugget is
// a plain cube [-1,1]^3 (no imprinted circles), tet-meshed by Gmsh's unstructured 3D
// Delaunay mesher inside a structured triangulated surface (n x n cells per face, each split
// in two); it is surrounded by the 26 sweepable boxes of a 3 x 3 x 3 split of [-2,2]^3
// (structured hexes, n/2 cells across each outer layer; block 1 "hex blocks"), instead of real
// sweepable parts. Nugget tets are block 2 "tet nugget". Side set 1 "outside" holds the outer
// boundary quads. n must be even and >= 2.
Model demo_nugget(int n = 4);

// The realistic models below mesh a hex part with the Gmsh API, triangulate the tet region's
// boundary (Gmsh's 2D mesher on the outer surfaces, the hex part's interface quads split into
// two triangles each) and fill it with Gmsh's 3D Delaunay tets; nothing is transfinite on the
// tet side. n sets the cell size (1/n per unit length); small n gives seconds-sized models.
enum class DemoDiagonals { kAlternate, kRandom };

// (a) Structured hexes [0,1]^3 (n^3, block 1 "hex") beside a Delaunay tet box [1,2] x [0,1]^2
// (block 2 "tet"); interface quads split alternately (checkerboard) or at random. With
// four_triangles, half of them (at random, the first always) are split into four triangles
// around a node at the quad's centre instead: a mixed interface for the four-triangle template.
Model demo_delaunay_block(int n = 4, DemoDiagonals diagonals = DemoDiagonals::kAlternate,
                          bool four_triangles = false);

// (b) A curved interface: a hex cylinder (radius 0.5, height 1: a disk of unstructured
// recombined quads swept in n layers; block 1) inside a tet-meshed box [-1,1]^3 (block 2).
// four_triangles: half the interface quads (as in (a)) in four triangles around their centre.
Model demo_cylinder(int n = 4, bool four_triangles = false);

// (c) A concave interface: a structured hex block [1,2]^2 x [0,1] in the notch of an L-shaped
// Delaunay tet part [0,2]^2 x [0,1] minus the notch, so the tet part wraps the interface edge.
Model demo_l_shape(int n = 4);

// (e) The paper's Section 4 example after Fulcher: the cube nugget [-1,1]^3 with circles of
// radii 0.3, 0.5, 0.7 imprinted on its faces x = 1, y = 1, z = 1, filled with Gmsh Delaunay tets
// (block 2 "tet nugget") inside the 26 blocks of a 3 x 3 x 3 split of [-2,2]^3 (block 1 "hex
// blocks"): the three slabs on the imprinted faces are swept in n/2 layers from an unstructured
// recombined quad mesh of the face (the circle a chain of quad edges), the other 23 blocks are
// structured (n cells along a nugget edge, n/2 across a layer), so the interface quads are
// unstructured on three faces. Interface diagonals random; side set 1 "outside" holds the outer
// boundary quads. n must be even and >= 2.
Model demo_fulcher(int n = 4);

// Hybrid models as an analyst makes them with Gmsh: one geometry, every volume meshed in one
// generate(3) (hex volumes transfinite or swept and recombined, tet volumes Delaunay), so
// Gmsh puts the pyramids on the quads tet volumes meet. Each volume is its own named block.
// hybrid: a transfinite hex box [0,1]^3 (block 1 "hex") sharing its face x = 1 with a
// Delaunay tet box [1,2] x [0,1]^2 (block 2 "tet", pyramids on the shared quads).
Model demo_hybrid(int n = 4);
// hybrid-cylinder: a disk of recombined quads swept in n layers (block 1 "hex cylinder",
// radius 0.5, height 1) inside a Delaunay box [-1,1]^3 (block 2 "tet box"): a curved interface
// of pyramids.
Model demo_hybrid_cylinder(int n = 4);
// boundary-layer: a Delaunay tet box [0,1]^3 (block 2 "tet") with 3 graded layers of wedges
// extruded off its top, 0.1 thick (block 4 "boundary layer"): no quad meets a triangle.
Model demo_boundary_layer(int n = 4);
// hexdominant: all four kinds side by side: transfinite hex boxes [0,1]^3 (block 1 "hex") and
// [0,1] x [1,2] x [0,1] (block 3 "hex back"), a Delaunay tet box [1,2] x [0,1]^2 (block 2
// "tet", pyramids on the face it shares with the first hex box) and 2 layers of wedges extruded
// 0.15 off its face x = 2 (block 4 "wedge layer"). (Debian's Gmsh 4.8 Mesh.Recombine3DAll
// gave only tets or crashed, so the kinds come from transfinite, extruded and Delaunay volumes.)
Model demo_hexdominant(int n = 4);
// layer-side: a Delaunay tet box [0,1]^3 (block 2 "tet"), 3 graded layers of wedges extruded
// 0.2 off its top (block 4 "boundary layer") and a Delaunay slab [1,1.5] x [0,1] x [1,1.2]
// swept off the layer's side (block 5 "tet slab"): Gmsh puts a pyramid on every wedge quad
// the slab meets, so wedge quads meet tet triangles (the transition beside wedges).
Model demo_layer_side(int n = 4);
// layer-interface: a transfinite hex box [0,1]^3 (block 1 "hex") beside a Delaunay tet box
// [1,2] x [0,1]^2 (block 2 "tet", pyramids on the shared face), 3 graded layers of wedges
// extruded 0.2 off the tet box's top (block 4 "boundary layer"): wedges at the nodes of the
// hex/tet interface's top edge.
Model demo_layer_interface(int n = 4);
// layer-mixed: Delaunay tet boxes [0,1]^3 and [1,2] x [0,1]^2 (block 2 "tet") under 3 graded
// layers extruded 0.2 off their tops, the left one recombined: hexes (block 1 "hex layer")
// beside wedges (block 4 "wedge layer"), pyramids on the hex quads the tets meet. The wedge
// layer joins the two sides of the hex/tet interface: conform splits its wedges into tets.
Model demo_layer_mixed(int n = 4);

// (f) The paper's proposed example, the complement of simple parts: six hex parts in a tet potting
// box [0, 6.2] x [0, 4.4] x [0, 2.2] (block 7 "potting", Delaunay): a cube (block 1
// "block_a"), a slab (2 "slab_b"), two swept cylinders along z and x (3 "pin_z", 4 "pin_x"), a
// box tilted 0.5 rad about (1, 1, 0) (5 "tilted") and an L-shaped bracket (6 "bracket": a
// concave edge, saddle corners). Boxes structured, cylinders swept from recombined disks; the
// potting's boundary around each part is that part's quads split in two. n >= 2.
Model demo_potting(int n = 4);

// (g) One dihedral angle (degrees, 30 to 330) at a hex-part edge, for studies: a prism over
// [0, 1] in z whose cross-section has the angle at the origin (k = ceil(angle / 120) kites
// with unit sides on the rays, transfinite, swept in n layers; block 1 "wedge"), in a Delaunay
// tet box one unit larger all round (block 2 "tet"). Its ends make 90-degree edges and corners
// with the edge (convex below 180 degrees, saddles above). Not in demo_model_names.
Model demo_wedge(int n, double angle);

// The names `geode demo --model` takes: half, delaunay, delaunay-random, cylinder, lshape,
// nugget (d: a convex Delaunay tet nugget in structured blocks), fulcher (e), fourtri (a,
// random diagonals, four-triangle quads), fourtri-cylinder (b with four-triangle quads),
// hybrid, hybrid-cylinder, boundary-layer, hexdominant, layer-side, layer-interface,
// layer-mixed, potting (f).
const std::vector<std::string>& demo_model_names();
// The model of that name with size parameter n (made even where the model needs it); throws
// InvalidInput naming an unknown name.
Model demo_model(const std::string& name, int n);

// The models of the edge-and-corner study (conform/corner_study.hpp), built when called: nugget,
// lshape, potting and cylinder at n, and "wedge-A", demo_wedge(n, A) for A = 60, 90, 120, 150,
// 210, 240, 270 and 300 degrees.
std::vector<std::pair<std::string, std::function<Model()>>> corner_study_models(int n);

}  // namespace geode::demo
