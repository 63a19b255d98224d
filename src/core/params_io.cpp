#include "cvo_odometry/core/params_io.hpp"

#include <ostream>

#include "cvo_odometry/core/cvo_settings.hpp"

namespace cvo {

void setCvoParam(CvoParams& params, const std::string& key, const std::string& value) {
  setSetting(params, key, value);
}

std::vector<std::string> cvoParamNames() {
  std::vector<std::string> names;
  for (const auto& row : settingRows(CvoParams()))
    names.push_back(row.name);
  return names;
}

CvoParams parseCvoParams(std::istream& in, const std::string& source_name, const CvoParams& base,
                         UnknownKeys unknown) {
  CvoParams params = base;
  readSettings(in, source_name, &params, unknown);
  return params;
}

CvoParams loadCvoParams(const std::string& path, const CvoParams& base, UnknownKeys unknown) {
  CvoParams params = base;
  loadSettings(path, &params, unknown);
  return params;
}

void writeCvoParams(std::ostream& out, const CvoParams& params) {
  out << describeSettings(params);
}

}  // namespace cvo
