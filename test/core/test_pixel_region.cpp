// PixelRegion (core/pixel_region.hpp): the cells a moving object's tracks mark, its gaps closed,
// and queries outside the image.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "cvo_odometry/core/pixel_region.hpp"

namespace {

constexpr int kCell = 8;

// Proves: a disc holds its centre and its whole radius, and nothing beyond radius + one cell
// (a cell counts when its nearest point is within the radius, so a cell is the most it spills).
TEST(PixelRegion, DiscHoldsItsCentreAndNothingBeyondRadiusPlusACell) {
  cvo::PixelRegion region(640, 480, kCell);
  EXPECT_TRUE(region.empty());
  EXPECT_EQ(region.coveredFraction(), 0.0);
  const double u = 203.0, v = 151.0, radius = 20.0;
  region.addDisc(u, v, radius);
  EXPECT_FALSE(region.empty());
  EXPECT_TRUE(region.contains(u, v));
  // Every pixel within the radius is inside, every pixel beyond radius + a cell's diagonal is
  // outside: all directions, sampled every 5 degrees.
  const double beyond = radius + kCell * std::sqrt(2.0) + 0.5;
  for (int degrees = 0; degrees < 360; degrees += 5) {
    const double a = degrees * M_PI / 180.0;
    EXPECT_TRUE(region.contains(u + (radius - 0.5) * std::cos(a), v + (radius - 0.5) * std::sin(a)))
        << degrees << " deg, inside the radius";
    EXPECT_FALSE(region.contains(u + beyond * std::cos(a), v + beyond * std::sin(a)))
        << degrees << " deg, beyond radius + a cell";
  }
  // Along the axes a cell is the most it spills.
  EXPECT_FALSE(region.contains(u + radius + kCell + 1.0, v));
  EXPECT_FALSE(region.contains(u - radius - kCell - 1.0, v));
  EXPECT_FALSE(region.contains(u, v + radius + kCell + 1.0));
  EXPECT_FALSE(region.contains(u, v - radius - kCell - 1.0));
  // Its share of the image: at least the disc's area, at most the disc grown by a cell's diagonal.
  const double image = 640.0 * 480.0;
  EXPECT_GE(region.coveredFraction(), M_PI * radius * radius / image);
  EXPECT_LE(region.coveredFraction(), M_PI * beyond * beyond / image);
}

// Proves: closeGaps fills the gap between two discs narrower than 2 * radius (the untextured
// inside of an object between its tracks), keeps both discs, and leaves a far point and the
// space towards it out.
TEST(PixelRegion, CloseGapsFillsANarrowGapAndLeavesAFarPointOut) {
  cvo::PixelRegion region(640, 480, kCell);
  const double radius = 16.0;
  region.addDisc(100.0, 100.0, radius);
  region.addDisc(150.0, 100.0, radius);  // a gap of about 18 px between the discs
  region.addDisc(420.0, 330.0, radius);  // a lone track far away
  const double between_u = 124.0, between_v = 100.0;
  ASSERT_FALSE(region.contains(between_u, between_v)) << "the fixture needs a gap to close";
  const double before = region.coveredFraction();
  region.closeGaps(radius);
  EXPECT_TRUE(region.contains(between_u, between_v)) << "the gap < 2 * radius is filled";
  EXPECT_TRUE(region.contains(100.0, 100.0));
  EXPECT_TRUE(region.contains(150.0, 100.0));
  EXPECT_TRUE(region.contains(420.0, 330.0)) << "closing never removes what was marked";
  EXPECT_GT(region.coveredFraction(), before);
  // Nothing between the pair and the far disc, nor around the far disc beyond radius + a cell.
  for (double t = 0.15; t < 0.86; t += 0.05) {
    const double u = 150.0 + t * (420.0 - 150.0), v = 100.0 + t * (330.0 - 100.0);
    EXPECT_FALSE(region.contains(u, v)) << "(" << u << ", " << v << ") joined to the far point";
  }
  EXPECT_FALSE(region.contains(420.0 + radius + 2 * kCell, 330.0));
  EXPECT_FALSE(region.contains(420.0, 330.0 - radius - 2 * kCell));
  // A gap wider than 2 * radius stays open.
  cvo::PixelRegion wide(640, 480, kCell);
  wide.addDisc(100.0, 100.0, radius);
  wide.addDisc(100.0 + 2 * radius + 4 * kCell + 40.0, 100.0, radius);
  wide.closeGaps(radius);
  EXPECT_FALSE(wide.contains(100.0 + radius + 2 * kCell + 20.0, 100.0)) << "a wide gap stays";
}

// Proves: queries outside the image (or not a number) are false, also where the region reaches
// the image's border; a disc beyond the image marks nothing; bad sizes throw.
TEST(PixelRegion, OutsideTheImageIsNeverContained) {
  cvo::PixelRegion region(640, 480, kCell);
  region.addDisc(0.0, 0.0, 30.0);
  region.addDisc(639.0, 479.0, 30.0);
  region.closeGaps(30.0);
  EXPECT_TRUE(region.contains(0.0, 0.0));
  EXPECT_TRUE(region.contains(639.9, 479.9));
  EXPECT_FALSE(region.contains(-0.5, 10.0));
  EXPECT_FALSE(region.contains(10.0, -0.5));
  EXPECT_FALSE(region.contains(640.0, 470.0));
  EXPECT_FALSE(region.contains(630.0, 480.0));
  EXPECT_FALSE(region.contains(1e9, 1e9));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(region.contains(nan, 10.0));
  EXPECT_FALSE(region.contains(10.0, nan));

  cvo::PixelRegion untouched(640, 480, kCell);
  untouched.addDisc(-200.0, -200.0, 30.0);
  untouched.addDisc(nan, 100.0, 30.0);
  untouched.addDisc(100.0, 100.0, -1.0);
  EXPECT_TRUE(untouched.empty());
  EXPECT_THROW(cvo::PixelRegion(0, 480), std::invalid_argument);
  EXPECT_THROW(cvo::PixelRegion(640, 480, 0), std::invalid_argument);
}

}  // namespace
