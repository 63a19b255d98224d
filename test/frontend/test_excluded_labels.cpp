// Labels of ignored classes decide which pixels no stage uses (issue 40): the excluded mask of
// each kind of segmentation image, and on a real TUM frame the cloud, FrameImages::excluded and
// the photometric image all leaving out the ignored pixels grown by ignore_border_px, and moved
// to the depth image's instant where an object moves and depth and colour differ in time.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include <opencv2/imgproc.hpp>

#include "cvo_odometry/frontend/depth_cloud_builder.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/empty_frame_error.hpp"
#include "cvo_odometry/frontend/semantic_image.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

const std::string kTum = std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz";

// Proves: excludedMask is 255 exactly where probabilities() is false (an ignored class or an id
// out of range) for 8-bit ids, 16-bit ids and float probabilities (by the most likely class).
TEST(ExcludedLabels, MaskOfEachSegmentationKind) {
  const cv::Mat ids8 = (cv::Mat_<std::uint8_t>(2, 3) << 0, 1, 2, 3, 9, 1);
  const cv::Mat mask8 = cvo::SemanticImage(ids8, 4, {1}).excludedMask();
  ASSERT_EQ(mask8.type(), CV_8UC1);
  ASSERT_EQ(mask8.size(), ids8.size());
  const cv::Mat want8 = (cv::Mat_<std::uint8_t>(2, 3) << 0, 255, 0, 0, 255, 255);
  EXPECT_EQ(cv::countNonZero(mask8 != want8), 0) << mask8;

  const cv::Mat ids16 = (cv::Mat_<std::uint16_t>(1, 5) << 0, 300, 299, 1000, 7);
  const cvo::SemanticImage wide(ids16, 301, {299, 7});
  const cv::Mat mask16 = wide.excludedMask();
  ASSERT_EQ(mask16.type(), CV_8UC1);
  const cv::Mat want16 = (cv::Mat_<std::uint8_t>(1, 5) << 0, 0, 255, 255, 255);
  EXPECT_EQ(cv::countNonZero(mask16 != want16), 0) << mask16;

  cv::Mat probs(1, 3, CV_32FC3);
  probs.at<cv::Vec3f>(0, 0) = {0.2f, 0.7f, 0.1f};  // class 1: ignored
  probs.at<cv::Vec3f>(0, 1) = {0.5f, 0.4f, 0.1f};  // class 0
  probs.at<cv::Vec3f>(0, 2) = {0.1f, 0.3f, 0.6f};  // class 2
  const cvo::SemanticImage soft(probs, 3, {1});
  const cv::Mat mask32 = soft.excludedMask();
  const cv::Mat want32 = (cv::Mat_<std::uint8_t>(1, 3) << 255, 0, 0);
  EXPECT_EQ(cv::countNonZero(mask32 != want32), 0) << mask32;

  // The same verdict as probabilities(), pixel by pixel.
  float p[301];
  for (int u = 0; u < 5; ++u)
    EXPECT_EQ(mask16.at<std::uint8_t>(0, u) != 0, !wide.probabilities(u, 0, p)) << u;
  for (int u = 0; u < 3; ++u)
    EXPECT_EQ(mask32.at<std::uint8_t>(0, u) != 0, !soft.probabilities(u, 0, p)) << u;
  // Nothing ignored and every id in range: nothing excluded.
  EXPECT_EQ(cv::countNonZero(cvo::SemanticImage(ids8, 10).excludedMask()), 0);
}

struct TumFrame {
  cv::Mat image, depth;
  cvo::PinholeIntrinsics K;
};

TumFrame tumFrame(std::size_t k) {
  const cvo::TumSequence sequence(kTum);
  TumFrame frame;
  cv::Mat raw;
  sequence.load(k, &frame.image, &raw);
  frame.depth = cvo::depthToMetres(raw, 5000.0, 0.1, 10.0);
  frame.K = cvo::tumIntrinsics("fr1");
  frame.K.distortion.clear();  // a point projects back onto its pixel with K alone
  return frame;
}

cvo::CloudBuilderOptions labelledOptions(int border) {
  cvo::CloudBuilderOptions options;
  options.semantic_classes = 2;
  options.ignore_classes = {1};
  options.ignore_border_px = border;
  options.image_levels = 2;
  return options;
}

