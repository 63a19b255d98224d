// Frame-to-frame odometry over CVO: each new cloud is registered to the reference, the last
// frame judged good. The first registration of a sequence starts from identity with the
// first-frame lengthscale; later ones from the reference's motion scaled to the new interval
// (constant velocity). Every registration is judged (see tracking_check.hpp); a bad one is
// retried from identity with the first-frame lengthscale, and a frame that fails both is lost:
// CvoParams::lost_frame_policy says what its pose is.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "cvo_odometry/core/cvo_registration.hpp"
#include "cvo_odometry/core/photometric_rotation.hpp"

namespace cvo {

enum class TrackingState {
  kFirstFrame,  // no reference yet: the frame becomes it, no registration
  kTracking,    // registered and judged good
  kRecovered,   // the first registration was bad, the retry good
  kLost,        // no trusted registration: the pose is the constant-velocity guess
  kReset        // lost, and tracking restarts from this frame, holding the last pose
};

std::string toString(TrackingState state);

struct OdometryUpdate {
  TrackingState state = TrackingState::kFirstFrame;
  // False for a lost frame under LostFramePolicy::kPublishNothing: report no pose.
  bool has_pose = true;
  double stamp = 0.0;
  double dt = 0.0;                                           // seconds since the reference frame
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();    // start <- current
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();  // reference <- current
  RegistrationReport report;      // of the registration used (the retry's after a retry)
  PhotometricReport photometric;  // of the photometric stage (run on a good registration)
  double cosine = 0.0;            // at the result and final lengthscale; 0 without a registration
  int attempts = 0;               // registrations run for this frame: 0, 1 or 2
  int lost_frames = 0;            // consecutive lost frames up to and including this one
  std::string problem;            // why a registration was judged bad (also after a recovery)
  // Points of the reference the frame was registered to.
  std::size_t reference_points = 0;

  bool firstFrame() const { return state == TrackingState::kFirstFrame; }
  // The pose comes from a registration judged good (or is the start of a trajectory).
  bool trusted() const {
    return state == TrackingState::kTracking || state == TrackingState::kRecovered ||
           (firstFrame() && problem.empty());
  }
};

class FrameToFrameOdometry {
 public:
  explicit FrameToFrameOdometry(const CvoParams& params,
                                std::unique_ptr<RegistrationBackend> backend = nullptr);

  // Throws std::invalid_argument if `stamp` is not after the previous frame's (call reset()
  // first for a new sequence), or for clouds the registration rejects (non-finite points,
  // missing features). A cloud with too few points is a lost frame, not an error.
  OdometryUpdate process(double stamp, LabeledCloud cloud);
  // A frame that produced no cloud (e.g. no valid depth): lost, for `why`.
  OdometryUpdate processLostFrame(double stamp, const std::string& why);
  // Forgets everything: the next frame starts a new trajectory at identity.
  void reset();

  // New parameters from the next frame on (see CvoRegistration::setParams).
  void setParams(const CvoParams& params);

  CvoRegistration& registration() { return registration_; }
  bool hasReference() const { return reference_.has_value(); }
  // The cloud the next frame will be registered to, or null.
  const LabeledCloud* referenceCloud() const { return reference_ ? &*reference_ : nullptr; }

 private:
  struct Attempt {
    RegistrationResult result;
    PhotometricReport photometric;
    double cosine = 0.0;
    std::string problems;
    bool good = false;
  };
  Attempt attempt(const LabeledCloud& cloud, const Eigen::Isometry3d& guess, bool first_frame,
                  double dt);
  // F(X, X) of the reference at `ell`, computed once per reference and lengthscale.
  double referenceSelfProduct(double ell);
  void checkStamp(double stamp) const;
  // A frame without a reference: it becomes the reference (with enough points); the pose holds.
  OdometryUpdate startFrom(double stamp, std::optional<LabeledCloud> cloud, const std::string& why);
  Eigen::Isometry3d predictedMotion(double dt) const;
  void accept(OdometryUpdate& update, LabeledCloud cloud);
  // `cloud` becomes the reference at the current pose; none when it is missing or has fewer
  // than min_tracking_points.
  void setReference(std::optional<LabeledCloud> cloud, double stamp);
  void lose(OdometryUpdate& update, std::optional<LabeledCloud> cloud, const std::string& why);

  CvoRegistration registration_;
  std::optional<LabeledCloud> reference_;
  // (lengthscale, F(X, X)) of reference_, and of the cloud being registered.
  std::optional<std::pair<double, double>> reference_self_, source_self_;
  double reference_stamp_ = 0.0;
  Eigen::Isometry3d reference_pose_ = Eigen::Isometry3d::Identity();
  std::optional<double> last_stamp_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();  // the latest estimate
  std::optional<Eigen::Isometry3d> last_motion_;            // of the last good registration
  double last_dt_ = 0.0;
  int lost_frames_ = 0;
};

}  // namespace cvo
