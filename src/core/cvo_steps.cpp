#include "cvo_odometry/core/cvo_steps.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include <Eigen/Cholesky>
#include <Eigen/SVD>

namespace cvo {

Vector6d objectiveGradient(const kernels::MomentSums& m, double ell) {
  // d/dxi exp(-|x - exp(xi) z|^2 / 2 ell^2) = a / ell^2 [z x x; x - z].
  const double* M = m.cross;  // sum a x z^T, M(r, c) = M[3 r + c]
  Vector6d g;
  g << M[3 * 2 + 1] - M[3 * 1 + 2], M[3 * 0 + 2] - M[3 * 2 + 0], M[3 * 1 + 0] - M[3 * 0 + 1],
      m.target[0] - m.source[0], m.target[1] - m.source[1], m.target[2] - m.source[2];
  return g / (ell * ell);
}

Eigen::Isometry3d weightedProcrustes(const kernels::MomentSums& m) {
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  if (m.pairs < 3 || !(m.weight > 0.0)) return D;
  const Eigen::Vector3d x_mean = Eigen::Vector3d(m.target[0], m.target[1], m.target[2]) / m.weight;
  const Eigen::Vector3d z_mean = Eigen::Vector3d(m.source[0], m.source[1], m.source[2]) / m.weight;
  const Eigen::Matrix3d cross =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.cross);
  // Covariance of (z, x): H = sum a (z - z_mean)(x - x_mean)^T; R = V S U^T.
  const Eigen::Matrix3d H = cross.transpose() - m.weight * z_mean * x_mean.transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0) S(2, 2) = -1.0;
  D.linear() = svd.matrixV() * S * svd.matrixU().transpose();
  D.translation() = x_mean - D.linear() * z_mean;
  return D;
}

bool newtonStep(const kernels::CurvatureSums& c, double ell, Vector6d* step) {
  Eigen::Matrix<double, 6, 6> H;
  int slot = 0;
  for (int r = 0; r < 6; ++r) {
    for (int k = r; k < 6; ++k)
      H(r, k) = H(k, r) = c.hessian[slot++];
  }
  const Vector6d g = objectiveGradient(c.moments, ell);
  // H negative definite <=> -H has a Cholesky factorisation.
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(-H);
  if (llt.info() != Eigen::Success) return false;
  *step = llt.solve(g);
  return step->allFinite();
}

double smallestPositiveCubicRoot(double a, double b, double c, double d) {
  const double scale = std::max({std::abs(a), std::abs(b), std::abs(c), std::abs(d)});
  if (scale == 0.0) return -1.0;
  a /= scale;
  b /= scale;
  c /= scale;
  d /= scale;
  double roots[3];
  int count = 0;
  if (std::abs(a) < 1e-12) {
    if (std::abs(b) < 1e-12) {
      if (std::abs(c) > 0.0) roots[count++] = -d / c;
    } else {
      const double disc = c * c - 4.0 * b * d;
      if (disc >= 0.0) {
        const double q = -0.5 * (c + std::copysign(std::sqrt(disc), c));
        roots[count++] = q / b;
        if (q != 0.0) roots[count++] = d / q;
      }
    }
  } else {
    // Depressed cubic t = y - b/(3a): y^3 + p y + q = 0.
    const double bn = b / a, cn = c / a, dn = d / a;
    const double p = cn - bn * bn / 3.0;
    const double q = 2.0 * bn * bn * bn / 27.0 - bn * cn / 3.0 + dn;
    const double shift = -bn / 3.0;
    const double disc = q * q / 4.0 + p * p * p / 27.0;
    if (disc > 0.0) {
      const double s = std::sqrt(disc);
      roots[count++] = std::cbrt(-q / 2.0 + s) + std::cbrt(-q / 2.0 - s) + shift;
    } else {
      const double r = std::sqrt(std::max(-p / 3.0, 0.0));
      const double arg = r > 0.0 ? std::clamp(-q / (2.0 * r * r * r), -1.0, 1.0) : 0.0;
      const double phi = std::acos(arg);
      for (int k = 0; k < 3; ++k)
        roots[count++] = 2.0 * r * std::cos((phi - 2.0 * M_PI * k) / 3.0) + shift;
    }
    // One Newton polish per root against cancellation.
    for (int k = 0; k < count; ++k) {
      const double t = roots[k];
      const double f = ((a * t + b) * t + c) * t + d;
      const double df = (3.0 * a * t + 2.0 * b) * t + c;
      if (df != 0.0) roots[k] = t - f / df;
    }
  }
  double best = -1.0;
  for (int k = 0; k < count; ++k) {
    if (roots[k] > 0.0 && (best < 0.0 || roots[k] < best)) best = roots[k];
  }
  return best;
}

double taylorStepLength(const kernels::TaylorSums& s, double min_step, double max_step) {
  // dF/dt = B + 2 C t + 3 D t^2 + 4 E t^3 = 0
  const double root = smallestPositiveCubicRoot(4.0 * s.e, 3.0 * s.d, 2.0 * s.c, s.b);
  if (root < 0.0) return max_step;
  return std::clamp(root, min_step, max_step);
}

}  // namespace cvo
