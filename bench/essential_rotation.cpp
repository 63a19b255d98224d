// essential_rotation: is the ground truth's rotation between KITTI frames right? A third
// estimator, independent of depth, stereo calibration and CVO: corners of left image k tracked
// into left image k + stride (pyramidal Lucas-Kanade, forward-backward check), the essential
// matrix by five-point RANSAC and the rotation from it. Prints, per frame pair, the angle by which
// it and an estimated trajectory (optional, KITTI format, one pose per strided frame) differ from
// the ground truth and from each other, each about the camera's axes, then the rms over the pairs
// and over the pairs from --from on. Where the essential matrix and the estimate agree with each
// other but not with the ground truth, the ground truth is the odd one out.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/color_features.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace {

const char* kUsage =
    "usage: essential_rotation --kitti DIR [--stride N] [--estimate FILE] [--from K]\n"
    "  DIR holds calib.txt, times.txt, poses.txt and image_0 (KITTI odometry layout)\n"
    "  --estimate FILE   a trajectory in KITTI format of frames 0, N, 2N, ... (cvo_run_sequence\n"
    "                    --stride N --out FILE)\n"
    "  --from K          also the rms over the pairs that start at frame K or later\n";

// Rotation (current <- next) from the essential matrix of tracked corners, or none.
bool essentialRotation(const cv::Mat& current, const cv::Mat& next, const cv::Matx33d& camera,
                       Eigen::Matrix3d* current_from_next, int* inliers) {
  std::vector<cv::Point2f> corners, tracked, back;
  cv::goodFeaturesToTrack(current, corners, 2000, 0.01, 8);
  std::vector<unsigned char> found, found_back;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(current, next, corners, tracked, found, error, cv::Size(21, 21), 4);
  cv::calcOpticalFlowPyrLK(next, current, tracked, back, found_back, error, cv::Size(21, 21), 4);
  std::vector<cv::Point2f> a, b;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    if (found[i] && found_back[i] && cv::norm(back[i] - corners[i]) < 0.5) {
      a.push_back(corners[i]);
      b.push_back(tracked[i]);
    }
  }
  if (a.size() < 8) return false;
  cv::Mat mask;
  const cv::Mat E = cv::findEssentialMat(a, b, camera, cv::RANSAC, 0.999, 0.5, mask);
  if (E.rows != 3 || E.cols != 3) return false;
  cv::Mat R, t;
  *inliers = cv::recoverPose(E, a, b, camera, R, t, mask);
  Eigen::Matrix3d next_from_current;  // x_next = R x_current + t
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      next_from_current(r, c) = R.at<double>(r, c);
  }
  *current_from_next = next_from_current.transpose();
  return *inliers >= 8;
}

// The rotation taking `from` to `to`, as a rotation vector in degrees.
Eigen::Vector3d differenceDeg(const Eigen::Matrix3d& from, const Eigen::Matrix3d& to) {
  return cvo::lie::logSO3(from.transpose() * to) * 180.0 / M_PI;
}

struct Rms {
  double sum = 0.0;
  int count = 0;
  void add(double v) { sum += v * v, ++count; }
  double value() const { return count ? std::sqrt(sum / count) : NAN; }
};

}  // namespace

int main(int argc, char** argv) {
  try {
    const cvo::CommandLine cli(argc, argv, {"kitti", "stride", "estimate", "from"}, {"help"});
    if (cli.has("help")) {
      std::cout << kUsage;
      return 0;
    }
    const std::string folder = cli.require("kitti");
    const int stride = cli.getInt("stride", 1);
    const int from = cli.getInt("from", 0);
    if (stride < 1) throw std::invalid_argument("--stride must be >= 1");
    const cvo::KittiSequence sequence(folder, 0, "");
    const cvo::Trajectory truth = cvo::readKittiTrajectory(folder + "/poses.txt");
    cvo::Trajectory estimate;
    if (cli.has("estimate")) estimate = cvo::readKittiTrajectory(cli.get("estimate"));
    const cvo::PinholeIntrinsics& K = sequence.calibration().left;
    const cv::Matx33d camera(K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
    const std::size_t frames = std::min(sequence.size(), truth.size());
    Rms essential_truth, estimate_truth, essential_estimate, late_essential, late_estimate;
    std::cout << std::fixed << std::setprecision(3)
              << "pair: ground-truth turn | essential - truth (x y z) | estimate - truth (x y z) "
                 "| essential - estimate, deg about the camera's axes\n";
    cv::Mat current, next, unused;
    sequence.load(0, &current, &unused, &unused);
    current = cvo::toGrey(current);
    for (std::size_t k = 0; k + stride < frames; k += stride) {
      sequence.load(k + stride, &next, &unused, &unused);
      next = cvo::toGrey(next);
      const Eigen::Matrix3d truth_turn =
          (truth[k].pose.inverse() * truth[k + stride].pose).linear();
      Eigen::Matrix3d essential_turn;
      int inliers = 0;
      const bool solved = essentialRotation(current, next, camera, &essential_turn, &inliers);
      current = next.clone();
      std::cout << std::setw(4) << k << ": " << cvo::lie::rotationAngle(truth_turn) * 180.0 / M_PI;
      if (!solved) {
        std::cout << " | no essential matrix\n";
        continue;
      }
      const Eigen::Vector3d e = differenceDeg(truth_turn, essential_turn);
      essential_truth.add(e.norm());
      if (static_cast<int>(k) >= from) late_essential.add(e.norm());
      std::cout << " | " << e.norm() << " (" << e.transpose() << ")";
      const std::size_t index = k / stride;
      if (index + 1 < estimate.size()) {
        const Eigen::Matrix3d estimate_turn =
            (estimate[index].pose.inverse() * estimate[index + 1].pose).linear();
        const Eigen::Vector3d d = differenceDeg(truth_turn, estimate_turn);
        const double apart = differenceDeg(estimate_turn, essential_turn).norm();
        estimate_truth.add(d.norm());
        essential_estimate.add(apart);
        if (static_cast<int>(k) >= from) late_estimate.add(d.norm());
        std::cout << " | " << d.norm() << " (" << d.transpose() << ") | " << apart;
      }
      std::cout << " | " << inliers << " inliers\n";
    }
    std::cout << "rms over " << essential_truth.count << " pairs: essential - truth "
              << essential_truth.value();
    if (estimate_truth.count) {
      std::cout << ", estimate - truth " << estimate_truth.value() << ", essential - estimate "
                << essential_estimate.value();
    }
    std::cout << " deg\n";
    if (from > 0) {
      std::cout << "rms over the " << late_essential.count << " pairs from frame " << from
                << ": essential - truth " << late_essential.value();
      if (late_estimate.count) std::cout << ", estimate - truth " << late_estimate.value();
      std::cout << " deg\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "essential_rotation: " << e.what() << "\n";
    return 1;
  }
}
