// FloatBufferPool and the photometric levels built in its buffers: a buffer handed back is the
// one taken next for that size, and an image built in reused buffers equals one built fresh.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/depth_cloud_builder.hpp"
#include "cvo_odometry/frontend/float_buffer_pool.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

const std::string kTum = std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz";

TEST(FloatBufferPool, HandsBackTheBufferKeptForThatSize) {
  cvo::FloatBufferPool pool(2);
  std::vector<float> a = pool.take(100);
  EXPECT_EQ(a.size(), 100u);
  a[7] = 3.0f;
  const float* storage = a.data();
  pool.give(std::move(a));
  pool.give({});  // nothing to keep
  EXPECT_EQ(pool.kept(), 1u);
  const std::vector<float> other = pool.take(70);  // no kept buffer of 70: a new one
  EXPECT_EQ(other.size(), 70u);
  EXPECT_EQ(pool.kept(), 1u);
  const std::vector<float> again = pool.take(100);
  EXPECT_EQ(again.data(), storage);
  EXPECT_EQ(again[7], 3.0f) << "a kept buffer holds what its last user left";
  EXPECT_EQ(pool.kept(), 0u);
}

TEST(FloatBufferPool, WhenFullTheBufferKeptLongestGoes) {
  // The images changed size: a pool full of the old size comes to serve the new one.
  cvo::FloatBufferPool pool(2);
  pool.give(std::vector<float>(100));
  pool.give(std::vector<float>(100));
  std::vector<float> first(200), second(200);
  const float* first_storage = first.data();
  const float* second_storage = second.data();
  pool.give(std::move(first));
  pool.give(std::move(second));
  EXPECT_EQ(pool.kept(), 2u);
  const std::vector<float> a = pool.take(200), b = pool.take(200);
  EXPECT_EQ(a.data(), first_storage);
  EXPECT_EQ(b.data(), second_storage);
  EXPECT_EQ(pool.kept(), 0u) << "both buffers of 100 went";
}

TEST(FloatBufferPool, LevelsBuiltInReusedBuffersEqualFreshOnes) {
  const cvo::TumSequence sequence(kTum);
  cv::Mat first, second, depth;
  sequence.load(0, &first, &depth);
  sequence.load(5, &second, &depth);
  const cvo::PinholeIntrinsics K = cvo::tumIntrinsics("fr1", first.cols, first.rows);
  auto buffers = std::make_shared<cvo::FloatBufferPool>(4);
  auto image = cvo::intensityImage(first, K, 2, buffers);
  ASSERT_TRUE(image);
  EXPECT_EQ(buffers->kept(), 0u);
  image.reset();  // the first frame's image is done with: its two levels go back
  EXPECT_EQ(buffers->kept(), 2u);
  const auto reused = cvo::intensityImage(second, K, 2, buffers);
  EXPECT_EQ(buffers->kept(), 0u);
  const auto fresh = cvo::intensityImage(second, K, 2);
  ASSERT_TRUE(reused && fresh);
  for (int level = 0; level < 2; ++level) {
    EXPECT_EQ(reused->blurSigma(level), fresh->blurSigma(level));
    for (int v = 1; v < first.rows - 1; v += 7) {
      for (int u = 1; u < first.cols - 1; u += 5) {
        ASSERT_EQ(reused->intensity(level, u, v), fresh->intensity(level, u, v))
            << "level " << level << " at " << u << ", " << v;
      }
    }
  }
}

}  // namespace
