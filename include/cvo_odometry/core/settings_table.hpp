// The one settings table. Every parameter of the package (core, front end, pipeline, node) is
// declared once, in its layer's visitSettings(), with its name, group, range and one line of
// documentation; its default is the initialiser of its struct member. Presets, ROS parameters,
// the tools' --set and --<name>, describe(), dynamic_reconfigure and README's parameter table
// are all read through the templates below, with one parser for every text form.
#pragma once

#include <fstream>
#include <functional>
#include <iosfwd>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace cvo {

// What the table says of one parameter. The range is inclusive and applies to numbers only;
// cross-parameter rules (ell_min <= ell_init, ...) stay in the structs' validate().
struct SettingInfo {
  const char* name;
  const char* group;
  const char* doc;
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
};

// The names of an enumeration's values, declared beside the enumeration as
// `const std::vector<EnumName<E>>& enumNames(E)`, found by argument-dependent lookup.
template <class E>
struct EnumName {
  E value;
  const char* name;
};

// What a preset reader does with a key no visited layer knows: a tool that reads only some
// layers of a full preset (the ROS-free benchmark) skips the others' keys.
enum class UnknownKeys { kError, kIgnore };

// The one parser: numbers in decimal or exponent form; an integer parameter takes an integral
// number ("3000" or "3000.0"); booleans true/false/True/False/1/0; lists "1,2,3" (or "[1, 2]").
double parseSettingNumber(const std::string& name, const std::string& text);
void parseSettingText(const SettingInfo& info, const std::string& text, double& out);
void parseSettingText(const SettingInfo& info, const std::string& text, int& out);
void parseSettingText(const SettingInfo& info, const std::string& text, bool& out);
void parseSettingText(const SettingInfo& info, const std::string& text, std::string& out);
void parseSettingText(const SettingInfo& info, const std::string& text, std::vector<int>& out);
void parseSettingText(const SettingInfo& info, const std::string& text, std::vector<double>& out);

std::string settingText(double value);
std::string settingText(int value);
std::string settingText(bool value);
std::string settingText(const std::string& value);
std::string settingText(const std::vector<int>& value);
std::string settingText(const std::vector<double>& value);

std::string settingType(double);
std::string settingType(int);
std::string settingType(bool);
std::string settingType(const std::string&);
std::string settingType(const std::vector<int>&);
std::string settingType(const std::vector<double>&);

// "a, b or c" of an enumeration's names.
template <class E>
std::string enumChoices(E) {
  const auto& names = enumNames(E{});
  std::string out;
  for (std::size_t k = 0; k < names.size(); ++k) {
    out += names[k].name;
    if (k + 2 < names.size()) {
      out += ", ";
    } else if (k + 1 < names.size()) {
      out += " or ";
    }
  }
  return out;
}

template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
void parseSettingText(const SettingInfo& info, const std::string& text, E& out) {
  for (const auto& entry : enumNames(E{})) {
    if (text == entry.name) {
      out = entry.value;
      return;
    }
  }
  throw std::invalid_argument("unknown " + std::string(info.name) + " '" + text + "' (" +
                              enumChoices(E{}) + ")");
}

template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
std::string settingText(E value) {
  for (const auto& entry : enumNames(E{})) {
    if (entry.value == value) return entry.name;
  }
  return "?";
}

template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
std::string settingType(E) {
  std::string out;
  for (const auto& entry : enumNames(E{}))
    out += (out.empty() ? "" : " / ") + std::string(entry.name);
  return out;
}

// The enumeration value named `text`, or std::invalid_argument naming `what` and the choices.
template <class E>
E parseEnum(const std::string& what, const std::string& text) {
  E value{};
  parseSettingText(SettingInfo{what.c_str(), "", ""}, text, value);
  return value;
}

// One row of the table as text: for listings, README and the reconfigure mapping.
struct SettingRow {
  std::string name, group, doc, type, value;
  double min, max;
};