// Proves: with a label square of an ignored class on a real TUM frame, no cloud point projects
// inside the square grown by ignore_border_px (while points crowd right outside it and the
// unlabelled cloud has points inside), FrameImages::excluded is exactly that grown square, and
// the photometric image's usable() is false inside it and true outside.
TEST(ExcludedLabels, CloudImagesAndPhotometricImageLeaveTheGrownSquareOut) {
  const TumFrame frame = tumFrame(5);
  const cv::Rect square(220, 150, 120, 100);  // has depth on the fixture's desk
  cv::Mat labels(frame.image.size(), CV_8UC1, cv::Scalar(0));
  labels(square).setTo(1);
  for (const int border : {0, 8, 15}) {
    SCOPED_TRACE("ignore_border_px " + std::to_string(border));
    const cv::Rect grown(square.x - border, square.y - border, square.width + 2 * border,
                         square.height + 2 * border);
    cvo::DepthCloudBuilder builder(labelledOptions(border));
    cvo::FrameImages images;
    const cvo::LabeledCloud cloud =
        builder.build(frame.image, frame.depth, frame.K, labels, nullptr, &images);
    ASSERT_GT(cloud.size(), 1000u);

    // FrameImages::excluded: the grown square, nothing else.
    cv::Mat expected(frame.image.size(), CV_8UC1, cv::Scalar(0));
    expected(grown).setTo(255);
    ASSERT_EQ(images.excluded.type(), CV_8UC1);
    ASSERT_EQ(images.excluded.size(), frame.image.size());
    EXPECT_EQ(cv::countNonZero((images.excluded != 0) != (expected != 0)), 0);

    // No point inside the grown square; many within 25 px around it.
    int inside = 0, around = 0;
    const cv::Rect ring(grown.x - 25, grown.y - 25, grown.width + 50, grown.height + 50);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Eigen::Vector3f p = cloud.position(i);
      const double u = frame.K.fx * p.x() / p.z() + frame.K.cx;
      const double v = frame.K.fy * p.y() / p.z() + frame.K.cy;
      const cv::Point pixel(cvRound(u), cvRound(v));
      ASSERT_LT(std::abs(u - pixel.x), 1e-2) << "a point off its pixel";
      inside += grown.contains(pixel);
      around += ring.contains(pixel) && !grown.contains(pixel);
      ASSERT_EQ(cloud.semantics(i)[1], 0.0f) << "a point of the ignored class";
    }
    EXPECT_EQ(inside, 0);
    EXPECT_GT(around, 50) << "the cloud reaches the square's border";

    // The photometric stage's image: unusable exactly inside the grown square.
    const cvo::IntensityImage* image = cloud.image();
    ASSERT_NE(image, nullptr);
    ASSERT_TRUE(image->hasExcludedPixels());
    int wrong = 0;
    for (int v = 1; v < image->height() - 1; ++v) {
      for (int u = 1; u < image->width() - 1; ++u)
        wrong += image->usable(u, v) == grown.contains(cv::Point(u, v));
    }
    EXPECT_EQ(wrong, 0) << "pixels whose usable() disagrees with the grown square";
  }

  // Without labels the same frame has points inside the square: the test above can fail.
  cvo::CloudBuilderOptions plain;
  cvo::DepthCloudBuilder unlabelled(plain);
  cvo::FrameImages images;
  const cvo::LabeledCloud all =
      unlabelled.build(frame.image, frame.depth, frame.K, cv::Mat(), nullptr, &images);
  EXPECT_TRUE(images.excluded.empty());
  ASSERT_NE(all.image(), nullptr);
  EXPECT_FALSE(all.image()->hasExcludedPixels());
  int inside = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Eigen::Vector3f p = all.position(i);
    inside += square.contains(cv::Point(cvRound(frame.K.fx * p.x() / p.z() + frame.K.cx),
                                        cvRound(frame.K.fy * p.y() / p.z() + frame.K.cy)));
  }
  EXPECT_GT(inside, 100);
}

