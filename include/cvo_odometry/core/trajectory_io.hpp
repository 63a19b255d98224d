// Trajectory files: TUM ("timestamp tx ty tz qx qy qz qw") and KITTI (12 numbers a line, the top
// three rows of world <- camera, row-major; stamps from a separate times file or the line index).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "cvo_odometry/core/trajectory.hpp"

namespace cvo {

enum class TrajectoryFormat { kTum, kKitti };

// Parse errors throw FormatError naming `source_name`, the line number and what was expected.
Trajectory parseTumTrajectory(std::istream& in, const std::string& source_name);
Trajectory parseKittiTrajectory(std::istream& in, const std::string& source_name,
                                const std::vector<double>& stamps = {});
std::vector<double> parseStamps(std::istream& in, const std::string& source_name);

Trajectory readTumTrajectory(const std::string& path);
// Without `times_path` the stamps are the line indices (0, 1, 2, ...).
Trajectory readKittiTrajectory(const std::string& path, const std::string& times_path = "");
Trajectory readTrajectory(const std::string& path, TrajectoryFormat format,
                          const std::string& times_path = "");

void writeTumTrajectory(std::ostream& out, const Trajectory& trajectory);
void writeKittiTrajectory(std::ostream& out, const Trajectory& trajectory);
void writeTrajectory(const std::string& path, const Trajectory& trajectory,
                     TrajectoryFormat format);

// "tum" or "kitti"; throws std::invalid_argument otherwise.
TrajectoryFormat parseTrajectoryFormat(const std::string& name);
// Guess from content: 8 numbers a line is TUM, 12 is KITTI.
TrajectoryFormat detectTrajectoryFormat(const std::string& path);

}  // namespace cvo
