#pragma once
/// @file
/// What the CUDA runtime answered on this machine, turned into a CudaProbe (dem_system.h): a
/// runtime failure is reported with CUDA's own message and what to do, never as "no device".
/// Plain C++ (no CUDA headers) so that the interpretation is tested without a GPU; the cuda
/// backend (backend/cuda/cuda_engine.cu) fills CudaRuntimeAnswer.

#include <optional>
#include <string>

#include "coredem/dem/dem_system.h"

namespace coredem::dem::backend {

/// cudaError_t values the interpretation distinguishes (static_assert'ed in cuda_engine.cu).
inline constexpr int kCudaSuccess = 0;
inline constexpr int kCudaErrorInsufficientDriver = 35;
inline constexpr int kCudaErrorNoDevice = 100;

/// The raw answers of cudaGetDeviceCount, cudaDriverGetVersion and cudaRuntimeGetVersion.
struct CudaRuntimeAnswer {
  int error = kCudaSuccess;                  ///< cudaGetDeviceCount's cudaError_t
  std::string errorName;                     ///< cudaGetErrorName
  std::string errorString;                   ///< cudaGetErrorString
  int deviceCount = 0;                       ///< when error == kCudaSuccess
  int driverVersion = 0;                     ///< 1000·major + 10·minor; 0: no driver installed
  int runtimeVersion = 0;                    ///< of the runtime this build links
  std::optional<std::string> visibleDevices; ///< CUDA_VISIBLE_DEVICES, when set
};

/// A runtime failure → error (CUDA's message, versions, what to do); no device, no driver or no
/// visible device → note; otherwise devices.
CudaProbe interpretCudaRuntime(const CudaRuntimeAnswer& a);

} // namespace coredem::dem::backend
