// The core on real data: clouds exported from TUM fr1_xyz frames 10 and 11 by the front end
// (test/data/tum_clouds, see test/data/README.md), with ground truth from groundtruth.txt.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "cvo_odometry/core/cloud_io.hpp"
#include "cvo_odometry/core/cvo_registration.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"

namespace {

const std::string kData = CVO_TEST_DATA_DIR;

// Depth stamp of frame `index` of the fixture (associations.txt: rgb stamp, file, depth stamp).
double depthStamp(int index) {
  std::ifstream in(kData + "/tum_fr1_xyz/associations.txt");
  std::string line;
  for (int k = 0; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (k++ == index) {
      std::istringstream ss(line);
      std::string rgb_stamp, rgb_file;
      double depth_stamp = 0.0;
      ss >> rgb_stamp >> rgb_file >> depth_stamp;
      return depth_stamp;
    }
  }
  throw std::runtime_error("no frame " + std::to_string(index));
}

// Ground-truth motion target (frame 10) <- source (frame 11), camera frames.
Eigen::Isometry3d groundTruthMotion() {
  const auto gt = cvo::readTumTrajectory(kData + "/tum_fr1_xyz/groundtruth.txt");
  Eigen::Isometry3d g10, g11;
  EXPECT_TRUE(gt.interpolate(depthStamp(10), 0.02, &g10));
  EXPECT_TRUE(gt.interpolate(depthStamp(11), 0.02, &g11));
  return g10.inverse() * g11;
}

cvo::CvoParams tumParams(bool color) {
  cvo::CvoParams p;
  p.backend = cvo::BackendChoice::kCpu;
  p.use_color = color;
  return p;
}

Eigen::Isometry3d perturbed(const Eigen::Isometry3d& T, const Eigen::Vector3d& shift,
                            double yaw_deg) {
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.translation() = shift;
  D.linear() =
      Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return D * T;
}

}  // namespace

TEST(RealTum, IndicatorPeaksAtGroundTruthAndFallsWithPerturbation) {
  const auto target = cvo::readCloud(kData + "/tum_clouds/frame10_3000.cloud");
  const auto source = cvo::readCloud(kData + "/tum_clouds/frame11_3000.cloud");
  const Eigen::Isometry3d truth = groundTruthMotion();
  for (bool color : {false, true}) {
    cvo::CvoRegistration registration(tumParams(color));
    const double ell = 0.05;
    const double at_truth = registration.indicator(target, source, truth, ell);
    double previous = at_truth;
    for (double cm : {1.0, 2.0, 4.0, 8.0}) {
      const double moved =
          registration.indicator(target, source, perturbed(truth, {cm / 100, 0, 0}, 0), ell);
      EXPECT_LT(moved, previous) << "colour " << color << ", " << cm << " cm";
      previous = moved;
    }
    previous = at_truth;
    for (double deg : {1.0, 2.0, 4.0, 8.0}) {
      const double turned = registration.indicator(
          target, source, perturbed(truth, Eigen::Vector3d::Zero(), deg), ell);
      EXPECT_LT(turned, previous) << "colour " << color << ", " << deg << " deg";
      previous = turned;
    }
    const double cosine = registration.cosine(target, source, truth, ell);
    EXPECT_GT(cosine, registration.cosine(target, source, perturbed(truth, {0.04, 0, 0}, 0), ell));
    EXPECT_GT(cosine, 0.0);
    EXPECT_LE(cosine, 1.0);
  }
}

TEST(RealTum, RegistrationLandsWithinACentimetreAndHalfADegree) {
  const Eigen::Isometry3d truth = groundTruthMotion();
  for (const char* size : {"3000", "8000"}) {
    const auto target = cvo::readCloud(kData + "/tum_clouds/frame10_" + size + ".cloud");
    const auto source = cvo::readCloud(kData + "/tum_clouds/frame11_" + size + ".cloud");
    for (bool color : {false, true}) {
      for (auto method : {cvo::StepMethod::kProcrustes, cvo::StepMethod::kReference}) {
        if (method == cvo::StepMethod::kReference && std::string(size) != "3000") continue;
        cvo::CvoParams params = tumParams(color);
        params.step_method = method;
        cvo::CvoRegistration registration(params);
        const auto result = registration.align(target, source, Eigen::Isometry3d::Identity());
        const Eigen::Isometry3d error = truth.inverse() * result.transform;
        const std::string what =
            std::string(size) + (color ? " colour " : " geometric ") + cvo::toString(method);
        EXPECT_TRUE(result.report.converged) << what << ": " << result.report.message;
        EXPECT_LT(error.translation().norm(), 0.01) << what;
        EXPECT_LT(cvo::lie::rotationAngle(error.linear()) * 180.0 / M_PI, 0.5) << what;
        EXPECT_GT(result.report.indicator_after, result.report.indicator_before) << what;
      }
    }
  }
}