// Proves: when every pixel with depth is of an ignored class the frame is an EmptyFrameError
// whose message names ignore_classes; labels that leave a strip that has depth still build.
TEST(ExcludedLabels, EveryPixelExcludedIsAnEmptyFrameNamingIgnoreClasses) {
  const TumFrame frame = tumFrame(0);
  cvo::DepthCloudBuilder builder(labelledOptions(8));
  const cv::Mat all_ignored(frame.image.size(), CV_8UC1, cv::Scalar(1));
  try {
    builder.build(frame.image, frame.depth, frame.K, all_ignored, nullptr);
    FAIL() << "no EmptyFrameError";
  } catch (const cvo::EmptyFrameError& e) {
    EXPECT_NE(std::string(e.what()).find("ignore_classes"), std::string::npos) << e.what();
  }
  // The border grows the labels over the rest: a strip narrower than the border is gone too.
  cv::Mat nearly(frame.image.size(), CV_8UC1, cv::Scalar(1));
  nearly.rowRange(200, 206).setTo(0);
  EXPECT_THROW(builder.build(frame.image, frame.depth, frame.K, nearly, nullptr),
               cvo::EmptyFrameError);
  cv::Mat wider(frame.image.size(), CV_8UC1, cv::Scalar(1));
  wider.rowRange(200, 260).setTo(0);
  EXPECT_GT(builder.build(frame.image, frame.depth, frame.K, wider, nullptr).size(), 100u);
}

// Proves: labelRegionMotions gives each region its own motion (two squares moving apart), the
// uncut edge's motion for a region the image border cuts (a square leaving on the right), and
// no motion to a region new in view or to two regions merged into one.
TEST(ExcludedLabels, EachLabelledRegionMovesAsItsUncutPartDoes) {
  cv::Mat before(120, 160, CV_8UC1, cv::Scalar(0)), after = before.clone();
  before(cv::Rect(40, 30, 20, 20)).setTo(255);   // moves left 6 px
  before(cv::Rect(90, 30, 20, 20)).setTo(255);   // moves right 5 px and down 3
  before(cv::Rect(130, 80, 30, 20)).setTo(255);  // leaves on the right, 8 px a frame
  before(cv::Rect(10, 80, 10, 10)).setTo(255);   // these two merge
  before(cv::Rect(22, 80, 10, 10)).setTo(255);
  after(cv::Rect(34, 30, 20, 20)).setTo(255);
  after(cv::Rect(95, 33, 20, 20)).setTo(255);
  after(cv::Rect(138, 80, 22, 20)).setTo(255);
  after(cv::Rect(10, 80, 25, 12)).setTo(255);
  after(cv::Rect(70, 100, 10, 10)).setTo(255);  // new
  const cvo::LabelRegionMotions motions = cvo::labelRegionMotions(before, after);
  ASSERT_EQ(motions.regions.type(), CV_32SC1);
  const auto motionAt = [&](int u, int v) {
    return motions.motion.at(static_cast<std::size_t>(motions.regions.at<int>(v, u)));
  };
  ASSERT_TRUE(motionAt(40, 40));
  EXPECT_NEAR(motionAt(40, 40)->x, -6.0, 1e-9);
  EXPECT_NEAR(motionAt(40, 40)->y, 0.0, 1e-9);
  ASSERT_TRUE(motionAt(100, 40));
  EXPECT_NEAR(motionAt(100, 40)->x, 5.0, 1e-9);
  EXPECT_NEAR(motionAt(100, 40)->y, 3.0, 1e-9);
  ASSERT_TRUE(motionAt(150, 90));
  EXPECT_NEAR(motionAt(150, 90)->x, 8.0, 1e-9) << "the centre moved 4 px";
  EXPECT_FALSE(motionAt(20, 85)) << "merged";
  EXPECT_FALSE(motionAt(75, 105)) << "new in view";
  EXPECT_THROW(cvo::labelRegionMotions(before, cv::Mat::zeros(10, 10, CV_8UC1)),
               std::invalid_argument);
}

// A real TUM frame with a near object (0.4 m; the desk is 0.65 m and more) of an ignored class
// moving right 36 px a frame: labelled at `label_x`, in the depth image at `depth_x`.
struct MovingObjectFrame {
  cv::Mat depth, labels;
};

MovingObjectFrame withObject(const TumFrame& frame, int label_x, int depth_x) {
  MovingObjectFrame out{frame.depth.clone(), cv::Mat(frame.image.size(), CV_8UC1, cv::Scalar(0))};
  out.labels(cv::Rect(label_x, 150, 120, 100)).setTo(1);
  out.depth(cv::Rect(depth_x, 150, 120, 100)).setTo(0.4f);
  return out;
}

