#include <geode/conform/conform.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <span>
#include <sstream>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <geode/conform/detail/conformer.hpp>
#include <geode/conform/reference_template.hpp>
#include <geode/primal/dice.hpp>
#include <geode/primal/dice_model.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/interface.hpp>
#include <geode/primal/multilinear.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/topology.hpp>

namespace geode::conform {
namespace detail {
namespace {

OutputBlocks output_blocks(const primal::Model& input, const std::string& geode_block) {
  OutputBlocks o;
  o.names = input.block_names;
  if (geode_block.empty()) return o;
  int top = 0;
  for (primal::ElementKind kind : primal::kElementKinds)
    for (std::size_t e = 0; e < primal::element_count(input, kind); ++e)
      top = std::max(top, primal::block_of(input, {kind, primal::index_cast(e)}));
  if (top == std::numeric_limits<int>::max())
    throw InvalidInput("--geode-block: the input's block ids reach " + std::to_string(top) +
                       ": no id above them is left for the geode hexes' block");
  o.geode_id = top + 1;
  o.names[o.geode_id] = geode_block;
  return o;
}

// A four-triangle top (a centre node, `centre`, at (r, s) = (1/2, 1/2)) at (r, s): linear over
// each of its four triangles, as buffer_map's two-triangle tops are.
Point four_triangle_top(const std::array<Point, 8>& P, const Point& centre, double r, double s) {
  // Top corners 4..7 at (r, s) = (0,0), (1,0), (1,1), (0,1); triangle i is (4+i, 4+(i+1)%4,
  // centre), the one whose side of the square is nearest to (r, s).
  const std::array<double, 4> side_distance{s, 1 - r, 1 - s, r};
  const int i = static_cast<int>(std::min_element(side_distance.begin(), side_distance.end()) -
                                 side_distance.begin());
  constexpr std::array<std::array<double, 2>, 4> kAt{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
  const auto& a = kAt[i];
  const auto& b = kAt[(i + 1) % 4];
  // Barycentric coordinates of (r, s) in (a, b, (1/2, 1/2)).
  const double ux = b[0] - a[0], uy = b[1] - a[1], vx = 0.5 - a[0], vy = 0.5 - a[1];
  const double px = r - a[0], py = s - a[1], det = ux * vy - uy * vx;
  const double lb = (px * vy - py * vx) / det, lc = (ux * py - uy * px) / det;
  return (1 - lb - lc) * P[4 + i] + lb * P[4 + (i + 1) % 4] + lc * centre;
}

}  // namespace

// The map of the reference cell into a buffer hex: bilinear on the bottom (the hex side's
// quad), piecewise linear over the two triangles of the top (so the tet side's diced nodes,
// edge midpoints and triangle centroids, are images of the template's), linear in t between
// them. The trilinear map would instead follow a twisted top's bilinear surface, whose
// diagonal midpoint passes the template nodes under it; this one keeps every template hex
// positive wherever the buffer hex is valid. With `centre`, the top is four_triangle_top.
Point buffer_map(const std::array<Point, 8>& P, const std::array<int, 2>& diagonal,
                 const Point& rst, const Point* centre) {
  const double r = rst.x(), s = rst.y(), t = rst.z();
  const Point bottom = primal::multilinear_point(P, Point(r, s, 0.0), 2);
  // Top corners 4..7 at (r, s) = (0,0), (1,0), (1,1), (0,1).
  Point top;
  if (centre) {
    top = four_triangle_top(P, *centre, r, s);
  } else if (diagonal[0] == 4) {  // split 4-6: the line r = s
    top = r >= s ? P[4] + r * (P[5] - P[4]) + s * (P[6] - P[5])
                 : P[4] + s * (P[7] - P[4]) + r * (P[6] - P[7]);
  } else {  // split 5-7: the line r + s = 1
    top = r + s <= 1 ? P[4] + r * (P[5] - P[4]) + s * (P[7] - P[4])
                     : P[6] + (1 - r) * (P[7] - P[6]) + (1 - s) * (P[5] - P[6]);
  }
  return (1 - t) * bottom + t * top;
}

void Conformer::find_interface() {
  res_.input_hexes = primal::index_cast(input_.hexes.size());
  res_.input_tets = primal::index_cast(input_.tets.size());
  res_.input_wedges = primal::index_cast(input_.wedges.size());
  if (primal::element_count(input_) == 0) throw InvalidInput("conform: the model has no elements");
  t0_ = Clock::now();
  // A model without tets, or without hexes and wedges, has no transition to make: it is simply
  // diced. Wedges are the hex part's where their quads meet tet triangles (a pyramid on a
  // wedge, split), and find_interface refuses a wedge joining the two sides around a node.
  if ((!input_.hexes.empty() || !input_.wedges.empty()) && !input_.tets.empty())
    interface_ = primal::find_interface(input_, options_.interface_tolerance, &joining_);
  if (!joining_.empty()) return;
  // Both parts but no shared quad: separate bodies (a bolt beside a bracket), or hexes that meet
  // the tets only through wedges' triangles; each diced alone, as a model with another interface
  // dices a body apart from it. Parts that touch without sharing their nodes were refused when
  // read (the covering check: "lie against each other").
  if (!input_.hexes.empty() && !input_.tets.empty() && interface_.quads.empty())
    res_.warnings.push_back(
        "the hex part and the tet part share no interface quad: each is diced alone, with no "
        "transition between them");
  measure_near_interface();
  wedge_diced_.reserve(input_.wedges.size());
  for (std::size_t w = 0; w < input_.wedges.size(); ++w)
    wedge_diced_.push_back(
        primal::diced_wedge_min_scaled_jacobian(input_.points, std::span(&input_.wedges[w], 1)));
  if (!wedge_diced_.empty())
    res_.input_diced_wedge_min_scaled_jacobian =
        *std::min_element(wedge_diced_.begin(), wedge_diced_.end());
  res_.local_yardstick = local_minima(tet_given_);
  aim_local_ = local_minima(tet_diced_);
  // Aims at least the reported local yardstick: relaxing the tets lowers a few quads' minima.
  for (std::size_t q = 0; q < aim_local_.size(); ++q)
    aim_local_[q] = std::max(aim_local_[q], res_.local_yardstick[q]);
  res_.interface_quads = primal::index_cast(interface_.quads.size());
  warped_interface();
  say("interface: " + std::to_string(interface_.quads.size()) + " quads" + took());
}

// A hex part's interface quad that is not planar (Gmsh's pyramids on a curved hex surface, split
// along a diagonal; TetGen's triangles on a sheared part) bounds its hex with its bilinear face
// and the tets with two (or four) flat triangles. Here the space between, per pair of blocks;
// warn_warped says what the output makes of it once the buffer side is known.
void Conformer::warped_interface() {
  const auto& p = input_.points;
  auto at = [&](Index v) -> const Point& { return p[primal::index_cast<std::size_t>(v)]; };
  for (const primal::InterfaceQuad& q : interface_.quads) {
    const Point& o = at(q.corners[0]);
    // A third of the flux of x.n through each surface, n towards the tets, from the quad's first
    // corner: the bilinear face's is the mean of its two triangulations', 0 and `twist`.
    const double twist =
        primal::tet_volume(o, at(q.corners[1]), at(q.corners[2]), at(q.corners[3]));
    double triangles = 0.0;
    if (q.centre != kInvalidIndex) {
      for (std::size_t i = 0; i < 4; ++i)
        triangles +=
            primal::tet_volume(o, at(q.corners[i]), at(q.corners[(i + 1) % 4]), at(q.centre));
    } else if (q.diagonal == 1) {
      triangles = twist;
    }
    // The quad's own scale, against which rounding is told from a twist: its size cubed.
    const double size =
        (at(q.corners[2]) - o).norm() + (at(q.corners[3]) - at(q.corners[1])).norm();
    auto& [between, scale, quads] =
        warped_[{primal::block_of(input_, q.owner()),
                 primal::block_of(input_, {primal::ElementKind::kTet, q.tets[0]}),
                 q.tets[0] >= tets_given_}];
    between += triangles - 0.5 * twist;
    scale += size * size * size;
    quads += std::abs(triangles - 0.5 * twist) > 1e-9 * size * size * size ? 1 : 0;
  }
}

// The buffer carved from the hex part, the geode hexes (the hex block's) fill up to the tets'
// triangles: the hex block takes the space between from what its bilinear faces enclose, and
// where those tets are a pyramid's or a wedge's the user's cell loses it. Carved from the tets,
// the geode hexes (the tet block's) fill up to the bilinear faces: a pyramid or wedge keeps its
// space, the caller's own tets gain it. Gmsh's 7-block ball (n = 4) in tet potting, from the
// hexes: 0.0019 of the ball's 0.49 moved without a word. A warning per block changed by more
// than 1e-9 of its quads' scale (so the same on geode_mpi's zone as on the whole model).
void Conformer::warn_warped() {
  std::map<int, std::array<double, 3>> change;  // per block: change, scale, quads
  auto add = [&](int block, double between, double scale, double quads) {
    auto& c = change[block];
    c[0] += between, c[1] += scale, c[2] += quads;
  };
  for (const auto& [key, moved] : warped_) {
    const auto& [hex_block, tet_block, split] = key;
    const auto& [between, scale, quads] = moved;
    if (res_.buffer_side == BufferSide::kHex) {
      add(hex_block, between, scale, static_cast<double>(quads));
      if (split) add(tet_block, -between, scale, static_cast<double>(quads));
    } else if (!split) {
      add(tet_block, between, scale, static_cast<double>(quads));
    }
  }
  for (const auto& [block, c] : change) {
    if (std::abs(c[0]) <= 1e-9 * c[1]) continue;
    const auto name = input_.block_names.find(block);
    std::ostringstream m;
    m << "block " << block << (name == input_.block_names.end() ? "" : " '" + name->second + "'")
      << (c[0] > 0 ? " gains " : " loses ") << std::abs(c[0])
      << " of volume: " << static_cast<std::size_t>(c[2])
      << " interface quads are not planar, and the output follows the "
      << (res_.buffer_side == BufferSide::kHex ? "tets' triangles" : "hexes' bilinear faces")
      << " on them";
    res_.warnings.push_back(m.str());
  }
}

// The local yardstick per interface quad, with the tets diced as `tet` gives: per interface
// node the lowest element around it (hexes, tets and wedges diced alone), per quad over its
// nodes.
std::vector<double> Conformer::local_minima(const std::vector<double>& tet) const {
  std::vector<double> node_min(input_.points.size(), 1.0);
  for (std::size_t h = 0; h < input_.hexes.size(); ++h)
    if (!hex_later_[h])  // a cell left for later touches no interface node
      for (Index v : input_.hexes[h])
        node_min[primal::index_cast<std::size_t>(v)] =
            std::min(node_min[primal::index_cast<std::size_t>(v)], hex_diced_[h]);
  for (std::size_t t = 0; t < input_.tets.size(); ++t)
    if (!tet_later_[t])
      for (Index v : input_.tets[t])
        node_min[primal::index_cast<std::size_t>(v)] =
            std::min(node_min[primal::index_cast<std::size_t>(v)], tet[t]);
  for (std::size_t w = 0; w < input_.wedges.size(); ++w)
    for (Index v : input_.wedges[w])
      node_min[primal::index_cast<std::size_t>(v)] =
          std::min(node_min[primal::index_cast<std::size_t>(v)], wedge_diced_[w]);
  std::vector<double> local;
  local.reserve(interface_.quads.size());
  for (const primal::InterfaceQuad& q : interface_.quads) {
    double m = 1.0;
    for (Index v : q.corners) m = std::min(m, node_min[primal::index_cast<std::size_t>(v)]);
    if (q.centre != kInvalidIndex)
      m = std::min(m, node_min[primal::index_cast<std::size_t>(q.centre)]);
    local.push_back(m);
  }
  return local;
}

namespace {

// Each listed cell diced alone, on `points`, into out[cell].
template <std::size_t N>
void measure_cells(std::span<const Point> points, const std::vector<std::array<Index, N>>& cells,
                   const std::vector<std::size_t>& which, std::vector<double>& out) {
  std::vector<std::array<Index, N>> picked;
  picked.reserve(which.size());
  for (std::size_t c : which) picked.push_back(cells[c]);
  const std::vector<double> figures = primal::diced_scaled_jacobian_per_cell(points, picked);
  for (std::size_t i = 0; i < which.size(); ++i) out[which[i]] = figures[i];
}

}  // namespace

// The input's hexes and tets diced alone (the yardsticks): now, the cells at an interface node
// (the local yardsticks read them), and the relaxed tets as the caller gave them. Every other
// figure is of a cell diced as it stands, read off its children once the output is measured
// (diced_alone_from_children), not computed a second time: measuring every input cell here was
// a tenth of a default run's CPU (the n = 36 bench).
void Conformer::measure_near_interface() {
  std::vector<char> at(input_.points.size(), 0);
  for (const primal::InterfaceQuad& q : interface_.quads) {
    for (Index v : q.corners) at[primal::index_cast<std::size_t>(v)] = 1;
    if (q.centre != kInvalidIndex) at[primal::index_cast<std::size_t>(q.centre)] = 1;
  }
  auto touches = [&](std::span<const Index> cell) {
    return std::any_of(cell.begin(), cell.end(),
                       [&](Index v) { return at[primal::index_cast<std::size_t>(v)] != 0; });
  };
  const bool relaxed = &given_ != &input_.points;
  auto moved = [&](std::span<const Index> cell) {
    return relaxed && std::any_of(cell.begin(), cell.end(), [&](Index v) {
             const auto i = primal::index_cast<std::size_t>(v);
             return given_[i] != input_.points[i];
           });
  };
  // Classified in parallel (each cell its own slot), then listed in order.
  auto classify = [](std::size_t n, std::vector<char>& later, auto&& kind) {
    later.resize(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t c = r.begin(); c != r.end(); ++c) later[c] = kind(c);
                      });
  };
  constexpr char kNowMoved = 3;  // a relaxed tet at the interface: measured now, both ways
  classify(input_.hexes.size(), hex_later_,
           [&](std::size_t h) { return touches(input_.hexes[h]) ? char{0} : kLater; });
  classify(input_.tets.size(), tet_later_, [&](std::size_t t) {
    const bool m = moved(input_.tets[t]);
    if (touches(input_.tets[t])) return m ? kNowMoved : char{0};
    return m ? kLaterGiven : kLater;
  });
  std::vector<std::size_t> now, given;
  for (std::size_t h = 0; h < hex_later_.size(); ++h)
    if (!hex_later_[h]) now.push_back(h);
  hex_diced_.assign(input_.hexes.size(), 1.0);
  measure_cells(input_.points, input_.hexes, now, hex_diced_);
  now.clear();
  for (std::size_t t = 0; t < tet_later_.size(); ++t) {
    if (tet_later_[t] == 0 || tet_later_[t] == kNowMoved) now.push_back(t);
    if (tet_later_[t] == kNowMoved || tet_later_[t] == kLaterGiven) given.push_back(t);
    if (tet_later_[t] == kNowMoved) tet_later_[t] = 0;
  }
  tet_diced_.assign(input_.tets.size(), 1.0);
  measure_cells(input_.points, input_.tets, now, tet_diced_);
  // The tets as given differ only where a node moved: those measured again (the same function,
  // so that an unmoved tet's figure is the one --relax none reports).
  tet_given_ = tet_diced_;
  measure_cells(given_, input_.tets, given, tet_given_);
}

// The cells left for later whose children will not be the input's (the buffer layer moved or
// renumbered a node of theirs): measured now, on the input, before trim_input frees it. None on
// today's layers, which change only cells at interface nodes; checked rather than assumed.
void Conformer::measure_changed() {
  if (layer_.hexes.empty()) return;  // no interface: the layer's model is the input itself
  const primal::Model& lm = layer_.model;
  auto same = [&](std::span<const Index> a, std::span<const Index> b) {
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i] != b[i] || input_.points[primal::index_cast<std::size_t>(a[i])] !=
                              lm.points[primal::index_cast<std::size_t>(b[i])])
        return false;
    return true;
  };
  // Flagged in parallel (each cell its own slot), then listed in order and measured now.
  auto changed = [&](const auto& cells, const auto& layer_cells, const std::vector<char>& later) {
    const bool all = cells.size() != layer_cells.size();
    std::vector<char> flag(cells.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t c = r.begin(); c != r.end(); ++c)
                          flag[c] = later[c] && (all || !same(cells[c], layer_cells[c]));
                      });
    std::vector<std::size_t> which;
    for (std::size_t c = 0; c < cells.size(); ++c)
      if (flag[c]) which.push_back(c);
    return which;
  };
  const std::vector<std::size_t> hexes = changed(input_.hexes, lm.hexes, hex_later_);
  measure_cells(input_.points, input_.hexes, hexes, hex_diced_);
  for (std::size_t h : hexes) hex_later_[h] = 0;
  const std::vector<std::size_t> tets = changed(input_.tets, lm.tets, tet_later_);
  measure_cells(input_.points, input_.tets, tets, tet_diced_);
  for (std::size_t t : tets) {
    if (tet_later_[t] == kLater) tet_given_[t] = tet_diced_[t];  // not relaxed
    tet_later_[t] = 0;
  }
}

