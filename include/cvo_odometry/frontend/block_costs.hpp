// Sums of absolute differences between windows of two 8-bit images: the point stereo matcher's
// block costs, computed only at the disparities it searches.
#pragma once

#include <cstdint>

namespace cvo {

// costs[i - from] = the sum over rows r < rows and columns c in [-h, h] of |a[r][c] - b[r][c + i]|,
// for i in [from, to): a's window against b's window moved by i. rows <= 32, 2h + 1 <= 31, and
// rows * (2h + 1) * 255 must fit 16 bits. Reads up to 15 bytes beyond either end of each window
// row (the caller's rows are padded).
void blockCosts(const std::uint8_t* const* a, const std::uint8_t* const* b, int h, int rows,
                int from, int to, std::uint16_t* costs);

// The same, one pixel at a time: the reference the tests hold blockCosts to.
void blockCostsOneByOne(const std::uint8_t* const* a, const std::uint8_t* const* b, int h,
                        int rows, int from, int to, std::uint16_t* costs);

}  // namespace cvo