// Points of the cloud nearer than the scene: the object's depth taken for the scene's.
int objectPoints(const cvo::LabeledCloud& cloud) {
  int near = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    near += cloud.position(i).z() < 0.5f;
  return near;
}

// Proves: where depth is taken 15 ms before the colour image the labels describe (TUM's Kinect)
// and an object moves 36 px a frame, its depth lies 16 px behind its labels, beyond the 8 px
// border: built with the frames' timing, the labels move to the depth's instant and no point
// takes the object's depth (with depth 15 ms after colour too, the other way); without the
// timing, or without the earlier frame to tell the motion, points of it are in the cloud.
TEST(ExcludedLabels, MovingObjectsDepthAtAnotherInstantIsLeftOutToo) {
  const TumFrame frame = tumFrame(5);
  const double interval = 0.033, gap = 0.015;
  const int step = 36, lag = static_cast<int>(std::lround(step * gap / interval));  // 16 px
  for (const double depth_after_colour : {-gap, gap}) {
    SCOPED_TRACE("depth after colour " + std::to_string(depth_after_colour) + " s");
    const int towards = depth_after_colour > 0.0 ? lag : -lag;
    const MovingObjectFrame first = withObject(frame, 200, 200 + towards);
    const MovingObjectFrame second = withObject(frame, 200 + step, 200 + step + towards);
    cvo::DepthCloudBuilder timed(labelledOptions(8));
    cvo::FrontendStats stats;
    const cvo::LabelTiming t0{100.0, depth_after_colour}, t1{100.0 + interval, depth_after_colour};
    // The first frame has no motion to go by: the plain border, and the object leaks.
    const cvo::LabeledCloud unknown =
        timed.build(frame.image, first.depth, frame.K, first.labels, &stats, nullptr, &t0);
    EXPECT_EQ(stats.label_motion_px, 0);
    EXPECT_GT(objectPoints(unknown), 20);
    cvo::FrameImages images;
    const cvo::LabeledCloud moved =
        timed.build(frame.image, second.depth, frame.K, second.labels, &stats, &images, &t1);
    EXPECT_NEAR(stats.label_motion_px, lag, 2);
    EXPECT_EQ(objectPoints(moved), 0);
    EXPECT_GT(moved.size(), 1000u);
    // The colour instant's labels stay left out as well (the tracks and the photometric stage
    // read the colour image).
    EXPECT_EQ(cv::countNonZero(second.labels & (images.excluded == 0)), 0);

    cvo::DepthCloudBuilder untimed(labelledOptions(8));
    const cvo::LabeledCloud leaking =
        untimed.build(frame.image, second.depth, frame.K, second.labels, &stats);
    EXPECT_EQ(stats.label_motion_px, 0);
    EXPECT_GT(objectPoints(leaking), 20);
  }
  // Depth and colour at one instant: the plain border, the same cloud as without timing.
  const MovingObjectFrame first = withObject(frame, 200, 200);
  const MovingObjectFrame second = withObject(frame, 200 + step, 200 + step);
  cvo::DepthCloudBuilder timed(labelledOptions(8)), untimed(labelledOptions(8));
  cvo::FrontendStats stats;
  const cvo::LabelTiming t0{100.0, 0.0}, t1{100.0 + interval, 0.0};
  timed.build(frame.image, first.depth, frame.K, first.labels, &stats, nullptr, &t0);
  const cvo::LabeledCloud synchronous =
      timed.build(frame.image, second.depth, frame.K, second.labels, &stats, nullptr, &t1);
  EXPECT_EQ(stats.label_motion_px, 0);
  EXPECT_EQ(objectPoints(synchronous), 0);
  EXPECT_EQ(synchronous.size(),
            untimed.build(frame.image, second.depth, frame.K, second.labels, nullptr).size());
}

