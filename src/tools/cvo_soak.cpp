// cvo_soak: runs frame-to-frame odometry over a recorded sequence for thousands of frames, back
// and forth (0..N-1, N-2..0, 1..N-1, ...) with stamps always moving forward, so every frame is
// a real, trackable motion. Logs each frame's time and resident memory, and prints whether
// memory stayed flat after warm-up and whether frames got slower.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <vector>

#include "cvo_odometry/core/robust_scale.hpp"
#include "cvo_odometry/tools/command_line.hpp"
#include "cvo_odometry/tools/tool_options.hpp"
#include "cvo_odometry/tools/tracking_tally.hpp"

namespace {

const char* kUsage =
    "usage: cvo_soak (--tum DIR | --kitti DIR) [--frames N] [--warmup N] [--log CSV]\n"
    "  --frames N      frames to run (3000)\n"
    "  --warmup N      frames before memory and time are compared (200)\n"
    "  --log CSV       per-frame log: frame, sequence index, ms, resident MiB, state\n"
    "  --max-growth M  exit 1 when resident memory grows more than M MiB after warm-up (8)\n";

double residentMiB() {
  std::ifstream statm("/proc/self/statm");
  long pages_total = 0, pages_resident = 0;
  statm >> pages_total >> pages_resident;
  return pages_resident * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

// Sequence index of soak frame k when running back and forth over n frames.
std::size_t pingPong(std::size_t k, std::size_t n) {
  if (n < 2) return 0;
  const std::size_t period = 2 * (n - 1), phase = k % period;
  return phase < n ? phase : period - phase;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  return cvo::medianInPlace(v);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    auto names = cvo::sharedOptionNames();
    names.insert(names.end(), {"frames", "warmup", "log", "max-growth"});
    const cvo::CommandLine cli(argc, argv, {names.begin(), names.end()}, {"help"});
    if (cli.has("help")) {
      std::cout << kUsage << cvo::sharedOptionsUsage();
      return 0;
    }
    const cvo::OdometrySettings settings = cvo::settingsFrom(cli);
    const cvo::SequenceInput input = cvo::openSequence(cli);
    const std::size_t frames = static_cast<std::size_t>(cli.getInt("frames", 3000));
    const std::size_t warmup = static_cast<std::size_t>(cli.getInt("warmup", 200));
    const double max_growth = cli.getDouble("max-growth", 8.0);
    if (warmup + 10 > frames) throw std::invalid_argument("--frames must exceed --warmup + 10");
    std::ofstream log;
    if (cli.has("log")) {
      log.open(cli.get("log"));
      if (!log) throw std::runtime_error("cannot write " + cli.get("log"));
      log << "frame,index,ms,resident_mib,state\n";
    }
    cvo::OdometryPipeline pipeline(settings);
    const std::size_t n = input.stamps.size();
    const double interval = (input.stamps.back() - input.stamps.front()) / (n - 1);
    std::vector<double> ms(frames), resident(frames);
    cvo::TrackingTally tally;
    for (std::size_t k = 0; k < frames; ++k) {
      const std::size_t index = pingPong(k, n);
      const cvo::CameraFrame frame = input.frame(index);
      const cvo::PipelineResult result =
          pipeline.process(input.stamps.front() + k * interval, frame);
      ms[k] = result.total_ms;
      resident[k] = residentMiB();
      tally.add(result);
      if (log.is_open()) {
        log << k << "," << index << "," << std::fixed << std::setprecision(3) << ms[k] << ","
            << resident[k] << "," << cvo::toString(result.update.state) << "\n";
      }
      if (k % 500 == 0) {
        std::cerr << "frame " << k << ": " << std::fixed << std::setprecision(1) << ms[k] << " ms, "
                  << resident[k] << " MiB\n";
      }
    }
    // Compare the first and last tenth after warm-up.
    const std::size_t tenth = std::max<std::size_t>((frames - warmup) / 10, 1);
    const std::vector<double> early(ms.begin() + warmup, ms.begin() + warmup + tenth);
    const std::vector<double> late(ms.end() - tenth, ms.end());
    const double peak_after = *std::max_element(resident.begin() + warmup, resident.end());
    const double growth = resident.back() - resident[warmup];
    std::cout << std::fixed << std::setprecision(1) << "soak: " << frames << " frames of "
              << input.kind << " (" << n << " frames back and forth), backend "
              << pipeline.backendName() << "\n";
    tally.print(std::cout);
    std::cout << "resident memory: " << resident[0] << " MiB after frame 0, " << resident[warmup]
              << " MiB after warm-up (frame " << warmup << "), " << resident.back()
              << " MiB at the end (peak after warm-up " << peak_after << " MiB); growth " << growth
              << " MiB\n"
              << std::setprecision(2) << "ms per frame (pipeline, decoded images in): median "
              << median(ms) << "; first tenth after warm-up " << median(early) << ", last tenth "
              << median(late) << " (ratio " << median(late) / median(early) << ")\n";
    if (growth > max_growth) {
      std::cout << "memory grew by more than " << max_growth << " MiB after warm-up\n";
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_soak: " << e.what() << "\n" << kUsage;
    return 2;
  }
}
