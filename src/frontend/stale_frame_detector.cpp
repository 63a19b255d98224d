#include "cvo_odometry/frontend/stale_frame_detector.hpp"

#include <cstring>

namespace cvo {

std::uint64_t imageFingerprint(const cv::Mat& image) {
  // FNV-1a (with a shift, below) over 64-bit words in four interleaved lanes (one lane's multiply
  // chain would take ~4 cycles a word: 0.3 ms for a TUM frame's two images), the tail bytes, the
  // shape, then the lanes folded together.
  constexpr std::uint64_t kPrime = 0x100000001b3ULL;
  constexpr int kLanes = 4;
  std::uint64_t lanes[kLanes];
  for (int l = 0; l < kLanes; ++l)
    lanes[l] = 0xcbf29ce484222325ULL + static_cast<std::uint64_t>(l);
  std::uint64_t h = 0xcbf29ce484222325ULL;
  // The shift after FNV's multiply carries high bits down: a multiply alone only moves a change
  // upwards, so a word's top byte would never reach the low bits (two images differing only there
  // collided about once in 256).
  const auto mix = [&](std::uint64_t& hash, std::uint64_t word) {
    hash ^= word;
    hash *= kPrime;
    hash ^= hash >> 29;
  };
  mix(h, static_cast<std::uint64_t>(image.rows));
  mix(h, static_cast<std::uint64_t>(image.cols));
  mix(h, static_cast<std::uint64_t>(image.type()));
  const std::size_t row_bytes = image.cols * image.elemSize();
  for (int r = 0; r < image.rows; ++r) {
    const unsigned char* row = image.ptr<unsigned char>(r);
    std::size_t k = 0;
    for (; k + 8 * kLanes <= row_bytes; k += 8 * kLanes) {
      for (int l = 0; l < kLanes; ++l) {
        std::uint64_t word;
        std::memcpy(&word, row + k + 8 * l, 8);
        mix(lanes[l], word);
      }
    }
    for (; k < row_bytes; ++k)
      mix(h, row[k]);
  }
  for (const std::uint64_t lane : lanes)
    mix(h, lane);
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
