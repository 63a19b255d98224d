// cvo_run_sequence: frame-to-frame CVO odometry over a recorded TUM RGB-D or KITTI stereo folder,
// with the trajectory written out and, given ground truth, evaluated (and plotted).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <iostream>
#include <optional>
#include <random>
#include <vector>

#include "cvo_odometry/core/evaluation_report.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/tools/command_line.hpp"
#include "cvo_odometry/tools/evaluation_options.hpp"
#include "cvo_odometry/tools/stage_timer.hpp"
#include "cvo_odometry/tools/tool_options.hpp"
#include "cvo_odometry/tools/tracking_tally.hpp"
#include "cvo_odometry/tools/trajectory_plot.hpp"

namespace {

const char* kUsage =
    "usage: cvo_run_sequence (--tum DIR | --kitti DIR | --7scenes DIR) [options]\n"
    "  --first N --last N      frame range (0 .. all)\n"
    "  --stride N              every N-th frame of the range (larger motions per frame)\n"
    "  --drop SHARE[,SEED]     leave out each frame after the first with probability SHARE\n"
    "                          (0 <= SHARE < 1), as a busy driver or a slow link drops them;\n"
    "                          the same SEED (1) leaves out the same frames\n"
    "  --out FILE --format tum|kitti   trajectory output (TUM for --tum, KITTI for --kitti)\n"
    "  --prior-out FILE        the feature prior's own trajectory, in the same format\n"
    "  --gt FILE               ground truth (TUM, or KITTI poses stamped by times.txt; 7-Scenes:\n"
    "                          its pose files unless given)\n"
    "  --plot FILE.png         estimated vs ground-truth trajectory, seen from above\n"
    "  --quiet                 no per-frame lines\n";

// The spread of the points' depths over a run: a depth scale wrong by a factor shows here.
class DepthRange {
 public:
  void add(const cvo::LabeledCloud& cloud) {
    for (std::size_t i = 0; i < cloud.size(); i += 97)
      depths_.push_back(cloud.position(i).z());
  }
  void print(std::ostream& out) {
    if (depths_.empty()) return;
    std::sort(depths_.begin(), depths_.end());
    const auto at = [&](double q) {
      return depths_[static_cast<std::size_t>(q * (depths_.size() - 1))];
    };
    out << std::fixed << std::setprecision(2) << "point depths: " << at(0.05) << " .. " << at(0.95)
        << " m (5th..95th percentile), median " << at(0.5)
        << " m: a wrong --depth-scale shows as depths too small or too large\n";
  }

