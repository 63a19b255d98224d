// Pairs two streams of stamped messages (colour and depth of an RGB-D camera) in order, learning
// the offset between their stamps. Nearest-stamp pairing (message_filters' approximate policy)
// fails when the offset is near half a frame: TUM's depth is 12-20 ms older than its colour at
// 30 Hz, so a depth 15.6 ms after one colour image and 20.2 ms before the next is given to the
// wrong one. Here each first-stream message is paired with the second-stream message nearest to
// its stamp plus the learned offset (the median of the recent pairs' offsets), within a tolerance.
// The first messages wait until the offset is learned (bootstrap_frames of them) and then pair
// with it, flagged `held`, so that a caller can use them all rather than only the newest: neither
// nearest-stamp pairing nor an offset from the first pair alone is right on TUM's stamps (the
// nearest depth of 7 of the fixture's 37 colour images is the next frame's).
// ROS-free so the pairing is unit-tested on real stamps; the nodelet feeds it message pointers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <deque>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "cvo_odometry/core/robust_scale.hpp"

namespace cvo {

struct StampPairerOptions {
  // Largest |second stamp - (first stamp + offset)| of a pair (s); 0: 0.4 x the streams' median
  // frame period, measured on the first frames (with a fixed offset, 0 means equal stamps).
  double tolerance = 0.0;
  // A known offset (second - first, s), e.g. 0 for a segmentation image stamped with its colour
  // image; unset: learned.
  std::optional<double> fixed_offset;
  // First-stream messages (with a second-stream message within half a frame) whose nearest
  // offsets give the first estimate.
  std::size_t bootstrap_frames = 5;
  // Recent pairs whose median offset is the estimate.
  std::size_t offset_window = 15;
  // Messages held per stream; beyond it the oldest is given up (counted as dropped).
  std::size_t queue_size = 30;
  // First-stream messages given up in a row, with second-stream messages arriving, after which
  // the learned offset is taken as wrong (the stream's timing changed) and learned again.
  std::size_t relearn_after_unpaired = 10;

  void validate() const {
    if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
      throw std::invalid_argument("stamp pairer: tolerance must be >= 0");
    }
    if (fixed_offset && !std::isfinite(*fixed_offset)) {
      throw std::invalid_argument("stamp pairer: the fixed offset must be finite");
    }
    if (bootstrap_frames < 2 || offset_window < 1) {
      throw std::invalid_argument("stamp pairer: bootstrap_frames >= 2 and offset_window >= 1");
    }
    if (queue_size < bootstrap_frames) {
      throw std::invalid_argument("stamp pairer: queue_size must be >= bootstrap_frames");
    }
    if (relearn_after_unpaired < 1) {
      throw std::invalid_argument("stamp pairer: relearn_after_unpaired must be >= 1");
    }
  }
};

template <class First, class Second>
class OrderedStampPairer {
 public:
  struct Pair {
    double first_stamp = 0.0, second_stamp = 0.0;
    First first;
    Second second;
    // Paired when the offset was learned from it and the messages held with it: the first
    // frames after a start, a restart or relearn().
    bool held = false;
  };

  explicit OrderedStampPairer(StampPairerOptions options = {}) : options_(std::move(options)) {
    options_.validate();
    if (options_.fixed_offset) {
      offset_ = *options_.fixed_offset;
      tolerance_ = options_.tolerance;
    }
  }

  // Adds a message; returns the pairs it completes, in stamp order.
  std::vector<Pair> addFirst(double stamp, First message) {
    add(stamp, std::move(message), Stream<First>{firsts_, last_first_, dropped_first_},
        Stream<Second>{seconds_, last_second_, dropped_second_});
    return drain();
  }
  std::vector<Pair> addSecond(double stamp, Second message) {
    add(stamp, std::move(message), Stream<Second>{seconds_, last_second_, dropped_second_},
        Stream<First>{firsts_, last_first_, dropped_first_});
    return drain();
  }

