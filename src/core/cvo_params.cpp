#include "cvo_odometry/core/cvo_params.hpp"

#include <algorithm>
#include <thread>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cvo {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("invalid CVO parameters: " + message);
}

void requirePositive(double value, const char* name) {
  std::ostringstream msg;
  msg << name << " must be a positive finite number, got " << value;
  require(std::isfinite(value) && value > 0.0, msg.str());
}

}  // namespace

void CvoParams::validate() const {
  requirePositive(ell_init, "ell_init");
  requirePositive(ell_min, "ell_min");
  requirePositive(ell_first_frame, "ell_first_frame");
  requirePositive(sigma, "sigma");
  require(sp_ratio >= 0.0 && sp_ratio < 1.0, "sp_ratio must be in [0, 1)");
  if (sp_ratio == 0.0) requirePositive(sp_thres, "sp_thres");
  require(ell_min <= ell_init, "ell_min (" + std::to_string(ell_min) + ") > ell_init (" +
                                   std::to_string(ell_init) + ")");
  require(ell_min <= ell_first_frame, "ell_min > ell_first_frame");
  requirePositive(ell_prior, "ell_prior");  // below ell_min: ell_min (no annealing)
  require(ell_min_ratio_with_ignored >= 0.01 && ell_min_ratio_with_ignored <= 1.0,
          "ell_min_ratio_with_ignored must be in [0.01, 1]");
  if (use_color) {
    requirePositive(color_ell, "color_ell");
    requirePositive(color_sigma, "color_sigma");
  }
  if (use_semantics) {
    require(semantic_cross_weight >= 0.0 && semantic_cross_weight <= 1.0,
            "semantic_cross_weight must be in [0, 1]");
    requirePositive(semantic_sigma, "semantic_sigma");
  }
  // The largest possible pair weight must clear the threshold, or no pair is ever retained.
  const double max_weight = maxKernelWeight();
  require(sp_ratio > 0.0 || max_weight > sp_thres,
          "sp_thres (" + std::to_string(sp_thres) +
              ") is not below the largest kernel product of the enabled kernels (" +
              std::to_string(max_weight) +
              "): no pair could count; lower sp_thres below that, or set sp_ratio (e.g. 0.3: "
              "the threshold then follows the kernels)");
  require(decay_rate > 0.0 && decay_rate <= 1.0, "decay_rate must be in (0, 1]");
  require(first_frame_decay_rate > 0.0 && first_frame_decay_rate <= 1.0,
          "first_frame_decay_rate must be in (0, 1]");
  require(schedule_decay > 0.0 && schedule_decay < 1.0, "schedule_decay must be in (0, 1)");
  require(decay_start >= 0 && first_frame_decay_start >= 0, "decay starts must be >= 0");
  require(indicator_window >= 1, "indicator_window must be >= 1");
  require(indicator_tolerance >= 0.0 && std::isfinite(indicator_tolerance),
          "indicator_tolerance must be >= 0");
  requirePositive(min_step, "min_step");
  requirePositive(max_step, "max_step");
  require(min_step <= max_step, "min_step > max_step");
  requirePositive(eps_2, "eps_2");
  requirePositive(level_tolerance, "level_tolerance");
  require(max_overrelaxation >= 1.0 && max_overrelaxation <= 3.0,
          "max_overrelaxation must be in [1, 3]");
  require(max_iterations >= 1, "max_iterations must be >= 1");
  require(max_level_iterations >= 1, "max_level_iterations must be >= 1");
  require(num_threads >= 0, "num_threads must be >= 0");
  require(min_cosine >= 0.0 && min_cosine < 1.0, "min_cosine must be in [0, 1)");
  require(min_tracking_points >= 1, "min_tracking_points must be >= 1");
  requirePositive(max_linear_speed, "max_linear_speed");
  requirePositive(max_angular_speed, "max_angular_speed");
  require(max_lost_frames >= 0, "max_lost_frames must be >= 0");
  require(max_source_points == 0 || max_source_points >= kMinSubsampledPoints,
          "max_source_points must be 0 (all) or at least " + std::to_string(kMinSubsampledPoints));
  require(photometric_iterations >= 1, "photometric_iterations must be >= 1");
  require(keyframe_cosine_ratio >= 0.0 && keyframe_cosine_ratio < 1.0,
          "keyframe_cosine_ratio must be in [0, 1)");
  requirePositive(keyframe_max_translation, "keyframe_max_translation");
  requirePositive(keyframe_max_rotation, "keyframe_max_rotation");
  require(min_prior_inliers >= 4, "min_prior_inliers must be >= 4");
  require(min_prior_inlier_ratio >= 0.0 && min_prior_inlier_ratio <= 1.0,
          "min_prior_inlier_ratio must be in [0, 1]");
  requirePositive(guess_disagreement_translation, "guess_disagreement_translation");
  requirePositive(guess_disagreement_rotation, "guess_disagreement_rotation");
  requirePositive(track_agreement_px, "track_agreement_px");
  require(min_track_agreement >= 0.0 && min_track_agreement <= 1.0,
          "min_track_agreement must be in [0, 1]");
  require(moving_region_px >= 0.0 && moving_region_px <= 1000.0,
          "moving_region_px must be in [0, 1000]");
  require(moving_track_agreement >= 0.0 && moving_track_agreement <= 1.0,
          "moving_track_agreement must be in [0, 1]");
  require(max_track_rotation_gap > 0.0 && max_track_rotation_gap <= 180.0,
          "max_track_rotation_gap must be in (0, 180]");
  require(motion_split_ratio >= 0.0 && motion_split_ratio <= 1.0,
          "motion_split_ratio must be in [0, 1]");
  require(moving_min_px >= 0.0 && moving_min_px <= 1000.0, "moving_min_px must be in [0, 1000]");
  require(motion_split_depth_ratio >= 1.0 && motion_split_depth_ratio <= 100.0,
          "motion_split_depth_ratio must be in [1, 100]");
  require(tracked_cosine_ratio >= 0.0 && tracked_cosine_ratio <= 1.0,
          "tracked_cosine_ratio must be in [0, 1]");
  require(weak_cosine >= 0.0 && weak_cosine <= 1.0, "weak_cosine must be in [0, 1]");
  requirePositive(photometric_max_correction, "photometric_max_correction");
}

