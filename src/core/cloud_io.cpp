#include "cvo_odometry/core/cloud_io.hpp"

#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "cvo_odometry/core/format_error.hpp"

namespace cvo {

namespace {
constexpr char kMagic[] = "CVOCLOUD 1\n";
constexpr std::size_t kMagicSize = sizeof(kMagic) - 1;
}  // namespace

void writeCloud(const std::string& path, const LabeledCloud& cloud) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  out.write(kMagic, kMagicSize);
  const std::uint64_t header[3] = {cloud.size(), cloud.hasColor() ? 1u : 0u,
                                   static_cast<std::uint64_t>(cloud.semanticClasses())};
  out.write(reinterpret_cast<const char*>(header), sizeof(header));
  for (const auto* data : {&cloud.positionData(), &cloud.colorData(), &cloud.semanticData()}) {
    out.write(reinterpret_cast<const char*>(data->data()),
              static_cast<std::streamsize>(data->size() * sizeof(float)));
  }
  if (!out) throw std::runtime_error("writing '" + path + "' failed");
}

LabeledCloud readCloud(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  char magic[kMagicSize];
  std::uint64_t header[3];
  if (!in.read(magic, kMagicSize) || std::string(magic, kMagicSize) != kMagic ||
      !in.read(reinterpret_cast<char*>(header), sizeof(header))) {
    throw FormatError(path + ": not a cvo_odometry cloud file");
  }
  const std::uint64_t n = header[0];
  const bool color = header[1] != 0;
  const std::uint64_t classes = header[2];
  if (n > (1u << 26) || classes > 1024) throw FormatError(path + ": implausible header");
  std::vector<float> positions(3 * n), colors(color ? LabeledCloud::kColorDim * n : 0),
      semantics(classes * n);
  for (auto* data : {&positions, &colors, &semantics}) {
    if (!in.read(reinterpret_cast<char*>(data->data()),
                 static_cast<std::streamsize>(data->size() * sizeof(float)))) {
      throw FormatError(path + ": truncated (expected " + std::to_string(n) + " points)");
    }
  }
  LabeledCloud cloud(color, static_cast<int>(classes));
  cloud.reserve(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    cloud.add(Eigen::Vector3f(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]),
              color ? &colors[LabeledCloud::kColorDim * i] : nullptr,
              classes ? &semantics[classes * i] : nullptr);
  }
  return cloud;
}

}  // namespace cvo
