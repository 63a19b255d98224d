// Keyframe odometry over CVO, the pipeline's core: each cloud is registered to the reference (the
// keyframe, or the previous good frame), judged (tracking_check.hpp), and chained into a pose
// with its covariance on SE(3) (pose_covariance.hpp) in the camera and the base frame.
//
// Guesses (CvoParams::initial_guess): the feature prior (previous <- current from tracked
// corners, when confident, applied to the previous frame's pose), constant velocity (the last good
// motion rate from the previous frame's pose), or none (the previous frame's pose, at the
// first-frame lengthscale). In auto, a confident prior is used; when it and constant velocity
// disagree by more than a bound both are tried and the better registration kept. A bad registration
// is retried from the guess not yet tried (prior, then none); if that fails too the frame is lost
// and CvoParams::lost_frame_policy says what its pose is. A registration is good only when it
// converged, its cosine and speed are plausible and, with enough inlier tracks to judge, the
// tracks agree with it.
#pragma once

#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "cvo_odometry/core/block_pool.hpp"
#include "cvo_odometry/core/cvo_registration.hpp"
#include "cvo_odometry/core/motion_prior.hpp"
#include "cvo_odometry/core/motion_split.hpp"
#include "cvo_odometry/core/photometric_rotation.hpp"
#include "cvo_odometry/core/voxel_grid.hpp"

namespace cvo {

enum class TrackingState {
  kFirstFrame,  // no reference yet: the frame becomes it, no registration
  kTracking,    // registered and judged good
  kRecovered,   // the first registration was bad, a retry good
  kLost,        // no trusted registration: the pose is a guess
  kReset        // lost, and tracking restarts from this frame, holding the last pose
};

std::string toString(TrackingState state);

// Which guess a registration started from.
enum class GuessKind { kNone, kConstantVelocity, kFeatures, kIdentity };
std::string toString(GuessKind guess);

// One frame for the odometry.
struct OdometryFrame {
  double stamp = 0.0;
  std::shared_ptr<const LabeledCloud> cloud;  // null: the front end found nothing to track
  std::string why_no_cloud;
  std::optional<MotionPrior> prior;  // previous frame <- current from feature tracks
  // The segmentation left pixels of moving classes out of this frame (cloud, tracks, images).
  bool moving_classes_left_out = false;
  // base <- camera; taken at the first frame of a trajectory (after a reset).
  Eigen::Isometry3d base_from_camera = Eigen::Isometry3d::Identity();
};

struct OdometryUpdate {
  TrackingState state = TrackingState::kFirstFrame;
  // False for a lost frame under LostFramePolicy::kPublishNothing: report no pose.
  bool has_pose = true;
  double stamp = 0.0;
  double dt = 0.0;                                           // seconds since the reference frame
  double frame_interval = 0.0;                               // seconds since the previous frame
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();    // start <- current (camera)
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();  // reference <- current (camera)
  RegistrationReport report;                                 // of the registration used
  PhotometricReport photometric;  // of the photometric stage (run on a good registration)
  double cosine = 0.0;            // at the result and final lengthscale; 0 without a registration
  int attempts = 0;               // registrations run for this frame
  int lost_frames = 0;            // consecutive lost frames up to and including this one
  std::string problem;            // why a registration was judged bad (also after a recovery)
  std::size_t reference_points = 0;
  bool new_keyframe = false;             // this frame is the reference from now on
  GuessKind guess = GuessKind::kNone;    // of the registration used
  double track_agreement = -1.0;         // of the registration used; -1: not judged
  double track_error_px = -1.0;          // its median reprojection error of the prior's inliers
  double track_flow_px = -1.0;           // their median image motion over the step
  double track_rotation_gap_deg = -1.0;  // the pose's turn over the step against the tracks'
  // A second motion among the tracks (an object moving through the view): its inlier tracks (0:
  // none), whether the frame's registration from it stayed there (a motion of its own), and the
  // share of the frame's cloud left out as its region.
  int second_motion_tracks = 0;
  bool second_motion_separate = false;
  double left_out_share = 0.0;
  std::string motion_split;  // how the scene's motion was told from the object's, if it was
  // The object's region in this frame's image (left out of its cloud), or null.
  std::shared_ptr<const PixelRegion> moving_region;
  // The next frame's feature tracks start from this one: a trusted frame, a lost one placed by a
  // confident prior that the next frame is registered to, or a restart (beside something moving,
  // one whose last trusted frame is too far back for its tracks to judge;
  // FeatureTracker::frameJudged). Else from the last such frame.
  bool restart_tracks = false;
  // In the base frame (REP-105: odom <- base_link), base = base_from_camera of the trajectory.
  Eigen::Isometry3d base_pose = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d base_frame_motion = Eigen::Isometry3d::Identity();  // previous <- current
  Matrix6d pose_covariance = Matrix6d::Zero();   // about odom's axes, [x y z rx ry rz]
  Matrix6d twist_covariance = Matrix6d::Zero();  // in the base frame, per s^2

