// The device code of device_pair_sums.cu compiled by the host compiler for Thrust's OpenMP system
// (THRUST_DEVICE_SYSTEM=THRUST_DEVICE_SYSTEM_OMP, set by src/core/CMakeLists.txt): the
// device_cpu backend, the same source as the CUDA backend's, run on CPU threads.
#include "device_pair_sums.cu"
