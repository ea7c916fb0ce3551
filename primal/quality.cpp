#include <geode/primal/quality.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>
#if defined(__SSE2__)
#include <emmintrin.h>
#if defined(__x86_64__)
#include <immintrin.h>
#endif
#endif
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <geode/primal/detail/scaled_jacobian_paths.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

namespace {

namespace topo = topology;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Sign (+1 / -1) of corner c along local axis i: the trilinear map's derivative at the centre
// weights each corner by the product of these signs (1/4 of it in the unit cube).
constexpr double corner_sign(int c, int i) { return topo::kHexCornerCoords[c][i] ? 1.0 : -1.0; }

// Inlined into the scaled Jacobians: their nine determinants are most of smoothing's and the
// tet relaxation's time, which the calls made 1.4 x longer (the same operations, so the same
// values).
[[gnu::always_inline]] inline double det3(const Point& a, const Point& b, const Point& c) {
  return a.dot(b.cross(c));
}

[[gnu::always_inline]] inline double scaled_det(const Point& a, const Point& b, const Point& c) {
  const double l = a.norm() * b.norm() * c.norm();
  return l > 0.0 ? det3(a, b, c) / l : 0.0;
}

[[gnu::always_inline]] inline std::array<Point, 3> corner_frame(const HexCorners& p, int c) {
  const auto& n = topology::kHexCornerNeighbors[c];
  return {p[n[0]] - p[c], p[n[1]] - p[c], p[n[2]] - p[c]};
}

[[gnu::always_inline]] inline std::array<Point, 3> principal_axes(const HexCorners& p) {
  std::array<Point, 3> x{Point::Zero(), Point::Zero(), Point::Zero()};
  for (int c = 0; c < 8; ++c) {
    for (int i = 0; i < 3; ++i) x[i] += corner_sign(c, i) * p[c];
  }
  return x;
}

// Cross derivatives X12, X13, X23 of [Verdict] (taper).
std::array<Point, 3> hex_cross_axes(const HexCorners& p) {
  std::array<Point, 3> x{Point::Zero(), Point::Zero(), Point::Zero()};
  for (int c = 0; c < 8; ++c) {
    x[0] += corner_sign(c, 0) * corner_sign(c, 1) * p[c];
    x[1] += corner_sign(c, 0) * corner_sign(c, 2) * p[c];
    x[2] += corner_sign(c, 1) * corner_sign(c, 2) * p[c];
  }
  return x;
}

std::array<double, 12> edge_lengths(const HexCorners& p) {
  std::array<double, 12> l{};
  for (int e = 0; e < 12; ++e) {
    l[e] = (p[topo::kHexEdgeCorners[e][1]] - p[topo::kHexEdgeCorners[e][0]]).norm();
  }
  return l;
}

// The 4 body diagonals join corner c to the corner with every local coordinate flipped.
std::array<double, 4> diagonal_lengths(const HexCorners& p) {
  // Corners 0..3 (bottom) and their opposites: 0-6, 1-7, 2-4, 3-5.
  constexpr std::array<std::array<int, 2>, 4> kDiagonals{{{0, 6}, {1, 7}, {2, 4}, {3, 5}}};
  std::array<double, 4> d{};
  for (int i = 0; i < 4; ++i) d[i] = (p[kDiagonals[i][1]] - p[kDiagonals[i][0]]).norm();
  return d;
}

double ratio(double num, double den) { return den > 0.0 ? num / den : kDegenerateMetric; }

// Derivatives of the trilinear shape function of corner c on [0,1]^3 at (r, s, t).
Point shape_gradient(int c, const Point& rst) {
  Point f, df;
  for (int i = 0; i < 3; ++i) {
    const bool one = topo::kHexCornerCoords[c][i] != 0;
    f[i] = one ? rst[i] : 1.0 - rst[i];
    df[i] = one ? 1.0 : -1.0;
  }
  return {df[0] * f[1] * f[2], f[0] * df[1] * f[2], f[0] * f[1] * df[2]};
}

// Shape-function gradients at the 2x2x2 Gauss points: [point][corner], point index 4 r + 2 s
// + t over {0.5 - g, 0.5 + g}. Tabulated once: every volume evaluation would recompute them.
struct GaussGradients {
  std::array<std::array<Point, 8>, 8> dn;
};

const GaussGradients& gauss_gradients() {
  static const GaussGradients table = [] {
    const double g = 0.5 / std::sqrt(3.0);
    const std::array<double, 2> pts{0.5 - g, 0.5 + g};
    GaussGradients t;
    int k = 0;
    for (double r : pts)
      for (double s : pts)
        for (double u : pts) {
          for (int c = 0; c < 8; ++c) t.dn[k][c] = shape_gradient(c, Point(r, s, u));
          ++k;
        }
    return t;
  }();
  return table;
}

// Exact volume of the trilinear hex and its gradient with respect to the corners. det J is of
// degree 2 in each local coordinate, so the 2x2x2 Gauss rule integrates it exactly.
double trilinear_volume(const HexCorners& p, std::array<Point, 8>* gradient) {
  const GaussGradients& gg = gauss_gradients();
  double volume = 0.0;
  if (gradient) gradient->fill(Point::Zero());
  for (const auto& dn : gg.dn) {
    // Columns of the Jacobian: sum over corners of x_c dN_c/dr (/ds, /dt).
    Point a = Point::Zero(), b = Point::Zero(), cc = Point::Zero();
    for (int c = 0; c < 8; ++c) {
      a += p[c] * dn[c][0];
      b += p[c] * dn[c][1];
      cc += p[c] * dn[c][2];
    }
    volume += det3(a, b, cc) / 8.0;
    if (gradient) {
      // d det / d x_c = (b x c) dN/dr + (c x a) dN/ds + (a x b) dN/dt
      const Point bc = b.cross(cc), ca = cc.cross(a), ab = a.cross(b);
      for (int c = 0; c < 8; ++c) {
        (*gradient)[c] += (bc * dn[c][0] + ca * dn[c][1] + ab * dn[c][2]) / 8.0;
      }
    }
  }
  return volume;
}

Point centre_normal(const QuadCorners& p) {
  // Verdict's quad centre normal: X1 x X2 with X1 = (p1 + p2) - (p0 + p3), X2 = (p2 + p3) -
  // (p0 + p1); it equals (p2 - p0) x (p3 - p1) / ... up to a factor 2.
  const Point n = (p[2] - p[0]).cross(p[3] - p[1]);
  const double len = n.norm();
  return len > 0.0 ? Point(n / len) : Point::Zero();
}

std::array<double, 4> quad_signed_corner_areas(const QuadCorners& p, const Point& unit_normal,
                                               std::array<double, 4>* scaled) {
  std::array<double, 4> area{};
  for (int c = 0; c < 4; ++c) {
    const Point a = p[(c + 1) % 4] - p[c];
    const Point b = p[(c + 3) % 4] - p[c];
    area[c] = a.cross(b).dot(unit_normal);
    if (scaled) {
      const double l = a.norm() * b.norm();
      (*scaled)[c] = l > 0.0 ? area[c] / l : 0.0;
    }
  }
  return area;
}

}  // namespace

