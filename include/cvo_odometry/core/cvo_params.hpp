// Every parameter of CVO registration, with the TUM RGB-D reference values as defaults.
// The names follow ../config/*.yaml; see README for what each does.
#pragma once

#include <string>

namespace cvo {

enum class StepMethod {
  kReference,  // the paper: normalised gradient, 4th-order Taylor line search, indicator annealing
  kProcrustes  // default: closed-form weighted Procrustes (MM) step, coarse-to-fine lengthscales
};

// kDeviceCpu: the CUDA backend's device code on OpenMP threads (tests it without a GPU).
enum class BackendChoice { kAuto, kCpu, kCuda, kDeviceCpu };

// What frame-to-frame odometry does with a frame it judges lost (see FrameToFrameOdometry).
enum class LostFramePolicy {
  kKeepGuess,       // report the constant-velocity guess, flagged, with a grown covariance
  kPublishNothing,  // report no pose for the frame
  kReset            // restart tracking from the frame, holding the last pose
};

struct CvoParams {
  // Geometric kernel k(x, z) = sigma^2 exp(-|x - z|^2 / (2 ell^2)).
  double ell_init = 0.15;         // lengthscale at the start of a registration (m)
  double ell_min = 0.05;          // smallest lengthscale of the annealing (m)
  double ell_first_frame = 0.15;  // ell_init for the first pair of a sequence (identity guess)
  double sigma = 0.1;             // amplitude s
  double sp_thres = 0.003;        // a pair counts only if its kernel product exceeds this

  // Appearance kernels s_V^2 exp(-|u - v|^2 / (2 ell_V^2)), multiplied into the pair weight.
  bool use_color = true;
  double color_ell = 0.15;
  double color_sigma = 0.6;
  bool use_semantics = false;
  double semantic_ell = 0.1;
  double semantic_sigma = 0.8;

  // Reference annealing: when the retained-pair ratio of the last `indicator_window` iterations is
  // within 1 +- indicator_tolerance of the window before, ell <- max(ell * decay_rate, ell_min).
  double decay_rate = 0.9;
  int decay_start = 10;
  double first_frame_decay_rate = 0.9;
  int first_frame_decay_start = 10;
  int indicator_window = 5;
  double indicator_tolerance = 0.02;

  // Step and convergence.
  StepMethod step_method = StepMethod::kProcrustes;
  double min_step = 1e-5;  // Taylor step clamp (reference method)
  double max_step = 0.8;
  double eps_2 = 1.2e-5;  // stop when |log(increment)| < eps_2 (at ell_min for Procrustes)
  int max_iterations = 2000;
  // Procrustes schedule: converge loosely at each lengthscale (|step| < level_tolerance * ell),
  // then ell <- max(ell * schedule_decay, ell_min); stop on eps_2 only at ell_min.
  double schedule_decay = 0.7;
  double level_tolerance = 0.01;
  // At lengthscales above ell_min use every k-th point of each cloud, k ~ ell / ell_min, so that
  // pairs per iteration stay near the finest level's; the finest level uses every point.
  bool subsample_coarse_levels = true;
  // Largest stretch of the Procrustes step while F keeps rising (1: plain MM steps).
  double max_overrelaxation = 2.0;
  // Iterations after which a coarse level ends even if its steps are not yet small.
  int max_level_iterations = 30;
  // At ell_min, Newton steps (analytic gradient and Hessian of sum (a - sp_thres)_+) where the
  // Hessian is negative definite and the step stays within 10x the MM step; after the first
  // Newton step that F does not follow upwards, MM steps only.
  bool newton_at_ell_min = true;

  // Photometric rotation stage after CVO (see photometric_rotation.hpp): needs clouds that carry
  // their image (the RGB-D front end attaches it). Gauss-Newton iterations per image level; a
  // correction above photometric_max_correction (deg) is refused and CVO's rotation kept.
  bool photometric_rotation = false;
  int photometric_iterations = 10;
  double photometric_max_correction = 2.0;

  BackendChoice backend = BackendChoice::kAuto;
  int num_threads = 0;  // 0: all cores

  // Tracking quality, judged per frame by FrameToFrameOdometry. A registration is good when it
  // converged, the cosine of the two functions at its final lengthscale is >= min_cosine, both
  // clouds have >= min_tracking_points and its motion is within the speed limits over the
  // frame interval. A bad one is retried from identity with the first-frame lengthscale; if that
  // fails too the frame is lost and lost_frame_policy applies. After max_lost_frames lost frames
  // in a row tracking restarts (as kReset).
  double min_cosine = 0.3;
  int min_tracking_points = 300;
  double max_linear_speed = 5.0;     // m/s
  double max_angular_speed = 180.0;  // deg/s
  LostFramePolicy lost_frame_policy = LostFramePolicy::kKeepGuess;
  int max_lost_frames = 5;

  // Throws std::invalid_argument naming the first parameter that makes no sense.
  void validate() const;
  // The largest pair weight: s^2 times s_V^2 of every appearance kernel in use.
  double maxKernelWeight() const;
};

// Threads for `num_threads` (0: OpenMP's default, all cores; 1 without OpenMP).
int resolvedThreadCount(int num_threads);

std::string toString(StepMethod method);
std::string toString(BackendChoice backend);
std::string toString(LostFramePolicy policy);
StepMethod parseStepMethod(const std::string& name);
BackendChoice parseBackendChoice(const std::string& name);
LostFramePolicy parseLostFramePolicy(const std::string& name);

}  // namespace cvo
