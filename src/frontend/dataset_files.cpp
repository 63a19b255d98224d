#include "cvo_odometry/frontend/dataset_files.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "cvo_odometry/core/format_error.hpp"

namespace cvo {

bool fileExists(const std::string& path) {
  return std::ifstream(path).good();
}

std::vector<std::vector<std::string>> readFieldRows(const std::string& path, std::size_t fields) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  std::vector<std::vector<std::string>> rows;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream ss(line);
    std::vector<std::string> row;
    std::string field;
    while (ss >> field)
      row.push_back(field);
    if (row.empty() || row[0][0] == '#') continue;
    if (fields > 0 && row.size() != fields) {
      throw FormatError(path + ":" + std::to_string(line_no) + ": expected " +
                        std::to_string(fields) + " fields, got " + std::to_string(row.size()));
    }
    rows.push_back(row);
  }
  return rows;
}

double parseFiniteNumber(const std::string& text, const std::string& where) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) {
    throw FormatError(where + ": bad number '" + text + "'");
  }
  return v;
}

}  // namespace cvo
