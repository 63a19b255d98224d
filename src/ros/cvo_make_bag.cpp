// cvo_make_bag: a TUM RGB-D or KITTI odometry folder as a rosbag with the nodelet's topics, so the
// public datasets replay like a live camera.
//   TUM:   <ns>/rgb/image_rect_color (bgr8, rgb time), <ns>/rgb/camera_info,
//          <ns>/depth_registered/image_rect (32FC1 metres, depth time),
//          with --segmentation DIR <ns>/segmentation/image (mono8/mono16 class ids, rgb time)
//   KITTI: <ns>/left/image_rect, <ns>/right/image_rect (mono8), <ns>/left|right/camera_info;
//          stamps are times.txt + 1 s (ROS time 0 means "no stamp"; --gt-out writes the ground
//          truth at the bag's stamps)
//          with --segmentation DIR <ns>/segmentation/image (class ids, the left image's stamp)
//   both:  /tf_static base_link -> the camera frame, a camera looking along base_link's x axis,
//          latched as a static transform publisher's is
#include <iostream>

#include <boost/make_shared.hpp>

#include <cv_bridge/cv_bridge.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_msgs/TFMessage.h>
#include <opencv2/imgproc.hpp>

#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/depth_conversion.hpp"
#include "cvo_odometry/frontend/kitti_sequence.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"
#include "cvo_odometry/ros/ros_conversions.hpp"
#include "cvo_odometry/tools/command_line.hpp"
#include "cvo_odometry/tools/tool_options.hpp"

