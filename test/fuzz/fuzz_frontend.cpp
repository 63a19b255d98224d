// libFuzzer target: arbitrary image bytes, encodings, sizes, intrinsics (camera_info values) and
// options through the RGB-D and stereo front ends. The front end may refuse a frame with
// std::invalid_argument naming the problem (EmptyFrameError is one); anything else (a crash, a
// sanitizer report, an OpenCV assertion escaping as cv::Exception) is a finding.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/stereo_cloud_builder.hpp"

namespace {

// Reads the input front to back; past its end every read gives zeros.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  template <class T>
  T value() {
    unsigned char bytes[sizeof(T)] = {};
    for (auto& b : bytes)
      b = byte();
    T v;
    std::memcpy(&v, bytes, sizeof(T));
    return v;
  }
  // An image of `type` filled from the remaining bytes (zeros when they run out).
  cv::Mat image(int rows, int cols, int type) {
    cv::Mat m(rows, cols, type);
    const std::size_t bytes = m.total() * m.elemSize();
    const std::size_t available = std::min(bytes, size_ - std::min(at_, size_));
    std::memcpy(m.data, data_ + std::min(at_, size_), available);
    std::memset(m.data + available, 0, bytes - available);
    at_ += available;
    return m;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

constexpr int kColourTypes[] = {CV_8UC3, CV_8UC1, CV_8UC4, CV_16UC3};
constexpr int kDepthTypes[] = {CV_16UC1, CV_32FC1, CV_8UC1, CV_64FC1};
constexpr int kDisparityTypes[] = {CV_32FC1, CV_16UC1, CV_16SC1, CV_8UC1};
constexpr int kSemanticTypes[] = {CV_8UC1, CV_16UC1, CV_32FC2, CV_32FC3};

}  // namespace

// OpenCV on the calling thread only, so that the machine's core count (OpenCV's thread count)
// cannot change what an input does: CI's fuzz stage must reach the same coverage on every
// machine. (Two runs here agreed with OpenCV's threads too; the run-to-run differences came from
// libFuzzer's compare tracing and stack depth feature, see run_fuzzer.sh.)
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  cv::setNumThreads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  const std::uint8_t flags = in.byte();
  const int cols = 1 + in.byte() % 48, rows = 1 + in.byte() % 48;
  const bool stereo = flags & 0x40, mismatched = flags & 0x80, with_semantics = flags & 0x10;

  cvo::PinholeIntrinsics K;
  K.fx = in.value<float>(), K.fy = in.value<float>();
  K.cx = in.value<float>(), K.cy = in.value<float>();
  K.width = mismatched ? cols + 1 : cols;
  K.height = rows;
  const int distortion = in.byte() % 9;
  for (int i = 0; i < distortion; ++i)
    K.distortion.push_back(in.value<float>());

  cvo::CloudBuilderOptions cloud;
  cloud.selector.kind = static_cast<cvo::SelectorKind>(in.byte() % 3);
  cloud.selector.min_points = 1 + in.byte() % 64;
  cloud.selector.max_points = cloud.selector.min_points + in.byte();
  cloud.min_depth = in.value<float>();
  cloud.max_depth = in.value<float>();
  cloud.crop_top_rows = in.byte() % 8;
  cloud.semantic_classes = with_semantics ? 1 + in.byte() % 4 : 0;
  const int ignored = in.byte() % 5;
  if (ignored < 4) cloud.ignore_classes = {ignored};

  const cv::Mat colour = in.image(rows, cols, kColourTypes[flags & 3]);
  cv::Mat semantics;
  if (with_semantics) semantics = in.image(rows, cols, kSemanticTypes[in.byte() % 4]);
  try {
    if (stereo) {
      cvo::StereoFrontendOptions options;
      options.cloud = cloud;
      options.disparity_scale = in.value<float>();
      options.matcher.num_disparities = 16 * (1 + in.byte() % 2);
      cvo::StereoFrame frame;
      frame.left = colour;
      if (flags & 0x08) {
        frame.right = in.image(mismatched ? rows + 1 : rows, cols, colour.type());
      } else {
        frame.disparity =
            in.image(rows, mismatched ? cols + 1 : cols, kDisparityTypes[(flags >> 2) & 3]);
      }
      frame.intrinsics = K;
      frame.baseline = in.value<float>();
      frame.semantics = semantics;
      cvo::StereoCloudBuilder(options).build(frame);
    } else {
      cvo::RgbdFrontendOptions options;
      options.cloud = cloud;
      options.depth_units_per_metre = in.value<float>();
      cvo::RgbdFrame frame;
      frame.image = colour;
      frame.depth = in.image(mismatched ? rows + 1 : rows, cols, kDepthTypes[(flags >> 2) & 3]);
      frame.intrinsics = K;
      frame.semantics = semantics;
      cvo::RgbdCloudBuilder(options).build(frame);
    }
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
