// Sums of absolute differences between windows of two 8-bit images: the point stereo matcher's
// block costs, computed only at the disparities it searches.
#pragma once

#include <cstdint>

namespace cvo {

// costs[i - from] = the sum over rows r < rows and columns c in [-h, h] of |a[r][c] - b[r][c + i]|,
// for i in [from, to): a's window against b's window moved by i, in 16 bits (the matcher's
// windows hold at most 21 x 21 pixels of differences up to 126: 55,566). rows <= 32,
// 2h + 1 <= 31. Reads up to 15 bytes beyond the right end of each window row (the caller's rows
// are padded). SSE2's psadbw where there is SSE2, else blockCostsInLanes.
void blockCosts(const std::uint8_t* const* a, const std::uint8_t* const* b, int h, int rows,
                int from, int to, std::uint16_t* costs);

// The same 16 shifts at a time with OpenCV's universal intrinsics (NEON on ARM), shifts up to
// 15 beyond `to` computed and dropped; reads up to 15 + 15 bytes beyond the right end.
void blockCostsInLanes(const std::uint8_t* const* a, const std::uint8_t* const* b, int h,
                       int rows, int from, int to, std::uint16_t* costs);

// The same, one pixel at a time: the reference the tests hold the others to.
void blockCostsOneByOne(const std::uint8_t* const* a, const std::uint8_t* const* b, int h,
                        int rows, int from, int to, std::uint16_t* costs);

}  // namespace cvo
