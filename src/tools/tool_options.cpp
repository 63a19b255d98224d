#include "cvo_odometry/tools/tool_options.hpp"

#include <sstream>
#include <stdexcept>

#include "cvo_odometry/core/params_io.hpp"

namespace cvo {

CvoParams cvoParamsFrom(const CommandLine& cli) {
  CvoParams params;
  if (cli.has("preset")) params = loadCvoParams(cli.get("preset"));
  if (cli.has("backend")) params.backend = parseBackendChoice(cli.get("backend"));
  std::stringstream overrides(cli.get("set"));
  std::string item;
  while (std::getline(overrides, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) {
      throw std::invalid_argument("--set expects key=value, got '" + item + "'");
    }
    setCvoParam(params, item.substr(0, eq), item.substr(eq + 1));
  }
  params.validate();
  return params;
}

RgbdFrontendOptions rgbdFrontendOptionsFrom(const CommandLine& cli) {
  RgbdFrontendOptions options;
  options.depth_units_per_metre = cli.getDouble("depth-scale", 5000.0);  // TUM PNGs
  options.selector.kind = parseSelectorKind(cli.get("selector", "fast"));
  options.selector.min_points = cli.getInt("min-points", options.selector.min_points);
  options.selector.max_points = cli.getInt("max-points", options.selector.max_points);
  return options;
}

}  // namespace cvo
