// cvo_benchmark: registers real consecutive TUM fr1_xyz frames (test/data/tum_clouds) at about
// 3k, 8k and 15k points and prints median ms per registration, iterations, retained pairs per
// iteration and the speed-up over the CPU backend, for each step method, kernel set and backend
// (cpu, cuda, device_cpu: the CUDA backend's code on CPU threads), then the GPU target: at most
// 2 ms per registration at 15k points with colour (procrustes) on an H100/H200-class GPU, and at
// least 10x the CPU backend on the same machine. Needs only the core (no ROS/OpenCV).
// --time-calls adds a line per row: the backend's calls per registration and their time, and the
// rest of the registration (its own steps between calls); for the device backends also the
// device work a registration asks for (Thrust algorithms, uploads, host waits: the same on
// device_cpu as on the GPU).
#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include "cvo_odometry/core/backend_factory.hpp"
#include "cvo_odometry/core/cloud_io.hpp"
#include "cvo_odometry/core/cvo_registration.hpp"
#include "cvo_odometry/core/params_io.hpp"
#include "cvo_odometry/core/timed_backend.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace {

const char* kUsage =
    "usage: cvo_benchmark --data DIR [options]\n"
    "  --data DIR            folder with frame10_N.cloud / frame11_N.cloud (test/data/tum_clouds)\n"
    "  --sizes 3000,8000,15000\n"
    "  --methods procrustes,reference\n"
    "  --kernels geometric,color\n"
    "  --backends cpu[,cuda][,device_cpu]  (default: cpu, and cuda when available)\n"
    "  --repeat N            registrations per configuration (7)\n"
    "  --threads N           CPU threads (0: all)\n"
    "  --preset FILE         base parameters\n"
    "  --max-source-points N the registration's source budget (0, the default here: every point,\n"
    "                        so that a row's size is what it sums over)\n"
    "  --reference-max-size N  skip the reference method above this size (3000)\n"
    "  --time-calls          after each row, the backend's calls per registration, their ms,\n"
    "                        and the rest of the registration's ms; device backends: the\n"
    "                        Thrust algorithms, uploads and host waits a registration asks for,\n"
    "                        on a new target (the warm-up) and on a kept one (the timed runs)\n"
    "  --check-cuda          only say whether a CUDA device is usable (exit 0, else 3)\n";

// The GPU target (README "Benchmark"): 15k points, colour, the default method.
constexpr double kTargetMs = 2.0;
constexpr double kTargetSpeedup = 10.0;

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    out.push_back(item);
  return out;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// "#   calls: moments 19 x 0.012 ms, ...; rest 0.41 ms" per registration, over `registrations`.
void printCallTimes(const cvo::TimedBackend& timed, int registrations, double total_ms) {
  std::cout << "#   per registration:";
  for (int call = 0; call < cvo::TimedBackend::kCallKinds; ++call) {
    const auto kind = static_cast<cvo::TimedBackend::Call>(call);
    const cvo::TimedBackend::Tally& tally = timed.tally(kind);
    if (tally.calls == 0) continue;
    std::cout << " " << cvo::TimedBackend::callName(kind) << " " << std::setprecision(1)
              << static_cast<double>(tally.calls) / registrations << " x " << std::setprecision(3)
              << tally.ms / tally.calls << " ms,";
  }
  std::cout << " rest " << std::setprecision(3) << (total_ms - timed.totalMs()) / registrations
            << " ms\n";
}

