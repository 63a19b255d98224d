// rostest node: the nodelet on simulated time, driven by this node's /clock, live (only the
// newest frame waits) with the ordered synchronization, as a bag played with --clock or a
// simulator drives it:
// - the odom rate diagnostic says "starting" (OK) at first, not "too low" as diagnostic_updater's
//   frequency status did (its window began at time 0, before /clock came), starts over when time
//   goes backwards, measures the rate once a whole window is watched, and warns once the odometry
//   stops;
// - the first frames of a start and of a reset, which wait for the learned colour/depth offset,
//   are all used (none dropped for latency), each with its own depth;
// - a frame stamped far from the node's clock has no latency (NaN) and the diagnostics say why.
// Time only moves when this node moves it, so nothing depends on the machine's speed.
#include <atomic>
#include <cmath>
#include <mutex>
#include <string>
#include <thread>

#include <rosgraph_msgs/Clock.h>
#include <std_srvs/Empty.h>

#include "rostest_main.hpp"
#include "tum_topic_driver.hpp"

namespace {

struct Status {
  int level = 0;
  std::string message;
  std::map<std::string, std::string> values;
};

class SimTime : public cvo_test::TumTopicDriver {
 protected:
  void SetUp() override {
    clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
    status_sub_ = nh_.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
          std::lock_guard<std::mutex> lock(record_.mutex);
          nodelet_clock_ = msg->header.stamp.toSec();
          for (const auto& status : msg->status) {
            Status s;
            s.level = status.level;
            s.message = status.message;
            for (const auto& kv : status.values)
              s.values[kv.key] = kv.value;
            if (ends(status.name, "odom topic status")) rate_.push_back(s);
            if (ends(status.name, ": odometry")) odometry_status_.push_back(s);
          }
        });
    clock_thread_ = std::thread([this] {
      // Published again and again (a late subscriber gets it); moving only in free run.
      while (!stop_) {
        {
          std::lock_guard<std::mutex> lock(clock_mutex_);
          if (free_run_) now_ = now_ + 0.01;
          publishClockLocked();
        }
        ros::WallDuration(0.01).sleep();
      }
    });
  }
  void TearDown() override {
    stop_ = true;
    clock_thread_.join();
  }

  static bool ends(const std::string& text, const std::string& tail) {
    return text.size() >= tail.size() &&
           text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
  }
  // Under clock_mutex_: reading the time and publishing it are one step, so that this thread and
  // the clock thread never publish an older time after a newer one (the nodelet's clock would go
  // back for a moment and a frame would arrive at the old time).
  void publishClockLocked() {
    rosgraph_msgs::Clock clock;
    clock.clock = ros::Time(now_.load());
    clock_pub_.publish(clock);
  }
  void setClock(double now) {
    std::lock_guard<std::mutex> lock(clock_mutex_);
    free_run_ = false;
    now_ = now;
    publishClockLocked();
  }

  // Waits until the nodelet's diagnostics are stamped at `now` or later: its clock has come
  // there (they are published at every second of its clock).
  bool waitForNodeletClock(double now) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kEventTimeout);
    while (ros::WallTime::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(record_.mutex);
        if (nodelet_clock_ >= now) return true;
      }
      ros::WallDuration(0.05).sleep();
    }
    return false;
  }

  std::vector<Status> rateStatuses() {
    std::lock_guard<std::mutex> lock(record_.mutex);
    return rate_;
  }
  // Waits (moving the clock by `step` s every 0.1 s when step > 0) until a rate status from
  // index `from` on satisfies `ready`; returns its index, or -1.
  template <class Ready>
  long waitForRate(std::size_t from, Ready ready, double step = 0.0) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kEventTimeout);
    while (ros::WallTime::now() < deadline) {
      const auto statuses = rateStatuses();
      for (std::size_t k = from; k < statuses.size(); ++k)
        if (ready(statuses[k])) return static_cast<long>(k);
      if (step > 0.0) setClock(now_ + step);
      ros::WallDuration(0.1).sleep();
    }
    return -1;
  }
  // The diagnostics' value of `key` once `ready`, moving the clock so that they are published.
  template <class Ready>
  std::string waitForValue(const std::string& key, Ready ready) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kEventTimeout);
    std::string value;
    while (ros::WallTime::now() < deadline) {
      value = diagnostic(key);
      if (!value.empty() && ready(value)) break;
      setClock(now_ + 0.5);
      ros::WallDuration(0.1).sleep();
    }
    return value;
  }

  // Frame k of the fixture with its colour stamp at `colour_stamp` and its depth as far from it
  // as the camera stamped them (12-20 ms older); the clock is set to the colour stamp first.
  double publishAt(std::size_t k, double colour_stamp) {
    const auto& f = sequence_.frames()[k];
    const double depth_stamp = colour_stamp + (f.depth_stamp - f.rgb_stamp);
    setClock(colour_stamp);
    publish(colour(k, colour_stamp), depth(k, depth_stamp));
    return depth_stamp;
  }

  const cvo::TumSequence sequence_{std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz"};
  ros::Publisher clock_pub_;
  ros::Subscriber status_sub_;
  std::vector<Status> rate_, odometry_status_;
  // The latest diagnostics' stamp (not the largest: the clock goes back to 1000 after 2000).
  double nodelet_clock_ = 0.0;
  std::mutex clock_mutex_;
  std::atomic<double> now_{0.0};
  std::atomic<bool> free_run_{false}, stop_{false};
  std::thread clock_thread_;
};

