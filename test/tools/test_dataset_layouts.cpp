// cvo_run_sequence on datasets laid out as their publishers ship them, made by the test from the
// fixtures: sparse ground truth, a KITTI folder with the wrong names and an unprefixed
// calib.txt, a 7-Scenes sequence, 320x240 images with a numeric camera, segmentation found
// below the dataset folder, and a wrong depth scale made visible.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "command_output.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

namespace fs = std::filesystem;
const fs::path kData = CVO_TEST_DATA_DIR;
const std::string kRunner = CVO_RUN_SEQUENCE;

using RunnerOutput = cvo_test::CommandOutput;

// The runner with `args`, from `cwd` (so relative paths are not resolved by chance).
RunnerOutput runner(const std::string& args, const fs::path& cwd = fs::temp_directory_path()) {
  return cvo_test::runCommand("cd '" + cwd.string() + "' && '" + kRunner +
                              "' --quiet --backend cpu " + args);
}

fs::path freshFolder(const std::string& name) {
  const fs::path folder = fs::path(testing::TempDir()) / ("cvo_layout_" + name);
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

// The first `frames` TUM frames as rgb.txt/depth.txt and images, optionally resized.
fs::path tumCopy(const std::string& name, std::size_t frames, cv::Size size = cv::Size()) {
  const fs::path folder = freshFolder(name);
  const cvo::TumSequence sequence((kData / "tum_fr1_xyz").string());
  fs::create_directories(folder / "rgb");
  fs::create_directories(folder / "depth");
  std::ofstream rgb(folder / "rgb.txt"), depth(folder / "depth.txt");
  for (std::size_t k = 0; k < frames; ++k) {
    const auto& f = sequence.frames()[k];
    cv::Mat image, d;
    sequence.load(k, &image, &d);
    if (size.area() > 0) {
      cv::resize(image, image, size, 0, 0, cv::INTER_AREA);
      cv::resize(d, d, size, 0, 0, cv::INTER_NEAREST);
    }
    const std::string rgb_name = fs::path(f.rgb_path).filename().string();
    const std::string depth_name = fs::path(f.depth_path).filename().string();
    cv::imwrite((folder / "rgb" / rgb_name).string(), image);
    cv::imwrite((folder / "depth" / depth_name).string(), d);
    rgb << std::fixed << std::setprecision(6) << f.rgb_stamp << " rgb/" << rgb_name << "\n";
    depth << std::fixed << std::setprecision(6) << f.depth_stamp << " depth/" << depth_name << "\n";
  }
  fs::copy_file(kData / "tum_fr1_xyz" / "groundtruth.txt", folder / "groundtruth.txt");
  return folder;
}

double reported(const std::string& output, const std::string& prefix, int field) {
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(prefix, 0) != 0) continue;
    std::istringstream words(line);
    std::string word;
    for (int k = 0; k <= field && words >> word;)
      ++k;
    return std::stod(word);
  }
  return -1.0;
}

TEST(DatasetLayouts, SparseGroundTruthIsMatchedToTheNearestSample) {
  const fs::path folder = tumCopy("sparse", 8);
  // One sample 6 ms after each frame, as a slow motion-capture export gives: every pose has a
  // sample near it, but never two within --max-gap to interpolate between.
  const cvo::Trajectory dense = cvo::readTumTrajectory((folder / "groundtruth.txt").string());
  const cvo::TumSequence sequence(folder.string());
  cvo::Trajectory sparse;
  for (const auto& frame : sequence.frames()) {
    const long k = dense.nearest(frame.depth_stamp + 0.006, 0.01);
    ASSERT_GE(k, 0);
    if (!sparse.empty() && sparse[sparse.size() - 1].stamp >= dense[k].stamp) continue;
    sparse.append(dense[static_cast<std::size_t>(k)].stamp,
                  dense[static_cast<std::size_t>(k)].pose);
  }
  cvo::writeTrajectory((folder / "sparse.txt").string(), sparse, cvo::TrajectoryFormat::kTum);
  const std::string args = "--tum " + folder.string() + " --gt " + (folder / "sparse.txt").string();
  const RunnerOutput interpolate = runner(args);
  EXPECT_EQ(interpolate.status, 0) << interpolate.output;
  EXPECT_NE(interpolate.output.find("to the nearest sample within"), std::string::npos)
      << interpolate.output;
  EXPECT_EQ(reported(interpolate.output, "poses:", 1), reported(interpolate.output, "poses:", 3))
      << "every pose associated: " << interpolate.output;
  const RunnerOutput nearest = runner(args + " --association nearest");
  EXPECT_EQ(nearest.status, 0) << nearest.output;
  EXPECT_NE(nearest.output.find("ATE rmse"), std::string::npos);
}

