#include "cvo_odometry/frontend/stale_frame_detector.hpp"

#include <cstring>

namespace cvo {

std::uint64_t imageFingerprint(const cv::Mat& image) {
  // FNV-1a over 64-bit words (and the tail bytes), seeded with the shape.
  constexpr std::uint64_t kPrime = 0x100000001b3ULL;
  std::uint64_t h = 0xcbf29ce484222325ULL;
  const auto mix = [&](std::uint64_t word) {
    h ^= word;
    h *= kPrime;
  };
  mix(static_cast<std::uint64_t>(image.rows));
  mix(static_cast<std::uint64_t>(image.cols));
  mix(static_cast<std::uint64_t>(image.type()));
  const std::size_t row_bytes = image.cols * image.elemSize();
  for (int r = 0; r < image.rows; ++r) {
    const unsigned char* row = image.ptr<unsigned char>(r);
    std::size_t k = 0;
    for (; k + 8 <= row_bytes; k += 8) {
      std::uint64_t word;
      std::memcpy(&word, row + k, 8);
      mix(word);
    }
    for (; k < row_bytes; ++k)
      mix(row[k]);
  }
  return h;
}

std::string StaleFrameDetector::check(const std::vector<cv::Mat>& images,
                                      const std::vector<std::string>& names) {
  std::vector<std::uint64_t> current;
  current.reserve(images.size());
  for (const cv::Mat& image : images)
    current.push_back(image.empty() ? 0 : imageFingerprint(image));
  std::string why;
  if (previous_.size() == current.size()) {
    for (std::size_t k = 0; k < current.size(); ++k) {
      if (current[k] == 0 || current[k] != previous_[k]) continue;
      why += (why.empty() ? "" : " and ") + (k < names.size() ? names[k] : std::string("image"));
    }
  }
  checked_ = current;
  return why.empty() ? "" : "the " + why + " image repeats the previous frame's";
}

}  // namespace cvo
