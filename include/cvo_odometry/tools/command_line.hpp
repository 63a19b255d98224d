// Minimal "--name value" / "--flag" parser shared by the command-line tools.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

namespace cvo {

class CommandLine {
 public:
  // `flags` take no value; every other option takes exactly one. Unknown options, and an option
  // given twice, throw std::invalid_argument naming them.
  CommandLine(int argc, char** argv, const std::set<std::string>& options,
              const std::set<std::string>& flags = {});

  bool has(const std::string& name) const;
  std::string get(const std::string& name, const std::string& fallback = "") const;
  std::string require(const std::string& name) const;
  double getDouble(const std::string& name, double fallback) const;
  int getInt(const std::string& name, int fallback) const;
  std::vector<double> getDoubleList(const std::string& name,
                                    const std::vector<double>& fallback) const;

 private:
  std::map<std::string, std::string> values_;
};

}  // namespace cvo