TEST(DatasetLayouts, AnIncompleteKittiFolderIsReportedAtOnceAndTheUnprefixedCalibAccepted) {
  const fs::path kitti = kData / "kitti_06_stereo";
  const fs::path folder = freshFolder("kitti");
  fs::copy(kitti / "image_0", folder / "image_l", fs::copy_options::recursive);
  fs::copy(kitti / "image_1", folder / "image_r", fs::copy_options::recursive);
  // calib.txt as some tools write it: the two projection rows without their P0:/P1: prefixes.
  {
    std::ifstream in(kitti / "calib.txt");
    std::ofstream out(folder / "calib.txt");
    std::string line;
    for (int k = 0; k < 2 && std::getline(in, line); ++k)
      out << line.substr(line.find(':') + 2) << "\n";
  }
  const RunnerOutput broken = runner("--kitti " + folder.string());
  EXPECT_EQ(broken.status, 2);
  for (const char* expected : {"times.txt", "image_0/000000.png", "image_1/000000.png", "image_l/"})
    EXPECT_NE(broken.output.find(expected), std::string::npos) << expected << ": " << broken.output;
  fs::rename(folder / "image_l", folder / "image_0");
  fs::rename(folder / "image_r", folder / "image_1");
  fs::copy_file(kitti / "times.txt", folder / "times.txt");
  const RunnerOutput fixed = runner("--kitti " + folder.string() + " --gt " +
                                    (kitti / "poses.txt").string() + " --drift-lengths 5");
  ASSERT_EQ(fixed.status, 0) << fixed.output;
  // Without --preset the KITTI preset runs, and says so.
  EXPECT_NE(fixed.output.find("preset kitti_stereo (the default for --kitti"), std::string::npos)
      << fixed.output;
  EXPECT_EQ(reported(fixed.output, "tracking:", 1), 7.0) << fixed.output;
  EXPECT_LT(reported(fixed.output, "RPE frame-to-frame", 4), 0.05) << fixed.output;
}

TEST(DatasetLayouts, SevenScenesSequenceWithItsPosesAsGroundTruth) {
  const fs::path folder = freshFolder("7scenes");
  const cvo::TumSequence sequence((kData / "tum_fr1_xyz").string());
  const cvo::Trajectory gt =
      cvo::readTumTrajectory((kData / "tum_fr1_xyz" / "groundtruth.txt").string());
  for (std::size_t k = 0; k < 8; ++k) {
    cv::Mat image, depth;
    sequence.load(k, &image, &depth);
    // 7-Scenes depth: millimetres, 65535 where there is none.
    cv::Mat mm;
    depth.convertTo(mm, CV_16U, 1000.0 / 5000.0);
    mm.setTo(65535, depth == 0);
    char name[32];
    std::snprintf(name, sizeof(name), "frame-%06zu", k);
    cv::imwrite((folder / (std::string(name) + ".color.png")).string(), image);
    cv::imwrite((folder / (std::string(name) + ".depth.png")).string(), mm);
    Eigen::Isometry3d pose;
    ASSERT_TRUE(gt.interpolate(sequence.frames()[k].depth_stamp, 0.02, &pose));
    std::ofstream out(folder / (std::string(name) + ".pose.txt"));
    out << std::setprecision(9) << pose.matrix() << "\n";
  }
  // The fixture's own camera (fr1), not the 7-Scenes nominal one: the images are TUM's.
  const RunnerOutput run = runner("--7scenes " + folder.string() + " --camera fr1");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(reported(run.output, "poses:", 1), 8.0) << run.output;
  // Frames at 30 Hz (the format has no stamps): the motion per frame compares.
  EXPECT_LT(reported(run.output, "RPE frame-to-frame", 4), 0.006) << run.output;
  EXPECT_GT(reported(run.output, "point depths:", 9), 0.8) << "millimetres read as metres";
  EXPECT_LT(reported(run.output, "point depths:", 9), 2.0) << run.output;
}

TEST(DatasetLayouts, ANumericCameraTakesItsSizeFromTheImages) {
  const fs::path folder = tumCopy("small", 6, cv::Size(320, 240));
  const RunnerOutput run =
      runner("--tum " + folder.string() + " --camera 258.65,258.25,159.3,127.65 " +
             "--min-points 1000 --gt " + (folder / "groundtruth.txt").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(reported(run.output, "tracking:", 1), reported(run.output, "poses:", 1) - 1)
      << "every frame after the first tracked: " << run.output;
}

TEST(DatasetLayouts, SegmentationIsFoundBelowTheDatasetAndAMissingImageIsAnError) {
  const fs::path folder = tumCopy("labels", 5);
  fs::create_directories(folder / "labels" / "rgb");
  for (const auto& entry : fs::directory_iterator(folder / "rgb")) {
    // A deterministic rule: left and right halves of the image are two classes.
    cv::Mat labels(480, 640, CV_8UC1, cv::Scalar(1));
    labels.colRange(320, 640).setTo(2);
    cv::imwrite((folder / "labels" / "rgb" / entry.path().filename()).string(), labels);
  }
  const std::string args = "--tum " + folder.string() +
                           " --segmentation labels --semantic-classes 3 --use-semantics true";
  const RunnerOutput run = runner(args);  // from the temp folder: "labels" is the dataset's
  EXPECT_EQ(run.status, 0) << run.output;
  fs::remove(fs::directory_iterator(folder / "labels" / "rgb")->path());
  const RunnerOutput missing = runner(args);
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.output.find("no segmentation image for"), std::string::npos) << missing.output;
}

TEST(DatasetLayouts, AWrongDepthScaleIsVisibleInTheSummary) {
  const fs::path folder = tumCopy("scale", 4);
  const RunnerOutput right = runner("--tum " + folder.string());
  const RunnerOutput wrong = runner("--tum " + folder.string() + " --depth-scale 1000");
  ASSERT_EQ(right.status, 0) << right.output;
  ASSERT_EQ(wrong.status, 0) << wrong.output;
  const double median = reported(right.output, "point depths:", 9);
  EXPECT_GT(median, 0.8);
  EXPECT_NEAR(reported(wrong.output, "point depths:", 9) / median, 5.0, 0.5) << wrong.output;
}

}  // namespace