  bool firstFrame() const { return state == TrackingState::kFirstFrame; }
  // The pose comes from a registration judged good (or is the start of a trajectory).
  bool trusted() const {
    return state == TrackingState::kTracking || state == TrackingState::kRecovered ||
           (firstFrame() && problem.empty());
  }
  // Linear (m/s) and angular (rad/s) velocity in the base frame over the frame interval.
  Vector6d baseTwist() const;
};

class KeyframeOdometry {
 public:
  explicit KeyframeOdometry(const CvoParams& params,
                            std::unique_ptr<RegistrationBackend> backend = nullptr);

  // Throws std::invalid_argument if the stamp is not after the previous frame's (reset() first
  // for a new sequence), or for clouds the registration rejects (non-finite points, missing
  // features). A missing cloud or one with too few points is a lost frame, not an error.
  OdometryUpdate process(OdometryFrame frame);
  OdometryUpdate process(double stamp, LabeledCloud cloud);
  // A frame that produced no cloud (e.g. no valid depth): lost, for `why`.
  OdometryUpdate processLostFrame(double stamp, const std::string& why);
  // Forgets everything: the next frame starts a new trajectory with the base at `base_pose`.
  void reset(const Eigen::Isometry3d& base_pose = Eigen::Isometry3d::Identity());

  // New parameters from the next frame on (see CvoRegistration::setParams).
  void setParams(const CvoParams& params);
  // The front end builds depths differently from now on (a new stereo disparity offset): the
  // reference, and the last good frame kept for a fallback, are moved to what they would have
  // been, each point along its ray to depth new_depth(z) (LabeledCloud::withDepths), so the next
  // frame is registered to a reference built as it is.
  void remapDepths(const std::function<float(float)>& new_depth);
  // At most `threads` CPU threads for the registration and the photometric stage from the next
  // frame on (ThreadGovernor; clamped to [1, num_threads]); the results do not change.
  void setThreadLimit(int threads);

  CvoRegistration& registration() { return registration_; }
  const CvoParams& params() const { return registration_.params(); }
  bool hasReference() const { return reference_ != nullptr; }
  // The cloud the next frame will be registered to, or null.
  const std::shared_ptr<const LabeledCloud>& referenceCloud() const { return reference_; }
  std::optional<double> lastStamp() const { return last_stamp_; }