TEST_F(SimTime, RateFirstFramesAndStampsFarFromTheClock) {
  // No /clock yet: the nodelet's time is 0. Its diagnostics reach this node before time starts.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kConnectTimeout);
  while (status_sub_.getNumPublishers() == 0 && ros::WallTime::now() < deadline)
    ros::WallDuration(0.1).sleep();
  ASSERT_GT(status_sub_.getNumPublishers(), 0u);
  // The clock starts decades after 0, as a bag's does, and runs while this node connects.
  {
    std::lock_guard<std::mutex> lock(clock_mutex_);
    now_ = 2000.0;
    free_run_ = true;
  }
  std::vector<std::size_t> frames;
  for (std::size_t k = 0; k < 22; ++k)
    frames.push_back(k);
  ASSERT_NO_FATAL_FAILURE(connect(frames, false));
  const auto first = rateStatuses();
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first.front().level, diagnostic_msgs::DiagnosticStatus::OK) << first.front().message;
  EXPECT_EQ(first.front().message.rfind("starting", 0), 0u) << first.front().message;

  // Time goes back to 1000 (a bag's loop): the rate is measured afresh.
  setClock(1000.0);
  const long jumped = waitForRate(
      first.size(),
      [](const Status& s) { return s.message.find("backwards") != std::string::npos; }, 0.5);
  ASSERT_GE(jumped, 0) << "no rate status after time went backwards";

  // The first five frames wait for the colour/depth offset, then come together: all used, none
  // dropped for latency, each with its own depth.
  double t = now_;
  std::vector<double> depth_stamps;
  for (std::size_t k = 0; k < 5; ++k)
    depth_stamps.push_back(publishAt(k, t += 0.5));
  if (waitFor(5) != 5u) {  // say what happened to them
    setClock(now_ + 1.0);
    waitForNodeletClock(now_);
  }
  ASSERT_EQ(waitFor(5), 5u) << "the first frames of a start were not all used: "
                            << diagnostic("frames") << " processed, "
                            << diagnostic("frames dropped for latency") << " dropped, "
                            << diagnostic("frames not synchronized") << " not synchronized, "
                            << diagnostic("skipped frames") << " skipped ("
                            << diagnostic("latest skip reason") << ")";
  EXPECT_TRUE(indicator(0).first_frame);
  EXPECT_EQ(indicator(4).dropped_frames, 0u);
  // Then one at a time, at 2 Hz of this clock, for more than a window.
  for (std::size_t k = 5; k < 16; ++k) {
    depth_stamps.push_back(publishAt(k, t += 0.5));
    ASSERT_EQ(waitFor(k + 1), k + 1) << "frame " << k;
  }
  for (std::size_t k = 0; k < 16; ++k) {
    EXPECT_NEAR(indicator(k).header.stamp.toSec(), depth_stamps[k], 1e-6) << "frame " << k;
    EXPECT_TRUE(std::isfinite(indicator(k).latency_ms)) << "frame " << k;
  }
  EXPECT_EQ(indicator(15).dropped_frames, 0u);
  // A measured rate, and no warning since time went back.
  const long measured = waitForRate(
      static_cast<std::size_t>(jumped),
      [](const Status& s) { return s.values.count("Actual frequency (Hz)") > 0; }, 0.5);
  ASSERT_GE(measured, 0) << "no measured rate after a whole window";
  {
    const auto statuses = rateStatuses();
    for (std::size_t k = static_cast<std::size_t>(jumped); k <= static_cast<std::size_t>(measured);
         ++k)
      EXPECT_EQ(statuses[k].level, diagnostic_msgs::DiagnosticStatus::OK) << statuses[k].message;
    const double hz = std::stod(statuses[measured].values.at("Actual frequency (Hz)"));
    EXPECT_GT(hz, 1.0) << statuses[measured].message;
    EXPECT_LT(hz, 4.0) << statuses[measured].message;
  }
  // The odometry stops: once a window holds nothing, the rate is too low.
  const long silent = waitForRate(
      static_cast<std::size_t>(measured),
      [](const Status& s) { return s.message.find("too low") != std::string::npos; }, 1.0);
  ASSERT_GE(silent, 0) << "no warning after the odometry stopped";
  EXPECT_EQ(rateStatuses()[silent].level, diagnostic_msgs::DiagnosticStatus::WARN);

  // A reset: the offset is learned again, and the first frames after it are all used too.
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::waitForService("cvo_odometry/reset", ros::Duration(kEventTimeout)));
  ASSERT_TRUE(ros::service::call("cvo_odometry/reset", reset));
  t = now_ + 0.5;
  for (std::size_t k = 16; k < 21; ++k)
    depth_stamps.push_back(publishAt(k, t += 0.5));
  ASSERT_EQ(waitFor(21), 21u) << "the first frames after a reset were not all used";
  EXPECT_TRUE(indicator(16).first_frame);
  EXPECT_EQ(indicator(20).dropped_frames, 0u);
  for (std::size_t k = 16; k < 21; ++k)
    EXPECT_NEAR(indicator(k).header.stamp.toSec(), depth_stamps[k], 1e-6) << "frame " << k;
  EXPECT_EQ(waitForValue("frames", [](const std::string& v) { return v == "21"; }), "21");
  EXPECT_EQ(diagnostic("frames dropped for latency"), "0");

  // The clock 100 s ahead of the stamps (a bag played without --clock, the other way round):
  // the frame is processed, its latency unknown, the diagnostics say why.
  setClock(t + 100.0);
  ASSERT_TRUE(waitForNodeletClock(t + 100.0));
  publish(colour(21, t + 0.5), depth(21, t + 0.5 - 0.015));
  ASSERT_EQ(waitFor(22), 22u);
  EXPECT_TRUE(std::isnan(indicator(21).latency_ms)) << indicator(21).latency_ms;
  // Diagnostics from after it was processed.
  ASSERT_EQ(waitForValue("frames", [](const std::string& v) { return v == "22"; }), "22");
  const std::string offset = diagnostic("clock - stamp at arrival (s)");
  ASSERT_NE(offset, "none yet");
  EXPECT_NEAR(std::stod(offset), 99.5, 0.6);
  EXPECT_EQ(diagnostic("latency (ms, stamp to publish)").rfind("unknown", 0), 0u);
  std::lock_guard<std::mutex> lock(record_.mutex);
  ASSERT_FALSE(odometry_status_.empty());
  const Status& latest = odometry_status_.back();
  EXPECT_EQ(latest.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(latest.message.find("behind this node's clock"), std::string::npos) << latest.message;
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_sim_time");
}