std::array<Point, 3> hex_corner_frame(const HexCorners& p, int c) { return corner_frame(p, c); }

double hex_corner_jacobian(const HexCorners& p, int c) {
  const auto f = corner_frame(p, c);
  return det3(f[0], f[1], f[2]);
}

std::array<Point, 3> hex_principal_axes(const HexCorners& p) { return principal_axes(p); }

double scaled_determinant(const Point& a, const Point& b, const Point& c) {
  return scaled_det(a, b, c);
}

std::array<double, 9> hex_scaled_jacobians(const HexCorners& p) {
  std::array<double, 9> q{};
  for (int c = 0; c < 8; ++c) {
    const auto f = corner_frame(p, c);
    q[c] = scaled_det(f[0], f[1], f[2]);
  }
  const auto x = principal_axes(p);
  q[8] = scaled_det(x[0], x[1], x[2]);
  return q;
}

std::array<double, 9> hex_jacobians(const HexCorners& p) {
  std::array<double, 9> j{};
  for (int c = 0; c < 8; ++c) j[c] = hex_corner_jacobian(p, c);
  const auto x = hex_principal_axes(p);
  j[8] = det3(x[0], x[1], x[2]) / 64.0;
  return j;
}

// [Verdict] hex edge ratio: Hmax / Hmin, the longest over the shortest of the 12 edges. VTK 9.1's
// vtkMeshQuality reports other values for some of the same hexes; this is Verdict's definition
// as written, and we keep it rather than match VTK.
double hex_edge_ratio(const HexCorners& p) {
  const auto l = edge_lengths(p);
  const auto [lo, hi] = std::minmax_element(l.begin(), l.end());
  return ratio(*hi, *lo);
}

