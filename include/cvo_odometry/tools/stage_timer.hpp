// Per-stage timing samples with median and 95th percentile, for the runner's summary.
#pragma once

#include <iosfwd>
#include <map>
#include <string>
#include <vector>

namespace cvo {

class StageTimer {
 public:
  void add(const std::string& stage, double ms) { samples_[stage].push_back(ms); }
  double percentile(const std::string& stage, double q) const;
  void print(std::ostream& out) const;

 private:
  std::map<std::string, std::vector<double>> samples_;
};

}  // namespace cvo