 private:
  std::vector<float> depths_;
};

// The frames a run processes: every stride-th of [first, last], and of those after the first,
// each left out with probability `drop` (a generator of its own, so the same seed drops the
// same frames on every machine).
std::vector<std::size_t> framesToRun(std::size_t first, std::size_t last, std::size_t stride,
                                     double drop, unsigned seed) {
  std::mt19937 draw(seed);
  std::vector<std::size_t> frames;
  for (std::size_t k = first; k <= last; k += stride) {
    const double u = static_cast<double>(draw()) / 4294967296.0;  // [0, 1)
    if (k == first || u >= drop) frames.push_back(k);
  }
  return frames;
}

// A progress bar on the terminal (stderr).
void progress(std::size_t done, std::size_t total, double fps) {
  const int width = 30;
  const int filled = static_cast<int>(width * done / std::max<std::size_t>(total, 1));
  std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, ' ') << "] " << done
            << "/" << total << "  " << std::fixed << std::setprecision(1) << fps << " frames/s"
            << std::flush;
  if (done == total) std::cerr << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  try {
    auto names = cvo::sharedOptionNames();
    names.insert(names.end(),
                 {"first", "last", "stride", "drop", "out", "prior-out", "format", "gt", "plot"});
    const auto evaluation = cvo::evaluationOptionNames();
    names.insert(names.end(), evaluation.begin(), evaluation.end());
    const cvo::CommandLine cli(argc, argv, {names.begin(), names.end()}, {"help", "quiet"});
    if (cli.has("help")) {
      std::cout << kUsage << cvo::sharedOptionsUsage() << cvo::kEvaluationOptionsUsage;
      return 0;
    }
    std::string preset_note;
    const cvo::OdometrySettings settings = cvo::settingsFrom(cli, &preset_note);
    const cvo::CvoParams& params = settings.cvo;
    const cvo::SequenceInput input = cvo::openSequence(cli);
    cvo::OdometryPipeline pipeline(settings);

    const std::size_t total = input.stamps.size();
    const std::size_t first = static_cast<std::size_t>(cli.getInt("first", 0));
    const std::size_t last = std::min(
        total - 1, static_cast<std::size_t>(cli.getInt("last", static_cast<int>(total) - 1)));
    if (first > last) throw std::invalid_argument("--first is after --last");
    const int stride = cli.getInt("stride", 1);
    if (stride < 1) throw std::invalid_argument("--stride must be >= 1");
    const std::vector<double> drop = cli.getDoubleList("drop", {0.0, 1.0});  // SHARE[,SEED]
    const double drop_seed = drop.size() == 2 ? drop[1] : 1.0;
    if (drop.size() > 2 || !(drop[0] >= 0.0 && drop[0] < 1.0) || !(drop_seed >= 0.0) ||
        drop_seed > 4294967295.0 || drop_seed != std::floor(drop_seed)) {
      throw std::invalid_argument("--drop '" + cli.get("drop") +
                                  "': a share in [0, 1), optionally ',SEED' (0 .. 2^32-1)");
    }
    const std::vector<std::size_t> frames = framesToRun(
        first, last, static_cast<std::size_t>(stride), drop[0], static_cast<unsigned>(drop_seed));
    const bool tty = isatty(STDERR_FILENO) && !cli.has("quiet");
    std::cerr << "cvo_run_sequence: " << input.kind << ", " << frames.size() << " frames, backend "
              << pipeline.backendName() << ", step " << cvo::toString(params.step_method)
              << ", colour " << (params.use_color ? "on" : "off") << "\n";
    std::cerr << "cvo_run_sequence: " << preset_note << "\n";
    if (!pipeline.backendNote().empty()) {
      std::cerr << "cvo_run_sequence: " << pipeline.backendNote() << "\n";
    }

    cvo::Trajectory trajectory, prior_trajectory;
    cvo::StageTimer timer;
    const auto start = std::chrono::steady_clock::now();
    cvo::TrackingTally tally;
    DepthRange depths;
    std::vector<double> trusted, restarts;
    std::optional<cvo::DisparityOffsetEstimate> offset_estimate;  // stereo self-calibration
    std::optional<std::size_t> offset_changed_at;  // the first frame built with another offset
    double offset_in_use = settings.disparity_offset;
    // The process's CPU time (all its threads) against the wall time of the frames' `total`:
    // how many cores the run got. Under load it tells where the scheduler put the run (README
    // "Benchmark": about 1 with a core to itself, about 0.55 when sharing one with a busy loop).
    double cpu_ms_sum = 0.0, total_ms_sum = 0.0;
    std::size_t processed = 0, one_thread = 0;  // adaptive_threads: frames it ran on one thread
    for (std::size_t done = 1; done <= frames.size(); ++done) {
      const std::size_t k = frames[done - 1];
      const auto decode_start = std::chrono::steady_clock::now();
      const cvo::CameraFrame frame = input.frame(k);
      timer.add("decode", std::chrono::duration<double, std::milli>(
                              std::chrono::steady_clock::now() - decode_start)
                              .count());
      const std::clock_t cpu_start = std::clock();
      const cvo::PipelineResult result = pipeline.process(input.stamps[k], frame);
      const double cpu_ms = 1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
      const cvo::OdometryUpdate& update = result.update;
      tally.add(result);
      if (result.outcome == cvo::FrameOutcome::kProcessed) {
        ++processed;
        if (result.threads == 1) ++one_thread;
        if (update.has_pose) trajectory.append(input.stamps[k], update.pose);
        if (update.has_pose && update.trusted()) trusted.push_back(input.stamps[k]);
        if (update.state == cvo::TrackingState::kReset) restarts.push_back(input.stamps[k]);
        if (result.prior_pose) prior_trajectory.append(input.stamps[k], *result.prior_pose);
        if (result.prior) {
          timer.add("feature prior", result.prior->time_ms);
          timer.add("corners (beside)", result.prior->seed_ms);
        }
        if (result.cloud) depths.add(*result.cloud);
        if (result.disparity_offset_ms > 0.0) {
          timer.add("disparity offset", result.disparity_offset_ms);
        }
        if (result.disparity_offset_estimate) {
          offset_estimate = result.disparity_offset_estimate;
          if (!offset_changed_at && result.disparity_offset != settings.disparity_offset) {
            offset_changed_at = k;
          }
          offset_in_use = result.disparity_offset;
        }
        timer.add("frontend", result.stats.time_ms);
        if (result.stats.matching_ms > 0.0) {
          timer.add("frontend: matching", result.stats.matching_ms);
        }
        if (update.attempts > 0) {
          timer.add("registration", update.report.time_ms);
          if (update.photometric.applied) timer.add("photometric", update.photometric.time_ms);
          timer.add("total", result.total_ms);
          timer.add("cpu (all threads)", cpu_ms);
          cpu_ms_sum += cpu_ms;
          total_ms_sum += result.total_ms;
        }
      }
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (tty) {
        progress(done, frames.size(), done / elapsed);
      } else if (!cli.has("quiet")) {
        std::cerr << "frame " << k << ": ";
        if (result.outcome != cvo::FrameOutcome::kProcessed) {
          std::cerr << (result.outcome == cvo::FrameOutcome::kStale ? "stale" : "skipped") << " ("
                    << result.why << ")\n";
          continue;
        }
        std::cerr << result.stats.selection.selected << " points";
        if (result.stats.spaced_out > 0) {
          std::cerr << " (" << result.stats.spaced_out << " left out for point_spacing)";
        }
        if (result.stats.label_motion_px > 0) {
          std::cerr << " (ignored classes moved " << result.stats.label_motion_px
                    << " px to the depth's instant)";
        }
        if (update.attempts > 0) {
          std::cerr << ", " << update.report.iterations << " iterations, " << std::setprecision(2)
                    << std::fixed << update.report.time_ms << " ms (frame " << result.total_ms
                    << " ms), cosine " << std::setprecision(3) << update.cosine << ", guess "
                    << cvo::toString(update.guess) << ", tracks "
                    << (result.prior ? result.prior->inliers : 0) << "/"
                    << (result.prior ? result.prior->tracks : 0) << " agree "
                    << update.track_agreement << " (median " << update.track_error_px << " px of "
                    << update.track_flow_px << " px, turn " << update.track_rotation_gap_deg
                    << " deg), " << (update.report.converged ? "converged" : update.report.message);
        }
        if (update.second_motion_tracks > 0) {
          std::cerr << ", second motion " << update.second_motion_tracks << " tracks"
                    << (update.second_motion_separate ? " (its own: " : " (")
                    << std::setprecision(1) << 100.0 * update.left_out_share << " % left out";
          // Tracks that settle where the first motion puts them too: a repeating texture.
          if (result.prior && result.prior->slipped > 0) {
            std::cerr << "; " << result.prior->slipped << " slipped";
          }
          std::cerr << ")";
          if (!update.motion_split.empty()) std::cerr << " [" << update.motion_split << "]";
        }
        if (update.state != cvo::TrackingState::kTracking) {
          std::cerr << ", " << cvo::toString(update.state);
        }
        if (update.new_keyframe) std::cerr << ", keyframe";
        if (!update.photometric.skipped.empty()) {
          std::cerr << ", photometric skipped: " << update.photometric.skipped;
        } else if (update.photometric.applied) {
          std::cerr << ", photometric " << std::setprecision(3) << update.photometric.correction_deg
                    << " deg in " << update.photometric.iterations << " iterations";
          if (update.photometric.tracks > 0) {
            std::cerr << " with " << update.photometric.tracks << " tracks";
          }
        }
        if (result.disparity_offset_estimate) {
          std::cerr << ", disparity offset " << std::setprecision(3) << result.disparity_offset
                    << " px (estimate " << result.disparity_offset_estimate->offset
                    << (result.disparity_offset_estimate->trusted ? ")" : ", not trusted yet)");
        }
        if (!update.problem.empty()) std::cerr << " (" << update.problem << ")";
        if (!result.why.empty()) std::cerr << " [" << result.why << "]";
        std::cerr << "\n";
      }
    }
    tally.print(std::cout);
    depths.print(std::cout);
    if (offset_estimate) {
      std::cout << std::fixed << std::setprecision(3) << "disparity offset: estimated "
                << offset_estimate->offset << " px (standard error "
                << offset_estimate->standard_error << " px, " << offset_estimate->pairs
                << " frame pairs), ";
      if (offset_changed_at) {
        std::cout << "in use " << offset_in_use << " px, from frame " << *offset_changed_at
                  << " on\n";
      } else {
        std::cout << "in use: the start, " << offset_in_use << " px ("
                  << (offset_estimate->trusted ? "within the step of it" : "not trusted yet")
                  << ")\n";
      }
    }
    timer.print(std::cout);
    if (total_ms_sum > 0.0) {
      std::cout << std::setprecision(2) << "cores in use: " << cpu_ms_sum / total_ms_sum
                << " (the process's CPU time over the wall time of its frames' total)\n";
    }
    const int threads = cvo::resolvedThreadCount(settings.cvo.num_threads);
    if (threads > 1) {
      std::cout << "threads: " << threads << ", " << one_thread << " of " << processed
                << " frames on one thread ("
                << (settings.cvo.adaptive_threads ? "adaptive_threads: while the frames got no "
                                                    "more than about a core)\n"
                                                  : "adaptive_threads off)\n");
    }
    if (cli.has("out")) {
      const auto format = cli.has("format") ? cvo::parseTrajectoryFormat(cli.get("format"))
                                            : input.trajectory_format;
      cvo::writeTrajectory(cli.get("out"), trajectory, format);
      std::cout << "trajectory: " << cli.get("out") << "\n";
    }
    if (cli.has("prior-out")) {
      const auto format = cli.has("format") ? cvo::parseTrajectoryFormat(cli.get("format"))
                                            : input.trajectory_format;
      cvo::writeTrajectory(cli.get("prior-out"), prior_trajectory, format);
    }
    if (cli.has("gt") || !input.ground_truth.empty()) {
      cvo::Trajectory ground_truth = input.ground_truth;
      if (cli.has("gt")) {
        const std::string gt_path = cli.get("gt");
        const auto gt_format = cvo::detectTrajectoryFormat(gt_path);
        ground_truth = cvo::readTrajectory(
            gt_path, gt_format, gt_format == cvo::TrajectoryFormat::kKitti ? input.times_path : "");
      }
      const cvo::EvaluationOptions options = cvo::evaluationOptionsFrom(cli);
      const auto report =
          cvo::evaluateTrajectory(ground_truth, trajectory, options, &trusted, restarts);
      cvo::printEvaluationReport(std::cout, report, options);
      if (prior_trajectory.size() >= 2) {
        std::cout << "feature prior alone (KLT + PnP frame to frame), for comparison:\n";
        cvo::printEvaluationReport(
            std::cout, cvo::evaluateTrajectory(ground_truth, prior_trajectory, options), options);
      }
      if (cli.has("plot")) {
        cvo::plotTrajectories(cli.get("plot"), ground_truth, trajectory, report.ate.alignment,
                              "cvo_odometry " + input.kind);
        std::cout << "plot: " << cli.get("plot") << "\n";
      }
    } else if (cli.has("plot")) {
      cvo::plotTrajectories(cli.get("plot"), cvo::Trajectory(), trajectory,
                            Eigen::Isometry3d::Identity(), "cvo_odometry " + input.kind);
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_run_sequence: " << e.what() << "\n";
    return 2;
  }
}
