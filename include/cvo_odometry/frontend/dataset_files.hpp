// Small readers the dataset folders share (TUM listings, KITTI calibration and times).
#pragma once

#include <string>
#include <vector>

namespace cvo {

bool fileExists(const std::string& path);

// Lines of `path` split in whitespace-separated fields, comments ('#') and blank lines skipped.
// With `fields` > 0 every line must have that many; throws FormatError naming file and line.
std::vector<std::vector<std::string>> readFieldRows(const std::string& path,
                                                    std::size_t fields = 0);

// A finite number, or FormatError naming `where`.
double parseFiniteNumber(const std::string& text, const std::string& where);

}  // namespace cvo
