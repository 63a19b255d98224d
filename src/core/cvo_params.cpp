#include "cvo_odometry/core/cvo_params.hpp"

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
  requirePositive(sp_thres, "sp_thres");
  require(ell_min <= ell_init, "ell_min (" + std::to_string(ell_min) + ") > ell_init (" +
                                   std::to_string(ell_init) + ")");
  require(ell_min <= ell_first_frame, "ell_min > ell_first_frame");
  if (use_color) {
    requirePositive(color_ell, "color_ell");
    requirePositive(color_sigma, "color_sigma");
  }
  if (use_semantics) {
    requirePositive(semantic_ell, "semantic_ell");
    requirePositive(semantic_sigma, "semantic_sigma");
  }
  // The largest possible pair weight must clear the threshold, or no pair is ever retained.
  const double max_weight = maxKernelWeight();
  require(max_weight > sp_thres, "sp_thres (" + std::to_string(sp_thres) +
                                     ") is not below the largest kernel product (" +
                                     std::to_string(max_weight) + "): no pair could count");
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
  require(photometric_iterations >= 1, "photometric_iterations must be >= 1");
  requirePositive(photometric_max_correction, "photometric_max_correction");
}

double CvoParams::maxKernelWeight() const {
  double weight = sigma * sigma;
  if (use_color) weight *= color_sigma * color_sigma;
  if (use_semantics) weight *= semantic_sigma * semantic_sigma;
  return weight;
}

std::string toString(StepMethod method) {
  return method == StepMethod::kReference ? "reference" : "procrustes";
}

std::string toString(BackendChoice backend) {
  switch (backend) {
    case BackendChoice::kCpu:
      return "cpu";
    case BackendChoice::kCuda:
      return "cuda";
    case BackendChoice::kDeviceCpu:
      return "device_cpu";
    default:
      return "auto";
  }
}

std::string toString(LostFramePolicy policy) {
  switch (policy) {
    case LostFramePolicy::kPublishNothing:
      return "publish_nothing";
    case LostFramePolicy::kReset:
      return "reset";
    default:
      return "keep_guess";
  }
}

LostFramePolicy parseLostFramePolicy(const std::string& name) {
  if (name == "keep_guess") return LostFramePolicy::kKeepGuess;
  if (name == "publish_nothing") return LostFramePolicy::kPublishNothing;
  if (name == "reset") return LostFramePolicy::kReset;
  throw std::invalid_argument("unknown lost_frame_policy '" + name +
                              "' (keep_guess, publish_nothing or reset)");
}

StepMethod parseStepMethod(const std::string& name) {
  if (name == "reference") return StepMethod::kReference;
  if (name == "procrustes") return StepMethod::kProcrustes;
  throw std::invalid_argument("unknown step_method '" + name + "' (reference or procrustes)");
}

BackendChoice parseBackendChoice(const std::string& name) {
  if (name == "auto") return BackendChoice::kAuto;
  if (name == "cpu") return BackendChoice::kCpu;
  if (name == "cuda") return BackendChoice::kCuda;
  if (name == "device_cpu") return BackendChoice::kDeviceCpu;
  throw std::invalid_argument("unknown backend '" + name + "' (auto, cpu, cuda or device_cpu)");
}

int resolvedThreadCount(int num_threads) {
#ifdef _OPENMP
  return num_threads > 0 ? num_threads : omp_get_max_threads();
#else
  (void)num_threads;
  return 1;
#endif
}

}  // namespace cvo
