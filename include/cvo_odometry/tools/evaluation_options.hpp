// The evaluation options cvo_evaluate and cvo_run_sequence share: --max-gap, --association,
// --delta, --drift-lengths.
#pragma once

#include <string>
#include <vector>

#include "cvo_odometry/core/evaluation_report.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace cvo {

std::vector<std::string> evaluationOptionNames();
extern const char* const kEvaluationOptionsUsage;
EvaluationOptions evaluationOptionsFrom(const CommandLine& cli);

}  // namespace cvo
