#include "cvo_odometry/core/params_io.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "cvo_odometry/core/format_error.hpp"

namespace cvo {

namespace {

// Calls f(name, member) for every numeric and boolean parameter: one list serves parsing,
// listing and printing.
template <class Params, class Visitor>
void visitScalars(Params& p, Visitor&& f) {
  f("ell_init", p.ell_init);
  f("ell_min", p.ell_min);
  f("ell_first_frame", p.ell_first_frame);
  f("sigma", p.sigma);
  f("sp_thres", p.sp_thres);
  f("use_color", p.use_color);
  f("color_ell", p.color_ell);
  f("color_sigma", p.color_sigma);
  f("use_semantics", p.use_semantics);
  f("semantic_ell", p.semantic_ell);
  f("semantic_sigma", p.semantic_sigma);
  f("decay_rate", p.decay_rate);
  f("decay_start", p.decay_start);
  f("first_frame_decay_rate", p.first_frame_decay_rate);
  f("first_frame_decay_start", p.first_frame_decay_start);
  f("indicator_window", p.indicator_window);
  f("indicator_tolerance", p.indicator_tolerance);
  f("min_step", p.min_step);
  f("max_step", p.max_step);
  f("eps_2", p.eps_2);
  f("max_iterations", p.max_iterations);
  f("schedule_decay", p.schedule_decay);
  f("level_tolerance", p.level_tolerance);
  f("subsample_coarse_levels", p.subsample_coarse_levels);
  f("max_overrelaxation", p.max_overrelaxation);
  f("max_level_iterations", p.max_level_iterations);
  f("newton_at_ell_min", p.newton_at_ell_min);
  f("photometric_rotation", p.photometric_rotation);
  f("photometric_iterations", p.photometric_iterations);
  f("photometric_max_correction", p.photometric_max_correction);
  f("num_threads", p.num_threads);
  f("min_cosine", p.min_cosine);
  f("min_tracking_points", p.min_tracking_points);
  f("max_linear_speed", p.max_linear_speed);
  f("max_angular_speed", p.max_angular_speed);
  f("max_lost_frames", p.max_lost_frames);
}

void parseValue(const std::string& key, const std::string& text, double& out) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) {
    throw std::invalid_argument(key + " expects a number, got '" + text + "'");
  }
  out = v;
}

void parseValue(const std::string& key, const std::string& text, int& out) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || v < INT32_MIN || v > INT32_MAX) {
    throw std::invalid_argument(key + " expects an integer, got '" + text + "'");
  }
  out = static_cast<int>(v);
}

void parseValue(const std::string& key, const std::string& text, bool& out) {
  if (text == "true" || text == "True" || text == "1") {
    out = true;
  } else if (text == "false" || text == "False" || text == "0") {
    out = false;
  } else {
    throw std::invalid_argument(key + " expects true or false, got '" + text + "'");
  }
}

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::string unquote(const std::string& s) {
  if (s.size() >= 2 && (s.front() == '"' || s.front() == '\'') && s.back() == s.front()) {
    return s.substr(1, s.size() - 2);
  }
  return s;
}

}  // namespace

void setCvoParam(CvoParams& params, const std::string& key, const std::string& value) {
  if (key == "step_method") {
    params.step_method = parseStepMethod(value);
    return;
  }
  if (key == "backend") {
    params.backend = parseBackendChoice(value);
    return;
  }
  if (key == "lost_frame_policy") {
    params.lost_frame_policy = parseLostFramePolicy(value);
    return;
  }
  bool found = false;
  visitScalars(params, [&](const char* name, auto& member) {
    if (key == name) {
      parseValue(key, value, member);
      found = true;
    }
  });
  if (!found) throw std::invalid_argument("unknown CVO parameter '" + key + "'");
}

std::vector<std::string> cvoParamNames() {
  std::vector<std::string> names{"step_method", "backend", "lost_frame_policy"};
  CvoParams p;
  visitScalars(p, [&](const char* name, auto&) { names.emplace_back(name); });
  return names;
}

void parseKeyValueLines(std::istream& in, const std::string& source_name,
                        const std::function<void(const std::string&, const std::string&)>& apply) {
  std::set<std::string> seen;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto hash = line.find('#');
    const std::string content = trim(hash == std::string::npos ? line : line.substr(0, hash));
    if (content.empty() || content == "---") continue;
    const std::string where = source_name + ":" + std::to_string(line_no) + ": ";
    const auto colon = content.find(':');
    if (colon == std::string::npos) throw FormatError(where + "expected 'key: value'");
    const std::string key = trim(content.substr(0, colon));
    const std::string value = unquote(trim(content.substr(colon + 1)));
    if (!seen.insert(key).second) throw FormatError(where + "'" + key + "' given twice");
    try {
      apply(key, value);
    } catch (const std::invalid_argument& e) {
      throw FormatError(where + e.what());
    }
  }
}

const std::vector<std::string>& frontendPresetKeys() {
  static const std::vector<std::string> keys{"point_selector", "min_points", "max_points",
                                             "min_depth",      "max_depth",  "crop_top_rows",
                                             "image_levels"};
  return keys;
}

CvoParams parseCvoParams(std::istream& in, const std::string& source_name, const CvoParams& base) {
  CvoParams params = base;
  const auto& skipped = frontendPresetKeys();
  parseKeyValueLines(in, source_name, [&](const std::string& key, const std::string& value) {
    if (std::find(skipped.begin(), skipped.end(), key) != skipped.end()) return;
    setCvoParam(params, key, value);
  });
  try {
    params.validate();
  } catch (const std::invalid_argument& e) {
    throw FormatError(source_name + ": " + e.what());
  }
  return params;
}

CvoParams loadCvoParams(const std::string& path, const CvoParams& base) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open parameter file '" + path + "'");
  return parseCvoParams(in, path, base);
}

void writeCvoParams(std::ostream& out, const CvoParams& params) {
  out << "step_method: " << toString(params.step_method) << "\n";
  out << "backend: " << toString(params.backend) << "\n";
  out << "lost_frame_policy: " << toString(params.lost_frame_policy) << "\n";
  CvoParams copy = params;
  visitScalars(copy, [&](const char* name, auto& member) {
    using T = std::decay_t<decltype(member)>;
    if constexpr (std::is_same_v<T, bool>) {
      out << name << ": " << (member ? "true" : "false") << "\n";
    } else {
      out << name << ": " << member << "\n";
    }
  });
}

}  // namespace cvo
