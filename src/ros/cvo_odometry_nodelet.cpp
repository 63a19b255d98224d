// The cvo_odometry nodelet: a thin shell over CvoOdometryRos, so the odometry can share a camera
// driver's nodelet manager (zero-copy images).
#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "cvo_odometry/ros/cvo_odometry_ros.hpp"

namespace cvo {

class CvoOdometryNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      odometry_ = std::make_unique<CvoOdometryRos>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL_STREAM("cvo_odometry: " << e.what() << "; the nodelet stays idle");
    }
  }

  std::unique_ptr<CvoOdometryRos> odometry_;
};

}  // namespace cvo

PLUGINLIB_EXPORT_CLASS(cvo::CvoOdometryNodelet, nodelet::Nodelet)