// "#   device work LABEL: ..." from the counts before and after `registrations` registrations.
void printDeviceWork(const char* label, const cvo::DeviceWork& before, const cvo::DeviceWork& after,
                     int registrations) {
  const auto per = [&](long a, long b) { return static_cast<double>(b - a) / registrations; };
  std::cout << std::setprecision(1) << "#   device work " << label << ": "
            << per(before.algorithms, after.algorithms) << " Thrust algorithms ("
            << per(before.evaluations, after.evaluations) << " evaluations, one reduction and "
            << "one wait each; " << per(before.grid_builds, after.grid_builds) << " grid builds), "
            << per(before.uploads, after.uploads) << " uploads, "
            << per(before.evaluations + before.uploads, after.evaluations + after.uploads)
            << " host waits\n";
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const cvo::CommandLine cli(argc, argv,
                               {"data", "sizes", "methods", "kernels", "backends", "repeat",
                                "max-source-points", "threads", "preset", "reference-max-size"},
                               {"help", "check-cuda", "time-calls"});
    if (cli.has("help")) {
      std::cout << kUsage;
      return 0;
    }
    std::string why_not;
    const bool cuda = cvo::cudaBackendAvailable(&why_not);
    if (cli.has("check-cuda")) {
      const bool says_so = why_not.rfind("no CUDA device", 0) == 0;
      std::cout << (cuda      ? "CUDA device usable"
                    : says_so ? why_not
                              : "no CUDA device: " + why_not)
                << "\n";
      return cuda ? 0 : 3;
    }
    const std::string data = cli.require("data");
    const int repeat = cli.getInt("repeat", 7);
    const int reference_max = cli.getInt("reference-max-size", 3000);
    cvo::CvoParams base;
    if (cli.has("preset"))
      base = cvo::loadCvoParams(cli.get("preset"), base, cvo::UnknownKeys::kIgnore);
    base.num_threads = cli.getInt("threads", 0);
    base.max_source_points = cli.getInt("max-source-points", 0);
    const bool time_calls = cli.has("time-calls");
    std::string default_backends = "cpu";
    if (cuda) {
      default_backends += ",cuda";
    } else {
      std::cout << "# CUDA backend not measured: " << why_not << "\n";
    }
    std::cout << std::left << std::setw(8) << "points" << std::setw(12) << "method" << std::setw(11)
              << "kernels" << std::setw(12) << "backend" << std::right << std::setw(11)
              << "median_ms" << std::setw(8) << "iters" << std::setw(14) << "pairs/iter"
              << std::setw(9) << "x_cpu"
              << "\n";
    double target_gpu_ms = -1.0, target_cpu_ms = -1.0;
    for (const auto& size : split(cli.get("sizes", "3000,8000,15000"))) {
      const cvo::LabeledCloud target = cvo::readCloud(data + "/frame10_" + size + ".cloud");
      const cvo::LabeledCloud source = cvo::readCloud(data + "/frame11_" + size + ".cloud");
      for (const auto& method : split(cli.get("methods", "procrustes,reference"))) {
        if (method == "reference" && std::stoi(size) > reference_max) continue;
        for (const auto& kernels : split(cli.get("kernels", "geometric,color"))) {
          double cpu_ms = -1.0;  // this configuration's CPU row, for the speed-up
          for (const auto& backend : split(cli.get("backends", default_backends))) {
            if (backend == "cuda" && !cuda) continue;
            cvo::CvoParams params = base;
            params.step_method = cvo::parseStepMethod(method);
            params.use_color = kernels == "color";
            params.backend = cvo::parseBackendChoice(backend);
            std::unique_ptr<cvo::RegistrationBackend> backend_given;  // null: the registration's
            cvo::TimedBackend* timed = nullptr;
            if (time_calls) {
              auto wrapper = std::make_unique<cvo::TimedBackend>(
                  cvo::makeBackend(params.backend, params.num_threads));
              timed = wrapper.get();
              backend_given = std::move(wrapper);
            }
            cvo::CvoRegistration registration(params, std::move(backend_given));
            std::vector<double> ms;
            cvo::RegistrationReport report;
            const std::optional<cvo::DeviceWork> work_new =
                timed ? timed->deviceWork() : std::nullopt;
            // Warm-up: the first registration on this target. The timed ones find it kept on
            // a device, with its grids, as a keyframe is between frames.
            registration.align(target, source, Eigen::Isometry3d::Identity());
            if (timed) timed->reset();
            const std::optional<cvo::DeviceWork> work_before =
                timed ? timed->deviceWork() : std::nullopt;
            for (int r = 0; r < repeat; ++r) {
              report = registration.align(target, source, Eigen::Isometry3d::Identity()).report;
              ms.push_back(report.time_ms);
            }
            const double median_ms = median(ms);
            if (backend == "cpu") cpu_ms = median_ms;
            char speedup[32] = "-";
            if (cpu_ms > 0.0) std::snprintf(speedup, sizeof speedup, "%.1f", cpu_ms / median_ms);
            std::cout << std::left << std::setw(8) << source.size() << std::setw(12) << method
                      << std::setw(11) << kernels << std::setw(12) << report.backend << std::right
                      << std::fixed << std::setprecision(2) << std::setw(11) << median_ms
                      << std::setw(8) << report.iterations << std::setw(14) << std::setprecision(0)
                      << report.mean_pairs << std::setw(9) << speedup << "\n";
            if (timed) {
              double total_ms = 0.0;
              for (const double m : ms)
                total_ms += m;
              printCallTimes(*timed, repeat, total_ms);
              if (work_before) {
                printDeviceWork("on a new target", *work_new, *work_before, 1);
                printDeviceWork("per registration (target kept)", *work_before,
                                *timed->deviceWork(), repeat);
              }
            }
            if (size == "15000" && method == "procrustes" && kernels == "color") {
              if (backend == "cpu") target_cpu_ms = median_ms;
              if (backend == "cuda") target_gpu_ms = median_ms;
            }
          }
        }
      }
    }
    std::cout << std::fixed << std::setprecision(2) << "# GPU target (15k points, colour, "
              << "procrustes: <= " << kTargetMs << " ms and >= " << kTargetSpeedup << "x cpu): ";
    if (target_gpu_ms < 0.0) {
      std::cout << "not measured (no cuda row)\n";
    } else {
      std::cout << target_gpu_ms << " ms (" << (target_gpu_ms <= kTargetMs ? "met" : "NOT met")
                << ")";
      if (target_cpu_ms > 0.0) {
        const double speedup = target_cpu_ms / target_gpu_ms;
        std::cout << ", " << std::setprecision(1) << speedup << "x cpu ("
                  << (speedup >= kTargetSpeedup ? "met" : "NOT met") << ")";
      }
      std::cout << "\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_benchmark: " << e.what() << "\n" << kUsage;
    return 2;
  }
}
