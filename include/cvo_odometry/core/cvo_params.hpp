// Every parameter of CVO registration, with the TUM RGB-D reference values as defaults.
// The names follow ../config/*.yaml; see README for what each does.
#pragma once

#include <string>
#include <vector>

#include "cvo_odometry/core/settings_table.hpp"

namespace cvo {

enum class StepMethod {
  kReference,  // the paper: normalised gradient, 4th-order Taylor line search, indicator annealing
  kProcrustes  // default: closed-form weighted Procrustes (MM) step, coarse-to-fine lengthscales
};

// kDeviceCpu: the CUDA backend's device code on OpenMP threads (tests it without a GPU).
enum class BackendChoice { kAuto, kCpu, kCuda, kDeviceCpu };

// What a frame is registered to: the keyframe (changed when overlap or distance demand it) or
// the previous good frame.
enum class ReferenceKind { kKeyframe, kPreviousFrame };

// Where a registration starts (see KeyframeOdometry).
enum class InitialGuess {
  kAuto,              // the feature prior when confident (both when it and constant velocity
                      // disagree), else constant velocity
  kConstantVelocity,  // the last motion, scaled to the interval
  kFeatures,          // the feature prior when confident, else constant velocity
  kIdentity           // no motion since the previous frame
};

// What frame-to-frame odometry does with a frame it judges lost (see FrameToFrameOdometry).
enum class LostFramePolicy {
  kKeepGuess,       // report the constant-velocity guess, flagged, with a grown covariance
  kPublishNothing,  // report no pose for the frame
  kReset            // restart tracking from the frame, holding the last pose
};

// Fewest points a subsampled cloud keeps (coarse levels, the source budget): sparser clouds give
// too few (colour) pairs to steer by.
inline constexpr int kMinSubsampledPoints = 500;

// Every parameter of the core. Names, ranges and meanings: the settings table
// (cvo_settings.hpp, README "Parameters"). Defaults: the RGB-D preset (a Kinect-class camera at
// 30 Hz): the paper's TUM kernels with ell_min 0.02, geometry only, then the photometric stage;
// config/*.yaml state only what they change.
struct CvoParams {
  // Geometric kernel k(x, z) = sigma^2 exp(-|x - z|^2 / (2 ell^2)).
  double ell_init = 0.15;
  double ell_min = 0.02;
  double ell_first_frame = 0.15;
  // From a confident feature prior: TUM fr1_xyz at strides 1 to 12 gives the same errors from
  // 0.15 down to ell_min; at ell_min itself (no annealing) the registration never changes its
  // clouds, and the indicator at the guess is its first sum (README "Motion prior").
  double ell_prior = 0.02;
  // Where ignored classes leave pixels out of a registration's clouds (the frame's or its
  // reference's), the annealing ends at ell_min times this (1: at ell_min). On RGB-D the dense
  // registration sets the translation, and with a third of the view left out it is the more
  // accurate at a smaller lengthscale, where without labels it is the less accurate (doc/
  // moving-objects.md "Lengthscale beside ignored classes").
  double ell_min_ratio_with_ignored = 0.625;
  double sigma = 0.1;
  // A pair counts when its kernel product a_ij exceeds the retain threshold: with sp_ratio > 0,
  // sp_ratio times the largest product the enabled kernels can give (sigma^2 color_sigma^2
  // semantic_sigma^2), so that switching a kernel on or changing an amplitude keeps the same
  // neighbourhood (default 0.3: the paper's 0.003 with geometry only); with sp_ratio 0, the
  // paper's absolute sp_thres.
  // retainThreshold() is the one conversion.
  double sp_ratio = 0.3;
  double sp_thres = 0.003;

  // Appearance kernels, multiplied into the pair weight: colour s_c^2 exp(-|c - c'|^2 / (2
  // ell_c^2)).
  bool use_color = false;
  double color_ell = 0.3;
  double color_sigma = 0.6;
  bool use_semantics = false;
  // Semantic factor s_s^2 (w + (1 - w) cos(p, q)) of class-probability vectors p, q: with hard
  // labels 1 within a class and w across (the paper's exp(-1 / l_s^2): l_s 0.1 gives 0, 1 gives
  // 0.37); probabilities are soft, a uniform vector weighs like semantics off.
  double semantic_cross_weight = 0.0;
  double semantic_sigma = 0.8;