// The cells left for later, diced alone: the lowest of their children as measured (sj_),
// bit for bit what diced_scaled_jacobian_per_cell gives (its nodes placed as dicing places
// them, the same corner order); dice_model makes each part's children in parent order, 8 per
// hex and 4 per tet. Then the yardsticks over all cells.
void Conformer::diced_alone_from_children(std::size_t tet_first) {
  auto from_children = [&](std::vector<double>& figure, const std::vector<char>& later,
                           std::size_t first, std::size_t per) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, figure.size(), 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t c = r.begin(); c != r.end(); ++c) {
                          if (!later[c]) continue;
                          double lowest = 1.0;  // as diced_scaled_jacobian_per_cell starts
                          for (std::size_t k = first + per * c; k < first + per * (c + 1); ++k)
                            lowest = std::min(lowest, sj_[k]);
                          figure[c] = lowest;
                        }
                      });
  };
  from_children(hex_diced_, hex_later_, 0, 8);
  from_children(tet_diced_, tet_later_, tet_first, 4);
  for (std::size_t t = 0; t < tet_given_.size(); ++t)
    if (tet_later_[t] == kLater) tet_given_[t] = tet_diced_[t];  // not relaxed
  primal::release(hex_later_, tet_later_);
  if (!hex_diced_.empty())
    res_.input_diced_hex_min_scaled_jacobian =
        *std::min_element(hex_diced_.begin(), hex_diced_.end());
  if (!tet_given_.empty())
    res_.input_diced_tet_min_scaled_jacobian =
        *std::min_element(tet_given_.begin(), tet_given_.end());
  aim_yardstick_ = std::min(
      {res_.input_diced_hex_min_scaled_jacobian, res_.input_diced_wedge_min_scaled_jacobian,
       tet_diced_.empty() ? 1.0 : *std::min_element(tet_diced_.begin(), tet_diced_.end())});
}

