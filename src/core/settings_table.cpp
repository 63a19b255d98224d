#include "cvo_odometry/core/settings_table.hpp"

#include <cmath>
#include <cstdlib>
#include <set>

#include "cvo_odometry/core/format_error.hpp"

namespace cvo {

namespace {

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

std::string numberText(double v) {
  std::ostringstream out;
  out.precision(12);
  out << v;
  return out.str();
}

void checkRange(const SettingInfo& info, double v) {
  if (v < info.min || v > info.max) {
    throw std::invalid_argument(std::string(info.name) + " must be in " +
                                settingRangeText(info.min, info.max) + ", got " + numberText(v));
  }
}

}  // namespace

double parseSettingNumber(const std::string& name, const std::string& text) {
  const std::string t = trim(text);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || *end != '\0' || !std::isfinite(v)) {
    throw std::invalid_argument(name + " expects a number, got '" + text + "'");
  }
  return v;
}

void parseSettingText(const SettingInfo& info, const std::string& text, double& out) {
  const double v = parseSettingNumber(info.name, text);
  checkRange(info, v);
  out = v;
}

void parseSettingText(const SettingInfo& info, const std::string& text, int& out) {
  double v = 0.0;
  try {
    v = parseSettingNumber(info.name, text);
  } catch (const std::invalid_argument&) {
    v = 0.5;  // not a number: reported as not an integer below
  }
  // Range first: converting a double outside int's range is undefined.
  if (!(v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max()) ||
      v != std::floor(v)) {
    throw std::invalid_argument(std::string(info.name) + " expects an integer, got '" + text + "'");
  }
  checkRange(info, v);
  out = static_cast<int>(v);
}

void parseSettingText(const SettingInfo& info, const std::string& text, bool& out) {
  const std::string t = trim(text);
  if (t == "true" || t == "True" || t == "1") {
    out = true;
  } else if (t == "false" || t == "False" || t == "0") {
    out = false;
  } else {
    throw std::invalid_argument(std::string(info.name) + " expects true or false, got '" + text +
                                "'");
  }
}

void parseSettingText(const SettingInfo&, const std::string& text, std::string& out) {
  out = text;
}

namespace {

template <class T>
void parseList(const SettingInfo& info, const std::string& text, std::vector<T>& out) {
  std::string t = trim(text);
  if (t.size() >= 2 && t.front() == '[' && t.back() == ']') t = t.substr(1, t.size() - 2);
  std::vector<T> values;
  std::stringstream items(t);
  std::string item;
  while (std::getline(items, item, ',')) {
    if (trim(item).empty()) continue;
    T v{};
    parseSettingText(info, item, v);
    values.push_back(v);
  }
  out = values;
}

template <class T>
std::string listText(const std::vector<T>& value) {
  std::string out;
  for (std::size_t k = 0; k < value.size(); ++k)
    out += (k ? "," : "") + settingText(value[k]);
  return out;
}

}  // namespace

void parseSettingText(const SettingInfo& info, const std::string& text, std::vector<int>& out) {
  parseList(info, text, out);
}

void parseSettingText(const SettingInfo& info, const std::string& text, std::vector<double>& out) {
  parseList(info, text, out);
}

std::string settingText(double value) {
  return numberText(value);
}
std::string settingText(int value) {
  return std::to_string(value);
}
std::string settingText(bool value) {
  return value ? "true" : "false";
}
std::string settingText(const std::string& value) {
  return value;
}
std::string settingText(const std::vector<int>& value) {
  return listText(value);
}
std::string settingText(const std::vector<double>& value) {
  return listText(value);
}

std::string settingType(double) {
  return "double";
}
std::string settingType(int) {
  return "int";
}
std::string settingType(bool) {
  return "bool";
}
std::string settingType(const std::string&) {
  return "string";
}
std::string settingType(const std::vector<int>&) {
  return "int list";
}
std::string settingType(const std::vector<double>&) {
  return "double list";
}

std::string settingRangeText(double min, double max) {
  const bool low = std::isfinite(min), high = std::isfinite(max);
  if (!low && !high) return "";
  return "[" + (low ? numberText(min) : std::string("-inf")) + ", " +
         (high ? numberText(max) : std::string("inf")) + "]";
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

void throwInvalidSettings(const std::string& source_name, const std::exception& e) {
  throw FormatError(source_name + ": " + e.what());
}

}  // namespace cvo
