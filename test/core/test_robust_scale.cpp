// medianNear against medianInPlace: the same value whatever the guess.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "cvo_odometry/core/robust_scale.hpp"

namespace {

double plainMedian(std::vector<double> values) {
  return cvo::medianInPlace(values);
}

TEST(RobustScale, MedianNearIsTheMedianWhateverTheGuess) {
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<double> scratch;
  for (const std::size_t count : {1u, 2u, 3u, 10u, 11u, 1000u, 1023u, 1024u, 9001u}) {
    std::vector<double> values(count);
    for (double& v : values)
      v = std::abs(noise(random));
    if (count > 4) values[1] = values[2] = values[3];  // ties
    const double median = plainMedian(values);
    // Near (the bracket holds it), at its edge, far below and above, none, nonsense.
    for (const double guess : {median, 0.95 * median, 1.09 * median, 0.91 * median, 0.3 * median,
                               3.0 * median, 0.0, -1.0, std::nan("")}) {
      std::vector<double> copy = values;
      EXPECT_EQ(cvo::medianNear(copy, guess, scratch), median)
          << count << " values, guess " << guess << " for " << median;
    }
  }
}

TEST(RobustScale, MedianNearIsExactWhenItsOwnSampleMisleadsIt) {
  // Every 16th value (the sample a guess-less call orders) far above the rest.
  std::vector<double> values(4000), scratch;
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = i % 16 == 0 ? 100.0 + static_cast<double>(i) : 0.001 * static_cast<double>(i % 97);
  const double median = plainMedian(values);
  EXPECT_EQ(cvo::medianNear(values, 0.0, scratch), median);
}

// Values exactly at the bracket's ends (guess 10: 9 and 11) count once, on the right side.
TEST(RobustScale, MedianNearCountsTheBracketsEndsOnce) {
  std::vector<double> scratch;
  for (const std::vector<double>& values :
       std::vector<std::vector<double>>{{9, 9, 9, 11, 11, 11, 10},
                                        {1, 9, 9, 9, 12, 13, 14},
                                        {8, 8, 8, 8, 9, 11, 11},
                                        {9, 11},
                                        {5, 9, 9, 11, 11, 11, 11, 20}}) {
    std::vector<double> copy = values;
    EXPECT_EQ(cvo::medianNear(copy, 10.0, scratch), plainMedian(values));
  }
}

TEST(RobustScale, MedianNearTakesTheUpperMiddleOfAnEvenCount) {
  std::vector<double> values{4.0, 1.0, 3.0, 2.0}, scratch;
  EXPECT_EQ(cvo::medianNear(values, 3.0, scratch), 3.0);
  EXPECT_EQ(cvo::medianNear(values, 2.0, scratch), 3.0);  // the guess is the lower middle
}

}  // namespace