// Hex cells at the interface flatter than 2 : 1 on some piece (a buffer from the hex part lower
// than this of its quads' edge on average there), but not taken for the tets' layer
// (thicker_from_tets): which side gives the better transition is found by trying both
// (conform_model.cpp, kPoorTransition); with --buffer-side hex given, the tet part's layer is
// tried where the output is invalid. Every demo's are 0.31 to 0.5 at n = 3 and 5 but layer-mixed's
// (0.11, 0.15); Gmsh's quads-only cylinder layers in 2 cells, 0.1 thick inward and 0.15 outward,
// 0.180 and 0.228 (their tets' layers 0.195 and 0.195): 0.069 and 0.029 from the hexes, 0.149 and
// 0.073 from the tets.
constexpr double kNearThinHexBuffer = 0.25;

void Conformer::insert_buffer() {
  t0_ = Clock::now();
  res_.buffer_side = options_.buffer.side;
  if (interface_.quads.empty()) {  // nothing to carve: the model is diced as it is
    layer_.model = input_;
    layer_.top_node.assign(input_.points.size(), kInvalidIndex);
    return;
  }
  try {
    layer_ = insert_buffer_layer(input_, interface_, options_.buffer);
    const bool automatic = buffer_side_automatic(options_);
    if (options_.buffer_fallback && options_.buffer.side == BufferSide::kHex) {
      thicker_from_tets(automatic);
      convex_hex_part_ = automatic && res_.buffer_side == BufferSide::kHex && near_thin_ == 0.0 &&
                         layer_.report.convex_corners > 0;
    }
  } catch (const TopologyError& e) {
    if (!options_.buffer_fallback) throw;
    BufferLayerOptions other = options_.buffer;
    other.side = options_.buffer.side == BufferSide::kHex ? BufferSide::kTet : BufferSide::kHex;
    other.thickness = 0.0;  // that side's default
    const char* first = buffer_side_name(options_.buffer.side);
    const char* second = buffer_side_name(other.side);
    try {
      layer_ = insert_buffer_layer(input_, interface_, other);
    } catch (const TopologyError& e2) {
      const std::string neither =
          std::string(e.what()) + "; from the " + second + " part: " + e2.what();
      if (!options_.buffer.keep_block_faces) throw TopologyError(neither);
      // Neither part's layer keeps every block's faces: the last resort lets the copies cross
      // them, each part in turn, and says so, before refusing.
      BufferLayerOptions crossing = options_.buffer;
      crossing.keep_block_faces = false;
      try {
        layer_ = insert_buffer_layer(input_, interface_, crossing);
      } catch (const TopologyError&) {
        crossing = other;
        crossing.keep_block_faces = false;
        try {
          layer_ = insert_buffer_layer(input_, interface_, crossing);
        } catch (const TopologyError&) {
          throw TopologyError(neither);
        }
      }
      res_.buffer_side = crossing.side;
      res_.warnings.push_back(std::string("buffer layer carved from the ") +
                              buffer_side_name(crossing.side) +
                              " part across faces between blocks, so blocks there do not keep "
                              "their volumes, nor side sets on those faces their place: no layer "
                              "from either part keeps them (" +
                              neither + ")");
      return carved();
    }
    res_.buffer_side = other.side;
    const std::string thickness =
        options_.buffer.thickness > 0.0
            ? " (its default thickness " + std::to_string(default_buffer_thickness(other.side)) +
                  ", not the " + std::to_string(options_.buffer.thickness) + " given)"
            : "";
    res_.warnings.push_back(std::string("buffer layer carved from the ") + second + " part" +
                            thickness + ", not the " + first + " part: " + e.what());
  }
  carved();
}

