// CvoParams from the flat "key: value" YAML presets in config/ (the same keys the nodelet reads
// as ROS parameters), and back to text for logging the effective values.
#pragma once

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "cvo_odometry/core/cvo_params.hpp"

namespace cvo {

// Sets one parameter from its text form; throws std::invalid_argument for an unknown key or a
// value of the wrong type.
void setCvoParam(CvoParams& params, const std::string& key, const std::string& value);
std::vector<std::string> cvoParamNames();

// Reads "key: value" lines ('#' comments, blank lines) and calls `apply` for each; a malformed
// line, a duplicate key, or std::invalid_argument from `apply` throws FormatError naming the
// source and line.
void parseKeyValueLines(std::istream& in, const std::string& source_name,
                        const std::function<void(const std::string&, const std::string&)>& apply);

// The keys a preset may carry for the front end (point_selector, min_points, max_points,
// min_depth, max_depth, crop_top_rows): the front end reads them, the core skips them.
const std::vector<std::string>& frontendPresetKeys();

// CvoParams from a preset; unknown keys and bad values throw FormatError naming the source and
// line. The front end's keys are skipped. Keys not in the text keep `base`'s values. The result
// is validated.
CvoParams parseCvoParams(std::istream& in, const std::string& source_name,
                         const CvoParams& base = CvoParams());
CvoParams loadCvoParams(const std::string& path, const CvoParams& base = CvoParams());

void writeCvoParams(std::ostream& out, const CvoParams& params);

}  // namespace cvo
