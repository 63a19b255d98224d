#pragma once

#include <string>

namespace cvo {

// What one registration did. Indicators are the paper's i_theta = F / sqrt(|X||Z|), both taken
// at the final lengthscale so that they compare.
struct RegistrationReport {
  int iterations = 0;
  bool converged = false;
  double initial_lengthscale = 0.0;
  double final_lengthscale = 0.0;
  int lengthscale_decays = 0;
  double indicator_before = 0.0;  // at the initial guess
  double indicator_after = 0.0;   // at the result
  double last_step = 0.0;         // |log(last increment)|
  double mean_pairs = 0.0;        // retained pairs per iteration
  double time_ms = 0.0;
  std::string backend;
  std::string message;  // why it stopped
  std::string warning;  // e.g. a GPU failure this registration recovered from
};

}  // namespace cvo