double CvoParams::maxKernelWeight() const {
  double weight = sigma * sigma;
  if (use_color) weight *= color_sigma * color_sigma;
  if (use_semantics) weight *= semantic_sigma * semantic_sigma;
  return weight;
}

const std::vector<EnumName<StepMethod>>& enumNames(StepMethod) {
  static const std::vector<EnumName<StepMethod>> names{{StepMethod::kReference, "reference"},
                                                       {StepMethod::kProcrustes, "procrustes"}};
  return names;
}

const std::vector<EnumName<BackendChoice>>& enumNames(BackendChoice) {
  static const std::vector<EnumName<BackendChoice>> names{
      {BackendChoice::kAuto, "auto"},
      {BackendChoice::kCpu, "cpu"},
      {BackendChoice::kCuda, "cuda"},
      {BackendChoice::kDeviceCpu, "device_cpu"}};
  return names;
}

const std::vector<EnumName<LostFramePolicy>>& enumNames(LostFramePolicy) {
  static const std::vector<EnumName<LostFramePolicy>> names{
      {LostFramePolicy::kKeepGuess, "keep_guess"},
      {LostFramePolicy::kPublishNothing, "publish_nothing"},
      {LostFramePolicy::kReset, "reset"}};
  return names;
}

const std::vector<EnumName<ReferenceKind>>& enumNames(ReferenceKind) {
  static const std::vector<EnumName<ReferenceKind>> names{
      {ReferenceKind::kKeyframe, "keyframe"}, {ReferenceKind::kPreviousFrame, "previous_frame"}};
  return names;
}

const std::vector<EnumName<InitialGuess>>& enumNames(InitialGuess) {
  static const std::vector<EnumName<InitialGuess>> names{
      {InitialGuess::kAuto, "auto"},
      {InitialGuess::kConstantVelocity, "constant_velocity"},
      {InitialGuess::kFeatures, "features"},
      {InitialGuess::kIdentity, "identity"}};
  return names;
}

std::string toString(StepMethod method) {
  return settingText(method);
}
std::string toString(BackendChoice backend) {
  return settingText(backend);
}
std::string toString(LostFramePolicy policy) {
  return settingText(policy);
}
StepMethod parseStepMethod(const std::string& name) {
  return parseEnum<StepMethod>("step_method", name);
}
BackendChoice parseBackendChoice(const std::string& name) {
  return parseEnum<BackendChoice>("backend", name);
}
LostFramePolicy parseLostFramePolicy(const std::string& name) {
  return parseEnum<LostFramePolicy>("lost_frame_policy", name);
}

int resolvedThreadCount(int num_threads) {
  if (num_threads > 0) return num_threads;
#ifdef _OPENMP
  return omp_get_max_threads();  // OMP_NUM_THREADS when set, else the cores
#else
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
#endif
}

}  // namespace cvo
