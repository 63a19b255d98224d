// registrationCovariance: symmetric positive definite, shrinking with more points and a smaller
// lengthscale, growing as the cosine falls, large for degenerate clouds.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Eigenvalues>

#include "cvo_odometry/core/registration_covariance.hpp"

namespace {

cvo::LabeledCloud randomCloud(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  cvo::LabeledCloud cloud(false);
  for (std::size_t i = 0; i < n; ++i)
    cloud.add(Eigen::Vector3f(u(rng), u(rng), 2.0f + u(rng)), nullptr);
  return cloud;
}

TEST(RegistrationCovariance, PositiveDefiniteAndScalesAsExpected) {
  const auto cloud = randomCloud(1000, 1);
  const auto T = Eigen::Isometry3d::Identity();
  const auto c = cvo::registrationCovariance(cloud, T, 0.05, 1.0);
  EXPECT_LT((c - c.transpose()).norm(), 1e-12 * c.norm());
  using Solver = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>;
  EXPECT_GT(Solver(c).eigenvalues().minCoeff(), 0.0);
  // Translation variance about ell^2 / n for n well-spread points.
  EXPECT_GT(c(0, 0), 0.2 * 0.05 * 0.05 / 1000);
  EXPECT_LT(c(0, 0), 20.0 * 0.05 * 0.05 / 1000);
  const auto more = cvo::registrationCovariance(randomCloud(4000, 2), T, 0.05, 1.0);
  EXPECT_LT(more.trace(), 0.5 * c.trace());
  EXPECT_NEAR(cvo::registrationCovariance(cloud, T, 0.1, 1.0).trace(), 4.0 * c.trace(),
              1e-9 * c.trace());
  EXPECT_NEAR(cvo::registrationCovariance(cloud, T, 0.05, 0.5).trace(), 2.0 * c.trace(),
              1e-9 * c.trace());
}

// The information from its ten sums is the sum of every point's J^T J, J = [I, -[T p]x].
TEST(RegistrationCovariance, IsTheInverseOfThePointsJacobianProducts) {
  const auto cloud = randomCloud(500, 3);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() << 0.3, -0.2, 1.5;
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = T * cloud.position(i).cast<double>();
    Eigen::Matrix<double, 3, 6> J;
    J.leftCols<3>().setIdentity();
    J.rightCols<3>() << 0, p.z(), -p.y(), -p.z(), 0, p.x(), p.y(), -p.x(), 0;
    information += J.transpose() * J;
  }
  const double ell = 0.05;
  const Eigen::Matrix<double, 6, 6> expected = (information / (ell * ell)).inverse();
  const auto c = cvo::registrationCovariance(cloud, T, ell, 1.0);
  EXPECT_LT((c - expected).norm(), 1e-9 * expected.norm()) << c << "\n\n" << expected;
}

TEST(RegistrationCovariance, DegenerateCloudsAreUnknown) {
  cvo::LabeledCloud line(false);
  for (int i = 0; i < 100; ++i)
    line.add(Eigen::Vector3f(0.01f * i, 0.0f, 2.0f), nullptr);  // rotation about the line is free
  const auto c = cvo::registrationCovariance(line, Eigen::Isometry3d::Identity(), 0.05, 1.0);
  EXPECT_GE(c(0, 0), 1e6);
  EXPECT_GE(cvo::registrationCovariance(randomCloud(2, 3), Eigen::Isometry3d::Identity(), 0.05,
                                        1.0)(0, 0),
            1e6);
}

}  // namespace
