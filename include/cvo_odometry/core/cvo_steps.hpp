// Step computations of CVO from the backend's sums (host side, shared by all backends).
#pragma once

#include <Eigen/Geometry>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/pair_kernels.hpp"

namespace cvo {

// dF/dxi of F(exp(xi) T) at xi = 0, twist order [omega; v].
Vector6d objectiveGradient(const kernels::MomentSums& m, double ell);

// The increment D maximising the minorizer of F (exp is convex: F >= const - sum a |x - D z|^2 /
// (2 ell^2)), i.e. the weighted Procrustes (Kabsch) solution on the retained pairs. Identity
// when fewer than three pairs carry weight.
Eigen::Isometry3d weightedProcrustes(const kernels::MomentSums& m);

// The Newton step -H^-1 g that maximises the quadratic model of F(exp(xi) T); false (no step)
// when the Hessian is not negative definite (the model has no maximum) or the step is not finite.
bool newtonStep(const kernels::CurvatureSums& c, double ell, Vector6d* step);

// Smallest positive real root of a t^3 + b t^2 + c t + d, or a negative value if none.
double smallestPositiveCubicRoot(double a, double b, double c, double d);

// Step length along a unit ascent direction from the 4th-order Taylor model of F: the smallest
// positive stationary point, clamped to [min_step, max_step]. With no positive stationary point
// the model rises all along the ray, so max_step is taken (as the reference does).
double taylorStepLength(const kernels::TaylorSums& s, double min_step, double max_step);

}  // namespace cvo
