// The disparity offset's self-calibration on synthetic stereo tracks with a known offset: a
// KITTI-like rig (f 707 px, baseline 0.54 m), corners 5-50 m away, a car moving about 1 m a frame.
#include <random>

#include <gtest/gtest.h>

#include "cvo_odometry/core/disparity_offset_estimator.hpp"
#include "cvo_odometry/core/lie_group.hpp"

namespace {

constexpr double kFocal = 707.0;
constexpr double kFocalBaseline = 707.0 * 0.54;

struct TrackNoise {
  double pixel = 0.3;           // px, KLT
  double disparity = 0.3;       // px, the matcher
  double gross_fraction = 0.0;  // tracks whose disparity is off by 3-8 px (an occluding edge)
};

// Tracks of `count` corners under `motion` (second <- first) for a rig whose raw disparities are
// `true_offset` short of f b / z.
cvo::StereoTracks makeTracks(int count, const Eigen::Isometry3d& motion, double true_offset,
                             const TrackNoise& noise, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  cvo::StereoTracks tracks;
  while (static_cast<int>(tracks.size()) < count) {
    // Uniform in inverse depth between 5 and 50 m, anywhere in a 1241 x 376 image.
    const double z = 1.0 / (1.0 / 50.0 + unit(rng) * (1.0 / 5.0 - 1.0 / 50.0));
    const Eigen::Vector2d pixel0(unit(rng) * 1241.0 - 620.0, unit(rng) * 376.0 - 188.0);
    const Eigen::Vector3d p0(pixel0.x() / kFocal * z, pixel0.y() / kFocal * z, z);
    const Eigen::Vector3d p1 = motion * p0;
    if (p1.z() < 1.0 || std::abs(p1.x() / p1.z() * kFocal) > 620.0 ||
        std::abs(p1.y() / p1.z() * kFocal) > 188.0) {
      continue;
    }
    auto seen = [&](const Eigen::Vector3d& p) {
      return Eigen::Vector2d(p.x() / p.z() + noise.pixel * gauss(rng) / kFocal,
                             p.y() / p.z() + noise.pixel * gauss(rng) / kFocal);
    };
    auto disparity = [&](const Eigen::Vector3d& p) {
      double d = kFocalBaseline / p.z() - true_offset + noise.disparity * gauss(rng);
      if (unit(rng) < noise.gross_fraction)
        d += (unit(rng) < 0.5 ? -1.0 : 1.0) * (3.0 + 5.0 * unit(rng));
      return d;
    };
    tracks.push_back({seen(p0), seen(p1), disparity(p0), disparity(p1)});
  }
  return tracks;
}

Eigen::Isometry3d carStep(std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  cvo::Vector6d xi;
  xi << 0.002 * unit(rng), 0.01 * unit(rng), 0.002 * unit(rng),    // rad
      0.05 * unit(rng), 0.02 * unit(rng), -1.0 - 0.3 * unit(rng);  // m: forward
  return cvo::lie::expSE3(xi);
}

double runPairs(cvo::DisparityOffsetEstimator& estimator, int pairs, double true_offset,
                double current_offset, const TrackNoise& noise, unsigned seed) {
  std::mt19937 rng(seed);
  for (int k = 0; k < pairs; ++k) {
    const Eigen::Isometry3d motion = carStep(rng);
    const cvo::StereoTracks tracks = makeTracks(250, motion, true_offset, noise, rng);
    // The solve starts from a motion a little off, as the feature prior's is.
    Eigen::Isometry3d guess = motion;
    guess.translation() += Eigen::Vector3d(0.01, -0.01, 0.03);
    EXPECT_TRUE(estimator.addPair(tracks, guess, kFocal, kFocalBaseline, current_offset));
  }
  return estimator.estimate()->offset;
}

TEST(DisparityOffsetEstimator, RecoversAKnownOffsetFromAnyStart) {
  for (const double true_offset : {-0.4, 0.0, 0.3, 1.0}) {
    for (const double start : {0.0, 0.8}) {
      cvo::DisparityOffsetEstimator estimator;
      const double estimate = runPairs(estimator, 20, true_offset, start, TrackNoise{}, 7);
      EXPECT_NEAR(estimate, true_offset, 0.05) << "start " << start;
      EXPECT_TRUE(estimator.estimate()->trusted);
      EXPECT_LT(estimator.estimate()->standard_error, 0.05);
    }
  }
}

TEST(DisparityOffsetEstimator, GrossDisparityErrorsDoNotPullTheEstimate) {
  TrackNoise noise;
  noise.gross_fraction = 0.15;
  cvo::DisparityOffsetEstimator estimator;
  EXPECT_NEAR(runPairs(estimator, 20, 0.3, 0.0, noise, 11), 0.3, 0.06);
}

TEST(DisparityOffsetEstimator, LargerMotionsGiveTheSameOffset) {
  // At two and three times the step (a faster car, dropped frames) the estimate must not move:
  // the solve treats both frames' disparities as noisy, neither as exact.
  cvo::DisparityOffsetEstimator estimator;
  std::mt19937 rng(5);
  for (int k = 0; k < 20; ++k) {
    cvo::Vector6d xi = cvo::lie::logSE3(carStep(rng));
    const Eigen::Isometry3d motion = cvo::lie::expSE3(3.0 * xi);
    estimator.addPair(makeTracks(250, motion, 0.3, TrackNoise{}, rng), motion, kFocal,
                      kFocalBaseline, 0.0);
  }
  EXPECT_NEAR(estimator.estimate()->offset, 0.3, 0.05);
}

TEST(DisparityOffsetEstimator, TrustedOnlyAfterEnoughAgreeingPairs) {
  cvo::DisparityOffsetEstimator estimator;
  EXPECT_FALSE(estimator.estimate().has_value());
  const int min_pairs = cvo::DisparityOffsetOptions{}.min_pairs;
  runPairs(estimator, min_pairs - 1, 0.3, 0.0, TrackNoise{}, 3);
  EXPECT_EQ(estimator.estimate()->pairs, min_pairs - 1);
  EXPECT_FALSE(estimator.estimate()->trusted);  // fewer than min_pairs
  runPairs(estimator, 1, 0.3, 0.0, TrackNoise{}, 4);
  EXPECT_TRUE(estimator.estimate()->trusted);
  EXPECT_NEAR(estimator.estimate()->offset, 0.3, 0.1);
  // Pairs that disagree wildly (each rig's offset different) are never trusted.
  cvo::DisparityOffsetEstimator scattered;
  for (int k = 0; k < 20; ++k) {
    runPairs(scattered, 1, (k % 2 == 0) ? -1.0 : 1.5, 0.0, TrackNoise{}, 100 + k);
  }
  EXPECT_GT(scattered.estimate()->standard_error, 0.1);
  EXPECT_FALSE(scattered.estimate()->trusted);
  estimator.reset();
  EXPECT_FALSE(estimator.estimate().has_value());
}

TEST(DisparityOffsetEstimator, RefusesPairsThatCannotSay) {
  cvo::DisparityOffsetEstimator estimator;
  std::mt19937 rng(1);
  const Eigen::Isometry3d motion = carStep(rng);
  // Too few tracks.
  EXPECT_FALSE(estimator.addPair(makeTracks(10, motion, 0.3, TrackNoise{}, rng), motion, kFocal,
                                 kFocalBaseline, 0.0));
  // No motion: near and far points move alike, nothing tells the offset from the depth.
  const cvo::StereoTracks still =
      makeTracks(250, Eigen::Isometry3d::Identity(), 0.3, TrackNoise{}, rng);
  const auto solution =
      estimator.solvePair(still, Eigen::Isometry3d::Identity(), kFocal, kFocalBaseline, 0.0);
  EXPECT_TRUE(!solution || solution->information < 1.0);
  // Nonsense camera.
  EXPECT_FALSE(estimator.addPair(makeTracks(250, motion, 0.3, TrackNoise{}, rng), motion, 0.0,
                                 kFocalBaseline, 0.0));
  EXPECT_THROW(cvo::DisparityOffsetEstimator(cvo::DisparityOffsetOptions{0}),
               std::invalid_argument);
}

}  // namespace