// [Verdict] hex maximum edge ratio: max over i < j of max(|Xi|, |Xj|) / min(|Xi|, |Xj|).
double hex_max_edge_ratio(const HexCorners& p) {
  const auto x = hex_principal_axes(p);
  double worst = 1.0;
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      const double a = x[i].norm(), b = x[j].norm();
      worst = std::max(worst, ratio(std::max(a, b), std::min(a, b)));
    }
  }
  return worst;
}

double hex_aspect_ratio(const HexCorners& p) { return hex_max_edge_ratio(p); }

// [Verdict] hex skew: max |cos| of the angles between the unit principal axes.
double hex_skew(const HexCorners& p) {
  auto x = hex_principal_axes(p);
  for (auto& v : x) {
    const double n = v.norm();
    if (n <= 0.0) return kDegenerateMetric;
    v /= n;
  }
  return std::max({std::abs(x[0].dot(x[1])), std::abs(x[0].dot(x[2])), std::abs(x[1].dot(x[2]))});
}

// [Verdict] hex taper: max over pairs (i, j) of |Xij| / min(|Xi|, |Xj|).
double hex_taper(const HexCorners& p) {
  const auto x = hex_principal_axes(p);
  const auto xx = hex_cross_axes(p);
  const double l0 = x[0].norm(), l1 = x[1].norm(), l2 = x[2].norm();
  return std::max({ratio(xx[0].norm(), std::min(l0, l1)), ratio(xx[1].norm(), std::min(l0, l2)),
                   ratio(xx[2].norm(), std::min(l1, l2))});
}

// Hex volume: the exact volume of the trilinear map, which is NOT [Verdict]'s definition.
// Verdict's v_hex_volume (V_HexMetric.cpp, "volume of a hex: Jacobian at hex center", after
// Taylor and Flanagan's Pronto3D) is the centre Jacobian det(X1, X2, X3) / 64, which CUBIT's
// "Element Volume" reports; later Verdict releases sum a 24-tet split through the face and cell
// centres instead. Ours equals the 24-tet value (checked in tests) and the centre value for
// parallelepipeds only (issue 21 found them up to 23% apart on a template's hexes).
double hex_volume(const HexCorners& p) { return trilinear_volume(p, nullptr); }

// [Verdict] hex stretch: sqrt(3) * shortest edge / longest body diagonal.
double hex_stretch(const HexCorners& p) {
  const auto l = edge_lengths(p);
  const auto d = diagonal_lengths(p);
  return std::sqrt(3.0) *
         ratio(*std::min_element(l.begin(), l.end()), *std::max_element(d.begin(), d.end()));
}

// [Verdict] hex diagonal (ratio): shortest over longest body diagonal.
double hex_diagonal(const HexCorners& p) {
  const auto d = diagonal_lengths(p);
  return ratio(*std::min_element(d.begin(), d.end()), *std::max_element(d.begin(), d.end()));
}

// [Verdict] hex dimension: Pronto3D's characteristic length for the stable time step (Taylor &
// Flanagan, SAND87-1912), sqrt(V^2 / (2 sum_c |dV/dx_c|^2)) with the exact trilinear volume.
// sqrt(3)/3 for the unit cube.
double hex_dimension(const HexCorners& p) {
  std::array<Point, 8> grad;
  const double v = trilinear_volume(p, &grad);
  double g2 = 0.0;
  for (const auto& g : grad) g2 += g.squaredNorm();
  return g2 > 0.0 ? std::sqrt(0.5 * v * v / g2) : 0.0;
}

