#pragma once

#include <memory>
#include <string>

#include "cvo_odometry/core/registration_backend.hpp"

namespace cvo {

// True when this build has the CUDA backend and a usable device is present.
bool cudaBackendAvailable(std::string* why_not = nullptr);

// auto: CUDA when available, else the CPU; cuda: throws std::runtime_error when unavailable;
// device_cpu: the device code on OpenMP threads, without a fallback (throws when not built).
// `why_cpu`, when given, receives why auto chose the CPU (empty otherwise), for the log.
std::unique_ptr<RegistrationBackend> makeBackend(BackendChoice choice, int num_threads = 0,
                                                 std::string* why_cpu = nullptr);

}  // namespace cvo
