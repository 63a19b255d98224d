#include "cvo_odometry/core/trajectory_io.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "cvo_odometry/core/format_error.hpp"

namespace cvo {

namespace {

bool isBlankOrComment(const std::string& line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first == std::string::npos || line[first] == '#';
}

// Splits `line` into numbers; throws naming the offending token.
std::vector<double> parseNumbers(const std::string& line, const std::string& source, int line_no) {
  std::istringstream ss(line);
  std::vector<double> values;
  std::string token;
  while (ss >> token) {
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0' || !std::isfinite(v)) {
      throw FormatError(source + ":" + std::to_string(line_no) + ": '" + token +
                        "' is not a finite number");
    }
    values.push_back(v);
  }
  return values;
}

[[noreturn]] void throwCount(const std::string& source, int line_no, std::size_t got,
                             const std::string& expected) {
  throw FormatError(source + ":" + std::to_string(line_no) + ": expected " + expected + ", got " +
                    std::to_string(got) + " numbers");
}

std::ifstream openOrThrow(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  return in;
}

}  // namespace

Trajectory parseTumTrajectory(std::istream& in, const std::string& source_name) {
  Trajectory trajectory;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (isBlankOrComment(line)) continue;
    const auto v = parseNumbers(line, source_name, line_no);
    if (v.size() != 8)
      throwCount(source_name, line_no, v.size(), "8 (timestamp tx ty tz qx qy qz qw)");
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    const double norm = q.norm();
    if (std::abs(norm - 1.0) > 1e-2) {
      throw FormatError(source_name + ":" + std::to_string(line_no) +
                        ": quaternion is not unit length (norm " + std::to_string(norm) + ")");
    }
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = q.normalized().toRotationMatrix();
    pose.translation() << v[1], v[2], v[3];
    if (!trajectory.empty() && !(v[0] > trajectory.poses().back().stamp)) {
      throw FormatError(source_name + ":" + std::to_string(line_no) +
                        ": timestamps must increase (" + std::to_string(v[0]) + " after " +
                        std::to_string(trajectory.poses().back().stamp) + ")");
    }
    trajectory.append(v[0], pose);
  }
  return trajectory;
}

Trajectory parseKittiTrajectory(std::istream& in, const std::string& source_name,
                                const std::vector<double>& stamps) {
  Trajectory trajectory;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (isBlankOrComment(line)) continue;
    const auto v = parseNumbers(line, source_name, line_no);
    if (v.size() != 12) throwCount(source_name, line_no, v.size(), "12 (3x4 pose, row-major)");
    Eigen::Matrix3d R;
    R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
    const double ortho_error = (R * R.transpose() - Eigen::Matrix3d::Identity()).norm();
    if (ortho_error > 1e-2 || R.determinant() < 0.0) {
      throw FormatError(
          source_name + ":" + std::to_string(line_no) +
          ": the 3x3 part is not a rotation (|R R^T - I| = " + std::to_string(ortho_error) + ")");
    }
    const std::size_t index = trajectory.size();
    if (!stamps.empty() && index >= stamps.size()) {
      throw FormatError(source_name + ":" + std::to_string(line_no) + ": more poses than the " +
                        std::to_string(stamps.size()) + " timestamps given");
    }
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
    pose.translation() << v[3], v[7], v[11];
    trajectory.append(stamps.empty() ? static_cast<double>(index) : stamps[index], pose);
  }
  return trajectory;
}

std::vector<double> parseStamps(std::istream& in, const std::string& source_name) {
  std::vector<double> stamps;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (isBlankOrComment(line)) continue;
    const auto v = parseNumbers(line, source_name, line_no);
    if (v.size() != 1) throwCount(source_name, line_no, v.size(), "1 (a timestamp)");
    stamps.push_back(v[0]);
  }
  return stamps;
}

Trajectory readTumTrajectory(const std::string& path) {
  auto in = openOrThrow(path);
  return parseTumTrajectory(in, path);
}

Trajectory readKittiTrajectory(const std::string& path, const std::string& times_path) {
  std::vector<double> stamps;
  if (!times_path.empty()) {
    auto times = openOrThrow(times_path);
    stamps = parseStamps(times, times_path);
  }
  auto in = openOrThrow(path);
  return parseKittiTrajectory(in, path, stamps);
}

Trajectory readTrajectory(const std::string& path, TrajectoryFormat format,
                          const std::string& times_path) {
  return format == TrajectoryFormat::kTum ? readTumTrajectory(path)
                                          : readKittiTrajectory(path, times_path);
}

void writeTumTrajectory(std::ostream& out, const Trajectory& trajectory) {
  out << "# timestamp tx ty tz qx qy qz qw\n" << std::fixed;
  for (const auto& p : trajectory.poses()) {
    const Eigen::Quaterniond q(p.pose.linear());
    const Eigen::Vector3d t = p.pose.translation();
    out << std::setprecision(6) << p.stamp << std::setprecision(9) << ' ' << t.x() << ' ' << t.y()
        << ' ' << t.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
  }
}

void writeKittiTrajectory(std::ostream& out, const Trajectory& trajectory) {
  out << std::scientific << std::setprecision(9);
  for (const auto& p : trajectory.poses()) {
    const Eigen::Matrix<double, 3, 4> M = p.pose.matrix().topRows<3>();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c)
        out << M(r, c) << ((r == 2 && c == 3) ? '\n' : ' ');
    }
  }
}

void writeTrajectory(const std::string& path, const Trajectory& trajectory,
                     TrajectoryFormat format) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  if (format == TrajectoryFormat::kTum) {
    writeTumTrajectory(out, trajectory);
  } else {
    writeKittiTrajectory(out, trajectory);
  }
}

TrajectoryFormat parseTrajectoryFormat(const std::string& name) {
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  throw std::invalid_argument("unknown trajectory format '" + name + "' (expected tum or kitti)");
}

TrajectoryFormat detectTrajectoryFormat(const std::string& path) {
  auto in = openOrThrow(path);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (isBlankOrComment(line)) continue;
    const auto v = parseNumbers(line, path, line_no);
    if (v.size() == 8) return TrajectoryFormat::kTum;
    if (v.size() == 12) return TrajectoryFormat::kKitti;
    throwCount(path, line_no, v.size(), "8 (TUM) or 12 (KITTI)");
  }
  throw FormatError(path + ": no poses in file");
}

}  // namespace cvo