TEST(RealTum, SourceBudgetKeepsThePoseAndScalesTheSums) {
  // 8000 points a frame; the registration sums over 2000 of the source's against all 8000 of the
  // target's. The pose stays (the target's function is as dense as before) and the indicators
  // and self products, scaled to the whole source, estimate the full sums.
  const auto target = cvo::readCloud(kData + "/tum_clouds/frame10_8000.cloud");
  const auto source = cvo::readCloud(kData + "/tum_clouds/frame11_8000.cloud");
  const Eigen::Isometry3d truth = groundTruthMotion();
  cvo::CvoParams all = tumParams(false);
  all.max_source_points = 0;
  cvo::CvoParams budget = all;
  budget.max_source_points = 2000;
  ASSERT_GT(source.size(), 3u * 2000u);
  cvo::CvoRegistration full(all), sampled(budget);
  // From a guess 1 cm and 1 deg off, at ell_min throughout (as from a confident feature prior).
  const Eigen::Isometry3d guess = perturbed(truth, {0.01, 0.0, 0.0}, 1.0);
  const auto a = full.align(target, source, guess, false, all.ell_min);
  const auto b = sampled.align(target, source, guess, false, all.ell_min);
  ASSERT_TRUE(a.report.converged && b.report.converged);
  const Eigen::Isometry3d apart = a.transform.inverse() * b.transform;
  EXPECT_LT(apart.translation().norm(), 0.002);
  EXPECT_LT(cvo::lie::rotationAngle(apart.linear()) * 180.0 / M_PI, 0.1);
  const Eigen::Isometry3d error = truth.inverse() * b.transform;
  EXPECT_LT(error.translation().norm(), 0.01);
  EXPECT_NEAR(b.report.indicator_after / a.report.indicator_after, 1.0, 0.05);
  EXPECT_NEAR(b.report.indicator_before / a.report.indicator_before, 1.0, 0.05);
  const double ell = all.ell_min;
  // The self product's sample (1000 points, below either budget) against the exact sum.
  const double exact = full.innerProduct(source, source, Eigen::Isometry3d::Identity(), ell);
  EXPECT_NEAR(sampled.selfProduct(source, ell) / exact, 1.0, 0.05);
  // A quarter of the source: about a quarter of the pairs an iteration.
  EXPECT_NEAR(b.report.mean_pairs / a.report.mean_pairs, 0.25, 0.05);
}

TEST(RealTum, ThinnedCloudSpreadsItsPointsEvenly) {
  const auto cloud = cvo::readCloud(kData + "/tum_clouds/frame10_3000.cloud");
  const auto thinned = cloud.thinned(1000);
  ASSERT_EQ(thinned.size(), 1000u);
  for (std::size_t k = 0; k < thinned.size(); ++k) {
    ASSERT_EQ(thinned.position(k), cloud.position(k * cloud.size() / 1000)) << k;
  }
  EXPECT_EQ(cloud.thinned(cloud.size() + 5).size(), cloud.size());
}

// The registration's coarse levels reuse one cloud's storage from level to level and frame to
// frame: each refill must hold exactly the points and features of a fresh copy, whatever it held.
TEST(RealTum, CloudsRefilledInPlaceEqualFreshCopies) {
  const auto cloud = cvo::readCloud(kData + "/tum_clouds/frame10_3000.cloud");
  ASSERT_TRUE(cloud.hasColor());
  const auto same = [](const cvo::LabeledCloud& a, const cvo::LabeledCloud& b) {
    return a.positionData() == b.positionData() && a.colorData() == b.colorData() &&
           a.semanticData() == b.semanticData() && a.hasColor() == b.hasColor() &&
           a.semanticClasses() == b.semanticClasses();
  };
  cvo::LabeledCloud reused;
  for (const std::size_t stride : {5, 2, 7, 1, 3}) {
    cloud.stridedInto(stride, reused);
    EXPECT_TRUE(same(reused, cloud.strided(stride))) << "stride " << stride;
    EXPECT_EQ(reused.size(), (cloud.size() + stride - 1) / stride);
  }
  for (const std::size_t count : {700, 2500, 10, 1000}) {
    cloud.thinnedInto(count, reused);
    EXPECT_TRUE(same(reused, cloud.thinned(count))) << "count " << count;
  }
  // A cloud without colour into storage that held colour.
  cvo::LabeledCloud grey(false);
  for (std::size_t i = 0; i < 20; ++i)
    grey.add(cloud.position(i));
  grey.stridedInto(3, reused);
  EXPECT_FALSE(reused.hasColor());
  EXPECT_TRUE(reused.colorData().empty());
  EXPECT_EQ(reused.size(), 7u);
}

