#pragma once
// Analytic first and second derivatives of the two corner measures the smoothers optimise, as
// functions of the corner matrix columns [a, b, c] (9 entries, a first):
//  - the determinant D = a . (b x c) (the corner Jacobian, primal/quality.hpp);
//  - the scaled determinant q = D / (|a| |b| |c|) (Verdict's scaled Jacobian of one corner,
//    [Verdict] hexahedron chapter; 0 with zero derivatives when a column has zero length);
//  - the corner shape s = N(D) / S (Verdict's shape of one corner: hexahedron 3 D^(2/3) / |A|_F^2,
//    quadrilateral 2 D / (|a|^2 + |b|^2) with c the plane's unit normal), used by the smoother's
//    shape guard (primal/smooth.hpp).
// The Hessian of D is the constant-free block matrix with (a, b) = -[c]x, (a, c) = [b]x,
// (b, c) = -[a]x ([v]x the cross-product matrix) and zero diagonal blocks; q = D P with
// P = 1 / (|a| |b| |c|) has  H_q = P H_D + gD gP^T + gP gD^T + D H_P, where
// H_P(a, a) = P (3 a a^T / |a|^4 - I / |a|^2) and H_P(a, b) = P a b^T / (|a|^2 |b|^2).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace geode::primal {

using FrameVector = Eigen::Matrix<double, 9, 1>;
using FrameMatrix = Eigen::Matrix<double, 9, 9>;

inline Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// D = det[a, b, c]; grad and hess (either may be null) with respect to (a, b, c).
inline double determinant_derivatives(const FrameVector& v, FrameVector* grad, FrameMatrix* hess) {
  const Eigen::Vector3d a = v.segment<3>(0), b = v.segment<3>(3), c = v.segment<3>(6);
  const Eigen::Vector3d bc = b.cross(c);
  if (grad) *grad << bc, c.cross(a), a.cross(b);
  if (hess) {
    hess->setZero();
    const Eigen::Matrix3d ab = -cross_matrix(c), ac = cross_matrix(b), bcm = -cross_matrix(a);
    hess->block<3, 3>(0, 3) = ab, hess->block<3, 3>(3, 0) = ab.transpose();
    hess->block<3, 3>(0, 6) = ac, hess->block<3, 3>(6, 0) = ac.transpose();
    hess->block<3, 3>(3, 6) = bcm, hess->block<3, 3>(6, 3) = bcm.transpose();
  }
  return a.dot(bc);
}

// A measure's value 0 and zero derivatives, where it is undefined (a zero column or frame).
inline double zero_derivatives(FrameVector* grad, FrameMatrix* hess) {
  if (grad) grad->setZero();
  if (hess) hess->setZero();
  return 0.0;
}

// q = det[a, b, c] / (|a| |b| |c|); grad and hess (either may be null).
inline double scaled_determinant_derivatives(const FrameVector& v, FrameVector* grad,
                                             FrameMatrix* hess) {
  const double len[3] = {v.segment<3>(0).norm(), v.segment<3>(3).norm(), v.segment<3>(6).norm()};
  if (!(len[0] > 0.0 && len[1] > 0.0 && len[2] > 0.0)) return zero_derivatives(grad, hess);
  FrameVector gd;
  FrameMatrix hd;
  const double d = determinant_derivatives(v, grad || hess ? &gd : nullptr, hess ? &hd : nullptr);
  const double p = 1.0 / (len[0] * len[1] * len[2]);
  if (!grad && !hess) return d * p;
  FrameVector gp;
  for (int i = 0; i < 3; ++i) gp.segment<3>(3 * i) = -p * v.segment<3>(3 * i) / (len[i] * len[i]);
  if (grad) *grad = p * gd + d * gp;
  if (hess) {
    FrameMatrix hp;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d u = v.segment<3>(3 * i);
      const double l2 = len[i] * len[i];
      hp.block<3, 3>(3 * i, 3 * i) =
          p * (3.0 * u * u.transpose() / (l2 * l2) - Eigen::Matrix3d::Identity() / l2);
      for (int j = 0; j < 3; ++j) {
        if (j == i) continue;
        const Eigen::Vector3d w = v.segment<3>(3 * j);
        hp.block<3, 3>(3 * i, 3 * j) = p * u * w.transpose() / (l2 * len[j] * len[j]);
      }
    }
    *hess = p * hd + gd * gp.transpose() + gp * gd.transpose() + d * hp;
  }
  return d * p;
}

// Corner shape s = N(D) / S of dimension `dim`: 3 gives N = 3 sgn(D) |D|^(2/3) and
// S = |a|^2 + |b|^2 + |c|^2; 2 gives N = 2 D and S = |a|^2 + |b|^2 (c, the plane normal, enters
// through D only). 0 with zero derivatives when S = 0. In 3D N'(D) = 2 |D|^(-1/3) is unbounded at
// D = 0, taken as 0 there (a smoother reaches the shape phase only with every D > 0). With R = 1/S:
//   grad s = R N' gD - s gS / S,
//   H_s = R (N'' gD gD^T + N' H_D) + gN gR^T + gR gN^T + N (2 gS gS^T / S^3 - H_S / S^2),
// where gS = 2 (a, b, c) over the dim columns counted, H_S = 2 I on them, gR = -gS / S^2.
inline double corner_shape_derivatives(const FrameVector& v, int dim, FrameVector* grad,
                                       FrameMatrix* hess) {
  const double sum = v.head(3 * dim).squaredNorm();
  if (!(sum > 0.0)) return zero_derivatives(grad, hess);
  FrameVector gd;
  FrameMatrix hd;
  const double d = determinant_derivatives(v, grad || hess ? &gd : nullptr, hess ? &hd : nullptr);
  const bool three = dim == 3;
  const double root = std::cbrt(std::abs(d));
  const double num = three ? 3.0 * std::copysign(root * root, d) : 2.0 * d;
  const double s = num / sum;
  if (!grad && !hess) return s;
  const double dnum = three ? (root > 0.0 ? 2.0 / root : 0.0) : 2.0;
  FrameVector gs = 2.0 * v;
  if (!three) gs.segment<3>(6).setZero();
  if (grad) *grad = (dnum / sum) * gd - (s / sum) * gs;
  if (hess) {
    const double ddnum = three && root > 0.0
                             ? -2.0 / 3.0 * std::copysign(1.0, d) / (root * root * root * root)
                             : 0.0;
    const FrameVector gn = dnum * gd, gr = -gs / (sum * sum);
    FrameMatrix hs = FrameMatrix::Zero();
    hs.diagonal().head(3 * dim).setConstant(2.0);
    *hess = (ddnum * gd * gd.transpose() + dnum * hd) / sum + gn * gr.transpose() +
            gr * gn.transpose() +
            num * (2.0 * gs * gs.transpose() / (sum * sum * sum) - hs / (sum * sum));
  }
  return s;
}

}  // namespace geode::primal