// What follows the layer's placement: each buffer hex's element, and the report's line.
void Conformer::carved() {
  carved_from_.reserve(layer_.hexes.size());
  for (const BufferHex& b : layer_.hexes) {
    const primal::InterfaceQuad& q = interface_.quads[b.quad];
    carved_from_.push_back(res_.buffer_side == BufferSide::kHex
                               ? q.owner()
                               : primal::ElementRef{primal::ElementKind::kTet, q.tets[0]});
  }
  interface_ = {};
  proportion_ = buffer_proportions(layer_);
  res_.buffer = layer_.report;
  say("buffer layer: " + std::to_string(layer_.hexes.size()) + " hexes, min scaled Jacobian " +
      std::to_string(layer_.report.min_scaled_jacobian) + took());
}

// Carved from the hex part, the buffer is half the shortest hex edge at each node thick: where the
// hex cells at the interface are a graded boundary layer's thin first cells (hexes beside wedges
// in an extruded layer), the buffer hexes and the diced hexes behind them are squashed flat
// (layer-mixed, n = 3 to 6: 0.43 to 0.79 x the yardstick, against 1.1 to 2.0 x carved from the
// tets). So where the hex part's buffer hexes on some piece of the interface are on average
// lower than kThinHexBuffer of their quads' edge (hex cells flatter than 2.5 : 1; every other
// demo's are 0.24 to 0.5), the tet part's layer is taken instead if it is thicker on that piece.
// Per piece, as a hex layer between tets has two sides: a layer graded out from a thin first
// cell (0.048 high where its last is 0.107) averaged 0.2 over both, and its thin side's geode
// hexes were inverted.
constexpr double kThinHexBuffer = 0.2;
// ... and only if the tets' layer is clearly thicker there: at about the same height, carving
// from the tets costs their first tets' height for nothing (a quads-only sphere layer, 0.197
// from the hexes against 0.204 from the tets: the layer's block 0.138 -> 0.695 but the core
// 0.180 -> 0.126 with the defaults, and the whole 0.033 -> 0.014 with --smooth none). Where it
// was taken: 1.20 to 1.52 times thicker (layer-mixed, the graded quads-only cylinder).
constexpr double kThickerBy = 1.1;

