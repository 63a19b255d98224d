#include "cvo_odometry/core/tracking_check.hpp"

#include <cmath>
#include <sstream>

#include "cvo_odometry/core/lie_group.hpp"

namespace cvo {

namespace {

void addProblem(TrackingCheck& check, const std::string& problem) {
  if (!check.problems.empty()) check.problems += "; ";
  check.problems += problem;
  check.good = false;
}

}  // namespace

TrackingCheck checkPointCounts(std::size_t target_points, std::size_t source_points,
                               const CvoParams& params) {
  TrackingCheck check;
  const auto minimum = static_cast<std::size_t>(params.min_tracking_points);
  if (target_points < minimum || source_points < minimum) {
    std::ostringstream why;
    why << "too few points (" << target_points << " previous, " << source_points
        << " current; min_tracking_points " << minimum << ")";
    addProblem(check, why.str());
  }
  return check;
}

TrackingCheck checkRegistration(const RegistrationReport& report, double cosine,
                                const Eigen::Isometry3d& motion, double dt,
                                const CvoParams& params) {
  TrackingCheck check;
  std::ostringstream why;
  if (!report.converged) addProblem(check, "not converged: " + report.message);
  if (!(cosine >= params.min_cosine)) {
    why.str("");
    why << "cosine " << cosine << " < min_cosine " << params.min_cosine;
    addProblem(check, why.str());
  }
  if (dt > 0.0) {
    const double speed = motion.translation().norm() / dt;
    const double turn_rate = lie::logSO3(motion.rotation()).norm() * 180.0 / M_PI / dt;
    if (!(speed <= params.max_linear_speed)) {
      why.str("");
      why << "implausible motion: " << speed << " m/s > max_linear_speed "
          << params.max_linear_speed;
      addProblem(check, why.str());
    }
    if (!(turn_rate <= params.max_angular_speed)) {
      why.str("");
      why << "implausible motion: " << turn_rate << " deg/s > max_angular_speed "
          << params.max_angular_speed;
      addProblem(check, why.str());
    }
  }
  return check;
}

}  // namespace cvo