  // Messages held, waiting for a partner or a decision, per stream.
  std::size_t pendingFirst() const { return firsts_.size(); }
  std::size_t pendingSecond() const { return seconds_.size(); }
  // Messages given up unpaired, per stream.
  std::size_t droppedFirst() const { return dropped_first_; }
  std::size_t droppedSecond() const { return dropped_second_; }
  // Times a stream's stamps went backwards (a looping bag): the older loop's messages are dropped.
  std::size_t restarts() const { return restarts_; }
  // The offset (second - first) and tolerance in use; unset until the first frames are seen.
  std::optional<double> offset() const { return offset_; }
  std::optional<double> tolerance() const { return tolerance_; }
  // Times the offset was learned afresh: after a restart of a stream, a run of
  // relearn_after_unpaired unpaired messages, or relearn().
  std::size_t relearns() const { return relearns_; }

  // Forgets the learned offset (not a fixed one): the next frames teach it again. For a reset,
  // or another source on the same topics.
  void relearn() {
    ++relearns_;
    unpaired_run_ = 0;
    if (options_.fixed_offset) return;
    offset_.reset();
    tolerance_.reset();
    second_spacing_.reset();
    recent_offsets_.clear();
  }

 private:
  template <class T>
  struct Stamped {
    double stamp;
    T message;
  };
  template <class T>
  using Queue = std::deque<Stamped<T>>;

  static double median(std::vector<double> values) { return medianInPlace(values); }

  template <class T>
  static double medianSpacing(const Queue<T>& queue) {
    std::vector<double> spacing;
    for (std::size_t k = 1; k < queue.size(); ++k) {
      spacing.push_back(queue[k].stamp - queue[k - 1].stamp);
    }
    return median(spacing);
  }

  // One stream's queue, latest stamp and drop count (the two streams may share a type).
  template <class T>
  struct Stream {
    Queue<T>& queue;
    double& last;
    std::size_t& dropped;
  };

  template <class T, class Other>
  void add(double stamp, T message, Stream<T> stream, Stream<Other> other) {
    if (!std::isfinite(stamp)) {
      ++stream.dropped;
      return;
    }
    if (stamp < stream.last) {
      // The stream started over: its queued messages and the other stream's messages from the
      // older loop (later than anything the new stamp could pair with) go.
      ++restarts_;
      stream.dropped += stream.queue.size();
      stream.queue.clear();
      const double reach = std::abs(offset_.value_or(0.0)) + tolerance_.value_or(0.0);
      while (!other.queue.empty() && other.queue.back().stamp > stamp + reach) {
        other.queue.pop_back();
        ++other.dropped;
      }
      other.last =
          other.queue.empty() ? -std::numeric_limits<double>::infinity() : other.queue.back().stamp;
      relearn();  // the replayed or new source may have other timing
    } else if (stamp == stream.last) {
      ++stream.dropped;  // a repeated stamp carries no new frame
      return;
    }
    stream.last = stamp;
    stream.queue.push_back({stamp, std::move(message)});
  }

  // The first estimate of the offset: the median nearest offset of the first-stream messages
  // that have a second-stream message within half a frame (so a stream that started late, or
  // older messages of the other, do not count), and of the tolerance: 0.4 frame period, so at
  // most one second-stream message falls in the window.
  bool learn() {
    if (firsts_.size() < 2 || seconds_.size() < 2) return false;
    const double period = std::min(medianSpacing(firsts_), medianSpacing(seconds_));
    std::vector<double> nearest;
    for (const auto& first : firsts_) {
      double best = std::numeric_limits<double>::infinity();
      for (const auto& second : seconds_) {
        const double offset = second.stamp - first.stamp;
        if (std::abs(offset) < std::abs(best)) best = offset;
      }
      if (std::abs(best) <= 0.5 * period) nearest.push_back(best);
    }
    if (nearest.size() < options_.bootstrap_frames) return false;
    offset_ = median(nearest);
    tolerance_ = options_.tolerance > 0.0 ? options_.tolerance : 0.4 * period;
    return true;
  }

