// stereo_sgbm_time: the time of one full-frame OpenCV StereoSGBM disparity of each pair of a KITTI
// odometry folder, the machine's yardstick for the stereo frame (bench/stereo_time.sh prints our
// whole frame as a ratio to it). KITTI parameters: 128 disparities, block 5, MODE_SGBM_3WAY, the
// rest OpenCV's suggestions as the front end's matcher takes them (P1 = 8 * 25, P2 = 32 * 25,
// disp12MaxDiff 1, preFilterCap 63, uniqueness 10, speckles 100 / 2). Only compute() is timed:
// the pairs are decoded before, and the disparity is left in OpenCV's fixed point. Pair `first`
// only warms OpenCV's buffers (as cvo_run_sequence's first frame only seeds the next), the
// others are timed: the same pairs as the runner's `total`.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <iomanip>
#include <iostream>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/tools/command_line.hpp"
#include "cvo_odometry/tools/stage_timer.hpp"

namespace {

const char* kUsage =
    "usage: stereo_sgbm_time --kitti DIR [--first N] [--last N] [--stride N]\n"
    "  times StereoSGBM::compute (128 disparities, block 5, MODE_SGBM_3WAY) on every pair of the\n"
    "  range but the first; prints the median and p95 wall time and CPU time\n"
    "  (all threads) in ms, as 'sgbm <median> <p95>' and 'sgbm cpu <median> <p95>'.\n";

}  // namespace

int main(int argc, char** argv) {
  try {
    const cvo::CommandLine cli(argc, argv, {"kitti", "first", "last", "stride"}, {"help"});
    if (cli.has("help")) {
      std::cout << kUsage;
      return 0;
    }
    const cvo::KittiSequence sequence(cli.require("kitti"), 0, "");
    if (sequence.size() < 2) throw std::invalid_argument("need at least two pairs");
    const int first = cli.getInt("first", 0);
    const int last = std::min(cli.getInt("last", static_cast<int>(sequence.size()) - 1),
                              static_cast<int>(sequence.size()) - 1);
    const int stride = cli.getInt("stride", 1);
    if (first < 0 || last <= first || stride < 1) {
      throw std::invalid_argument("--first, --last, --stride: need first < last, stride >= 1");
    }
    const int block = 5, area = block * block;
    const cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
        0, 128, block, 8 * area, 32 * area, 1, 63, 10, 100, 2, cv::StereoSGBM::MODE_SGBM_3WAY);
    cvo::StageTimer timer;  // the runner's percentiles
    std::size_t pairs = 0;
    cv::Mat left, right, unused, disparity;
    for (int k = first; k <= last; k += stride) {
      sequence.load(static_cast<std::size_t>(k), &left, &right, &unused);
      const std::clock_t cpu_start = std::clock();
      const auto start = std::chrono::steady_clock::now();
      sgbm->compute(left, right, disparity);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      const double cpu_ms =
          1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
      if (k == first) continue;  // warms the buffers
      timer.add("sgbm", ms);
      timer.add("cpu", cpu_ms);
      ++pairs;
    }
    std::cout << std::fixed << std::setprecision(2) << "pairs " << pairs << " ("
              << left.cols << "x" << left.rows << ", " << cv::getNumThreads()
              << " OpenCV threads)\n"
              << "sgbm " << timer.percentile("sgbm", 0.5) << " " << timer.percentile("sgbm", 0.95)
              << "\n"
              << "sgbm cpu " << timer.percentile("cpu", 0.5) << " " << timer.percentile("cpu", 0.95)
              << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "stereo_sgbm_time: " << e.what() << "\n";
    return 1;
  }
}