namespace {

// Per piece of the interface (interface_pieces), the mean of its buffer hexes' values.
std::vector<double> piece_means(const std::vector<double>& value, const std::vector<Index>& piece) {
  std::vector<double> sum, count;
  for (std::size_t h = 0; h < value.size(); ++h) {
    const auto p = primal::index_cast<std::size_t>(piece[h]);
    if (p >= sum.size()) sum.resize(p + 1, 0.0), count.resize(p + 1, 0.0);
    sum[p] += value[h], count[p] += 1.0;
  }
  for (std::size_t p = 0; p < sum.size(); ++p) sum[p] /= count[p];
  return sum;
}

}  // namespace

void Conformer::thicker_from_tets(bool may_switch) {
  const std::vector<Index> piece = interface_pieces(layer_);
  const std::vector<double> hex_means = piece_means(buffer_height_ratios(layer_), piece);
  if (hex_means.empty()) return;
  const auto thinnest = static_cast<std::size_t>(
      std::min_element(hex_means.begin(), hex_means.end()) - hex_means.begin());
  const double hex = hex_means[thinnest];
  if (hex >= kThinHexBuffer || !may_switch) {
    if (hex < kNearThinHexBuffer) near_thin_ = hex;
    return;
  }
  BufferLayerOptions other = options_.buffer;
  other.side = BufferSide::kTet;
  BufferLayer tets;
  // A layer that keeps the tet part's block faces, else one crossing them: not taken here, for
  // the hex part's keeps every block's volume; conform() tries it where the hex part's output is
  // below the yardstick or invalid (tets_cross()). Layer-mixed's split wedges, a block of their
  // own beside the tets: from the hex part its thin cells give 0.050 against a yardstick of
  // 0.052 at n = 3; a TetGen potting split into two tet blocks across a part with thin cells
  // gave 2.4 x the yardstick from the hex part, and lost 0.3 % of a block's volume from the tets.
  std::string crossed;
  try {
    tets = insert_buffer_layer(input_, interface_, other);
  } catch (const TopologyError& e) {
    if (!options_.buffer.keep_block_faces) return;
    other.keep_block_faces = false;
    try {
      tets = insert_buffer_layer(input_, interface_, other);
    } catch (const TopologyError&) {
      return;
    }
    crossed = e.what();
  }
  const double tet = piece_means(buffer_height_ratios(tets), piece)[thinnest];
  if (tet <= kThickerBy * hex || !crossed.empty()) {
    near_thin_ = hex;
    tets_cross_ = !crossed.empty();
    return;
  }
  layer_ = std::move(tets);
  res_.buffer_side = BufferSide::kTet;
  std::ostringstream m;
  m << "buffer layer carved from the tet part, not the hex part: its hexes are " << tet
    << " of their interface quads' edge high on average";
  if (hex_means.size() > 1)
    m << " on the interface's thinnest piece ("
      << std::count(piece.begin(), piece.end(), primal::index_cast(thinnest)) << " of its "
      << piece.size() << " quads)";
  m << ", against " << hex
    << " from the hex part (thin hex cells at the interface, as a boundary layer's)";
  res_.warnings.push_back(m.str());
}

// After the buffer layer the stages read the input for its blocks only (the layer's model is
// a copy of it): where conform may change the input, the rest is freed before dicing, the
// run's peak (the n = 36 bench: 9.3 MiB where conform copied it to relax its tets, 10.2 MiB
// where the caller gave it up and it was not copied).
void Conformer::trim_input() {
  measure_changed();
  blocks_ = output_blocks(input_, options_.geode_block);
  // Kept for the tet part's layer (near_thin(), convex_hex_part()).
  if (near_thin_ > 0.0 || convex_hex_part_) return;
  if (given_copy_) primal::release(*given_copy_);
  if (!disposable_) return;
  primal::Model& m = *disposable_;
  primal::release(m.points, m.hexes, m.tets, m.pyramids, m.wedges, m.node_sets, m.side_sets,
                  m.node_ids, m.hex_ids, m.tet_ids, m.pyramid_ids, m.wedge_ids);
}