// Proves: two objects moving apart (their labels' centre stays) each move their own way to the
// depth's instant, so that neither leaks.
TEST(ExcludedLabels, LabelsMovingApartMoveEachTheirOwnWay) {
  const TumFrame frame = tumFrame(5);
  const double interval = 0.033, gap = -0.015;
  const int step = 36, lag = 16;
  const auto twoObjects = [&](int spread, int depth_spread) {
    MovingObjectFrame out{frame.depth.clone(), cv::Mat(frame.image.size(), CV_8UC1, cv::Scalar(0))};
    for (const int side : {-1, 1}) {
      out.labels(cv::Rect(270 + side * (80 + spread), 150, 100, 100)).setTo(1);
      out.depth(cv::Rect(270 + side * (80 + depth_spread), 150, 100, 100)).setTo(0.4f);
    }
    return out;
  };
  const MovingObjectFrame first = twoObjects(0, -lag), second = twoObjects(step, step - lag);
  cvo::DepthCloudBuilder timed(labelledOptions(8)), untimed(labelledOptions(8));
  cvo::FrontendStats stats;
  const cvo::LabelTiming t0{100.0, gap}, t1{100.0 + interval, gap};
  timed.build(frame.image, first.depth, frame.K, first.labels, &stats, nullptr, &t0);
  const cvo::LabeledCloud grown =
      timed.build(frame.image, second.depth, frame.K, second.labels, &stats, nullptr, &t1);
  EXPECT_NEAR(stats.label_motion_px, lag, 2);
  EXPECT_EQ(objectPoints(grown), 0);
  EXPECT_GT(objectPoints(untimed.build(frame.image, second.depth, frame.K, second.labels, nullptr)),
            20);
}

// Proves: labels of still things, which move only as the camera does, and a region flickering
// on far from the rest leave the plain border: nothing is moved, the same cloud as untimed.
TEST(ExcludedLabels, StillOrFlickeringLabelsKeepThePlainBorder) {
  const TumFrame frame = tumFrame(5);
  cv::Mat first(frame.image.size(), CV_8UC1, cv::Scalar(0)), second = first.clone();
  for (int k = 0; k < 6; ++k) {
    first(cv::Rect(40 + 90 * k, 60 + 50 * k, 40, 30)).setTo(1);
    second(cv::Rect(42 + 90 * k, 61 + 50 * k, 40, 30)).setTo(1);  // 2 px with the camera
  }
  second(cv::Rect(300, 380, 60, 60)).setTo(1);  // on in this frame only
  cvo::DepthCloudBuilder timed(labelledOptions(8)), untimed(labelledOptions(8));
  cvo::FrontendStats stats;
  const cvo::LabelTiming t0{100.0, -0.015}, t1{100.033, -0.015};
  timed.build(frame.image, frame.depth, frame.K, first, &stats, nullptr, &t0);
  cvo::FrameImages timed_images, untimed_images;
  timed.build(frame.image, frame.depth, frame.K, second, &stats, &timed_images, &t1);
  EXPECT_EQ(stats.label_motion_px, 0);
  untimed.build(frame.image, frame.depth, frame.K, second, nullptr, &untimed_images);
  EXPECT_EQ(cv::countNonZero(timed_images.excluded != untimed_images.excluded), 0);
}

// Proves: where the depth is older than the colour, an object whose labels are gone in this
// frame (it left the view between the two, or the segmentation missed it) is left out where it
// was labelled in the last frame: its depth there is no point of the cloud. With depth after
// colour nothing of the last frame is kept.
TEST(ExcludedLabels, LabelsGoneSinceTheLastFrameStayOutOfOlderDepth) {
  const TumFrame frame = tumFrame(5);
  const MovingObjectFrame first = withObject(frame, 250, 250);
  cv::Mat depth = first.depth.clone();  // still there 15 ms before this frame's colour
  const cv::Mat no_labels(frame.image.size(), CV_8UC1, cv::Scalar(0));
  for (const double depth_after_colour : {-0.015, 0.015}) {
    cvo::DepthCloudBuilder timed(labelledOptions(8));
    const cvo::LabelTiming t0{100.0, depth_after_colour}, t1{100.033, depth_after_colour};
    timed.build(frame.image, first.depth, frame.K, first.labels, nullptr, nullptr, &t0);
    cvo::FrameImages images;
    const cvo::LabeledCloud cloud =
        timed.build(frame.image, depth, frame.K, no_labels, nullptr, &images, &t1);
    if (depth_after_colour < 0.0) {
      EXPECT_EQ(objectPoints(cloud), 0);
      EXPECT_GT(cv::countNonZero(images.excluded), 120 * 100);
    } else {
      EXPECT_GT(objectPoints(cloud), 100);
      EXPECT_TRUE(images.excluded.empty());
    }
  }
}

}  // namespace