// [Verdict] hex jacobian: min over the 8 corner determinants and the centre det(X)/64.
double hex_jacobian(const HexCorners& p) {
  const auto j = hex_jacobians(p);
  return *std::min_element(j.begin(), j.end());
}

// [Verdict] hex scaled jacobian: min over the 8 corners and the centre (principal axes) of
// det / product of the three column lengths. Verdict returns 1e30 when a column vanishes; we
// return 0 for such a corner (a collapsed edge is a degenerate corner, not a perfect one).
#if defined(__SSE2__)
// Corners c and c + 1 at once (SSE2, two doubles a register): scaled_det of their corner_frame,
// with the same operations in the same order as the scalar code (Eigen's cross, its dot and
// squared norm summing (x + y) + z), so the same bits (quality_test checks them against
// hex_scaled_jacobians); lanes [0] corner c, [1] corner c + 1.
[[gnu::always_inline]] inline void corner_pair(const HexCorners& p, int c, double out[2]) {
  const auto& n0 = topology::kHexCornerNeighbors[c];
  const auto& n1 = topology::kHexCornerNeighbors[c + 1];
  auto at = [&](int a, int b, int i) { return _mm_set_pd(p[b][i], p[a][i]); };
  __m128d e[3][3];  // edge k, coordinate i
  for (int i = 0; i < 3; ++i) {
    const __m128d o = at(c, c + 1, i);
    for (int k = 0; k < 3; ++k) e[k][i] = _mm_sub_pd(at(n0[k], n1[k], i), o);
  }
  const auto& a = e[0];
  const auto& b = e[1];
  const auto& d = e[2];
  // b x d, then a . (b x d)
  const __m128d x0 = _mm_sub_pd(_mm_mul_pd(b[1], d[2]), _mm_mul_pd(b[2], d[1]));
  const __m128d x1 = _mm_sub_pd(_mm_mul_pd(b[2], d[0]), _mm_mul_pd(b[0], d[2]));
  const __m128d x2 = _mm_sub_pd(_mm_mul_pd(b[0], d[1]), _mm_mul_pd(b[1], d[0]));
  const __m128d det =
      _mm_add_pd(_mm_add_pd(_mm_mul_pd(a[0], x0), _mm_mul_pd(a[1], x1)), _mm_mul_pd(a[2], x2));
  auto norm = [](const __m128d* v) {
    return _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(v[0], v[0]), _mm_mul_pd(v[1], v[1])),
                                  _mm_mul_pd(v[2], v[2])));
  };
  const __m128d l = _mm_mul_pd(_mm_mul_pd(norm(a), norm(b)), norm(d));
  // l > 0 ? det / l : +0 (the masked-off lane's quotient, inf or NaN, is dropped)
  const __m128d q = _mm_and_pd(_mm_cmpgt_pd(l, _mm_setzero_pd()), _mm_div_pd(det, l));
  _mm_storeu_pd(out, q);
}
#endif

