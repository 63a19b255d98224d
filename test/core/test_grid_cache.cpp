// GridCache: a grid is served again only for the same positions and cell size (a keyframe's grid
// across the frames registered to it), never for a cloud changed in place.
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "cvo_odometry/core/cloud_io.hpp"
#include "cvo_odometry/core/grid_cache.hpp"

namespace {

const std::string kCloud = std::string(CVO_TEST_DATA_DIR) + "/tum_clouds/frame10_8000.cloud";

std::set<std::uint32_t> neighbours(const cvo::VoxelGrid& grid, const float* p, float radius) {
  std::set<std::uint32_t> found;
  grid.forEachWithin(p, radius, [&](std::uint32_t i, float) { found.insert(i); });
  return found;
}

TEST(GridCache, ServesAKeptGridOnlyForTheSamePositionsAndCellSize) {
  const cvo::LabeledCloud cloud = cvo::readCloud(kCloud);
  ASSERT_GT(cloud.size(), 7000u);
  std::vector<float> keyframe = cloud.positionData();
  std::vector<float> frame(keyframe.begin(), keyframe.begin() + 3 * 4000);
  const std::size_t n = keyframe.size() / 3, m = frame.size() / 3;
  cvo::GridCache cache;

  const cvo::VoxelGrid* first = &cache.grid(keyframe.data(), n, 0.05f);
  EXPECT_EQ(cache.builds(), 1u);
  cache.grid(frame.data(), m, 0.03f);
  EXPECT_EQ(cache.builds(), 2u);
  // The keyframe again, as the next frame's registration asks: served, not rebuilt.
  EXPECT_EQ(&cache.grid(keyframe.data(), n, 0.05f), first);
  EXPECT_EQ(cache.builds(), 2u);
  // Another cell size, or fewer of the same points, is another grid.
  cache.grid(keyframe.data(), n, 0.04f);
  cache.grid(keyframe.data(), n - 1, 0.05f);
  EXPECT_EQ(cache.builds(), 4u);

  // A cloud changed in place (same address and size) gets a grid of its new positions.
  const float* query = keyframe.data() + 3 * 100;
  const std::set<std::uint32_t> before =
      neighbours(cache.grid(keyframe.data(), n, 0.05f), query, 0.05f);
  EXPECT_EQ(cache.builds(), 5u) << "the two grids above replaced the n-point one";
  ASSERT_TRUE(before.count(100));
  keyframe[3 * 100 + 2] += 1.0f;  // point 100 moves 1 m away from its old place
  const float old_place[3] = {query[0], query[1], query[2] - 1.0f};
  const std::set<std::uint32_t> after =
      neighbours(cache.grid(keyframe.data(), n, 0.05f), old_place, 0.05f);
  EXPECT_EQ(cache.builds(), 6u);
  EXPECT_FALSE(after.count(100)) << "a stale grid would still find point 100 at its old place";
  EXPECT_EQ(after.size() + 1, before.size());
}

TEST(GridCache, KeepsTheMostRecentlyUsedGrids) {
  const cvo::LabeledCloud cloud = cvo::readCloud(kCloud);
  const std::vector<float>& points = cloud.positionData();
  const float* a = points.data();
  const float* b = points.data() + 3 * 1000;
  const float* c = points.data() + 3 * 2000;
  cvo::GridCache cache(2);
  cache.grid(a, 1000, 0.05f);
  cache.grid(b, 1000, 0.05f);
  cache.grid(a, 1000, 0.05f);  // kept
  cache.grid(c, 1000, 0.05f);  // replaces b, used longest ago
  cache.grid(a, 1000, 0.05f);  // still kept
  EXPECT_EQ(cache.builds(), 3u);
  cache.grid(b, 1000, 0.05f);
  EXPECT_EQ(cache.builds(), 4u);

  cvo::GridCache single(0);  // at least one grid is kept
  single.grid(a, 1000, 0.05f);
  single.grid(a, 1000, 0.05f);
  EXPECT_EQ(single.builds(), 1u);
}

}  // namespace
