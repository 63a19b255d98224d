#include "cvo_odometry/core/frame_to_frame_odometry.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/tracking_check.hpp"

namespace cvo {

std::string toString(TrackingState state) {
  switch (state) {
    case TrackingState::kFirstFrame:
      return "first_frame";
    case TrackingState::kTracking:
      return "tracking";
    case TrackingState::kRecovered:
      return "recovered";
    case TrackingState::kLost:
      return "lost";
    default:
      return "reset";
  }
}

FrameToFrameOdometry::FrameToFrameOdometry(const CvoParams& params,
                                           std::unique_ptr<RegistrationBackend> backend)
    : registration_(params, std::move(backend)) {}

void FrameToFrameOdometry::reset() {
  reference_.reset();
  reference_self_.reset();
  last_stamp_.reset();
  last_motion_.reset();
  pose_.setIdentity();
  reference_pose_.setIdentity();
  last_dt_ = 0.0;
  lost_frames_ = 0;
}

void FrameToFrameOdometry::setParams(const CvoParams& params) {
  registration_.setParams(params);
  reference_self_.reset();  // the kernels may have changed
}

void FrameToFrameOdometry::checkStamp(double stamp) const {
  if (last_stamp_ && !(stamp > *last_stamp_)) {
    throw std::invalid_argument("frame time " + std::to_string(stamp) +
                                " is not after the previous frame's " +
                                std::to_string(*last_stamp_) + "; reset the odometry first");
  }
}

Eigen::Isometry3d FrameToFrameOdometry::predictedMotion(double dt) const {
  if (!last_motion_) return Eigen::Isometry3d::Identity();
  return lie::expSE3(lie::logSE3(*last_motion_) * (dt / last_dt_));
}

FrameToFrameOdometry::Attempt FrameToFrameOdometry::attempt(const LabeledCloud& cloud,
                                                            const Eigen::Isometry3d& guess,
                                                            bool first_frame, double dt) {
  Attempt a;
  a.result = registration_.align(*reference_, cloud, guess, first_frame);
  const RegistrationReport& report = a.result.report;
  // cos = F_XZ / sqrt(F_XX F_ZZ). F_XZ comes with the report (the indicator times
  // sqrt(|X||Z|)); F_XX was the previous frame's F_ZZ. No pairs in reach: nothing to take.
  const double ell = report.final_lengthscale;
  if (ell > 0.0) {
    const double cross =
        report.indicator_after * std::sqrt(static_cast<double>(reference_->size()) * cloud.size());
    if (!source_self_ || source_self_->first != ell) {
      source_self_.emplace(ell, registration_.selfProduct(cloud, ell));
    }
    a.cosine = cross / std::sqrt(referenceSelfProduct(ell) * source_self_->second);
  }
  const TrackingCheck check =
      checkRegistration(report, a.cosine, a.result.transform, dt, registration_.params());
  a.good = check.good;
  a.problems = check.problems;
  // Only a registration judged good is refined: the stage starts from CVO's pose, and a bad
  // attempt is retried or lost anyway, so its image alignment would be wasted.
  if (a.good && registration_.params().photometric_rotation) {
    if (reference_->image() && cloud.image()) {
      PhotometricRotationResult refined = refineRotationPhotometrically(
          *reference_->image(), *cloud.image(), cloud, a.result.transform, registration_.params());
      a.result.transform = refined.transform;
      a.photometric = refined.report;
    } else {
      a.photometric.skipped = "the clouds carry no image";
    }
  }
  return a;
}

double FrameToFrameOdometry::referenceSelfProduct(double ell) {
  if (!reference_self_ || reference_self_->first != ell) {
    reference_self_.emplace(ell, registration_.selfProduct(*reference_, ell));
  }
  return reference_self_->second;
}

OdometryUpdate FrameToFrameOdometry::process(double stamp, LabeledCloud cloud) {
  checkStamp(stamp);
  source_self_.reset();
  if (!reference_) return startFrom(stamp, std::move(cloud), "");
  OdometryUpdate update;
  update.stamp = stamp;
  update.dt = stamp - reference_stamp_;
  update.reference_points = reference_->size();
  const TrackingCheck counts =
      checkPointCounts(reference_->size(), cloud.size(), registration_.params());
  if (!counts.good) {
    lose(update, std::move(cloud), counts.problems);
    return update;
  }
  const bool first_registration = !last_motion_.has_value();
  Attempt first = attempt(cloud, predictedMotion(update.dt), first_registration, update.dt);
  update.attempts = 1;
  if (!first.good && !first_registration) {
    // Recovery: as at the start of a sequence (identity, first-frame lengthscale).
    Attempt retry = attempt(cloud, Eigen::Isometry3d::Identity(), true, update.dt);
    update.attempts = 2;
    update.problem = first.problems;
    if (retry.good) {
      update.state = TrackingState::kRecovered;
    } else {
      update.problem += "; retry: " + retry.problems;
    }
    first = std::move(retry);
  } else if (!first.good) {
    update.problem = first.problems;
  }
  update.report = first.result.report;
  update.photometric = first.photometric;
  update.cosine = first.cosine;
  if (!first.good) {
    lose(update, std::move(cloud), update.problem);
    return update;
  }
  if (update.state != TrackingState::kRecovered) update.state = TrackingState::kTracking;
  update.motion = first.result.transform;
  accept(update, std::move(cloud));
  return update;
}

OdometryUpdate FrameToFrameOdometry::processLostFrame(double stamp, const std::string& why) {
  checkStamp(stamp);
  if (!reference_) return startFrom(stamp, std::nullopt, why);
  OdometryUpdate update;
  update.stamp = stamp;
  update.dt = stamp - reference_stamp_;
  update.reference_points = reference_->size();
  lose(update, std::nullopt, why);
  return update;
}

OdometryUpdate FrameToFrameOdometry::startFrom(double stamp, std::optional<LabeledCloud> cloud,
                                               const std::string& why) {
  OdometryUpdate update;
  update.stamp = stamp;
  update.state = TrackingState::kFirstFrame;
  update.pose = pose_;
  update.problem = why;
  const auto minimum = static_cast<std::size_t>(registration_.params().min_tracking_points);
  if (cloud && cloud->size() < minimum) {
    // Not worth tracking against: wait for a better first frame, holding the pose.
    update.problem = "too few points for a first frame (" + std::to_string(cloud->size()) + ")";
  }
  setReference(std::move(cloud), stamp);
  last_stamp_ = stamp;
  return update;
}

void FrameToFrameOdometry::setReference(std::optional<LabeledCloud> cloud, double stamp) {
  reference_.reset();
  reference_self_.reset();
  if (cloud &&
      cloud->size() >= static_cast<std::size_t>(registration_.params().min_tracking_points)) {
    reference_ = std::move(*cloud);
    reference_self_ = source_self_;  // F(Z, Z) of this cloud, if its registration computed it
  }
  reference_stamp_ = stamp;
  reference_pose_ = pose_;
}

void FrameToFrameOdometry::accept(OdometryUpdate& update, LabeledCloud cloud) {
  pose_ = lie::orthonormalized(reference_pose_ * update.motion);
  update.pose = pose_;
  last_motion_ = update.motion;
  last_dt_ = update.dt;
  setReference(std::move(cloud), update.stamp);
  last_stamp_ = update.stamp;
  lost_frames_ = 0;
}

void FrameToFrameOdometry::lose(OdometryUpdate& update, std::optional<LabeledCloud> cloud,
                                const std::string& why) {
  const CvoParams& params = registration_.params();
  update.problem = why;
  update.lost_frames = ++lost_frames_;
  update.motion = predictedMotion(update.dt);
  last_stamp_ = update.stamp;
  if (params.lost_frame_policy == LostFramePolicy::kReset ||
      lost_frames_ > params.max_lost_frames) {
    // Restart from this frame. The pose holds (odom must stay continuous) and the velocity is
    // forgotten; a frame with too few points leaves no reference, so the next one starts anew.
    update.state = TrackingState::kReset;
    update.pose = pose_;
    update.has_pose = params.lost_frame_policy != LostFramePolicy::kPublishNothing;
    setReference(std::move(cloud), update.stamp);
    last_motion_.reset();
    lost_frames_ = 0;
    return;
  }
  // Keep the reference: the next frame is registered to the last good one.
  update.state = TrackingState::kLost;
  pose_ = lie::orthonormalized(reference_pose_ * update.motion);
  update.pose = pose_;
  update.has_pose = params.lost_frame_policy == LostFramePolicy::kKeepGuess;
}

}  // namespace cvo