  // Reference annealing: when the retained-pair ratio of the last `indicator_window` iterations is
  // within 1 +- indicator_tolerance of the window before, ell <- max(ell * decay_rate, ell_min).
  double decay_rate = 0.9;
  int decay_start = 10;
  double first_frame_decay_rate = 0.9;
  int first_frame_decay_start = 10;
  int indicator_window = 5;
  double indicator_tolerance = 0.02;

  StepMethod step_method = StepMethod::kProcrustes;
  double min_step = 1e-5;
  double max_step = 0.8;
  double eps_2 = 1.2e-5;
  int max_iterations = 2000;
  // Procrustes schedule: converge loosely at each lengthscale (|step| < level_tolerance * ell),
  // then ell <- max(ell * schedule_decay, ell_min); stop on eps_2 only at ell_min.
  double schedule_decay = 0.7;
  double level_tolerance = 0.01;
  bool subsample_coarse_levels = true;
  double max_overrelaxation = 2.0;
  int max_level_iterations = 30;
  // Procrustes: the registration sums over at most this many points of the source (spread
  // evenly over its order), the target keeping all of its points: the target's function stays as
  // smooth as its density makes it while the cost, linear in the source's points, is capped. 0:
  // all. Measured in README "Source point budget".
  int max_source_points = 4000;
  // Newton steps (analytic gradient and Hessian of sum (a - sp_thres)_+) where the Hessian is
  // negative definite and the step stays within 10x the MM step; after the first Newton step
  // that F does not follow upwards, MM steps only.
  bool newton_at_ell_min = true;

  // The photometric rotation stage after CVO (photometric_rotation.hpp); needs clouds that
  // carry their image (the RGB-D front end attaches it).
  bool photometric_rotation = true;
  int photometric_iterations = 30;
  double photometric_max_correction = 2.0;
  // Keep the stage's translation too (where depth and image are simultaneous: stereo).
  bool photometric_translation = false;
  // The feature prior's inlier tracks join the stage's alignment as reprojection errors, each
  // set weighed by its robust scale (where depth and image are simultaneous: stereo).
  bool photometric_tracks = false;

  BackendChoice backend = BackendChoice::kAuto;
  int num_threads = 0;
  // With more than one thread: one while the process gets no more than about a core (cores
  // shared with other processes), all again when they free up (ThreadGovernor).
  bool adaptive_threads = true;

  // Tracking quality, judged per frame (tracking_check.hpp): a registration is good when it
  // converged, its cosine is >= min_cosine, both clouds have >= min_tracking_points and its
  // motion is within the speed limits over the frame interval.
  double min_cosine = 0.5;
  int min_tracking_points = 300;
  double max_linear_speed = 5.0;
  double max_angular_speed = 180.0;
  LostFramePolicy lost_frame_policy = LostFramePolicy::kKeepGuess;
  int max_lost_frames = 5;

  // Keyframes: a new one when the cosine to it falls below keyframe_cosine_ratio times the
  // cosine of the first frame registered to it (so the rule holds for stereo clouds, whose
  // cosines are low, and RGB-D ones alike), or the camera has moved or turned beyond the bounds
  // since it (README "Keyframes").
  ReferenceKind reference = ReferenceKind::kKeyframe;
  double keyframe_cosine_ratio = 0.7;
  double keyframe_max_translation = 0.1;  // m
  double keyframe_max_rotation = 5.0;     // deg

