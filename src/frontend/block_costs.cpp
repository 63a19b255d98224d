#include "cvo_odometry/frontend/block_costs.hpp"

#include <algorithm>
#include <cstdlib>

#include <opencv2/core/hal/intrin.hpp>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace cvo {

void blockCostsOneByOne(const std::uint8_t* const* a, const std::uint8_t* const* b, int h,
                        int rows, int from, int to, std::uint16_t* costs) {
  for (int i = from; i < to; ++i) {
    int sum = 0;
    for (int r = 0; r < rows; ++r)
      for (int c = -h; c <= h; ++c)
        sum += std::abs(a[r][c] - b[r][c + i]);
    costs[i - from] = static_cast<std::uint16_t>(sum);
  }
}

void blockCostsInLanes(const std::uint8_t* const* a, const std::uint8_t* const* b, int h,
                       int rows, int from, int to, std::uint16_t* costs) {
  constexpr int kLanes = 16;
  for (int k = from; k < to; k += kLanes) {
    std::uint16_t lanes[kLanes];
#if CV_SIMD128
    cv::v_uint16x8 low = cv::v_setzero_u16(), high = cv::v_setzero_u16();
    for (int r = 0; r < rows; ++r) {
      const std::uint8_t* br = b[r] + k;
      for (int c = -h; c <= h; ++c) {
        cv::v_uint16x8 l, u;
        cv::v_expand(cv::v_absdiff(cv::v_load(br + c), cv::v_setall_u8(a[r][c])), l, u);
        low += l;
        high += u;
      }
    }
    cv::v_store(lanes, low);
    cv::v_store(lanes + 8, high);
#else
    blockCostsOneByOne(a, b, h, rows, k, k + kLanes, lanes);
#endif
    std::copy(lanes, lanes + std::min(kLanes, to - k), costs + (k - from));
  }
}

#if defined(__SSE2__)

namespace {

__m128i load8(const std::uint8_t* p) {
  return _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p));
}

__m128i load16(const std::uint8_t* p) {
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
}

// The first `bytes` (<= 16) bytes of a register set, the rest clear.
__m128i firstBytes(int bytes) {
  alignas(16) std::uint8_t keep[16];
  for (int k = 0; k < 16; ++k)
    keep[k] = k < bytes ? 0xff : 0;
  return _mm_load_si128(reinterpret_cast<const __m128i*>(keep));
}

int sumOfHalves(__m128i sums) {
  return _mm_cvtsi128_si32(sums) + _mm_cvtsi128_si32(_mm_unpackhi_epi64(sums, sums));
}

}  // namespace

// SSE2's psadbw sums 8 absolute differences at once into each 64-bit half. A window row of at
// most 8 pixels takes half a register (two rows a register), a wider one 16-pixel pieces; the
// pixels beyond the window are cleared in both windows, so they add nothing. One disparity at a
// time: only the searched ones are computed (16 at a time cost a third more on KITTI's points).
void blockCosts(const std::uint8_t* const* a, const std::uint8_t* const* b, int h, int rows,
                int from, int to, std::uint16_t* costs) {
  const int side = 2 * h + 1;
  if (side <= 8) {
    const __m128i keep = _mm_unpacklo_epi64(firstBytes(side), firstBytes(side));
    const int pairs = (rows + 1) / 2;
    __m128i left[16];
    for (int p = 0; p < pairs; ++p) {
      const int r = 2 * p;
      const __m128i second = r + 1 < rows ? load8(a[r + 1] - h) : _mm_setzero_si128();
      left[p] = _mm_and_si128(_mm_unpacklo_epi64(load8(a[r] - h), second), keep);
    }
    for (int i = from; i < to; ++i) {
      __m128i sums = _mm_setzero_si128();
      for (int p = 0; p < pairs; ++p) {
        const int r = 2 * p;
        const __m128i second = r + 1 < rows ? load8(b[r + 1] + i - h) : _mm_setzero_si128();
        const __m128i right = _mm_and_si128(_mm_unpacklo_epi64(load8(b[r] + i - h), second), keep);
        sums = _mm_add_epi64(sums, _mm_sad_epu8(left[p], right));
      }
      costs[i - from] = static_cast<std::uint16_t>(sumOfHalves(sums));
    }
    return;
  }
  // Wider windows: each row in 16-pixel pieces, the last one cut to the window.
  const int pieces = (side + 15) / 16;
  const __m128i last_keep = firstBytes(side - 16 * (pieces - 1));
  for (int i = from; i < to; ++i) {
    __m128i sums = _mm_setzero_si128();
    for (int r = 0; r < rows; ++r) {
      for (int p = 0; p < pieces; ++p) {
        __m128i left = load16(a[r] - h + 16 * p), right = load16(b[r] + i - h + 16 * p);
        if (p + 1 == pieces) {
          left = _mm_and_si128(left, last_keep);
          right = _mm_and_si128(right, last_keep);
        }
        sums = _mm_add_epi64(sums, _mm_sad_epu8(left, right));
      }
    }
    costs[i - from] = static_cast<std::uint16_t>(sumOfHalves(sums));
  }
}

#else

void blockCosts(const std::uint8_t* const* a, const std::uint8_t* const* b, int h, int rows,
                int from, int to, std::uint16_t* costs) {
  blockCostsInLanes(a, b, h, rows, from, to, costs);
}

#endif

}  // namespace cvo
