// libFuzzer target: arbitrary text through every parameter and text-file reader (CVO presets,
// the whole settings table, TUM and KITTI trajectories, time stamps). Each may refuse the
// input with the errors it documents; anything else (a crash, a sanitizer report, another
// exception) is a finding.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "cvo_odometry/core/format_error.hpp"
#include "cvo_odometry/core/params_io.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/frontend/odometry_settings.hpp"

namespace {

template <class Parse>
void refuseCleanly(Parse&& parse) {
  try {
    parse();
  } catch (const std::invalid_argument&) {
  } catch (const cvo::FormatError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  refuseCleanly([&] {
    std::istringstream in(text);
    cvo::parseCvoParams(in, "fuzz").validate();
  });
  refuseCleanly([&] {
    std::istringstream in(text);
    cvo::OdometrySettings settings;
    cvo::readSettings(in, "fuzz", &settings);
  });
  refuseCleanly([&] {
    std::istringstream in(text);
    cvo::parseTumTrajectory(in, "fuzz");
  });
  refuseCleanly([&] {
    std::istringstream in(text);
    cvo::parseKittiTrajectory(in, "fuzz", {});
  });
  refuseCleanly([&] {
    std::istringstream in(text);
    cvo::parseStamps(in, "fuzz");
  });
  return 0;
}