// A new depth for every point (a stereo rig's disparity offset changed): each point stays on its
// ray (the same pixel), its features and the image kept; points left without a depth dropped.
TEST(RealTum, CloudWithNewDepthsKeepsEachPointOnItsRay) {
  auto cloud = cvo::readCloud(kData + "/tum_clouds/frame10_3000.cloud");
  cloud.setImage(std::make_shared<const cvo::IntensityImage>(
      3, 3, cvo::CameraModel{},
      std::vector<cvo::IntensityImage::Level>{{0.0, std::vector<float>(9)}}));
  const float far = 1.5f;  // beyond it, no depth
  const auto moved =
      cloud.withDepths([&](float z) { return z < far ? 2.0f * z + 0.1f : std::nanf(""); });
  EXPECT_EQ(moved.image(), cloud.image());
  ASSERT_EQ(moved.hasColor(), cloud.hasColor());
  std::size_t k = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f p = cloud.position(i);
    if (!(p.z() < far)) continue;
    ASSERT_LT(k, moved.size());
    const Eigen::Vector3f q = moved.position(k);
    EXPECT_NEAR(q.z(), 2.0f * p.z() + 0.1f, 1e-5f) << i;
    EXPECT_NEAR(q.x() / q.z(), p.x() / p.z(), 1e-6f) << i;
    EXPECT_NEAR(q.y() / q.z(), p.y() / p.z(), 1e-6f) << i;
    if (cloud.hasColor()) {
      for (int c = 0; c < cvo::LabeledCloud::kColorDim; ++c)
        ASSERT_EQ(moved.color(k)[c], cloud.color(i)[c]) << i;
    }
    ++k;
  }
  EXPECT_EQ(k, moved.size());
  EXPECT_GT(k, 100u);
  EXPECT_LT(k, cloud.size()) << "some points are beyond 1.5 m";
}

TEST(RealTum, IndicatorAtTheGuessIsTheSameWhereverItComesFrom) {
  // From ell_min (a confident prior) the first iteration's sum is the indicator at the guess;
  // from ell_init it is a sum of its own at the final lengthscale. Both equal the indicator
  // computed on its own.
  const auto target = cvo::readCloud(kData + "/tum_clouds/frame10_3000.cloud");
  const auto source = cvo::readCloud(kData + "/tum_clouds/frame11_3000.cloud");
  const Eigen::Isometry3d guess = perturbed(groundTruthMotion(), {0.005, 0.0, 0.0}, 0.5);
  cvo::CvoParams params = tumParams(false);
  params.max_source_points = 0;
  cvo::CvoRegistration registration(params);
  for (double start : {params.ell_min, params.ell_init}) {
    const auto result = registration.align(target, source, guess, false, start);
    const double ell = result.report.final_lengthscale;
    EXPECT_EQ(ell, params.ell_min);
    const double alone = registration.indicator(target, source, guess, ell);
    EXPECT_NEAR(result.report.indicator_before / alone, 1.0, 1e-5) << "from " << start;
  }
}

TEST(RealTum, CosineOfACloudWithItselfIsOneAboveTheSourceBudget) {
  // 8000 points, twice the default budget: cosine() sums over every point, so the cloud's
  // function with itself gives exactly 1, and the estimate the odometry uses is close to it.
  const auto cloud = cvo::readCloud(kData + "/tum_clouds/frame10_8000.cloud");
  cvo::CvoParams params = tumParams(false);
  ASSERT_GT(cloud.size(), static_cast<std::size_t>(params.max_source_points));
  cvo::CvoRegistration registration(params);
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  EXPECT_NEAR(registration.cosine(cloud, cloud, I, params.ell_min), 1.0, 1e-9);
  const double exact = registration.innerProduct(cloud, cloud, I, params.ell_min);
  EXPECT_NEAR(registration.selfProduct(cloud, params.ell_min) / exact, 1.0, 0.05);
}