// The reference templates the buffer hexes use, built in parallel (each once per process);
// the four-triangle one only when some buffer hex needs it (it costs time). Before dicing, so
// that dicing knows how many hexes the output will hold.
void Conformer::build_references() {
  if (layer_.hexes.empty()) return;  // no interface: no template
  t0_ = Clock::now();
  const bool any_four = std::any_of(layer_.hexes.begin(), layer_.hexes.end(),
                                    [](const BufferHex& b) { return b.centre != kInvalidIndex; });
  tbb::parallel_invoke(
      [&] {
        refs_[0] = &reference_template(options_.template_box, {4, 6});
      },
      [&] {
        refs_[1] = &reference_template(options_.template_box, {5, 7});
      },
      [&] {
        if (any_four) refs_[2] = &reference_template_four_triangles(options_.template_box);
      });
  res_.template_min_scaled_jacobian =
      std::min(refs_[0]->min_scaled_jacobian, refs_[1]->min_scaled_jacobian);
  if (any_four)
    res_.template_min_scaled_jacobian =
        std::min(res_.template_min_scaled_jacobian, refs_[2]->min_scaled_jacobian);
  say("reference templates: min scaled Jacobian " +
      std::to_string(res_.template_min_scaled_jacobian) + took());
}

// Both parts diced over the layer model's point array, nodes merged by origin; the buffer
// hex corners are shareable so that template nodes find their diced nodes by origin. The tet
// children get room for every other output hex: assembly puts the hex children and the
// templates in front of them and the wedge children after, without a copy of the tet
// children (the largest part of most models) beside the output's connectivity.
void Conformer::dice_and_merge() {
  t0_ = Clock::now();
  std::vector<char> shareable(layer_.model.points.size(), 0);
  for (const auto& b : layer_.hexes) {
    for (Index v : b.corners) shareable[v] = 1;
    if (b.centre != kInvalidIndex) shareable[b.centre] = 1;
  }
  std::size_t room = 8 * layer_.model.hexes.size() + 6 * layer_.model.wedges.size();
  for (std::size_t b = 0; b < layer_.hexes.size(); ++b) room += ref(b).tpl.hex.hexes.size();
  diced_ = primal::dice_model(layer_.model, shareable, room);
  res_.diced_hexes = primal::index_cast(diced_.hex_children.size());
  res_.diced_tet_hexes = primal::index_cast(diced_.tet_children.size());
  res_.diced_wedge_hexes = primal::index_cast(diced_.wedge_children.size());
  check_dicing();
  say("dicing: " + std::to_string(res_.diced_hexes) + " hexes from hexes, " +
      std::to_string(res_.diced_tet_hexes) + " from tets, " +
      std::to_string(res_.diced_wedge_hexes) + " from wedges" + took());
}

// Local verification: the diced children against the dicer's tables, now that they exist (the
// dicing data are gone by check()); the children's topology is final here, smoothing moves
// nodes only.
void Conformer::check_dicing() {
  if (!verify_locally()) return;
  const auto t = Clock::now();
  res_.dicing = primal::check_dicing(layer_.model, diced_);
  dicing_check_seconds_ = since(t);
}

bool Conformer::verify_locally() const {
  return options_.verify == ConformVerify::kLocal && options_.smooth != ConformSmooth::kGlobal;
}

// A template in every buffer hex: tet/hex-side nodes become their diced node, interior nodes
// new nodes, side-face nodes disjoint-sets items merged across shared faces by match_sides.
void Conformer::place_templates() {
  t0_ = Clock::now();
  if (layer_.hexes.empty()) return;  // no interface: no template
  const primal::Model& lm = layer_.model;
  const std::size_t nb = layer_.hexes.size();
  inst_global_.assign(nb, {});
  inst_side_.assign(nb, {});
  for (std::size_t b = 0; b < nb; ++b) {
    const BufferHex& bh = layer_.hexes[b];
    const RefTemplate& rt = ref(b);
    std::array<Point, 8> P;
    for (int c = 0; c < 8; ++c) P[c] = lm.points[bh.corners[c]];
    const bool four = bh.centre != kInvalidIndex;
    const Point centre = four ? lm.points[bh.centre] : Point::Zero();
    const std::size_t n = rt.rst.size();
    inst_global_[b].assign(n, kInvalidIndex);
    inst_side_[b].assign(n, kInvalidIndex);
    res_.geode_hexes += primal::index_cast(rt.tpl.hex.hexes.size());
    for (std::size_t i = 0; i < n; ++i) {
      const Point x = buffer_map(P, bh.diagonal, rt.rst[i], four ? &centre : nullptr);
      if (!rt.key_corners[i].empty()) {
        FaceKey key = kNoOrigin;
        for (std::size_t k = 0; k < rt.key_corners[i].size(); ++k) {
          const int c = rt.key_corners[i][k];
          key[k] = c == kCentreCorner ? bh.centre : bh.corners[c];
        }
        const Index g = diced_.find(key);
        if (g == kInvalidIndex)
          throw TopologyError("buffer hex " + std::to_string(b) +
                              ": a template node has no diced node to merge with");
        inst_global_[b][i] = g;
      } else if (rt.interior(i)) {
        inst_global_[b][i] = diced_.add_node(x);
      } else {
        inst_side_[b][i] = side_sets_uf_.add();
        side_pos_.push_back(x);
        FaceKey origin = kNoOrigin;
        for (std::size_t k = 0; k < rt.side_corners[i].size() && k < origin.size(); ++k)
          origin[k] = bh.corners[rt.side_corners[i][k]];
        side_origin_.push_back(primal::normalized_origin(origin));
      }
    }
  }
  diced_.shared = primal::KeyMap<4>();  // every template node is placed
  say("geode templates: " + std::to_string(nb) + " buffer hexes placed" + took());
}