namespace {

#if defined(__x86_64__)
// The same with AVX2 (four doubles a register), for the processors that have it (chosen at run
// time: the build targets plain x86-64): the bottom corners 0-3 at once, then the top ones 4-7,
// their neighbours (kHexCornerNeighbors: c + 1, c + 3 around their face and the corner across)
// permuted from the coordinates' registers; and the principal axes summed a corner at a time,
// three coordinates a register. The same operations in the same order as the scalar code, no
// FMA (not enabled, and never formed from separate intrinsics), so the same bits.
// Rotations of four corners' coordinates: to corner c + 1, c + 3 (modulo 4).
[[gnu::target("avx2"), gnu::always_inline]] inline __m256d rotate1(__m256d v) {
  return _mm256_permute4x64_pd(v, 0x39);
}
[[gnu::target("avx2"), gnu::always_inline]] inline __m256d rotate3(__m256d v) {
  return _mm256_permute4x64_pd(v, 0x93);
}
[[gnu::target("avx2"), gnu::always_inline]] inline __m256d norm4(const __m256d* v) {
  return _mm256_sqrt_pd(
      _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(v[0], v[0]), _mm256_mul_pd(v[1], v[1])),
                    _mm256_mul_pd(v[2], v[2])));
}
// Four corners at o with neighbours n0, n1, n2 (per coordinate): as corner_pair, l > 0 ?
// det / l : +0.
[[gnu::target("avx2"), gnu::always_inline]] inline __m256d corner_quad(const __m256d* o,
                                                                       const __m256d* n0,
                                                                       const __m256d* n1,
                                                                       const __m256d* n2) {
  __m256d a[3], b[3], d[3];
  for (int i = 0; i < 3; ++i) {
    a[i] = _mm256_sub_pd(n0[i], o[i]);
    b[i] = _mm256_sub_pd(n1[i], o[i]);
    d[i] = _mm256_sub_pd(n2[i], o[i]);
  }
  const __m256d x0 = _mm256_sub_pd(_mm256_mul_pd(b[1], d[2]), _mm256_mul_pd(b[2], d[1]));
  const __m256d x1 = _mm256_sub_pd(_mm256_mul_pd(b[2], d[0]), _mm256_mul_pd(b[0], d[2]));
  const __m256d x2 = _mm256_sub_pd(_mm256_mul_pd(b[0], d[1]), _mm256_mul_pd(b[1], d[0]));
  const __m256d det = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(a[0], x0), _mm256_mul_pd(a[1], x1)),
                                    _mm256_mul_pd(a[2], x2));
  const __m256d l = _mm256_mul_pd(_mm256_mul_pd(norm4(a), norm4(b)), norm4(d));
  return _mm256_and_pd(_mm256_cmp_pd(l, _mm256_setzero_pd(), _CMP_GT_OQ), _mm256_div_pd(det, l));
}

// The eight corners' lowest scaled determinant.
[[gnu::target("avx2")]] double corners_min_avx2(const HexCorners& p) {
  __m256d lo[3], hi[3];  // per coordinate: corners 0-3, 4-7
  for (int i = 0; i < 3; ++i) {
    lo[i] = _mm256_set_pd(p[3][i], p[2][i], p[1][i], p[0][i]);
    hi[i] = _mm256_set_pd(p[7][i], p[6][i], p[5][i], p[4][i]);
  }
  __m256d n0[3], n1[3];
  for (int i = 0; i < 3; ++i) n0[i] = rotate1(lo[i]), n1[i] = rotate3(lo[i]);
  const __m256d bottom = corner_quad(lo, n0, n1, hi);
  for (int i = 0; i < 3; ++i) n0[i] = rotate3(hi[i]), n1[i] = rotate1(hi[i]);
  const __m256d top = corner_quad(hi, n0, n1, lo);
  alignas(32) double q[8];
  _mm256_store_pd(q, bottom);
  _mm256_store_pd(q + 4, top);
  double m = kInf;
  for (double x : q) m = std::min(m, x);
  return m;
}

// The centre's scaled determinant. Principal axes: x[i] += sign(c, i) * p[c], corner by corner,
// lanes x, y, z (and 0).
[[gnu::target("avx2")]] double centre_avx2(const HexCorners& p) {
  __m256d x[3] = {_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd()};
  for (int c = 0; c < 8; ++c) {
    const __m256d pc = _mm256_set_pd(0.0, p[c][2], p[c][1], p[c][0]);
    for (int i = 0; i < 3; ++i)
      x[i] = _mm256_add_pd(x[i], _mm256_mul_pd(_mm256_set1_pd(corner_sign(c, i)), pc));
  }
  alignas(32) double axes[3][4];
  for (int i = 0; i < 3; ++i) _mm256_store_pd(axes[i], x[i]);
  return scaled_det(Point(axes[0][0], axes[0][1], axes[0][2]),
                    Point(axes[1][0], axes[1][1], axes[1][2]),
                    Point(axes[2][0], axes[2][1], axes[2][2]));
}

[[gnu::target("avx2")]] double hex_scaled_jacobian_avx2(const HexCorners& p) {
  return std::min(corners_min_avx2(p), centre_avx2(p));
}

// All eight corners cost about what one or two do one at a time: the centre is left out when
// they are at or below the bound already.
[[gnu::target("avx2")]] double hex_scaled_jacobian_bounded_avx2(const HexCorners& p, double bound) {
  const double m = corners_min_avx2(p);
  return m > bound ? std::min(m, centre_avx2(p)) : m;
}
#endif

