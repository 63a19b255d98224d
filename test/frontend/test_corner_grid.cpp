// MinEigenCorners with grid_columns (frontend/min_eigen_corners.hpp): on a real TUM image with a
// high-contrast checkerboard pasted over a third of it (a corner-rich object), no cell keeps
// more than its share of the corners, and each cell is judged by its own strongest response.
#include <gtest/gtest.h>

#include <iostream>
#include <map>
#include <string>

#include <opencv2/imgproc.hpp>

#include "cvo_odometry/frontend/min_eigen_corners.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

const std::string kTum = std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz";
constexpr int kGridColumns = 8;
constexpr double kQuality = 0.01, kMinDistance = 12.0;

struct Checkered {
  cv::Mat grey, depth;
  cv::Rect board;  // the checkerboard's pixels
};

// TUM frame 0 in grey with a black-and-white checkerboard of 10 px squares over its left third;
// depth everywhere (the test is about the corners' spread, not the depth mask).
Checkered checkeredFrame() {
  const cvo::TumSequence sequence(kTum);
  cv::Mat image, depth;
  sequence.load(0, &image, &depth);
  Checkered out;
  cv::cvtColor(image, out.grey, cv::COLOR_BGR2GRAY);
  out.board = cv::Rect(0, 0, out.grey.cols / 3, out.grey.rows);
  for (int v = out.board.y; v < out.board.br().y; ++v) {
    for (int u = out.board.x; u < out.board.br().x; ++u)
      out.grey.at<uchar>(v, u) = ((u / 10) + (v / 10)) % 2 ? 255 : 0;
  }
  out.depth = cv::Mat(out.grey.size(), CV_32FC1, cv::Scalar(1.5f));
  return out;
}

// The spreading cells as the header describes them: square, kGridColumns across.
int cellSide(int width) {
  return (width + kGridColumns - 1) / kGridColumns;
}

std::map<std::pair<int, int>, int> perCell(const std::vector<cv::Point2f>& corners, int side) {
  std::map<std::pair<int, int>, int> counts;
  for (const cv::Point2f& c : corners)
    ++counts[{static_cast<int>(c.x) / side, static_cast<int>(c.y) / side}];
  return counts;
}

// Proves: with grid_columns no cell holds more than its share of max_corners, so the
// checkerboard holds no more of the corners than its cells' share, where the un-spread search
// gives it nearly all of them.
TEST(CornerGrid, NoCellHoldsMoreThanItsShare) {
  const Checkered frame = checkeredFrame();
  const int side = cellSide(frame.grey.cols);
  const int columns = (frame.grey.cols + side - 1) / side;
  const int rows = (frame.grey.rows + side - 1) / side;
  const int max_corners = 500;
  const int cap = (max_corners + columns * rows - 1) / (columns * rows);
  cvo::MinEigenCorners finder;
  const std::vector<cv::Point2f> spread =
      finder.find(frame.grey, frame.depth, 0, max_corners, kQuality, kMinDistance, kGridColumns);
  const std::vector<cv::Point2f> strongest =
      finder.find(frame.grey, frame.depth, 0, max_corners, kQuality, kMinDistance, 0);
  ASSERT_GT(spread.size(), 150u);
  ASSERT_LE(spread.size(), static_cast<std::size_t>(max_corners));
  for (const auto& [cell, n] : perCell(spread, side)) {
    EXPECT_LE(n, cap) << "cell (" << cell.first << ", " << cell.second << ")";
  }
  const auto onBoard = [&](const std::vector<cv::Point2f>& corners) {
    int n = 0;
    for (const cv::Point2f& c : corners)
      n += frame.board.contains(cv::Point(cvRound(c.x), cvRound(c.y)));
    return n;
  };
  // The board's cells: those that hold any of its pixels (3 of the 8 columns).
  const int board_cells = ((frame.board.width + side - 1) / side) * rows;
  EXPECT_LE(onBoard(spread), board_cells * cap);
  EXPECT_LT(onBoard(spread), static_cast<int>(0.5 * spread.size()))
      << "the board holds a third of the image, no more than about a third of the corners";
  EXPECT_GT(onBoard(strongest), static_cast<int>(0.9 * strongest.size()))
      << "without the grid the board takes nearly all corners (else the fixture proves nothing)";
}

// Counts the cells right of the board (none of its pixels) that hold corners with the grid but
// none without it.
struct CellTally {
  int outside = 0, only_with_grid = 0, only_without = 0;
};
CellTally tallyOutside(const Checkered& frame, int max_corners) {
  const int side = cellSide(frame.grey.cols);
  cvo::MinEigenCorners finder;
  const auto spread = perCell(
      finder.find(frame.grey, frame.depth, 0, max_corners, kQuality, kMinDistance, kGridColumns),
      side);
  const auto strongest = perCell(
      finder.find(frame.grey, frame.depth, 0, max_corners, kQuality, kMinDistance, 0), side);
  const int board_columns = (frame.board.width + side - 1) / side;
  CellTally tally;
  for (int row = 0; row * side < frame.grey.rows; ++row) {
    for (int column = board_columns; column * side < frame.grey.cols; ++column) {
      ++tally.outside;
      const bool with_grid = spread.count({column, row}) > 0;
      const bool without = strongest.count({column, row}) > 0;
      tally.only_with_grid += with_grid && !without;
      tally.only_without += without && !with_grid;
    }
  }
  return tally;
}

// Proves: at the tracker's 500 corners the un-spread search spends them on the board and leaves
// most cells of the scene empty; with the grid those cells get corners, and no cell the
// un-spread search fills is left empty.
TEST(CornerGrid, CellsTheUnspreadSearchLeavesEmptyGetCorners) {
  const CellTally tally = tallyOutside(checkeredFrame(), 500);
  std::cout << tally.only_with_grid << " of the " << tally.outside
            << " cells off the board have corners only with the grid\n";
  EXPECT_GE(tally.only_with_grid, tally.outside / 2);
  EXPECT_EQ(tally.only_without, 0);
}

// Proves the per-cell quality bar: with room for every corner (no cap reached) and the scene
// dimmed to 15 % of its contrast (its corners under 1 % of the board's strongest response, the
// un-spread search's one bar), cells of the scene still get corners, judged by their own
// strongest response.
TEST(CornerGrid, EachCellIsJudgedByItsOwnStrongestResponse) {
  Checkered frame = checkeredFrame();
  const cv::Rect scene(frame.board.width, 0, frame.grey.cols - frame.board.width, frame.grey.rows);
  cv::Mat part = frame.grey(scene);
  const double mean = cv::mean(part)[0];
  part.convertTo(part, CV_8U, 0.15, (1.0 - 0.15) * mean);
  const CellTally bright = tallyOutside(checkeredFrame(), 5000);
  const CellTally dim = tallyOutside(frame, 5000);
  std::cout << "cells off the board with corners only with the grid: " << bright.only_with_grid
            << " of " << bright.outside << " at full contrast, " << dim.only_with_grid
            << " dimmed\n";
  EXPECT_GE(dim.only_with_grid, dim.outside / 3);
  EXPECT_EQ(dim.only_without, 0);
  EXPECT_EQ(bright.only_without, 0);
}

}  // namespace