// Side faces shared by two buffer hexes: their template nodes matched topologically, one node
// per class at the mean of its members.
void Conformer::match_sides() {
  t0_ = Clock::now();
  const std::size_t nb = layer_.hexes.size();
  std::unordered_map<FaceKey, std::vector<std::pair<int, int>>, primal::IndexArrayHash> side_uses;
  for (std::size_t b = 0; b < nb; ++b)
    for (int k = 0; k < 4; ++k) {
      std::array<Index, 4> f{};
      for (int j = 0; j < 4; ++j) f[j] = layer_.hexes[b].corners[topo::kHexFaceCorners[k][j]];
      side_uses[primal::face_key(f)].push_back({static_cast<int>(b), k});
    }
  Index shared_faces = 0;
  for (const auto& [key, uses] : side_uses) {
    if (uses.size() > 2) {
      std::ostringstream m;
      m << "side face (" << key[0] << " " << key[1] << " " << key[2] << " " << key[3]
        << ") of the buffer layer is shared by " << uses.size()
        << " buffer hexes (the interface is non-manifold along edge " << key[0] << "-" << key[1]
        << ")";
      throw TopologyError(m.str());
    }
    if (uses.size() < 2) continue;
    ++shared_faces;
    const auto [ba, ka] = uses[0];
    const auto [bb, kb] = uses[1];
    const auto m = match_side(ref(ba), ka, inst_global_[ba], ref(bb), kb, inst_global_[bb],
                              "buffer hexes " + std::to_string(ba) + " and " + std::to_string(bb));
    for (const auto& [a, b] : m) {
      const Index sa = inst_side_[ba][a], sb = inst_side_[bb][b];
      if ((sa == kInvalidIndex) != (sb == kInvalidIndex))
        throw TopologyError("buffer hexes " + std::to_string(ba) + " and " + std::to_string(bb) +
                            ": a side node matches a tet/hex-side node");
      if (sa != kInvalidIndex) side_sets_uf_.unite(sa, sb);
    }
  }
  auto& uf = side_sets_uf_;
  const Index ns = primal::index_cast(uf.size());
  std::vector<Point> sum(ns, Point::Zero());
  std::vector<int> cnt(ns, 0);
  for (Index s = 0; s < ns; ++s) sum[uf.find(s)] += side_pos_[s], ++cnt[uf.find(s)];
  std::vector<Index> gid(ns, kInvalidIndex);
  for (Index s = 0; s < ns; ++s)
    if (uf.find(s) == s) gid[s] = diced_.add_node(sum[s] / cnt[s], side_origin_[s]);
  for (std::size_t b = 0; b < nb; ++b)
    for (std::size_t i = 0; i < inst_side_[b].size(); ++i)
      if (inst_side_[b][i] != kInvalidIndex) inst_global_[b][i] = gid[uf.find(inst_side_[b][i])];
  uf = {};
  primal::release(side_pos_, side_origin_, inst_side_);
  say("side faces: " + std::to_string(shared_faces) + " shared by two buffer hexes, merged" +
      took());
}