double hex_scaled_jacobian_bounded_portable(const HexCorners& p, double bound) {
  double m = kInf;
  for (int c = 0; c < 8 && m > bound; ++c) {
    const auto f = corner_frame(p, c);
    m = std::min(m, scaled_det(f[0], f[1], f[2]));
  }
  if (m > bound) {
    const auto x = principal_axes(p);
    m = std::min(m, scaled_det(x[0], x[1], x[2]));
  }
  return m;
}

double hex_scaled_jacobian_portable(const HexCorners& p) {
#if defined(__SSE2__)
  double m = kInf;
  for (int c = 0; c < 8; c += 2) {
    double q[2];
    corner_pair(p, c, q);
    m = std::min(m, q[0]);
    m = std::min(m, q[1]);
  }
  const auto x = principal_axes(p);
  return std::min(m, scaled_det(x[0], x[1], x[2]));
#else
  return hex_scaled_jacobian_bounded_portable(p, -kInf);
#endif
}

}  // namespace

namespace detail {

ScaledJacobianPaths scaled_jacobian_paths() {
  ScaledJacobianPaths paths{&hex_scaled_jacobian_portable, &hex_scaled_jacobian_bounded_portable,
                            &hex_scaled_jacobian_portable, &hex_scaled_jacobian_bounded_portable};
#if defined(__x86_64__)
  if (__builtin_cpu_supports("avx2"))
    paths.fastest = &hex_scaled_jacobian_avx2,
    paths.fastest_bounded = &hex_scaled_jacobian_bounded_avx2;
#endif
  return paths;
}

}  // namespace detail

// Every corner measured (no bound to stop at), four at a time with AVX2, else two with SSE2:
// with SSE2 110 -> 83 ns per hex on a million distorted cubes (one core), with AVX2 (measured
// against SSE2 on a busier machine) 188 -> 65 ns; a conform run measures every output hex. The
// bounded form, without AVX2, goes one corner at a time: its searches mostly stop at the first.
double hex_scaled_jacobian(const HexCorners& p) {
  static const auto fastest = detail::scaled_jacobian_paths().fastest;
  return fastest(p);
}

double hex_scaled_jacobian_bounded(const HexCorners& p, double bound) {
  static const auto fastest = detail::scaled_jacobian_paths().fastest_bounded;
  return fastest(p, bound);
}

// [Verdict] hex condition (maximum Frobenius aspect; Knupp, IJNME 48:1165, 2000): max over
// corners of |A|_F |A^-1|_F / 3, 1 for a cube; 1e30 where a corner determinant is <= 0.
double hex_condition(const HexCorners& p) {
  double worst = 1.0;
  for (int c = 0; c < 8; ++c) {
    const auto f = hex_corner_frame(p, c);
    const double det = det3(f[0], f[1], f[2]);
    if (det <= 0.0) return kDegenerateMetric;
    // |A^-1|_F = |adj A|_F / det, and the rows of adj A are the pairwise cross products.
    const double a2 = f[0].squaredNorm() + f[1].squaredNorm() + f[2].squaredNorm();
    const double adj2 = f[0].cross(f[1]).squaredNorm() + f[1].cross(f[2]).squaredNorm() +
                        f[2].cross(f[0]).squaredNorm();
    worst = std::max(worst, std::sqrt(a2 * adj2) / det / 3.0);
  }
  return worst;
}

// [Verdict] hex shape (Knupp): min over corners of 3 det(A)^(2/3) / |A|_F^2; 0 where a corner
// determinant is <= 0.
double hex_shape(const HexCorners& p) {
  double best = 1.0;
  for (int c = 0; c < 8; ++c) {
    const auto f = hex_corner_frame(p, c);
    const double det = det3(f[0], f[1], f[2]);
    if (det <= 0.0) return 0.0;
    const double a2 = f[0].squaredNorm() + f[1].squaredNorm() + f[2].squaredNorm();
    best = std::min(best, 3.0 * std::cbrt(det * det) / a2);
  }
  return best;
}

