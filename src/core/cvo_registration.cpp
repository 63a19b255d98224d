#include "cvo_odometry/core/cvo_registration.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "cvo_odometry/core/backend_factory.hpp"
#include "cvo_odometry/core/cvo_steps.hpp"
#include "cvo_odometry/core/failover_backend.hpp"

namespace cvo {

namespace {

// Points of a cloud selfProduct() sums over, at most.
constexpr std::size_t kSelfProductPoints = 1000;
// Newton steps taken with one Hessian before it is summed again. TUM fr1_xyz, one thread:
// registration median 13.7-14.1 ms with a fresh Hessian every step, 11.5-12.7 with one every
// third (the poses within 0.01 mm), 12.0-13.2 with the first step's throughout. A failed step on
// a reused Hessian sums a fresh one: 13.8 iterations a frame, 14.0 with a fresh one every step.
constexpr int kNewtonStepsPerHessian = 3;
// A Newton step is shortened to at most this many times the (unstretched) MM step's length (a
// trust region):
// the full step went up to 10x, 4 deg on TUM fr1_xyz frame 33, F fell, Newton was switched off
// and the MM steps walked back over 20 iterations, each departure rebuilding every candidate
// list (6 times there). TUM at strides 1 / 3 / 5 / 8: 905 / 522 / 267 / 256 -> 812 / 491 / 184 /
// 240 iterations in all (at 3x: 798 / 491 / 260 / 225), the poses within 0.02 mm.
constexpr double kNewtonTrustRatio = 2.0;
// Relative fall of the smoothed F below which it counts as unchanged.
constexpr double kFallTolerance = 1e-8;
// At ell_min, pairs crossing the retain threshold can make the steps hop round a cycle of nearby
// poses for ever (KITTI 06 reversed, stride 2: three poses 0.5 mm apart, MM steps of 6e-5-5e-4,
// 10000 iterations and 500 ms before the limit). F rising by less than kStallRise of itself in
// kStallIterations steps ends the level at the best pose seen. Converging frames keep rising by
// ~1e-5 of F a step until eps_2 stops them (at most 79 iterations on the fixtures), so they are
// never cut.
constexpr int kStallIterations = 30;
constexpr double kStallRise = 1e-6;

}  // namespace

CvoRegistration::CvoRegistration(const CvoParams& params,
                                 std::unique_ptr<RegistrationBackend> backend)
    : params_(params), backend_(std::move(backend)) {
  params_.validate();
  if (!backend_) backend_ = makeBackend(params_.backend, params_.num_threads, &backend_note_);
}

CvoRegistration::~CvoRegistration() = default;

void CvoRegistration::setParams(const CvoParams& params) {
  params.validate();
  params_ = params;
}

void CvoRegistration::checkInputs(const LabeledCloud& target, const LabeledCloud& source) const {
  for (const auto* cloud : {&target, &source}) {
    const char* which = cloud == &target ? "target" : "source";
    if (cloud->size() < 3) {
      throw std::invalid_argument(std::string(which) + " cloud has " +
                                  std::to_string(cloud->size()) + " points; at least 3 needed");
    }
    const long bad = cloud->firstNonFinite();
    if (bad >= 0) {
      throw std::invalid_argument(std::string(which) + " cloud point " + std::to_string(bad) +
                                  " has a non-finite position or feature");
    }
    if (params_.use_color && !cloud->hasColor()) {
      throw std::invalid_argument(std::string("use_color is on but the ") + which +
                                  " cloud has no colour");
    }
    if (params_.use_semantics && cloud->semanticClasses() == 0) {
      throw std::invalid_argument(std::string("use_semantics is on but the ") + which +
                                  " cloud has no semantics");
    }
  }
  if (params_.use_semantics && target.semanticClasses() != source.semanticClasses()) {
    throw std::invalid_argument("target has " + std::to_string(target.semanticClasses()) +
                                " semantic classes, source " +
                                std::to_string(source.semanticClasses()));
  }
}

RegistrationResult CvoRegistration::align(const LabeledCloud& target, const LabeledCloud& source,
                                          const Eigen::Isometry3d& initial_guess, bool first_frame,
                                          double initial_lengthscale) {
  const auto start = std::chrono::steady_clock::now();
  checkInputs(target, source);
  if (!initial_guess.matrix().allFinite()) {
    throw std::invalid_argument("initial guess is not finite");
  }
  target_ = &target;
  source_ = &source;
  first_weight_at_final_ = -1.0;
  auto* failover = dynamic_cast<FailoverBackend*>(backend_.get());
  // Each registration tries the GPU again: before the problem is set, so that the GPU has it.
  if (failover) failover->restore();
  // The whole clouds once (a device copies them here); each level then names its subsets.
  backend_->setProblem(target, source, params_);
  subsets_ = CloudSubsets{};
  RegistrationResult result;
  RegistrationReport& report = result.report;
  report.backend = backend_->name();
  const double ell = initial_lengthscale > 0.0 ? std::max(initial_lengthscale, params_.ell_min)
                     : first_frame             ? params_.ell_first_frame
                                               : params_.ell_init;
  report.initial_lengthscale = ell;
  const Eigen::Isometry3d guess = lie::orthonormalized(initial_guess);
  if (params_.step_method == StepMethod::kProcrustes) {
    runProcrustes(guess, ell, result.transform, report);
  } else {
    runReference(guess, ell, first_frame, result.transform, report);
  }
  // The indicators over the finest level's clouds (the source's budget of points), scaled to
  // every source point: F sums over source points, so the subsample estimates F / k.
  const double scale = useFinestClouds();
  const double norm = std::sqrt(static_cast<double>(target.size()) * source.size());
  report.indicator_after =
      scale * backend_->moments(result.transform, report.final_lengthscale).weight / norm;
  // At the guess: the first iteration's sum when it ran on these clouds at this lengthscale (a
  // registration from a confident prior, at ell_min throughout), else a sum of its own.
  const double at_guess = first_weight_at_final_ >= 0.0
                              ? first_weight_at_final_
                              : backend_->oneOffMoments(guess, report.final_lengthscale).weight;
  report.indicator_before = scale * at_guess / norm;
  if (failover && failover->failedOver()) {
    report.backend = failover->name();
    report.warning = "GPU failed, this registration ran on the CPU: " + failover->lastError();
  }
  report.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void CvoRegistration::runProcrustes(const Eigen::Isometry3d& guess, double ell,
                                    Eigen::Isometry3d& T, RegistrationReport& report) {
  T = guess;
  double pair_total = 0.0;
  // Adaptive over-relaxation: the MM step is conservative, so while F keeps rising the step is
  // stretched (up to max_overrelaxation); a fall resets it. Restarted at every level.
  double omega = 1.0;
  double previous_weight = -1.0;
  int level_iterations = 0;
  bool newton_allowed = params_.newton_at_ell_min, last_was_newton = false;
  double first_weight = -1.0;        // F at the guess
  kernels::CurvatureSums curvature;  // the Hessian of the last curvature pass, this step's moments
  int hessian_uses = 0;              // Newton iterations since that pass
  bool last_newton_fresh = false;    // the last Newton step's Hessian was summed at its pose
  // At ell_min: the highest smoothed F so far, where it was, and the steps since it rose.
  std::optional<double> best_weight;
  Eigen::Isometry3d best_pose = T;
  int steps_since_rise = 0;
  report.message = "iteration limit reached";
  for (int it = 0; it < params_.max_iterations; ++it) {
    useCloudsForLengthscale(ell);
    // At ell_min, while Newton steps are on, one pass gives the moments and the curvature; the
    // Hessian, which changes slowly near the optimum, serves kNewtonStepsPerHessian steps (a pass
    // with it costs 3-4 plain ones).
    const bool with_curvature = newton_allowed && ell <= params_.ell_min;
    const bool fresh_hessian = with_curvature && hessian_uses % kNewtonStepsPerHessian == 0;
    if (fresh_hessian) curvature = backend_->curvature(T, ell);
    if (with_curvature) ++hessian_uses;
    const kernels::MomentSums m = fresh_hessian ? curvature.moments : backend_->moments(T, ell);
    curvature.moments = m;
    if (it == 0) first_weight = m.weight;
    report.iterations = it + 1;
    pair_total += static_cast<double>(m.pairs);
    if (m.pairs < 3) {
      report.message =
          "fewer than 3 pairs within the kernels' reach at lengthscale " + std::to_string(ell);
      break;
    }
    // The MM fixed point is a stationary point of the continuous sum_ij (a_ij - sp_thres)_+
    // (the retained-pair sum F jumps as pairs cross the threshold): steer by that.
    const double smooth_weight =
        m.weight - params_.retainThreshold() * static_cast<double>(m.pairs);
    // Fell, beyond the rounding between a curvature pass and a plain one (the same sum in
    // another order: ~1e-9 of F).
    const bool fell = previous_weight >= 0.0 &&
                      smooth_weight < previous_weight - kFallTolerance * std::abs(previous_weight);
    // A Newton step after which F fell: on a fresh Hessian its quadratic model misleads here, MM
    // steps from now on; on a reused one, the next step sums a fresh Hessian.
    if (fell && last_was_newton) {
      if (last_newton_fresh) newton_allowed = false;
      hessian_uses = 0;
    }
    last_was_newton = false;
    if (previous_weight >= 0.0) {
      omega = smooth_weight >= previous_weight ? std::min(omega * 1.5, params_.max_overrelaxation)
                                               : 1.0;
    }
    previous_weight = smooth_weight;
    if (ell <= params_.ell_min) {
      if (!best_weight || smooth_weight > *best_weight + kStallRise * std::abs(*best_weight)) {
        best_weight = smooth_weight;
        best_pose = T;
        steps_since_rise = 0;
      } else if (++steps_since_rise >= kStallIterations) {
        T = best_pose;
        report.converged = true;
        report.message = "converged: F rose no further in " + std::to_string(kStallIterations) +
                         " steps (they hop across the retain threshold)";
        break;
      }
    }
    const Vector6d step = lie::logSE3(weightedProcrustes(m));
    Vector6d newton;
    // Near the optimum MM steps converge linearly, slowly along weakly constrained directions;
    // Newton's converge quadratically. Taken only while F rises, where the Hessian (the last
    // one summed) is negative definite and the step stays within 10x the MM step (a guard
    // against a misleading model), and shortened to the trust region.
    bool took_newton = false;
    if (with_curvature && !fell) {
      took_newton =
          newtonStep(curvature, ell, &newton) && newton.norm() < 10.0 * step.norm() + 1e-4;
      const double trust = kNewtonTrustRatio * step.norm();
      if (took_newton && newton.norm() > trust) newton *= trust / newton.norm();
      if (!took_newton) {
        // A fresh model without a maximum nearby will not have one an iteration later either:
        // stop paying for the curvature sums. A reused one is summed afresh first.
        if (fresh_hessian) newton_allowed = false;
        hessian_uses = 0;
      }
    }
    if (took_newton) {
      T = lie::orthonormalized(lie::expSE3(newton) * T);
      last_was_newton = true;
      last_newton_fresh = fresh_hessian;
    } else {
      T = lie::orthonormalized(lie::expSE3(omega * step) * T);
    }
    report.last_step = step.norm();  // the plain MM step decides convergence
    ++level_iterations;
    if (ell > params_.ell_min) {
      // A coarse level ends when its steps are small, or after max_level_iterations (the
      // thresholded sum can make the step hop between nearby states there).
      if (report.last_step < params_.level_tolerance * ell ||
          level_iterations >= params_.max_level_iterations) {
        level_iterations = 0;
        ell *= params_.schedule_decay;
        // A level just above ell_min costs a full level and gains nothing: go to ell_min.
        if (ell < params_.ell_min * 1.15) ell = params_.ell_min;
        ++report.lengthscale_decays;
        omega = 1.0;
        previous_weight = -1.0;
      }
    } else if (report.last_step < params_.eps_2) {
      report.converged = true;
      report.message = "converged";
      break;
    }
  }
  report.final_lengthscale = ell;
  report.mean_pairs = report.iterations ? pair_total / report.iterations : 0.0;
  // The first iteration ran on the finest clouds at the final lengthscale: its sum is F at the
  // guess.
  if (report.lengthscale_decays == 0 && ell <= params_.ell_min)
    first_weight_at_final_ = first_weight;
}

void CvoRegistration::runReference(const Eigen::Isometry3d& guess, double ell, bool first_frame,
                                   Eigen::Isometry3d& T, RegistrationReport& report) {
  T = guess;
  const double decay = first_frame ? params_.first_frame_decay_rate : params_.decay_rate;
  const int decay_start = first_frame ? params_.first_frame_decay_start : params_.decay_start;
  const auto window = static_cast<std::size_t>(params_.indicator_window);
  std::deque<double> ratios;
  double pair_total = 0.0;
  report.message = "iteration limit reached";
  useFinestClouds();
  for (int it = 0; it < params_.max_iterations; ++it) {
    const kernels::MomentSums m = backend_->moments(T, ell);
    report.iterations = it + 1;
    pair_total += static_cast<double>(m.pairs);
    if (m.pairs == 0) {
      report.message = "no pairs within the kernels' reach at lengthscale " + std::to_string(ell);
      break;
    }
    const Vector6d gradient = objectiveGradient(m, ell);
    if (!(gradient.norm() > 0.0)) {
      report.converged = true;
      report.message = "zero gradient";
      break;
    }
    const Vector6d direction = gradient.normalized();
    const double step =
        taylorStepLength(backend_->taylor(T, direction, ell), params_.min_step, params_.max_step);
    T = lie::orthonormalized(lie::expSE3(step * direction) * T);
    report.last_step = step;
    if (step < params_.eps_2) {
      report.converged = true;
      report.message = "converged";
      break;
    }
    // Annealing on the retained-pair count (the reference's indicator; its 1/sqrt(NM) cancels in
    // the ratio of two adjacent windows).
    ratios.push_back(static_cast<double>(m.pairs));
    if (ratios.size() > 2 * window) ratios.pop_front();
    if (it >= decay_start && ratios.size() == 2 * window && ell > params_.ell_min) {
      const double previous = std::accumulate(ratios.begin(), ratios.begin() + window, 0.0);
      const double recent = std::accumulate(ratios.begin() + window, ratios.end(), 0.0);
      if (previous > 0.0 && std::abs(recent / previous - 1.0) <= params_.indicator_tolerance) {
        ell = std::max(ell * decay, params_.ell_min);
        ++report.lengthscale_decays;
        ratios.clear();
      }
    }
  }
  report.final_lengthscale = ell;
  report.mean_pairs = report.iterations ? pair_total / report.iterations : 0.0;
}

std::size_t CvoRegistration::sourceBudget(const LabeledCloud& source) const {
  if (params_.step_method != StepMethod::kProcrustes || params_.max_source_points <= 0) {
    return source.size();
  }
  return std::min(source.size(), static_cast<std::size_t>(params_.max_source_points));
}

double CvoRegistration::useCloudsForLengthscale(double ell) {
  std::size_t stride = 1;
  if (params_.subsample_coarse_levels && ell > params_.ell_min) {
    const std::size_t smaller = std::min(target_->size(), source_->size());
    const auto most = std::max<std::size_t>(1, smaller / kMinSubsampledPoints);
    stride = std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(ell / params_.ell_min)), 1,
                                     most);
  }
  // The source: every stride-th point, or fewer when the budget asks for it.
  const std::size_t strided_count = (source_->size() + stride - 1) / stride;
  const std::size_t source_count = std::min(strided_count, sourceBudget(*source_));
  CloudSubsets subsets;
  subsets.target_stride = stride;
  subsets.source_stride = stride;
  if (source_count < strided_count) subsets.source_count = source_count;
  if (subsets != subsets_) {
    backend_->useSubsets(subsets);
    subsets_ = subsets;
  }
  return static_cast<double>(source_->size()) / static_cast<double>(source_count);
}

