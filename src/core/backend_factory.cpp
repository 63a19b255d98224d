#include "cvo_odometry/core/backend_factory.hpp"

#include <stdexcept>

#include "cvo_odometry/core/cpu_backend.hpp"
#include "cvo_odometry/core/failover_backend.hpp"
#if defined(CVO_HAVE_CUDA) || defined(CVO_HAVE_DEVICE_CPU)
#include "cvo_odometry/core/device_backend.hpp"
#endif

namespace cvo {

bool cudaBackendAvailable(std::string* why_not) {
#ifdef CVO_HAVE_CUDA
  return cudaDeviceUsable(why_not);
#else
  if (why_not)
    *why_not = "this build has no CUDA backend (built without nvcc or CVO_WITH_CUDA=OFF)";
  return false;
#endif
}

std::unique_ptr<RegistrationBackend> makeBackend(BackendChoice choice, int num_threads,
                                                 std::string* why_cpu) {
  if (why_cpu) why_cpu->clear();
  if (choice == BackendChoice::kDeviceCpu) {
    // For tests: no fallback, so that a failure of the device code shows.
#ifdef CVO_HAVE_DEVICE_CPU
    return std::make_unique<DeviceCpuBackend>(num_threads);
#else
    throw std::runtime_error(
        "backend device_cpu: this build has none (it needs Thrust's headers and OpenMP)");
#endif
  }
  if (choice != BackendChoice::kCpu) {
    std::string why_not;
    if (cudaBackendAvailable(&why_not)) {
#ifdef CVO_HAVE_CUDA
      try {
        // A CUDA error later falls back to the CPU for that registration.
        return std::make_unique<FailoverBackend>(std::make_unique<CudaBackend>(),
                                                 std::make_unique<CpuBackend>(num_threads));
      } catch (const std::runtime_error& e) {
        why_not = e.what();
      }
#endif
    }
    if (choice == BackendChoice::kCuda) {
      throw std::runtime_error("CUDA backend requested but unavailable: " + why_not);
    }
    if (why_cpu) *why_cpu = "backend auto: the CPU, " + why_not;
  }
  return std::make_unique<CpuBackend>(num_threads);
}

}  // namespace cvo
