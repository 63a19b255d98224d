#include "cvo_odometry/tools/command_line.hpp"

#include <stdexcept>

namespace cvo {

CommandLine::CommandLine(int argc, char** argv, const std::set<std::string>& options,
                         const std::set<std::string>& flags) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument '" + arg + "'");
    const std::string name = arg.substr(2);
    // A second value would silently replace the first (a second --set dropping the first's).
    if (values_.count(name)) {
      throw std::invalid_argument("option --" + name + " given twice" +
                                  (name == "set" ? " (one --set takes k=v,k2=v2,...)" : ""));
    }
    if (flags.count(name)) {
      values_[name] = "1";
    } else if (options.count(name)) {
      if (i + 1 >= argc) throw std::invalid_argument("option --" + name + " needs a value");
      values_[name] = argv[++i];
    } else {
      throw std::invalid_argument("unknown option --" + name);
    }
  }
}

bool CommandLine::has(const std::string& name) const {
  return values_.count(name) > 0;
}

std::string CommandLine::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

std::string CommandLine::require(const std::string& name) const {
  if (!has(name)) throw std::invalid_argument("missing required option --" + name);
  return get(name);
}

double CommandLine::getDouble(const std::string& name, double fallback) const {
  if (!has(name)) return fallback;
  try {
    std::size_t used = 0;
    const double v = std::stod(get(name), &used);
    if (used == get(name).size()) return v;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("--" + name + " expects a number, got '" + get(name) + "'");
}

int CommandLine::getInt(const std::string& name, int fallback) const {
  if (!has(name)) return fallback;
  try {
    std::size_t used = 0;
    const int v = std::stoi(get(name), &used);
    if (used == get(name).size()) return v;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("--" + name + " expects an integer, got '" + get(name) + "'");
}

std::vector<double> CommandLine::getDoubleList(const std::string& name,
                                               const std::vector<double>& fallback) const {
  if (!has(name)) return fallback;
  // Each item wholly a number: "0.4x" or a trailing comma is a typo, not 0.4.
  const std::string text = get(name);
  std::vector<double> values;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = text.find(',', begin);
    const std::string item =
        text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (item.empty() || used != item.size()) {
      throw std::invalid_argument("--" + name + " expects comma-separated numbers, got '" + text +
                                  "'");
    }
    values.push_back(value);
    if (comma == std::string::npos) return values;
    begin = comma + 1;
  }
}

}  // namespace cvo
