// rostest node: the nodelet's services and refusals, with real TUM frames published here.
// Reconfigures the nodelet must refuse (a backend it cannot make, ell_init below ell_min) are
// written back to the server and the odometry goes on; ~pause drops and counts frames and
// ~resume continues from the last pose; ~reset_to_pose starts at the given pose; without a
// camera transform the forward-looking optical frame is assumed, and one published later is
// taken at ~reset.
#include <limits>
#include <string>
#include <type_traits>

#include <dynamic_reconfigure/Reconfigure.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <Eigen/Core>

#include "cvo_odometry/ResetToPose.h"
#include "cvo_odometry/core/backend_factory.hpp"
#include "rostest_main.hpp"
#include "tum_topic_driver.hpp"

namespace {

class NodeServices : public cvo_test::TumTopicDriver {
 protected:
  void SetUp() override { ASSERT_NO_FATAL_FAILURE(connect({0, 1, 2, 3, 4, 5, 6, 7}, false)); }

  template <class Service>
  void call(const std::string& name, Service& service) {
    ASSERT_TRUE(ros::service::waitForService(name, ros::Duration(kEventTimeout))) << name;
    ASSERT_TRUE(ros::service::call(name, service)) << name;
  }
  void call(const std::string& name) {
    std_srvs::Empty empty;
    call(name, empty);
  }

  // The configuration the server answers with after a reconfigure of one value.
  template <class Value>
  dynamic_reconfigure::Config reconfigure(const std::string& name, const Value& value) {
    dynamic_reconfigure::Reconfigure change;
    if constexpr (std::is_same_v<Value, std::string>) {
      dynamic_reconfigure::StrParameter p;
      p.name = name, p.value = value;
      change.request.config.strs.push_back(p);
    } else {
      dynamic_reconfigure::DoubleParameter p;
      p.name = name, p.value = value;
      change.request.config.doubles.push_back(p);
    }
    call("cvo_odometry/set_parameters", change);
    return change.response.config;
  }

  Eigen::Vector3d position(std::size_t k) {
    const auto odometry = this->odometry();
    const auto& p = odometry.at(k).pose.pose.position;
    return {p.x, p.y, p.z};
  }
};

std::string stringValue(const dynamic_reconfigure::Config& config, const std::string& name) {
  for (const auto& p : config.strs)
    if (p.name == name) return p.value;
  return "(missing)";
}
double doubleValue(const dynamic_reconfigure::Config& config, const std::string& name) {
  for (const auto& p : config.doubles)
    if (p.name == name) return p.value;
  return std::numeric_limits<double>::quiet_NaN();
}

TEST_F(NodeServices, RefusalsPauseResetToPoseAndLateCameraTransform) {
  const double t0 = 1000.0, dt = 1.0 / 30.0;
  // No camera transform anywhere: the optical frame is assumed (z forward = base x).
  publish(0, t0);
  publish(1, t0 + dt);
  ASSERT_EQ(waitFor(2), 2u);
  const Eigen::Vector3d assumed_axes = position(1);
  ASSERT_GT(assumed_axes.norm(), 1e-3) << "the camera moved between frames 0 and 1";

  // A backend the nodelet cannot make here (no GPU): refused and written back, odometry goes on.
  std::string why_not;
  const bool gpu = cvo::cudaBackendAvailable(&why_not);
  const auto after_backend = reconfigure("backend", std::string("cuda"));
  EXPECT_EQ(stringValue(after_backend, "backend"), gpu ? "cuda" : "cpu") << why_not;
  publish(2, t0 + 2 * dt);
  ASSERT_EQ(waitFor(3), 3u) << "the nodelet stopped after the reconfigure";
  EXPECT_EQ(indicator(2).backend.rfind(gpu ? "cuda" : "cpu", 0), 0u) << indicator(2).backend;
  if (!gpu) {
    EXPECT_FALSE(indicator(2).first_frame) << "a refused change restarted the odometry";
  }

  // An invalid value (ell_init below ell_min 0.02): refused, the server shows the old value.
  const auto after_ell = reconfigure("ell_init", 0.01);
  EXPECT_NEAR(doubleValue(after_ell, "ell_init"), 0.15, 1e-12);
  publish(3, t0 + 3 * dt);
  ASSERT_EQ(waitFor(4), 4u);
  EXPECT_TRUE(indicator(3).converged) << indicator(3).message;

  // Paused: frames are dropped and counted, nothing is published; resumed: the next frame
  // starts over at the last pose.
  const Eigen::Vector3d before_pause = position(odometry().size() - 1);
  call("cvo_odometry/pause");
  publish(4, t0 + 4 * dt);
  publish(5, t0 + 5 * dt);
  EXPECT_EQ(
      diagnostic("frames dropped while paused", [](const std::string& v) { return v == "2"; }),
      "2");
  EXPECT_EQ(waitFor(4, 0.0), 4u) << "a frame was processed while paused";
  call("cvo_odometry/resume");
  publish(6, t0 + 6 * dt);
  ASSERT_EQ(waitFor(5), 5u);
  EXPECT_TRUE(indicator(4).first_frame);
  EXPECT_LT((position(odometry().size() - 1) - before_pause).norm(), 1e-9);

  // Reset to a pose: the next frame is there.
  cvo_odometry::ResetToPose to_pose;
  to_pose.request.pose.position.x = 1.0;
  to_pose.request.pose.position.y = 2.0;
  to_pose.request.pose.position.z = 3.0;
  to_pose.request.pose.orientation.w = 1.0;
  call("cvo_odometry/reset_to_pose", to_pose);
  EXPECT_TRUE(to_pose.response.success) << to_pose.response.message;
  publish(7, t0 + 7 * dt);
  ASSERT_EQ(waitFor(6), 6u);
  EXPECT_TRUE(indicator(5).first_frame);
  EXPECT_LT((position(odometry().size() - 1) - Eigen::Vector3d(1, 2, 3)).norm(), 1e-9);
  cvo_odometry::ResetToPose bad;  // a zero quaternion
  call("cvo_odometry/reset_to_pose", bad);
  EXPECT_FALSE(bad.response.success);
  EXPECT_FALSE(bad.response.message.empty());

  // A camera transform published now (camera axes = base axes) is taken at the next reset: the
  // same two frames then move the base along the camera's axes instead of the assumed ones.
  tf2_ros::StaticTransformBroadcaster broadcaster;
  geometry_msgs::TransformStamped camera;
  camera.header.stamp = ros::Time::now();
  camera.header.frame_id = "base_link";
  camera.child_frame_id = "camera_rgb_optical_frame";
  camera.transform.rotation.w = 1.0;
  broadcaster.sendTransform(camera);
  call("cvo_odometry/reset");
  const std::size_t before = odometry().size();
  publish(0, t0 + 10.0);
  publish(1, t0 + 10.0 + dt);
  ASSERT_EQ(waitFor(8), 8u);
  ASSERT_EQ(odometry().size(), before + 2);
  const Eigen::Vector3d camera_axes = position(before + 1);
  Eigen::Matrix3d base_from_optical;  // REP-103: optical z forward = base x, optical y down
  base_from_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Vector3d expected = base_from_optical.transpose() * assumed_axes;
  EXPECT_LT((camera_axes - expected).norm(), 1e-6)
      << "camera axes " << camera_axes.transpose() << ", assumed " << assumed_axes.transpose();
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_node_services");
}
