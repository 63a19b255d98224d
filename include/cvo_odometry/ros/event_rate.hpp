// The odometry's publishing rate for the diagnostics, judged over a window of the node's clock
// (simulated or wall) and only once a whole window has been watched. diagnostic_updater's
// FrequencyStatus starts its window when it is constructed: under simulated time that is time 0,
// before /clock comes, so a bag's first window (a short bag's whole run) spans decades and reads
// "Frequency too low". Here the window starts at the first reading of a running clock, and again
// when time goes backwards (a looping bag). ROS-free, so it is tested on given times.
#pragma once

#include <cstddef>
#include <cstdio>
#include <deque>
#include <optional>
#include <stdexcept>
#include <string>

namespace cvo {

struct EventRateOptions {
  double window = 5.0;                      // s of the node's clock
  double min_rate = 1.0, max_rate = 100.0;  // Hz
  double tolerance = 0.1;                   // fraction below min / above max still accepted
};

class EventRate {
 public:
  using Options = EventRateOptions;
  struct Judgement {
    bool warn = false;      // a rate outside the bounds over a whole window
    bool measured = false;  // a whole window watched: `rate` is a measurement
    std::string message;
    double rate = 0.0;       // events per second over the window (measured only)
    std::size_t events = 0;  // in the window (or since watching began)
    double span = 0.0;       // s watched, at most the window
  };

  explicit EventRate(Options options = {}) : options_(options) {
    if (!(options_.window > 0.0) || !(options_.min_rate >= 0.0) ||
        !(options_.max_rate >= options_.min_rate) || !(options_.tolerance >= 0.0)) {
      throw std::invalid_argument("EventRate: window > 0 and 0 <= min_rate <= max_rate");
    }
  }

  const Options& options() const { return options_; }
  std::size_t total() const { return total_; }

  // An event at `now` (s of the node's clock; 0: no clock yet, not counted in a window).
  void tick(double now) {
    ++total_;
    if (now <= 0.0) return;
    observe(now);
    ticks_.push_back(now);
  }

  Judgement judge(double now) {
    Judgement judgement;
    if (now <= 0.0) {
      judgement.message = "no clock yet (use_sim_time is set and no /clock has come)";
      return judgement;
    }
    observe(now);
    while (!ticks_.empty() && ticks_.front() <= now - options_.window)
      ticks_.pop_front();
    judgement.events = ticks_.size();
    judgement.span = now - *since_;
    char text[160];
    if (judgement.span < options_.window) {
      std::snprintf(text, sizeof text, "%s: %zu published in the first %.1f of %.1f s watched",
                    went_back_ ? "time went backwards, measuring again" : "starting",
                    judgement.events, judgement.span, options_.window);
      judgement.message = text;
      return judgement;
    }
    went_back_ = false;
    judgement.span = options_.window;
    judgement.measured = true;
    judgement.rate = static_cast<double>(judgement.events) / options_.window;
    const char* verdict = "rate";
    if (judgement.rate < options_.min_rate * (1.0 - options_.tolerance)) {
      judgement.warn = true;
      verdict = "odometry rate too low";
    } else if (judgement.rate > options_.max_rate * (1.0 + options_.tolerance)) {
      judgement.warn = true;
      verdict = "odometry rate too high";
    }
    std::snprintf(text, sizeof text, "%s: %.3g Hz over the last %.1f s (expected %.3g-%.3g Hz)",
                  verdict, judgement.rate, options_.window, options_.min_rate, options_.max_rate);
    judgement.message = text;
    return judgement;
  }

 private:
  // Watching starts at the first reading, and again when time goes backwards.
  void observe(double now) {
    if (last_ && now < *last_) {
      ticks_.clear();
      since_ = now;
      went_back_ = true;
    }
    if (!since_) since_ = now;
    last_ = now;
  }

  Options options_;
  std::deque<double> ticks_;
  std::optional<double> since_, last_;
  bool went_back_ = false;
  std::size_t total_ = 0;
};

}  // namespace cvo
