// CvoParams from the flat "key: value" YAML presets in config/ and back to text, through the
// settings table (cvo_settings.hpp). A full preset also carries the front end's keys: the
// ROS-free tools that read only the core skip them (UnknownKeys::kIgnore); everyone else reads
// the whole aggregate (frontend/odometry_settings.hpp).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "cvo_odometry/core/cvo_params.hpp"

namespace cvo {

// Sets one parameter from its text form; throws std::invalid_argument for an unknown key, a
// value of the wrong form or one outside its range.
void setCvoParam(CvoParams& params, const std::string& key, const std::string& value);
std::vector<std::string> cvoParamNames();

// CvoParams from a preset; bad keys and values throw FormatError naming the source and line.
// Keys not in the text keep `base`'s values. The result is validated.
CvoParams parseCvoParams(std::istream& in, const std::string& source_name,
                         const CvoParams& base = CvoParams(),
                         UnknownKeys unknown = UnknownKeys::kError);
CvoParams loadCvoParams(const std::string& path, const CvoParams& base = CvoParams(),
                        UnknownKeys unknown = UnknownKeys::kError);

void writeCvoParams(std::ostream& out, const CvoParams& params);

}  // namespace cvo