  // The motion guess and the feature tracks' check (README "Fast motion").
  InitialGuess initial_guess = InitialGuess::kAuto;
  bool forget_motion = false;  // no constant-velocity guess: as after a restart (tests, bench)
  int min_prior_inliers = 20;
  double min_prior_inlier_ratio = 0.3;
  double guess_disagreement_translation = 0.05;  // m
  double guess_disagreement_rotation = 2.0;      // deg
  // A prior with min_prior_inliers inliers, whatever their ratio, judges every registration: at
  // least min_track_agreement of its inliers within track_agreement_px. Only a confident one
  // (min_prior_inlier_ratio too) is a guess and relaxes the cosine.
  double track_agreement_px = 10.0;
  double min_track_agreement = 0.75;
  // ... and its turn over the step within this of the prior's (deg): tracks fix rotation well at
  // any depth (static fixtures: at most 0.22 deg apart), and a pose turned further was pulled by
  // something the tracks do not follow.
  double max_track_rotation_gap = 0.5;
  // ... and while something moved in view lately (a second motion of its own, or registrations
  // the tracks refused, within 2 s), or before a frame since the start is trusted (nothing
  // tells yet whether something moves), at least this fraction of them must agree.
  double moving_track_agreement = 0.9;
  // ... and a registration the tracks judge needs a cosine of only this fraction of min_cosine.
  double tracked_cosine_ratio = 0.25;
  // ... and one scoring below weak_cosine needs its tracks within a median of 0.6
  // track_agreement_px of its pose (0: no such bound). Each sign alone is common in right frames
  // (an RGB-D camera's tracks miss a right pose by 6-9 px where their depth is older than their
  // colour; a keyframe some steps back scores a low cosine), the two together are not. Stereo's
  // cosine falls with range: its preset has none.
  double weak_cosine = 0.7;
  // An object moving through the view shows as a second motion among the tracks (MotionPrior::
  // second). One of min_prior_inliers tracks that moves them at least moving_min_px from where
  // the first puts them is a motion of its own: the scene is the farther tracks' motion when
  // their median depth is motion_split_depth_ratio times the other's, else the one with more
  // tracks when the other has less than motion_split_ratio times as many (motion_split.hpp has
  // the rest; undecided, the frame is not trusted); the other's region, within
  // moving_region_px of its tracks, is left out of the cloud and the photometric stage. The
  // region closes gaps of up to 4x moving_region_px: at 24 px it also took the scene between a
  // board and the image's border and the edges of a monitor beside it (TUM, a checkerboard a
  // third of the view: 63 % of the points left out, 25 of 36 frames lost); 14-20 px keep 34-36.
  // A third motion 1.5 moving_min_px from both others (two objects) loses the frame
  // (thirdMotionSeparate); the tracker searches one only beside a second moving_min_px apart.
  double moving_min_px = 4.0;
  double moving_region_px = 16.0;
  double motion_split_ratio = 0.3;
  double motion_split_depth_ratio = 1.2;

  // Throws std::invalid_argument naming the first parameter that makes no sense.
  void validate() const;
  // The largest pair weight: s^2 times s_V^2 of every appearance kernel in use.
  double maxKernelWeight() const;
  // The kernel product a pair must exceed to count (see sp_ratio).
  double retainThreshold() const {
    return sp_ratio > 0.0 ? sp_ratio * maxKernelWeight() : sp_thres;
  }
};

// Threads for `num_threads` (0: all cores, or OMP_NUM_THREADS when set).
int resolvedThreadCount(int num_threads);

// Value names, for the settings table (settings_table.hpp: settingText, parseEnum).
const std::vector<EnumName<StepMethod>>& enumNames(StepMethod);
const std::vector<EnumName<BackendChoice>>& enumNames(BackendChoice);
const std::vector<EnumName<LostFramePolicy>>& enumNames(LostFramePolicy);
const std::vector<EnumName<ReferenceKind>>& enumNames(ReferenceKind);
const std::vector<EnumName<InitialGuess>>& enumNames(InitialGuess);

std::string toString(StepMethod method);
std::string toString(BackendChoice backend);
std::string toString(LostFramePolicy policy);
StepMethod parseStepMethod(const std::string& name);
BackendChoice parseBackendChoice(const std::string& name);
LostFramePolicy parseLostFramePolicy(const std::string& name);

}  // namespace cvo