// The output hexes (diced hexes, geode hexes, diced tets, diced wedges, each in the block of
// the element it comes from: not in block order), unused nodes dropped, node and side sets carried
// over (they depend only on the numbering). Memory: the output is built out of the dicing data, not
// beside them: the tet children's array becomes the output's hex array, each dicing array is
// released as soon as it is consumed, and the nodes are renumbered in place (no second copy of the
// output mesh); the smoothing and verification that follow need room of their own.
void Conformer::assemble() {
  const std::size_t nb = layer_.hexes.size();
  // Each output hex is in the input block of the element it comes from; a geode hex in the
  // block of the element its buffer hex was carved from, or in a block of its own.
  const primal::Model& lm = layer_.model;
  // Side sets read the children in diced numbers: taken before the children move.
  carry_side_sets();
  // Nodes numbered in order of first use by the output hexes (unused ones dropped), read off
  // the children where they are, so that the node sets (which need the origins) are made and
  // the origins freed before the output's connectivity is built beside the children.
  std::vector<Index> renum(diced_.points.size(), kInvalidIndex);
  Index used = 0;
  auto number = [&](const std::array<Index, 8>& h) {
    for (Index v : h) {
      Index& r = renum[primal::index_cast<std::size_t>(v)];
      if (r == kInvalidIndex) r = used++;
    }
  };
  auto instance = [&](std::size_t b, const std::array<Index, 8>& h) {
    std::array<Index, 8> o{};
    for (int c = 0; c < 8; ++c) o[c] = inst_global_[b][h[c]];
    return o;
  };
  for (const auto& h : diced_.hex_children) number(h);
  for (std::size_t b = 0; b < nb; ++b)
    for (const auto& h : ref(b).tpl.hex.hexes) number(instance(b, h));
  for (const auto& h : diced_.tet_children) number(h);
  for (const auto& h : diced_.wedge_children) number(h);
  diced_.shared = primal::KeyMap<4>();
  node_sets_ = primal::diced_node_sets(node_set_model(), diced_, renum);
  primal::release(diced_.origin);

  // The output hexes in output numbers: hex children, templates, tet children, wedge children.
  // The tet children are renumbered where they are and the others put around them, in the
  // room dicing left (dice_and_merge), so that no copy of them is made beside the output.
  const std::size_t total = diced_.hex_children.size() +
                            primal::index_cast<std::size_t>(res_.geode_hexes) +
                            diced_.tet_children.size() + diced_.wedge_children.size();
  const std::size_t front =
      diced_.hex_children.size() + primal::index_cast<std::size_t>(res_.geode_hexes);
  auto renumbered = [&](std::array<Index, 8> h) {
    for (Index& v : h) v = renum[primal::index_cast<std::size_t>(v)];
    return h;
  };
  // The children renumbered and their blocks read in parallel (each element its own slot).
  auto each = [](std::size_t n, auto&& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
                      });
  };
  each(diced_.tet_children.size(),
       [&](std::size_t i) { diced_.tet_children[i] = renumbered(diced_.tet_children[i]); });
  std::vector<std::array<Index, 8>> hexes = std::move(diced_.tet_children);
  hexes.reserve(total);                                        // dicing's room: no copy
  hexes.insert(hexes.begin(), front, std::array<Index, 8>{});  // shifted within capacity
  std::vector<int> block(total);
  auto blocks_of = [&](primal::ElementKind kind, const std::vector<Index>& parents,
                       std::size_t first) {
    each(parents.size(), [&](std::size_t i) {
      block[first + i] = primal::block_of(lm, {kind, parents[i]});
    });
  };
  each(diced_.hex_children.size(),
       [&](std::size_t i) { hexes[i] = renumbered(diced_.hex_children[i]); });
  std::size_t at = diced_.hex_children.size();
  primal::release(diced_.hex_children);
  blocks_of(primal::ElementKind::kHex, diced_.hex_parent, 0);
  diced_parent_ = std::move(diced_.hex_parent);  // per output diced hex: its input hex
  primal::release(diced_.hex_parent);
  geode_first_.reserve(nb + 1);
  for (std::size_t b = 0; b < nb; ++b) {
    geode_first_.push_back(primal::index_cast(at));
    // Their carved-from block's, a named geode block's id given only by verify_and_output:
    // smoothing would take that block's faces for the material interfaces they are not.
    const int id = primal::block_of(lm, carved_from_[b]);
    for (const auto& h : ref(b).tpl.hex.hexes) {
      block[at] = id;
      hexes[at++] = renumbered(instance(b, h));
    }
  }
  geode_first_.push_back(primal::index_cast(at));
  primal::release(inst_global_, diced_.tet_children);
  const std::size_t tet_first = at;
  blocks_of(primal::ElementKind::kTet, diced_.tet_parent, at);
  primal::release(diced_.tet_parent);
  for (const auto& h : diced_.wedge_children) hexes.push_back(renumbered(h));
  primal::release(diced_.wedge_children);
  blocks_of(primal::ElementKind::kWedge, diced_.wedge_parent, total - diced_.wedge_parent.size());
  primal::release(diced_.wedge_parent);
  // The points permuted in place, one coordinate at a time through an array of one
  // coordinate per node (gathered in parallel, then put back): following the permutation's
  // cycles, one random access after another, was half of assembly; a second array of points
  // would be the run's peak.
  std::vector<Point>& points = diced_.points;
  {
    std::vector<Index> from(primal::index_cast<std::size_t>(used));  // per output node: its own
    each(renum.size(), [&](std::size_t i) {
      if (const Index r = renum[i]; r != kInvalidIndex)
        from[primal::index_cast<std::size_t>(r)] = primal::index_cast(i);
    });
    primal::release(renum);
    std::vector<double> coordinate(from.size());
    for (int c = 0; c < 3; ++c) {
      each(from.size(), [&](std::size_t r) {
        coordinate[r] = points[primal::index_cast<std::size_t>(from[r])][c];
      });
      each(from.size(), [&](std::size_t r) { points[r][c] = coordinate[r]; });
    }
  }
  // No shrink_to_fit: dice_model reserved about what it made, and a shrinking copy of every
  // point would be the run's peak.
  points.resize(primal::index_cast<std::size_t>(used));
  mesh_.points = std::move(points);
  mesh_.hexes = std::move(hexes);
  mesh_.block = std::move(block);
  diced_ = primal::DicedModel();
  // The stages after this one read the buffer hexes only (their quads), not the layer's model
  // or the interface: freed before smoothing, verification and writing add their own.
  layer_.model = primal::Model();
  primal::release(layer_.top_node);
  interface_ = primal::Interface();
  res_.min_scaled_jacobian_before_smoothing = measure();
  diced_alone_from_children(tet_first);
}

}  // namespace detail

ConformSmooth parse_conform_smooth(const std::string& word) {
  if (word == "local") return ConformSmooth::kLocal;
  if (word == "global") return ConformSmooth::kGlobal;
  if (word == "none") return ConformSmooth::kNone;
  throw InvalidInput("smoothing mode '" + word + "': expected local, global or none");
}

ConformQuality parse_conform_quality(const std::string& word) {
  if (word == "sj") return ConformQuality::kScaledJacobian;
  if (word == "full") return ConformQuality::kFull;
  throw InvalidInput("quality report '" + word + "': expected sj or full");
}

ConformVerify parse_conform_verify(const std::string& word) {
  if (word == "local") return ConformVerify::kLocal;
  if (word == "full") return ConformVerify::kFull;
  throw InvalidInput("verification '" + word + "': expected local or full");
}

ConformPyramids parse_conform_pyramids(const std::string& word) {
  if (word == "split") return ConformPyramids::kSplit;
  throw InvalidInput("pyramid treatment '" + word + "': expected split");
}

ConformRelax parse_conform_relax(const std::string& word) {
  if (word == "interface") return ConformRelax::kInterface;
  if (word == "none") return ConformRelax::kNone;
  throw InvalidInput("tet relaxation '" + word + "': expected interface or none");
}

void set_buffer_side(ConformOptions& options, const std::string& word) {
  options.buffer_side_chosen = !word.empty();
  options.buffer.side = word.empty() ? BufferSide::kHex : parse_buffer_side(word);
}

}  // namespace geode::conform
