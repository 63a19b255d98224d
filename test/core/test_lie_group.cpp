#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvo_odometry/core/lie_group.hpp"

using cvo::Vector6d;
namespace lie = cvo::lie;

namespace {

Eigen::Matrix4d twistHat(const Vector6d& xi) {
  Eigen::Matrix4d X = Eigen::Matrix4d::Zero();
  X.topLeftCorner<3, 3>() = lie::hat(xi.head<3>());
  X.topRightCorner<3, 1>() = xi.tail<3>();
  return X;
}

Eigen::Matrix4d matrixExp(const Eigen::Matrix4d& X) {
  // Scaling and squaring with a long Taylor series: an independent reference for expSE3.
  Eigen::Matrix4d A = X / 1024.0, term = Eigen::Matrix4d::Identity(), sum = term;
  for (int k = 1; k < 30; ++k) {
    term = term * A / k;
    sum += term;
  }
  for (int k = 0; k < 10; ++k)
    sum = sum * sum;
  return sum;
}

Vector6d randomTwist(std::mt19937& rng, double rot_scale, double trans_scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector6d xi;
  for (int k = 0; k < 3; ++k)
    xi[k] = rot_scale * u(rng);
  for (int k = 3; k < 6; ++k)
    xi[k] = trans_scale * u(rng);
  return xi;
}

}  // namespace

TEST(LieGroup, HatVeeAndCrossProduct) {
  const Eigen::Vector3d a(0.3, -1.2, 2.0), b(-0.7, 0.4, 1.1);
  EXPECT_TRUE((lie::hat(a) * b).isApprox(a.cross(b)));
  EXPECT_TRUE(lie::vee(lie::hat(a)).isApprox(a));
}

TEST(LieGroup, ExpSO3MatchesAngleAxis) {
  for (double angle : {1e-12, 1e-6, 1e-3, 0.5, 2.0, M_PI - 1e-4}) {
    const Eigen::Vector3d axis = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
    const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_LT((lie::expSO3(angle * axis) - expected).norm(), 1e-14) << "angle " << angle;
  }
}

TEST(LieGroup, LogSO3InvertsExpIncludingSmallAndNearPi) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double angle : {0.0, 1e-10, 1e-6, 1e-3, 0.1, 1.0, 3.0, M_PI - 1e-6, M_PI - 1e-9}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      const Eigen::Vector3d w = angle * axis;
      const Eigen::Vector3d back = lie::logSO3(lie::expSO3(w));
      // Near pi the rotation vector is defined up to sign; compare rotations there.
      EXPECT_LT((lie::expSO3(back) - lie::expSO3(w)).norm(), 1e-9) << "angle " << angle;
      if (angle < 3.0) {
        EXPECT_LT((back - w).norm(), 1e-9 * std::max(1.0, angle)) << "angle " << angle;
      }
    }
  }
}

TEST(LieGroup, ExpSE3MatchesMatrixExponential) {
  std::mt19937 rng(11);
  for (double rot : {0.0, 1e-9, 1e-4, 0.3, 2.5}) {
    for (int trial = 0; trial < 10; ++trial) {
      const Vector6d xi = randomTwist(rng, rot, 2.0);
      const Eigen::Matrix4d expected = matrixExp(twistHat(xi));
      EXPECT_LT((lie::expSE3(xi).matrix() - expected).norm(), 1e-10) << xi.transpose();
    }
  }
}

TEST(LieGroup, SmallAngleTranslationIsLinear) {
  // The reference implementation's small-angle branch was wrong: for omega -> 0, exp gives t = v.
  Vector6d xi;
  xi << 1e-12, -2e-12, 0.0, 0.4, -0.2, 0.1;
  EXPECT_LT((lie::expSE3(xi).translation() - xi.tail<3>()).norm(), 1e-12);
  xi.head<3>().setZero();
  EXPECT_LT((lie::expSE3(xi).translation() - xi.tail<3>()).norm(), 1e-15);
}

TEST(LieGroup, LogSE3InvertsExp) {
  std::mt19937 rng(13);
  for (double rot : {0.0, 1e-8, 0.01, 1.0, 3.0}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Vector6d xi = randomTwist(rng, rot, 3.0);
      if (xi.head<3>().norm() >= M_PI) continue;
      EXPECT_LT((lie::logSE3(lie::expSE3(xi)) - xi).norm(), 1e-9) << xi.transpose();
    }
  }
}

TEST(LieGroup, DerivativeOfExpIsTheHat) {
  std::mt19937 rng(17);
  const Vector6d xi = randomTwist(rng, 1.0, 1.0);
  const double h = 1e-6;
  const Eigen::Matrix4d numeric =
      (lie::expSE3(h * xi).matrix() - lie::expSE3(-h * xi).matrix()) / (2.0 * h);
  EXPECT_LT((numeric - twistHat(xi)).norm(), 1e-8);
}

TEST(LieGroup, LeftJacobianMatchesNumericalDifferentiation) {
  std::mt19937 rng(19);
  for (double rot : {1e-7, 0.4, 2.0}) {
    const Eigen::Vector3d w = randomTwist(rng, rot, 0.0).head<3>();
    const double h = 1e-6;
    Eigen::Matrix3d numeric;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d dw = Eigen::Vector3d::Zero();
      dw[k] = h;
      // exp(w + dw) exp(w)^-1 = exp(J_l(w) dw)
      const Eigen::Vector3d plus = lie::logSO3(lie::expSO3(w + dw) * lie::expSO3(w).transpose());
      const Eigen::Vector3d minus = lie::logSO3(lie::expSO3(w - dw) * lie::expSO3(w).transpose());
      numeric.col(k) = (plus - minus) / (2.0 * h);
    }
    EXPECT_LT((numeric - lie::leftJacobianSO3(w)).norm(), 1e-8) << "rot " << rot;
    EXPECT_LT(
        (lie::leftJacobianSO3(w) * lie::leftJacobianInverseSO3(w) - Eigen::Matrix3d::Identity())
            .norm(),
        1e-12);
  }
}

TEST(LieGroup, AdjointConjugatesTwists) {
  std::mt19937 rng(23);
  const Eigen::Isometry3d T = lie::expSE3(randomTwist(rng, 1.5, 2.0));
  const Vector6d xi = randomTwist(rng, 0.7, 1.0);
  const Eigen::Matrix4d lhs = lie::expSE3(lie::adjoint(T) * xi).matrix();
  const Eigen::Matrix4d rhs = (T * lie::expSE3(xi) * T.inverse()).matrix();
  EXPECT_LT((lhs - rhs).norm(), 1e-12);
}

TEST(LieGroup, OrthonormalizedRemovesDrift) {
  Eigen::Isometry3d T = lie::expSE3((Vector6d() << 0.2, 0.1, -0.3, 1, 2, 3).finished());
  T.linear() *= 1.001;
  const Eigen::Isometry3d fixed = lie::orthonormalized(T);
  EXPECT_LT((fixed.linear() * fixed.linear().transpose() - Eigen::Matrix3d::Identity()).norm(),
            1e-14);
  EXPECT_TRUE(fixed.translation().isApprox(T.translation()));
}