 private:
  struct Attempt {
    RegistrationResult result;
    PhotometricReport photometric;
    GuessKind guess = GuessKind::kNone;
    double cosine = 0.0;
    double agreement = -1.0;
    double track_error_px = -1.0;
    double track_flow_px = -1.0;
    double track_rotation_gap_deg = -1.0;
    std::string problems;
    bool good = false;
    // The share of the cloud's points left out as not following the tracks' motion (an attempt
    // with the consistent points only), else -1.
    double left_out_share = -1.0;
  };
  struct Guess {
    GuessKind kind;
    Eigen::Isometry3d motion;  // reference <- current
  };
  // The last frame judged good: where a frame falls back to when the keyframe is out of reach.
  struct GoodFrame {
    std::shared_ptr<const LabeledCloud> cloud;
    double stamp = 0.0;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    Matrix6d covariance = Matrix6d::Zero();
  };
  // A registration of `cloud` to reference_ from `guess`, judged; `judge_view`: also refused
  // when it explains too little of the view (viewUnexplained).
  Attempt attempt(const LabeledCloud& cloud, const Guess& guess, const OdometryFrame& frame,
                  double dt, bool judge_view = true);
  // The segmentation left pixels of ignored classes out of `cloud` (this frame's) or the
  // reference: the registration then ends at ell_min times ell_min_ratio_with_ignored.
  bool ignoredPixelsLeftOut(const LabeledCloud& cloud) const;
  // The guesses to try, in order, and those kept for a retry.
  void chooseGuesses(const OdometryFrame& frame, double interval, std::vector<Guess>* first,
                     std::vector<Guess>* retries) const;
  bool priorConfident(const std::optional<MotionPrior>& prior) const;
  // The prior's motion as a step from the reference (reference <- current): it moves the camera
  // from the pose of the frame its tracks start from.
  Eigen::Isometry3d priorMotionFromReference(const MotionPrior& prior) const;
  // The prior's second motion is an object moving on its own: min_prior_inliers tracks, and
  // its motion moves the tracks at least moving_min_px from where the first puts them.
  bool separateSecondMotion(const std::optional<MotionPrior>& prior) const;
  // `cloud` without the points within moving_region_px of `pixels` (an object's tracks, in the
  // image of the prior's camera), which it keeps as its left-out region.
  std::shared_ptr<const LabeledCloud> withoutRegion(
      const std::shared_ptr<const LabeledCloud>& cloud, const MotionPrior& prior,
      const std::vector<Eigen::Vector2f, Eigen::aligned_allocator<Eigen::Vector2f>>& pixels) const;
  // The object's region left out of the reference too, where it is the frame the prior's
  // tracks start from and still whole.
  void leaveOutObjectFromReference(const MotionPrior& prior, const MotionSplit& split);
  // The reference's and the cloud's points that the tracks' motion (frame.prior, which must be
  // confident) puts near a point of the other, and a registration of those alone from that
  // motion. Points that do not follow the scene's motion (a moving object without corners of its
  // own: its leading and trailing edges, and all of it once it moved off its place in the
  // keyframe) are left out. Null when too few are left, or when what is left out may be the
  // scene (not nearer than what is kept, the tracks' motion not told from another's).
  std::optional<Attempt> attemptWithConsistentPoints(const LabeledCloud& cloud,
                                                     const OdometryFrame& frame, double dt);
  // The prior's second motion checked and, when it is an object moving on its own, the scene's
  // motion made the prior's first and the object's region left out of the frame's cloud. Why the
  // frame cannot be trusted (which motion the scene follows is unknown), or empty.
  std::string judgeSecondMotion(OdometryFrame& frame);
  // Why the scene may not follow the motion it is taken to (sceneBehindItsMotion), kept as an
  // undecided split; empty when nothing says so.
  std::string judgeSceneBehind(const OdometryFrame& frame, bool scene_is_second);
  // Why a frame whose tracks start where those of an undecided split did cannot be trusted:
  // its inliers are one side of that split (the other's tracks gone or refused), whose motion is
  // the scene's as likely as the object's. Empty otherwise.
  std::string oneSideOfUndecidedSplit(const OdometryFrame& frame) const;
  // The next frame's tracks start from this one (update.restart_tracks), and the frames since
  // their start are counted from it.
  void tracksStartHere(OdometryUpdate& update);
  // Enough inliers to contradict a registration, even at a ratio too low to be a guess.
  bool priorJudges(const std::optional<MotionPrior>& prior) const;
  // initial_guess lets a confident feature prior's motion be where registrations start.
  bool priorGuesses() const;
  // F(X, X) of the reference at `ell`, computed once per reference and lengthscale.
  double referenceSelfProduct(double ell);
  // A grid over the reference's points for consistency queries, built again only when
  // reference_ is another cloud.
  const VoxelGrid& referenceGrid();
  // Why `reference_from_cloud` cannot be the scene's motion: it brings too few of the cloud's
  // points near the reference's, hardly more than the reference's own pose does. Empty when
  // it explains enough of the view.
  std::string viewUnexplained(const LabeledCloud& cloud,
                              const Eigen::Isometry3d& reference_from_cloud);
  void checkStamp(double stamp) const;
  // A frame without a reference: it becomes the reference (with enough points); the pose holds.
  OdometryUpdate startFrom(const OdometryFrame& frame);
  // reference <- current if the camera kept its velocity since the previous frame.
  std::optional<Eigen::Isometry3d> constantVelocityMotion(double interval) const;
  // Something moved in view within kMovingMemorySeconds before `stamp` (moving_seen_stamp_).
  bool movedLately(double stamp) const;
  Eigen::Isometry3d stillMotion() const;  // reference <- previous frame
  // start <- the frame the prior's tracks start from, when its pose means something.
  std::optional<Eigen::Isometry3d> priorFramePose(const MotionPrior& prior) const;
  // The pose `reference_from_current` against the prior's tracks' motion over the same step
  // (tracks' frame <- current, composed with the motion's inverse): identity where they agree.
  Eigen::Isometry3d gapToTracks(const MotionPrior& prior,
                                const Eigen::Isometry3d& reference_from_current) const;
  // Why a pose recovered against the last good frame is not trusted; empty when it is.
  std::string recoveredPoseProblem(const MotionPrior& prior,
                                   const Eigen::Isometry3d& reference_from_current) const;
  void accept(OdometryUpdate& update, Attempt& chosen, const OdometryFrame& frame);
  bool wantsKeyframe(const OdometryUpdate& update) const;
  // `cloud` becomes the reference at the current pose; none when it is missing or has fewer
  // than min_tracking_points.
  void setReference(const std::shared_ptr<const LabeledCloud>& cloud, double stamp);
  void setReference(const GoodFrame& frame);
  void lose(OdometryUpdate& update, const OdometryFrame& frame, const std::string& why);
  // The base-frame pose, motion and covariances of `update` from the camera-frame chain.
  void fillBaseFrame(OdometryUpdate& update, const Matrix6d& motion_covariance);

