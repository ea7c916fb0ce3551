#include <geode/stc/dualize.hpp>

#include <algorithm>
#include <set>

#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity.hpp>

namespace geode::stc {
namespace {

std::string sheet_list(const Arrangement& A, const std::vector<int>& S) {
  std::string r;
  for (std::size_t i = 0; i < S.size(); ++i)
    r += (i ? ", '" : "'") + A.sheet_names[primal::index_cast<std::size_t>(S[i])] + "'";
  return r;
}

// Euler characteristic of the link of every node. In a hex mesh the link of node v has a
// vertex per edge at v, an edge per face at v and a triangle per hex at v; in a quad mesh a
// vertex per edge at v and an edge per quad at v. A ball's interior node has a sphere (2) or
// circle (0) as link; a boundary node a disk (1) or a path (1).
std::vector<int> link_euler(const DualMesh& D, std::size_t nodes) {
  std::vector<std::set<std::pair<int, int>>> edges(nodes);
  std::vector<std::set<std::vector<int>>> faces(nodes);
  std::vector<int> cells(nodes, 0);
  auto key = [](int a, int b) { return std::make_pair(std::min(a, b), std::max(a, b)); };
  if (D.dim == 3) {
    for (const auto& h : D.hex.hexes) {
      for (const auto& e : primal::topology::kHexEdgeCorners) {
        edges[primal::index_cast<std::size_t>(h[primal::index_cast<std::size_t>(e[0])])].insert(key(
            h[primal::index_cast<std::size_t>(e[0])], h[primal::index_cast<std::size_t>(e[1])]));
        edges[primal::index_cast<std::size_t>(h[primal::index_cast<std::size_t>(e[1])])].insert(key(
            h[primal::index_cast<std::size_t>(e[0])], h[primal::index_cast<std::size_t>(e[1])]));
      }
      for (const auto& f : primal::topology::kHexFaceCorners) {
        std::vector<int> q;
        for (int c : f) q.push_back(h[primal::index_cast<std::size_t>(c)]);
        std::sort(q.begin(), q.end());
        for (int c : f)
          faces[primal::index_cast<std::size_t>(h[primal::index_cast<std::size_t>(c)])].insert(q);
      }
      for (int c : h) ++cells[primal::index_cast<std::size_t>(c)];
    }
    std::vector<int> chi(nodes);
    for (std::size_t v = 0; v < nodes; ++v)
      chi[v] = primal::index_cast<int>(edges[v].size()) - primal::index_cast<int>(faces[v].size()) +
               cells[v];
    return chi;
  }
  for (const auto& q : D.quad.quads) {
    for (const auto& e : primal::topology::kQuadEdgeCorners) {
      const int a = q[primal::index_cast<std::size_t>(e[0])],
                b = q[primal::index_cast<std::size_t>(e[1])];
      edges[primal::index_cast<std::size_t>(a)].insert(key(a, b));
      edges[primal::index_cast<std::size_t>(b)].insert(key(a, b));
    }
    for (int c : q) ++cells[primal::index_cast<std::size_t>(c)];
  }
  std::vector<int> chi(nodes);
  for (std::size_t v = 0; v < nodes; ++v)
    chi[v] = primal::index_cast<int>(edges[v].size()) - cells[v];
  return chi;
}

}  // namespace

DualMesh dualize(const Arrangement& A) {
  const int dim = A.domain.dim;
  DualMesh D;
  D.dim = dim;
  const int corners = 1 << dim;
  // Number the nodes in the order they first appear as element corners.
  std::vector<int> node_of_region(primal::index_cast<std::size_t>(A.region_count), -1);
  std::vector<int> region_of_node;
  auto node = [&](int region) {
    int& n = node_of_region[primal::index_cast<std::size_t>(region)];
    if (n < 0) {
      n = primal::index_cast<int>(region_of_node.size());
      region_of_node.push_back(region);
    }
    return n;
  };
  for (std::size_t v = 0; v < A.vertices.size(); ++v) {
    const Vertex& V = A.vertices[v];
    std::array<primal::Index, 8> cell{};
    for (int c = 0; c < corners; ++c) {
      // Corner c of the reference element sits on the positive side of sheet i when its
      // local coordinate i is 1; a negative orientation mirrors the first axis.
      const auto& rc = primal::topology::kHexCornerCoords[primal::index_cast<std::size_t>(c)];
      int bits = 0;
      for (int i = 0; i < dim; ++i) {
        bool pos = rc[primal::index_cast<std::size_t>(i)] == 1;
        if (i == 0 && V.orientation < 0) pos = !pos;
        if (pos) bits |= 1 << i;
      }
      cell[primal::index_cast<std::size_t>(c)] =
          node(A.region[v][primal::index_cast<std::size_t>(bits)]);
    }
    std::set<primal::Index> distinct(cell.begin(), cell.begin() + corners);
    if (primal::index_cast<int>(distinct.size()) != corners)
      throw TopologyError("dualize: around the vertex of sheets " + sheet_list(A, V.sheets) +
                          " at " + format_point(V.x, dim) +
                          " two octants are one region: its element would repeat a node");
    if (dim == 3)
      D.hex.hexes.push_back(cell);
    else
      D.quad.quads.push_back({cell[0], cell[1], cell[2], cell[3]});
    D.element_sheets.push_back(V.sheets);
    D.element_centres.push_back(V.x);
  }
  const std::size_t nodes = region_of_node.size();
  if (static_cast<int>(nodes) != A.region_count)
    throw TopologyError("dualize: " + std::to_string(A.region_count - static_cast<int>(nodes)) +
                        " region(s) touch no vertex: a cell with no element around it");

  // Node positions: the mean of the vertices around the region, put onto the domain faces
  // it touches. In a hexahedral domain taken in local coordinates, where faces are planes,
  // and mapped, so the node stays inside; in a box (an affine image of its local
  // coordinates, so the same point) in physical ones, as results before hexahedral domains
  // were, bit for bit. A first guess only: node placement and smoothing come later.
  const bool cell = A.domain.corners.has_value();
  std::vector<primal::Point> sum(nodes, primal::Point::Zero());
  std::vector<int> count(nodes, 0);
  auto accumulate = [&](const auto& elements) {
    for (std::size_t e = 0; e < elements.size(); ++e)
      for (auto n : elements[e]) {
        sum[primal::index_cast<std::size_t>(n)] += cell ? A.vertices[e].local : A.vertices[e].x;
        ++count[primal::index_cast<std::size_t>(n)];
      }
  };
  if (dim == 3)
    accumulate(D.hex.hexes);
  else
    accumulate(D.quad.quads);
  std::vector<primal::Point> pts(nodes);
  for (std::size_t n = 0; n < nodes; ++n) {
    const int r = region_of_node[n];
    primal::Point p = sum[n] / count[n];
    const unsigned f = A.region_faces[primal::index_cast<std::size_t>(r)];
    for (int axis = 0; axis < dim; ++axis) {
      if ((f >> (2 * axis)) & 1u) p[axis] = cell ? 0.0 : A.domain.lo[axis];
      if ((f >> (2 * axis + 1)) & 1u) p[axis] = cell ? 1.0 : A.domain.hi[axis];
    }
    pts[n] = cell ? domain_point(A.domain, p) : p;
    D.node_faces.push_back(f);
    D.node_signs.push_back(A.region_signs[primal::index_cast<std::size_t>(r)]);
  }
  if (dim == 3)
    D.hex.points = pts;
  else
    D.quad.points = pts;

  // Every region must be a ball, or a half-ball where it touches the domain boundary. Unlike
  // primal::check_validity, which judges a node against the mesh's own boundary, this holds
  // the link to what the region touches geometrically, so a region inside the box whose node
  // lands on the mesh boundary is caught too.
  const std::vector<int> chi = link_euler(D, nodes);
  for (std::size_t n = 0; n < nodes; ++n) {
    const bool boundary = D.node_faces[n] != 0;
    const int expect = boundary ? 1 : (dim == 3 ? 2 : 0);
    if (chi[n] != expect) {
      std::string s;
      for (std::size_t i = 0; i < D.node_signs[n].size(); ++i)
        s += std::string(i ? ", " : "") + A.sheet_names[i] + (D.node_signs[n][i] > 0 ? "+" : "-");
      throw TopologyError("dualize: the region on sides {" + s + "} near " +
                          format_point(pts[n], dim) + " is not a " +
                          (boundary ? "half-ball meeting the boundary in one disk" : "ball") +
                          " (its node's link has Euler characteristic " + std::to_string(chi[n]) +
                          ", expected " + std::to_string(expect) + ")");
    }
  }

  // The whole dual must be a ball whose boundary nodes are exactly the regions touching the
  // domain boundary. Regions are joined only along 1-cells, so a piece of sheet with a hole
  // (an annulus no curve crosses) splits its region into parts that each look like a ball, and
  // a region meeting the boundary where no curve ends is not known to touch it; both leave
  // this global trace. check_validity also requires every node's elements to be connected
  // through faces (edges in 2D): a link Euler characteristic of 2 cannot tell a sphere from
  // two disks.
  std::vector<char> on_boundary(nodes, 0);
  bool ball = true;
  std::string found;
  if (dim == 3) {
    const primal::HexValidityReport v = primal::check_validity(D.hex);
    ball = v.overshared_faces.empty() && v.nonmanifold_edges.empty() &&
           v.nonmanifold_vertices.empty() && v.euler == 1 && v.boundary.closed &&
           v.boundary.euler == 2;
    found = "V - E + F - C = " + std::to_string(v.euler) +
            ", boundary V - E + F = " + std::to_string(v.boundary.euler);
    for (primal::Index n : v.boundary.vertex_node)
      on_boundary[primal::index_cast<std::size_t>(n)] = 1;
  } else {
    const primal::QuadValidityReport v = primal::check_validity(D.quad);
    ball = v.overshared_edges.empty() && v.nonmanifold_vertices.empty() && v.euler == 1 &&
           v.boundary_loops.size() == 1;
    found = "V - E + F = " + std::to_string(v.euler) + ", " +
            std::to_string(v.boundary_loops.size()) + " boundary loop(s)";
    for (const auto& loop : v.boundary_loops)
      for (primal::Index n : loop) on_boundary[primal::index_cast<std::size_t>(n)] = 1;
  }
  if (!ball)
    throw TopologyError("dualize: the dual of the arrangement is not a " +
                        std::string(dim == 3 ? "ball" : "disk") + " (" + found +
                        ", expected 1 and " + (dim == 3 ? "2" : "one loop") +
                        "): a piece of sheet with a hole, or a region split where no curve runs");
  for (std::size_t n = 0; n < nodes; ++n)
    if ((D.node_faces[n] != 0) != (on_boundary[n] != 0))
      throw TopologyError("dualize: the node of the region near " + format_point(pts[n], dim) +
                          " is " + (on_boundary[n] ? "" : "not ") +
                          "on the dual's boundary but its region " +
                          (D.node_faces[n] ? "touches" : "does not touch") +
                          " the domain boundary as the traced curves show it");
  return D;
}

}  // namespace geode::stc