// [Verdict] quad jacobian: minimum signed corner area (a x b) . n.
double quad_jacobian(const QuadCorners& p) { return quad_jacobian(p, centre_normal(p)); }

double quad_jacobian(const QuadCorners& p, const Point& normal) {
  const double n = normal.norm();
  const Point u = n > 0.0 ? Point(normal / n) : Point::Zero();
  const auto a = quad_signed_corner_areas(p, u, nullptr);
  return *std::min_element(a.begin(), a.end());
}

// [Verdict] quad scaled jacobian: min over corners of the signed area / (|a| |b|).
double quad_scaled_jacobian(const QuadCorners& p) {
  return quad_scaled_jacobian(p, centre_normal(p));
}

double quad_scaled_jacobian(const QuadCorners& p, const Point& normal) {
  const double n = normal.norm();
  const Point u = n > 0.0 ? Point(normal / n) : Point::Zero();
  std::array<double, 4> q{};
  quad_signed_corner_areas(p, u, &q);
  return *std::min_element(q.begin(), q.end());
}

std::span<const HexMetricInfo> hex_metrics() {
  // Acceptable ranges from the [Verdict] hexahedron tables.
  static const std::array<HexMetricInfo, 12> table{{
      {HexMetric::kEdgeRatio, "Edge Ratio", "edge_ratio", &hex_edge_ratio, 1.0, 1.3,
       "Lmax / Lmin over the 12 edges [Verdict hex edge ratio]"},
      {HexMetric::kAspectRatio, "Aspect Ratio", "aspect_ratio", &hex_aspect_ratio, 1.0, 1.3,
       "max |Xi|/|Xj| of principal axes [Verdict hex max edge ratio = CUBIT aspect ratio]"},
      {HexMetric::kSkew, "Skew", "skew", &hex_skew, 0.0, 0.5,
       "max |cos| between unit principal axes [Verdict hex skew]"},
      {HexMetric::kTaper, "Taper", "taper", &hex_taper, 0.0, 0.5,
       "max |Xij| / min(|Xi|,|Xj|) [Verdict hex taper]"},
      {HexMetric::kVolume, "Element Volume", "volume", &hex_volume, 0.0, kInf,
       "exact volume of the trilinear map (not [Verdict]'s centre Jacobian det(X1,X2,X3)/64)"},
      {HexMetric::kStretch, "Stretch", "stretch", &hex_stretch, 0.25, 1.0,
       "sqrt(3) Lmin / Dmax [Verdict hex stretch]"},
      {HexMetric::kDiagonal, "Diagonal Ratio", "diagonal", &hex_diagonal, 0.65, 1.0,
       "Dmin / Dmax of body diagonals [Verdict hex diagonal]"},
      {HexMetric::kDimension, "Dimension", "dimension", &hex_dimension, -kInf, kInf,
       "V / sqrt(2 |grad V|^2), Pronto3D length [Verdict hex dimension]"},
      {HexMetric::kJacobian, "Jacobian", "jacobian", &hex_jacobian, 0.0, kInf,
       "min corner det, centre det/64 [Verdict hex jacobian]"},
      {HexMetric::kScaledJacobian, "Scaled Jacobian", "scaled_jacobian", &hex_scaled_jacobian, 0.5,
       1.0, "min over 8 corners and centre of det/(|a||b||c|) [Verdict hex scaled jacobian]"},
      {HexMetric::kCondition, "Condition No.", "condition", &hex_condition, 1.0, 8.0,
       "max corner |A|_F |A^-1|_F / 3 [Verdict hex condition; Knupp 2000]"},
      {HexMetric::kShape, "Shape", "shape", &hex_shape, 0.3, 1.0,
       "min corner 3 det^(2/3) / |A|_F^2 [Verdict hex shape; Knupp]"},
  }};
  return table;
}

const HexMetricInfo& hex_metric_info(HexMetric metric) {
  for (const auto& m : hex_metrics()) {
    if (m.metric == metric) return m;
  }
  throw InvalidInput("hex_metric_info: unknown metric id " +
                     std::to_string(static_cast<int>(metric)));
}