  CvoRegistration registration_;
  BlockPool photometric_pool_;  // num_threads threads for the photometric stage
  std::shared_ptr<const LabeledCloud> reference_;
  // referenceGrid()'s grid and the cloud it was built over.
  VoxelGrid reference_grid_;
  std::weak_ptr<const LabeledCloud> reference_grid_cloud_;
  // The reference is a lost frame: its pose a guess (constant velocity, a prior, or held at a
  // restart), not a registration's.
  bool reference_guessed_ = false;
  // When something last moved in view: a second motion of its own among the tracks, or tracks
  // that refused a registration.
  std::optional<double> moving_seen_stamp_;
  std::optional<MotionSplit> split_;  // of the frame being processed, when it was split
  bool trusted_since_start_ = false;  // a frame was trusted since the last (re)start
  // The tracks of the last split left undecided, by their start points (the camera frame of
  // the frame they start from) and the motion each followed (MotionSplit::owner).
  struct UndecidedSplit {
    double from_stamp = 0.0;
    std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> points;
    std::vector<int> owner;
  };
  std::optional<UndecidedSplit> undecided_split_;
  // The frame being processed came with feature tracks (a prior), judging or not.
  bool frame_has_tracks_ = false;
  // start <- the frame the processed frame's prior starts from (valid while it has one).
  Eigen::Isometry3d prior_frame_pose_ = Eigen::Isometry3d::Identity();
  // (lengthscale, F(X, X)) of reference_, and of the cloud being registered.
  std::optional<std::pair<double, double>> reference_self_, source_self_;
  double reference_stamp_ = 0.0;
  std::optional<double> reference_first_cosine_;  // of the first frame registered to it
  std::optional<GoodFrame> last_good_;
  Eigen::Isometry3d reference_pose_ = Eigen::Isometry3d::Identity();
  Matrix6d reference_covariance_ = Matrix6d::Zero();
  std::optional<double> last_stamp_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();  // the latest estimate
  Matrix6d covariance_ = Matrix6d::Zero();                  // of pose_ (body frame)
  // The last good frame-to-frame motion rate (twist per second, [omega; v]).
  std::optional<Vector6d> velocity_;
  // How far (px, on the tracks) the constant-velocity prediction was from the motion trusted,
  // over the last trusted frames: how much a prediction can tell two motions apart.
  std::deque<double> prediction_errors_px_;
  Eigen::Isometry3d last_trusted_pose_ = Eigen::Isometry3d::Identity();
  std::optional<double> last_trusted_stamp_;
  int lost_frames_ = 0;
  // Frames since the one the feature tracks start from (the last trusted one, a lost one placed by
  // its prior, or a restart).
  int frames_since_anchor_ = 0;
  bool previous_placed_by_prior_ = false;  // the last lost frame's pose came from the prior
  bool started_ = false;
  Eigen::Isometry3d base_from_camera_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d start_base_pose_ = Eigen::Isometry3d::Identity();
};

}  // namespace cvo
