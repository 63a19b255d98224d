// Drivers that repeat frames: an image byte-identical to the previous one of its stream carries
// no new measurement, and registering it would report stale motion as tracked. A 64-bit
// fingerprint of each stream's last image tells such frames apart at a fraction of a millisecond.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace cvo {

// A 64-bit fingerprint of an image's size, type and bytes (equal images, equal fingerprints).
std::uint64_t imageFingerprint(const cv::Mat& image);

class StaleFrameDetector {
 public:
  // Compares each stream's image with the one of the last accepted frame (`names` label the
  // streams in the message); returns why the frame is stale, or "" for a fresh frame. Empty
  // images are not compared.
  std::string check(const std::vector<cv::Mat>& images, const std::vector<std::string>& names);
  // The images last checked become the ones to compare with: a frame the odometry took (a
  // malformed one, skipped, leaves no trace).
  void accept() { previous_ = checked_; }
  void reset() { previous_.clear(), checked_.clear(); }

 private:
  std::vector<std::uint64_t> previous_, checked_;
};

}  // namespace cvo
