#include "cvo_odometry/frontend/frontend_params.hpp"

#include <algorithm>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "cvo_odometry/core/format_error.hpp"
#include "cvo_odometry/core/params_io.hpp"

namespace cvo {

namespace {

double toNumber(const std::string& key, const std::string& value) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size()) {
    throw std::invalid_argument("'" + key + "' expects a number, got '" + value + "'");
  }
  return v;
}

int toInt(const std::string& key, const std::string& value) {
  const double v = toNumber(key, value);
  // Range first: converting a double outside int's range is undefined.
  if (!(v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max()) ||
      v != static_cast<int>(v)) {
    throw std::invalid_argument("'" + key + "' expects an integer, got '" + value + "'");
  }
  return static_cast<int>(v);
}

}  // namespace

void setFrontendParam(CloudBuilderOptions& options, const std::string& key,
                      const std::string& value) {
  if (key == "point_selector") {
    options.selector.kind = parseSelectorKind(value);
  } else if (key == "min_points") {
    options.selector.min_points = toInt(key, value);
  } else if (key == "max_points") {
    options.selector.max_points = toInt(key, value);
  } else if (key == "min_depth") {
    options.min_depth = toNumber(key, value);
  } else if (key == "max_depth") {
    options.max_depth = toNumber(key, value);
  } else if (key == "crop_top_rows") {
    options.crop_top_rows = toInt(key, value);
  } else if (key == "image_levels") {
    options.image_levels = toInt(key, value);
  } else {
    throw std::invalid_argument("unknown front-end parameter '" + key + "'");
  }
}

void parseFrontendParams(std::istream& in, const std::string& source_name,
                         CloudBuilderOptions* options) {
  const auto cvo_keys = cvoParamNames();
  parseKeyValueLines(in, source_name, [&](const std::string& key, const std::string& value) {
    if (std::find(cvo_keys.begin(), cvo_keys.end(), key) == cvo_keys.end())
      setFrontendParam(*options, key, value);
  });
  try {
    options->validate();
  } catch (const std::invalid_argument& e) {
    throw FormatError(source_name + ": " + e.what());
  }
}

void loadFrontendParams(const std::string& path, CloudBuilderOptions* options) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open parameter file '" + path + "'");
  parseFrontendParams(in, path, options);
}

CloudBuilderOptions frontendOptionsFor(CloudBuilderOptions options, const CvoParams& params) {
  if (!params.photometric_rotation) options.image_levels = 0;
  return options;
}

}  // namespace cvo