double CvoRegistration::useFinestClouds() {
  return useCloudsForLengthscale(params_.ell_min);
}

double CvoRegistration::innerProduct(const LabeledCloud& target, const LabeledCloud& source,
                                     const Eigen::Isometry3d& T, double ell) {
  checkInputs(target, source);
  backend_->setProblem(target, source, params_);
  return backend_->oneOffMoments(T, ell).weight;
}

double CvoRegistration::indicator(const LabeledCloud& target, const LabeledCloud& source,
                                  const Eigen::Isometry3d& T, double ell) {
  return innerProduct(target, source, T, ell) /
         std::sqrt(static_cast<double>(target.size()) * source.size());
}

double CvoRegistration::cosine(const LabeledCloud& target, const LabeledCloud& source,
                               const Eigen::Isometry3d& T, double ell) {
  // Every sum over every point (selfProduct() estimates from a sample, as the odometry's
  // cosine does with its cross term from the registration's source budget).
  const double cross = innerProduct(target, source, T, ell);
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  return cross /
         std::sqrt(innerProduct(target, target, I, ell) * innerProduct(source, source, I, ell));
}

double CvoRegistration::selfProduct(const LabeledCloud& cloud, double ell) {
  // An estimate from an even sample of the cloud (F(X, X) / k): the cosine only has to tell
  // overlap from none and keyframes apart, and the full budget cost 1.2 ms a TUM frame against
  // 0.7 with 1000 points, for the same trajectory.
  const std::size_t count = std::min(sourceBudget(cloud), kSelfProductPoints);
  if (count >= cloud.size()) return innerProduct(cloud, cloud, Eigen::Isometry3d::Identity(), ell);
  const LabeledCloud sample = cloud.thinned(count);
  return static_cast<double>(cloud.size()) / static_cast<double>(count) *
         innerProduct(cloud, sample, Eigen::Isometry3d::Identity(), ell);
}

}  // namespace cvo
