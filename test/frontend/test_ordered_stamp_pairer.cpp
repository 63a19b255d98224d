// OrderedStampPairer on the real stamps of the TUM fr1_xyz excerpt (rgb.txt, depth.txt; the
// dataset's associations.txt is the truth), in the arrival orders a bag or a live camera gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cvo_odometry/frontend/dataset_files.hpp"
#include "cvo_odometry/frontend/ordered_stamp_pairer.hpp"

namespace cvo {
namespace {

using Pairer = OrderedStampPairer<int, int>;

struct TumStamps {
  std::vector<double> rgb, depth;
  std::vector<int> depth_of_rgb;  // associations.txt: depth index of each rgb index
};

TumStamps loadTumStamps() {
  const std::string folder = std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz/";
  TumStamps stamps;
  for (const auto& row : readFieldRows(folder + "rgb.txt", 2)) {
    stamps.rgb.push_back(parseFiniteNumber(row[0], "rgb.txt"));
  }
  for (const auto& row : readFieldRows(folder + "depth.txt", 2)) {
    stamps.depth.push_back(parseFiniteNumber(row[0], "depth.txt"));
  }
  for (const auto& row : readFieldRows(folder + "associations.txt", 4)) {
    const double depth = parseFiniteNumber(row[2], "associations.txt");
    const auto found = std::find(stamps.depth.begin(), stamps.depth.end(), depth);
    stamps.depth_of_rgb.push_back(static_cast<int>(found - stamps.depth.begin()));
  }
  return stamps;
}

// One message: stream (0 colour, 1 depth) and index.
struct Arrival {
  int stream;
  int index;
};

// Each stream's messages in order, merged by arrival time = stamp + that stream's delay.
std::vector<Arrival> arrivals(const TumStamps& stamps, double rgb_delay, double depth_delay) {
  std::vector<std::pair<double, Arrival>> timed;
  for (std::size_t k = 0; k < stamps.rgb.size(); ++k) {
    timed.push_back({stamps.rgb[k] + rgb_delay, {0, static_cast<int>(k)}});
  }
  for (std::size_t k = 0; k < stamps.depth.size(); ++k) {
    timed.push_back({stamps.depth[k] + depth_delay, {1, static_cast<int>(k)}});
  }
  std::stable_sort(timed.begin(), timed.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Arrival> order;
  for (const auto& t : timed)
    order.push_back(t.second);
  return order;
}

std::vector<Pairer::Pair> feed(Pairer& pairer, const TumStamps& stamps,
                               const std::vector<Arrival>& order) {
  std::vector<Pairer::Pair> pairs;
  for (const Arrival& a : order) {
    auto done = a.stream == 0 ? pairer.addFirst(stamps.rgb[a.index], a.index)
                              : pairer.addSecond(stamps.depth[a.index], a.index);
    pairs.insert(pairs.end(), done.begin(), done.end());
  }
  return pairs;
}

void expectTruePairs(const TumStamps& stamps, const std::vector<Pairer::Pair>& pairs) {
  for (const auto& pair : pairs) {
    EXPECT_EQ(pair.second, stamps.depth_of_rgb[pair.first]) << "rgb " << pair.first;
  }
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    EXPECT_LT(pairs[k - 1].first, pairs[k].first) << "pairs out of order";
  }
}

TEST(OrderedStampPairer, NearestStampPairingIsWrongOnThisExcerpt) {
  // Why the pairer exists: depth 31 is nearer to rgb 30 than to rgb 31, its true partner.
  const TumStamps stamps = loadTumStamps();
  ASSERT_EQ(stamps.rgb.size(), 37u);
  ASSERT_EQ(stamps.depth_of_rgb[31], 31);
  EXPECT_LT(std::abs(stamps.depth[31] - stamps.rgb[30]),
            std::abs(stamps.depth[31] - stamps.rgb[31]));
}

TEST(OrderedStampPairer, PairsTheWholeTumExcerptInBagOrder) {
  const TumStamps stamps = loadTumStamps();
  Pairer pairer;
  const auto pairs = feed(pairer, stamps, arrivals(stamps, 0.0, 0.0));
  ASSERT_EQ(pairs.size(), 37u);
  expectTruePairs(stamps, pairs);
  EXPECT_EQ(pairer.droppedFirst(), 0u);
  EXPECT_EQ(pairer.droppedSecond(), 0u);
  ASSERT_TRUE(pairer.offset().has_value());
  EXPECT_NEAR(*pairer.offset(), -0.0155, 0.003);  // depth about 15 ms older than colour
  EXPECT_NEAR(*pairer.tolerance(), 0.4 * 0.032, 0.002);
}

// A live start (or a reset, or a loop) may begin at any frame: the first frames wait for the
// offset and then pair with it, all of them and each with its own depth, flagged held so that
// the nodelet uses them rather than only the newest.
TEST(OrderedStampPairer, EveryStartPairsItsFirstFramesWithTheirOwnDepth) {
  const TumStamps stamps = loadTumStamps();
  const StampPairerOptions defaults;
  // Every start with at least two estimates' worth of frames after it (a stream that ends sooner
  // may end before the offset is learned).
  for (std::size_t start = 0; start + 2 * defaults.bootstrap_frames <= stamps.rgb.size(); ++start) {
    TumStamps tail = stamps;
    tail.rgb.erase(tail.rgb.begin(), tail.rgb.begin() + static_cast<std::ptrdiff_t>(start));
    tail.depth.erase(tail.depth.begin(), tail.depth.begin() + static_cast<std::ptrdiff_t>(start));
    for (int& depth : tail.depth_of_rgb)
      depth -= static_cast<int>(start);
    tail.depth_of_rgb.erase(tail.depth_of_rgb.begin(),
                            tail.depth_of_rgb.begin() + static_cast<std::ptrdiff_t>(start));
    Pairer pairer;
    const auto pairs = feed(pairer, tail, arrivals(tail, 0.0, 0.0));
    ASSERT_EQ(pairs.size(), tail.rgb.size()) << "start " << start;
    expectTruePairs(tail, pairs);
    std::size_t held = 0;
    while (held < pairs.size() && pairs[held].held)
      ++held;
    // At least bootstrap_frames (more where a colour image's own depth is over half a frame
    // away and its estimate waits for the next depth), and only the first pairs.
    EXPECT_GE(held, defaults.bootstrap_frames) << "start " << start;
    EXPECT_LE(held, 2 * defaults.bootstrap_frames) << "start " << start;
    for (std::size_t k = held; k < pairs.size(); ++k)
      EXPECT_FALSE(pairs[k].held) << "start " << start << ", pair " << k;
  }
}

// Why the first frames wait rather than pair by nearest stamp, or by an offset learned from the
// first pair alone: at these starts the first colour image's nearest depth is the next frame's,
// and that offset (about +16 ms instead of -16 ms) would pair every later frame with the wrong
// depth just as consistently.
TEST(OrderedStampPairer, TheFirstPairAloneWouldMislead) {
  const TumStamps stamps = loadTumStamps();
  std::vector<std::size_t> misleading;
  for (std::size_t k = 0; k < stamps.rgb.size(); ++k) {
    const auto nearest =
        std::min_element(stamps.depth.begin(), stamps.depth.end(), [&](double a, double b) {
          return std::abs(a - stamps.rgb[k]) < std::abs(b - stamps.rgb[k]);
        });
    if (nearest - stamps.depth.begin() != stamps.depth_of_rgb[k]) misleading.push_back(k);
  }
  const std::vector<std::size_t> expected = {1, 10, 13, 22, 25, 31, 34};
  EXPECT_EQ(misleading, expected);
}

TEST(OrderedStampPairer, PairsWhicheverStreamArrivesLate) {
  const TumStamps stamps = loadTumStamps();
  // Depth processed 50 ms late (a registration step in the driver), then colour 80 ms late.
  for (const auto& [rgb_delay, depth_delay] : {std::pair{0.0, 0.05}, std::pair{0.08, 0.0}}) {
    Pairer pairer;
    const auto pairs = feed(pairer, stamps, arrivals(stamps, rgb_delay, depth_delay));
    ASSERT_EQ(pairs.size(), 37u) << rgb_delay << " " << depth_delay;
    expectTruePairs(stamps, pairs);
  }
}

TEST(OrderedStampPairer, PairsUnderRandomInterleaving) {
  // Each topic in order, the two interleaved at random (separate subscriber threads).
  const TumStamps stamps = loadTumStamps();
  std::mt19937 random(7);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Arrival> order;
    std::size_t next_rgb = 0, next_depth = 0;
    while (next_rgb < stamps.rgb.size() || next_depth < stamps.depth.size()) {
      // Neither stream runs more than 3 frames ahead of the other, as a bounded queue would.
      const bool rgb_ahead = next_rgb > next_depth + 2, depth_ahead = next_depth > next_rgb + 2;
      const bool take_rgb =
          next_depth == stamps.depth.size() ||
          (next_rgb < stamps.rgb.size() && !rgb_ahead && (depth_ahead || random() % 2 == 0));
      order.push_back(take_rgb ? Arrival{0, static_cast<int>(next_rgb++)}
                               : Arrival{1, static_cast<int>(next_depth++)});
    }
    Pairer pairer;
    const auto pairs = feed(pairer, stamps, order);
    EXPECT_EQ(pairs.size(), 37u) << "trial " << trial;
    expectTruePairs(stamps, pairs);
  }
}

TEST(OrderedStampPairer, MissingMessagesLeaveTheirPartnerUnpaired) {
  const TumStamps stamps = loadTumStamps();
  std::vector<Arrival> order;
  for (const Arrival& a : arrivals(stamps, 0.0, 0.0)) {
    const bool lost = (a.stream == 1 && a.index == 10) || (a.stream == 0 && a.index == 20);
    if (!lost) order.push_back(a);
  }
  Pairer pairer;
  const auto pairs = feed(pairer, stamps, order);
  EXPECT_EQ(pairs.size(), 35u);
  expectTruePairs(stamps, pairs);
  EXPECT_EQ(pairer.droppedFirst(), 1u);   // rgb 10: its depth never came
  EXPECT_EQ(pairer.droppedSecond(), 1u);  // depth 20: its colour never came
}

TEST(OrderedStampPairer, ALoopingBagStartsOverWithoutMixingLoops) {
  const TumStamps stamps = loadTumStamps();
  const auto once = arrivals(stamps, 0.0, 0.0);
  std::vector<Arrival> twice = once;
  twice.insert(twice.end(), once.begin(), once.end());
  Pairer pairer;
  const auto pairs = feed(pairer, stamps, twice);
  EXPECT_EQ(pairer.restarts(), 1u);
  EXPECT_EQ(pairs.size(), 74u);
  for (const auto& pair : pairs)
    EXPECT_EQ(pair.second, stamps.depth_of_rgb[pair.first]);
}

TEST(OrderedStampPairer, ASilentStreamKeepsTheQueueBounded) {
  const TumStamps stamps = loadTumStamps();
  StampPairerOptions options;
  options.queue_size = 10;
  Pairer pairer(options);
  for (std::size_t k = 0; k < stamps.rgb.size(); ++k) {
    EXPECT_TRUE(pairer.addFirst(stamps.rgb[k], static_cast<int>(k)).empty());
  }
  EXPECT_EQ(pairer.droppedFirst(), 27u);
  EXPECT_FALSE(pairer.offset().has_value());
  // Depth from the start of the excerpt (a bag whose depth topic lags): the colour frames the
  // queue kept pair with their own depth, once it comes, and nothing earlier is mispaired.
  std::size_t paired = 0;
  for (std::size_t k = 0; k < stamps.depth.size(); ++k) {
    for (const auto& pair : pairer.addSecond(stamps.depth[k], static_cast<int>(k))) {
      EXPECT_EQ(pair.second, stamps.depth_of_rgb[pair.first]);
      ++paired;
    }
  }
  EXPECT_EQ(paired, 10u);  // rgb 27..36, all that the queue kept
}

TEST(OrderedStampPairer, FixedZeroOffsetPairsEqualStampsOnly) {
  // A segmentation image stamped with its colour image's stamp.
  StampPairerOptions options;
  options.fixed_offset = 0.0;
  Pairer pairer(options);
  const std::vector<double> colour = {10.000, 10.033, 10.066, 10.100, 10.133};
  std::vector<std::pair<int, int>> paired;
  auto keep = [&](const std::vector<Pairer::Pair>& pairs) {
    for (const auto& p : pairs)
      paired.push_back({p.first, p.second});
  };
  for (int k = 0; k < 5; ++k)
    keep(pairer.addFirst(colour[k], k));
  // Labels come late; the one for frame 2 is missing and frame 3's is stamped 1 ms off.
  keep(pairer.addSecond(colour[0], 100));
  keep(pairer.addSecond(colour[1], 101));
  keep(pairer.addSecond(colour[3] + 0.001, 103));
  keep(pairer.addSecond(colour[4], 104));
  const std::vector<std::pair<int, int>> expected = {{0, 100}, {1, 101}, {4, 104}};
  EXPECT_EQ(paired, expected);
  EXPECT_EQ(pairer.droppedFirst(), 2u);
  EXPECT_EQ(pairer.droppedSecond(), 1u);
}

// The excerpt's frames 0..17, then another source on the same topics (a driver restarted with
// other settings): stamps jump 100 s ahead and depth now carries its colour image's stamp instead
// of one ~15 ms older, so no depth falls in the learned window (an offset change of about a frame
// period would instead look like a consistent pairing with the neighbour frame's depth; nothing
// can tell those apart from stamps). Arrivals in stamp order.
std::vector<Pairer::Pair> feedWithNewTiming(Pairer& pairer, const TumStamps& stamps) {
  std::vector<Pairer::Pair> pairs;
  auto keep = [&](const std::vector<Pairer::Pair>& done) {
    pairs.insert(pairs.end(), done.begin(), done.end());
  };
  std::vector<std::pair<double, Arrival>> timed;  // the message is the colour image's index
  for (int k = 0; k < 37; ++k) {
    const double colour = stamps.rgb[k] + (k < 18 ? 0.0 : 100.0);
    const double depth = k < 18 ? stamps.depth[stamps.depth_of_rgb[k]] : colour;
    timed.push_back({colour, {0, k}});
    timed.push_back({depth, {1, k}});
  }
  std::stable_sort(timed.begin(), timed.end(),  // equal stamps: colour first
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [stamp, a] : timed)
    keep(a.stream == 0 ? pairer.addFirst(stamp, a.index) : pairer.addSecond(stamp, a.index));
  return pairs;
}

TEST(OrderedStampPairer, LearnsTheOffsetAgainWhenFramesStopPairing) {
  const TumStamps stamps = loadTumStamps();
  Pairer pairer;
  const auto pairs = feedWithNewTiming(pairer, stamps);
  EXPECT_EQ(pairer.relearns(), 1u);
  ASSERT_TRUE(pairer.offset().has_value());
  EXPECT_NEAR(*pairer.offset(), 0.0, 1e-6);
  std::size_t after_change = 0;
  for (const auto& pair : pairs) {
    // Second messages carry their colour image's index here (feedWithNewTiming).
    EXPECT_EQ(pair.second, pair.first) << "colour " << pair.first << " mispaired";
    if (pair.first >= 18) ++after_change;
  }
  // The first 10 frames of the new source go unpaired, the rest pair once the offset is known.
  EXPECT_EQ(after_change, 37u - 18u - 10u);
}

TEST(OrderedStampPairer, RelearnOnRequestForgetsTheOffset) {
  const TumStamps stamps = loadTumStamps();
  Pairer pairer;
  feed(pairer, stamps, arrivals(stamps, 0.0, 0.0));
  ASSERT_TRUE(pairer.offset().has_value());
  pairer.relearn();
  EXPECT_FALSE(pairer.offset().has_value());
  EXPECT_EQ(pairer.relearns(), 1u);
  // The same frames again, 100 s later (a reset): all paired, the first ones held.
  TumStamps later = stamps;
  for (double& stamp : later.rgb)
    stamp += 100.0;
  for (double& stamp : later.depth)
    stamp += 100.0;
  const auto pairs = feed(pairer, later, arrivals(later, 0.0, 0.0));
  ASSERT_EQ(pairs.size(), 37u);
  expectTruePairs(later, pairs);
  EXPECT_TRUE(pairs.front().held);
  EXPECT_FALSE(pairs.back().held);
  StampPairerOptions fixed;
  fixed.fixed_offset = 0.0;
  Pairer labels(fixed);
  labels.relearn();
  EXPECT_EQ(labels.offset(), std::optional<double>(0.0)) << "a fixed offset is kept";
}

TEST(OrderedStampPairer, RejectsBadStampsAndOptions) {
  Pairer pairer;
  EXPECT_TRUE(pairer.addFirst(std::numeric_limits<double>::quiet_NaN(), 0).empty());
  EXPECT_TRUE(pairer.addFirst(1.0, 1).empty());
  EXPECT_TRUE(pairer.addFirst(1.0, 2).empty());  // repeated stamp
  EXPECT_EQ(pairer.droppedFirst(), 2u);
  StampPairerOptions bad;
  bad.tolerance = -1.0;
  EXPECT_THROW(Pairer{bad}, std::invalid_argument);
  bad = StampPairerOptions();
  bad.queue_size = 2;
  EXPECT_THROW(Pairer{bad}, std::invalid_argument);
  bad = StampPairerOptions();
  bad.fixed_offset = std::numeric_limits<double>::infinity();
  EXPECT_THROW(Pairer{bad}, std::invalid_argument);
  bad = StampPairerOptions();
  bad.relearn_after_unpaired = 0;
  EXPECT_THROW(Pairer{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace cvo