namespace {

const char* kUsage =
    "usage: cvo_make_bag (--tum DIR [--camera fr1|fr2|fr3|fx,fy,cx,cy] | --kitti DIR) --out BAG\n"
    "  --ns NAME          topic namespace (/camera for TUM, /stereo for KITTI)\n"
    "  --frame-id NAME    camera frame (camera_rgb_optical_frame / camera_left)\n"
    "  --base-frame NAME  the frame /tf_static puts the camera in (base_link)\n"
    "  --gt-out FILE      ground truth (TUM format) at the bag's stamps, for cvo_evaluate\n"
    "  --first N --last N frame range\n"
    "  --stride N         every N-th frame of the range (larger motions per frame)\n"
    "  --segmentation DIR each colour (KITTI: left) image's class ids, 8 or 16 bit (e.g. from\n"
    "                     cvo_make_labels), on <ns>/segmentation/image with that image's stamp:\n"
    "                     TUM DIR/<rgb path> or DIR/<file name>; KITTI DIR/image_0/<name> or\n"
    "                     DIR/<name>\n";

sensor_msgs::CameraInfo cameraInfo(const cvo::PinholeIntrinsics& K, double tx,
                                   const std_msgs::Header& header) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = static_cast<uint32_t>(K.width);
  info.height = static_cast<uint32_t>(K.height);
  info.distortion_model = "plumb_bob";
  info.D = K.distortion.empty() ? std::vector<double>(5, 0.0) : K.distortion;
  info.K = {K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  // Unrectified images (TUM's distortion) carry no P: the nodelet then projects through K and D,
  // as the offline tools do for the same folder.
  if (K.distortion.empty()) info.P = {K.fx, 0, K.cx, tx, 0, K.fy, K.cy, 0, 0, 0, 1, 0};
  return info;
}

// base -> camera on /tf_static at the first stamp: the bag plays like a robot with a camera.
// Latched, as tf2's static broadcaster publishes it (rosbag play latches a connection recorded so):
// a listener started after playback began (rviz, tf_echo) still gets it.
void writeCameraTransform(rosbag::Bag& bag, const std::string& base, const std::string& camera,
                          const ros::Time& stamp) {
  tf2_msgs::TFMessage tf;
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = base;
  t.child_frame_id = camera;
  t.transform = cvo::toTransformMsg(cvo::opticalFrameInBase());
  tf.transforms.push_back(t);
  using Traits = ros::message_traits::Definition<tf2_msgs::TFMessage>;
  auto header = boost::make_shared<ros::M_string>();
  (*header)["topic"] = "/tf_static";
  (*header)["type"] = ros::message_traits::datatype(tf);
  (*header)["md5sum"] = ros::message_traits::md5sum(tf);
  (*header)["message_definition"] = Traits::value();
  (*header)["callerid"] = "/cvo_make_bag";
  (*header)["latching"] = "1";
  bag.write("/tf_static", stamp, tf, header);
}

// 8 or 16-bit class ids as a mono8 / mono16 image message.
sensor_msgs::ImagePtr labelsMsg(const cv::Mat& labels, const std::string& what,
                                const std_msgs::Header& header) {
  if (labels.channels() != 1 || (labels.depth() != CV_8U && labels.depth() != CV_16U)) {
    throw std::invalid_argument("--segmentation: " + what +
                                "'s labels are not 8 or 16-bit class ids");
  }
  return cv_bridge::CvImage(header,
                            labels.depth() == CV_8U ? sensor_msgs::image_encodings::MONO8
                                                    : sensor_msgs::image_encodings::MONO16,
                            labels)
      .toImageMsg();
}

sensor_msgs::ImagePtr imageMsg(const cv::Mat& image, const std::string& encoding,
                               const std_msgs::Header& header) {
  return cv_bridge::CvImage(header, encoding, image).toImageMsg();
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const cvo::CommandLine cli(argc, argv,
                               {"tum", "kitti", "camera", "out", "ns", "frame-id", "base-frame",
                                "gt-out", "first", "last", "stride", "segmentation"},
                               {"help"});
    if (cli.has("help") || (!cli.has("tum") && !cli.has("kitti"))) {
      std::cout << kUsage;
      return cli.has("help") ? 0 : 2;
    }
    rosbag::Bag bag(cli.require("out"), rosbag::bagmode::Write);
    const int first = cli.getInt("first", 0);
    const int stride = cli.getInt("stride", 1);
    if (stride < 1) throw std::invalid_argument("--stride must be >= 1");
    const std::string base_frame = cli.get("base-frame", "base_link");
    std::size_t written = 0;
    cvo::Trajectory ground_truth;  // at the bag's stamps
    const std::string segmentation = cli.get("segmentation");
    if (cli.has("tum")) {
      const cvo::TumSequence sequence(cli.get("tum"));
      const std::string gt_path = cli.get("tum") + "/groundtruth.txt";
      if (cli.has("gt-out")) ground_truth = cvo::readTumTrajectory(gt_path);
      const std::string ns = cli.get("ns", "/camera");
      const cvo::PinholeIntrinsics K = cvo::tumIntrinsics(cli.get("camera", "fr1"));
      const int last = cli.getInt("last", static_cast<int>(sequence.frames().size()) - 1);
      std_msgs::Header header;
      header.frame_id = cli.get("frame-id", "camera_rgb_optical_frame");
      for (int k = first; k <= last; k += stride) {
        cv::Mat image, depth;
        sequence.load(static_cast<std::size_t>(k), &image, &depth);
        const auto& f = sequence.frames()[static_cast<std::size_t>(k)];
        header.seq = static_cast<uint32_t>(k);
        if (k == first)
          writeCameraTransform(bag, base_frame, header.frame_id, ros::Time(f.rgb_stamp));
        header.stamp = ros::Time(f.rgb_stamp);
        bag.write(ns + "/rgb/image_rect_color", header.stamp,
                  imageMsg(image, sensor_msgs::image_encodings::BGR8, header));
        bag.write(ns + "/rgb/camera_info", header.stamp, cameraInfo(K, 0.0, header));
        if (!segmentation.empty()) {
          bag.write(
              ns + "/segmentation/image", header.stamp,
              labelsMsg(cvo::readSegmentation(segmentation, f.rgb_listed), f.rgb_path, header));
        }
        header.stamp = ros::Time(f.depth_stamp);
        const cv::Mat metres = cvo::depthToMetres(depth, 5000.0, 0.0, 1e9);
        bag.write(ns + "/depth_registered/image_rect", header.stamp,
                  imageMsg(metres, sensor_msgs::image_encodings::TYPE_32FC1, header));
        ++written;
      }
    } else {
      const cvo::KittiSequence sequence(cli.get("kitti"));
      if (cli.has("gt-out")) {
        cvo::Trajectory poses = cvo::readKittiTrajectory(cli.get("kitti") + "/poses.txt",
                                                         cli.get("kitti") + "/times.txt");
        for (const auto& sample : poses.poses())
          ground_truth.append(sample.stamp + 1.0, sample.pose);
      }
      const std::string ns = cli.get("ns", "/stereo");
      const auto& calibration = sequence.calibration();
      const int last = cli.getInt("last", static_cast<int>(sequence.size()) - 1);
      std_msgs::Header header;
      header.frame_id = cli.get("frame-id", "camera_left");
      for (int k = first; k <= last; k += stride) {
        cv::Mat left, right;
        sequence.load(static_cast<std::size_t>(k), &left, &right, nullptr);
        cv::cvtColor(left, left, cv::COLOR_BGR2GRAY);
        cv::cvtColor(right, right, cv::COLOR_BGR2GRAY);
        header.seq = static_cast<uint32_t>(k);
        header.stamp = ros::Time(sequence.stamps()[static_cast<std::size_t>(k)] + 1.0);
        if (k == first) writeCameraTransform(bag, base_frame, header.frame_id, header.stamp);
        const double tx = -calibration.left.fx * calibration.baseline;
        bag.write(ns + "/left/image_rect", header.stamp,
                  imageMsg(left, sensor_msgs::image_encodings::MONO8, header));
        bag.write(ns + "/left/camera_info", header.stamp,
                  cameraInfo(calibration.left, 0.0, header));
        bag.write(ns + "/right/image_rect", header.stamp,
                  imageMsg(right, sensor_msgs::image_encodings::MONO8, header));
        bag.write(ns + "/right/camera_info", header.stamp,
                  cameraInfo(calibration.left, tx, header));
        if (!segmentation.empty()) {
          // Found as the runner finds them (tool_options: the left image's path, then its name).
          const std::string left_path =
              "image_0/" + sequence.imageName(static_cast<std::size_t>(k));
          bag.write(ns + "/segmentation/image", header.stamp,
                    labelsMsg(cvo::readSegmentation(segmentation, left_path), left_path, header));
        }
        ++written;
      }
    }
    bag.close();
    if (cli.has("gt-out")) {
      cvo::writeTrajectory(cli.get("gt-out"), ground_truth, cvo::TrajectoryFormat::kTum);
      std::cout << "cvo_make_bag: ground truth at the bag's stamps -> " << cli.get("gt-out")
                << "\n";
    }
    std::cout << "cvo_make_bag: " << written << " frames -> " << cli.get("out") << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_make_bag: " << e.what() << "\n";
    return 2;
  }
}