  // Second-stream messages are at least this far apart (a margin below their median spacing):
  // a candidate is final once no later message could be nearer to the target.
  double secondSpacing() {
    if (!second_spacing_ && !options_.fixed_offset && seconds_.size() >= 2) {
      second_spacing_ = 0.75 * medianSpacing(seconds_);
    }
    return second_spacing_.value_or(0.0);
  }

  std::vector<Pair> drain() {
    std::vector<Pair> pairs;
    const bool learning = !offset_;
    if (learning && !learn()) {
      trimQueues();
      return pairs;
    }
    const double spacing = secondSpacing();
    const double slack = 1e-9;  // stamps converted from integer nanoseconds
    while (!firsts_.empty()) {
      const bool overflow = firsts_.size() > options_.queue_size;
      const double target = firsts_.front().stamp + *offset_;
      while (!seconds_.empty() && seconds_.front().stamp < target - *tolerance_ - slack) {
        seconds_.pop_front();  // too old for this first message and every later one
        ++dropped_second_;
      }
      std::size_t best = seconds_.size();
      for (std::size_t k = 0;
           k < seconds_.size() && seconds_[k].stamp <= target + *tolerance_ + slack; ++k) {
        if (best == seconds_.size() ||
            std::abs(seconds_[k].stamp - target) < std::abs(seconds_[best].stamp - target)) {
          best = k;
        }
      }
      if (best == seconds_.size()) {
        // Nothing in the window: unpaired once a later message has passed it, or the queue is full.
        if (overflow || (!seconds_.empty() && seconds_.front().stamp > target + *tolerance_)) {
          firsts_.pop_front();
          ++dropped_first_;
          if (++unpaired_run_ >= options_.relearn_after_unpaired && !options_.fixed_offset) {
            relearn();
            trimQueues();
            return pairs;
          }
          continue;
        }
        break;
      }
      const double distance = std::abs(seconds_[best].stamp - target);
      const bool final = last_second_ + spacing >= target + distance - slack;
      if (!final && !overflow) break;
      pairs.push_back({firsts_.front().stamp, seconds_[best].stamp,
                       std::move(firsts_.front().message), std::move(seconds_[best].message),
                       learning});
      firsts_.pop_front();
      dropped_second_ += best;  // passed over: nearer to no first message
      seconds_.erase(seconds_.begin(), seconds_.begin() + static_cast<std::ptrdiff_t>(best) + 1);
      unpaired_run_ = 0;
      updateOffset(pairs.back().second_stamp - pairs.back().first_stamp);
    }
    trimQueues();
    return pairs;
  }

  // Each queue keeps its latest queue_size messages (a silent partner stream, an unlearned
  // offset); older ones are given up.
  void trimQueues() {
    while (firsts_.size() > options_.queue_size) {
      firsts_.pop_front();
      ++dropped_first_;
    }
    while (seconds_.size() > options_.queue_size) {
      seconds_.pop_front();
      ++dropped_second_;
    }
  }

  void updateOffset(double offset) {
    if (options_.fixed_offset) return;
    recent_offsets_.push_back(offset);
    if (recent_offsets_.size() > options_.offset_window) recent_offsets_.pop_front();
    offset_ = median({recent_offsets_.begin(), recent_offsets_.end()});
  }

  StampPairerOptions options_;
  Queue<First> firsts_;
  Queue<Second> seconds_;
  double last_first_ = -std::numeric_limits<double>::infinity();
  double last_second_ = -std::numeric_limits<double>::infinity();
  std::optional<double> offset_, tolerance_, second_spacing_;
  std::deque<double> recent_offsets_;
  std::size_t dropped_first_ = 0, dropped_second_ = 0, restarts_ = 0, relearns_ = 0;
  std::size_t unpaired_run_ = 0;  // first-stream messages given up since the last pair
};

}  // namespace cvo