// Generic operations on a settings aggregate S; each needs `visitSettings(S&, visitor)` found
// by argument-dependent lookup, calling visitor(const SettingInfo&, member&) for every member.
template <class S>
std::vector<SettingRow> settingRows(const S& settings) {
  S copy = settings;
  std::vector<SettingRow> rows;
  visitSettings(copy, [&](const SettingInfo& info, auto& member) {
    rows.push_back({info.name, info.group, info.doc, settingType(member), settingText(member),
                    info.min, info.max});
  });
  return rows;
}

template <class S>
bool hasSetting(const S& settings, const std::string& name) {
  for (const auto& row : settingRows(settings))
    if (row.name == name) return true;
  return false;
}

// Sets one parameter from text; throws std::invalid_argument for an unknown name, a value of the
// wrong form or one outside the parameter's range.
template <class S>
void setSetting(S& settings, const std::string& name, const std::string& text) {
  bool found = false;
  visitSettings(settings, [&](const SettingInfo& info, auto& member) {
    if (found || name != info.name) return;
    found = true;
    auto value = member;
    parseSettingText(info, text, value);
    member = value;
  });
  if (!found) throw std::invalid_argument("unknown parameter '" + name + "'");
}

template <class S>
std::string settingValue(const S& settings, const std::string& name) {
  for (const auto& row : settingRows(settings))
    if (row.name == name) return row.value;
  throw std::invalid_argument("unknown parameter '" + name + "'");
}

// "name: value" lines, a preset that reads back to the same settings.
template <class S>
std::string describeSettings(const S& settings) {
  std::ostringstream out;
  for (const auto& row : settingRows(settings))
    out << row.name << ": " << row.value << "\n";
  return out.str();
}

// The lines whose value differs from `reference`'s.
template <class S>
std::string describeChanges(const S& settings, const S& reference) {
  const auto rows = settingRows(settings), base = settingRows(reference);
  std::ostringstream out;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (rows[k].value != base[k].value) out << rows[k].name << ": " << rows[k].value << "\n";
  return out.str();
}

// Reads "key: value" lines ('#' comments, blank lines, "---"); a malformed line, a duplicate key
// or an error from `apply` throws FormatError naming the source and line.
void parseKeyValueLines(std::istream& in, const std::string& source_name,
                        const std::function<void(const std::string&, const std::string&)>& apply);

// Throws FormatError("source: what") for an aggregate whose validate() refuses it.
[[noreturn]] void throwInvalidSettings(const std::string& source_name, const std::exception& e);

// Reads a preset's text into `settings` (keys not in it keep their values) and validates;
// FormatError names the source and line of a bad key or value.
template <class S>
void readSettings(std::istream& in, const std::string& source_name, S* settings,
                  UnknownKeys unknown = UnknownKeys::kError) {
  parseKeyValueLines(in, source_name, [&](const std::string& key, const std::string& value) {
    if (unknown == UnknownKeys::kIgnore && !hasSetting(*settings, key)) return;
    setSetting(*settings, key, value);
  });
  try {
    settings->validate();
  } catch (const std::invalid_argument& e) {
    throwInvalidSettings(source_name, e);
  }
}

template <class S>
void loadSettings(const std::string& path, S* settings, UnknownKeys unknown = UnknownKeys::kError) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open parameter file '" + path + "'");
  readSettings(in, path, settings, unknown);
}

std::string settingRangeText(double min, double max);

// README's parameter table (markdown) of an aggregate's defaults, in table order.
template <class S>
std::string settingsMarkdown(const S& defaults) {
  std::ostringstream out;
  out << "| group | name | type | default | range | meaning |\n|---|---|---|---|---|---|\n";
  for (const auto& row : settingRows(defaults)) {
    out << "| " << row.group << " | `" << row.name << "` | " << row.type << " | "
        << (row.value.empty() ? "\"\"" : row.value) << " | " << settingRangeText(row.min, row.max)
        << " | " << row.doc << " |\n";
  }
  return out.str();
}

}  // namespace cvo
