// libFuzzer target: arbitrary message streams through OrderedStampPairer (learned and fixed
// offsets, any tolerance and queue size, stamps that jump, repeat, go backwards or are not
// finite). Invariants: every message is paired at most once, paired + dropped + pending adds up
// to what went in, queues stay bounded, and between restarts pairs leave in stamp order.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <set>

#include "cvo_odometry/frontend/ordered_stamp_pairer.hpp"

namespace {

void require(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  cvo::StampPairerOptions options;
  options.queue_size = 5 + data[0] % 40;
  options.tolerance = (data[1] % 8) * 0.004;
  if (data[2] & 1) options.fixed_offset = ((data[2] >> 1) % 64 - 32) * 0.001;
  cvo::OrderedStampPairer<int, int> pairer(options);
  std::set<int> paired_firsts, paired_seconds;
  std::size_t firsts = 0, seconds = 0, pairs = 0, restarts = 0;
  double last_first = -std::numeric_limits<double>::infinity(), last_second = last_first;
  double stamp[2] = {100.0, 100.0};
  for (std::size_t k = 3; k + 1 < size; k += 2) {
    const int stream = data[k] & 1;
    // Mostly frame-like steps; some large jumps, repeats, backwards steps and NaN.
    const int step = static_cast<int8_t>(data[k + 1]);
    const int kind = (data[k] >> 1) % 16;
    double next = stamp[stream] + step * 0.001;
    if (kind == 0) next = stamp[stream] - 5.0;
    if (kind == 1) next = stamp[stream] + 2.0;
    if (kind == 2) next = std::numeric_limits<double>::quiet_NaN();
    if (!std::isnan(next)) stamp[stream] = next;
    const int id = static_cast<int>(k);
    const auto done = stream == 0 ? pairer.addFirst(next, id) : pairer.addSecond(next, id);
    (stream == 0 ? firsts : seconds) += 1;
    if (pairer.restarts() != restarts) {
      restarts = pairer.restarts();
      last_first = last_second = -std::numeric_limits<double>::infinity();
    }
    for (const auto& pair : done) {
      require(paired_firsts.insert(pair.first).second);
      require(paired_seconds.insert(pair.second).second);
      require(pair.first_stamp > last_first && pair.second_stamp > last_second);
      last_first = pair.first_stamp, last_second = pair.second_stamp;
      if (pairer.tolerance()) {
        require(std::isfinite(pair.first_stamp) && std::isfinite(pair.second_stamp));
      }
      ++pairs;
    }
    require(pairer.pendingFirst() <= options.queue_size);
    require(pairer.pendingSecond() <= options.queue_size);
    require(pairs + pairer.droppedFirst() + pairer.pendingFirst() == firsts);
    require(pairs + pairer.droppedSecond() + pairer.pendingSecond() == seconds);
  }
  return 0;
}
