#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"

#include <chrono>
#include <limits>
#include <stdexcept>

#include "cvo_odometry/frontend/depth_conversion.hpp"

namespace cvo {

RgbdCloudBuilder::RgbdCloudBuilder(const RgbdFrontendOptions& options)
    : options_(options), cloud_builder_(options.cloud) {}

LabeledCloud RgbdCloudBuilder::build(const RgbdFrame& frame, FrontendStats* stats,
                                     FrameImages* images, double stamp) {
  const auto start = std::chrono::steady_clock::now();
  // Beyond max_depth kept for the feature tracker; the cloud builder applies the range.
  const cv::Mat depth =
      depthToMetres(frame.depth, options_.depth_units_per_metre, options_.cloud.min_depth,
                    std::numeric_limits<double>::infinity());
  // The labels move between colour instants: the pipeline's stamp is the depth image's.
  const LabelTiming timing{stamp - frame.depth_after_colour, frame.depth_after_colour};
  LabeledCloud cloud = cloud_builder_.build(frame.image, depth, frame.intrinsics, frame.semantics,
                                            stats, images, &timing);
  if (stats) {
    stats->time_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  return cloud;
}

}  // namespace cvo
