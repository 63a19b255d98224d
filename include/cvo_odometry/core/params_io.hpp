// CvoParams from the flat "key: value" YAML presets in config/ (the same keys the nodelet reads
// as ROS parameters), and back to text for logging the effective values.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "cvo_odometry/core/cvo_params.hpp"

namespace cvo {

// Sets one parameter from its text form; throws std::invalid_argument for an unknown key or a
// value of the wrong type.
void setCvoParam(CvoParams& params, const std::string& key, const std::string& value);
std::vector<std::string> cvoParamNames();

// Parses "key: value" lines ('#' comments, blank lines); unknown keys, bad values and duplicate
// keys throw FormatError naming the source and line. Keys not in the text keep `base`'s values.
// The result is validated.
CvoParams parseCvoParams(std::istream& in, const std::string& source_name,
                         const CvoParams& base = CvoParams());
CvoParams loadCvoParams(const std::string& path, const CvoParams& base = CvoParams());

void writeCvoParams(std::ostream& out, const CvoParams& params);

}  // namespace cvo