const HexMetricInfo& hex_metric_info(std::string_view key_or_name) {
  for (const auto& m : hex_metrics()) {
    if (m.key == key_or_name || m.name == key_or_name) return m;
  }
  std::string known;
  for (const auto& m : hex_metrics()) known += (known.empty() ? "" : ", ") + std::string(m.key);
  throw InvalidInput("unknown hex quality metric '" + std::string(key_or_name) +
                     "' (known: " + known + ")");
}

HexCorners hex_corners(const HexMesh& mesh, Index h) {
  if (h < 0 || index_cast<std::size_t>(h) >= mesh.hexes.size()) {
    throw InvalidInput("hex_corners: hex " + std::to_string(h) + " out of range (mesh has " +
                       std::to_string(mesh.hexes.size()) + " hexes)");
  }
  HexCorners p;
  for (int c = 0; c < 8; ++c) {
    const Index n = mesh.hexes[h][c];
    if (n < 0 || index_cast<std::size_t>(n) >= mesh.points.size()) {
      throw InvalidInput("hex_corners: hex " + std::to_string(h) + " corner " + std::to_string(c) +
                         " names node " + std::to_string(n) + ", out of range (mesh has " +
                         std::to_string(mesh.points.size()) + " nodes)");
    }
    p[c] = mesh.points[n];
  }
  return p;
}

std::vector<double> scaled_jacobian_per_hex(const HexMesh& mesh) {
  // Each hex in its own slot (TBB): the values do not depend on the thread count.
  std::vector<double> sj(mesh.hexes.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sj.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t h = r.begin(); h != r.end(); ++h)
                        sj[h] = hex_scaled_jacobian(hex_corners(mesh, index_cast(h)));
                    });
  return sj;
}

double hex_shortest_edge(const HexCorners& p) {
  const auto l = edge_lengths(p);
  return *std::min_element(l.begin(), l.end());
}

std::vector<double> shortest_edge_per_hex(const HexMesh& mesh) {
  std::vector<double> e(mesh.hexes.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, e.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t h = r.begin(); h != r.end(); ++h)
                        e[h] = hex_shortest_edge(hex_corners(mesh, index_cast(h)));
                    });
  return e;
}

double min_scaled_jacobian(const HexMesh& mesh, std::vector<Index>* inverted) {
  const std::vector<double> sj = scaled_jacobian_per_hex(mesh);
  double mn = 1.0;
  for (std::size_t h = 0; h < sj.size(); ++h) {
    mn = std::min(mn, sj[h]);
    if (inverted && sj[h] <= 0) inverted->push_back(index_cast(h));
  }
  return mn;
}

QuadCorners quad_corners(const QuadMesh& mesh, Index q) {
  if (q < 0 || index_cast<std::size_t>(q) >= mesh.quads.size()) {
    throw InvalidInput("quad_corners: quad " + std::to_string(q) + " out of range (mesh has " +
                       std::to_string(mesh.quads.size()) + " quads)");
  }
  QuadCorners p;
  for (int c = 0; c < 4; ++c) {
    const Index n = mesh.quads[q][c];
    if (n < 0 || index_cast<std::size_t>(n) >= mesh.points.size()) {
      throw InvalidInput("quad_corners: quad " + std::to_string(q) + " corner " +
                         std::to_string(c) + " names node " + std::to_string(n) +
                         ", out of range (mesh has " + std::to_string(mesh.points.size()) +
                         " nodes)");
    }
    p[c] = mesh.points[n];
  }
  return p;
}

double tet_scaled_jacobian(const Point& p0, const Point& p1, const Point& p2, const Point& p3) {
  const double det = (p1 - p0).dot((p2 - p0).cross(p3 - p0));  // 6V, the same at every corner
  const std::array<Point, 4> p{p0, p1, p2, p3};
  double max_product = 0.0;
  for (int c = 0; c < 4; ++c) {
    double product = 1.0;
    for (int o = 0; o < 4; ++o) {
      if (o != c) product *= (p[o] - p[c]).norm();
    }
    max_product = std::max(max_product, product);
  }
  if (max_product <= 0.0) return 0.0;
  return det * std::sqrt(2.0) / max_product;
}

}  // namespace geode::primal
