// The CUDA runtime's answers turned into a CudaProbe (backend/cuda_probe.h): a runtime failure
// is an error with CUDA's own message and what to do, never "no device".
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "backend/cuda_probe.h"
#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"

using namespace coredem::dem;
using namespace coredem::dem::backend;

namespace {
CudaRuntimeAnswer answer(int error, std::string name, std::string text, int driver) {
  CudaRuntimeAnswer a;
  a.error = error;
  a.errorName = std::move(name);
  a.errorString = std::move(text);
  a.driverVersion = driver;
  a.runtimeVersion = 13000;
  return a;
}
} // namespace

TEST(CudaProbe, DevicesFound) {
  CudaRuntimeAnswer a = answer(kCudaSuccess, "cudaSuccess", "no error", 13000);
  a.deviceCount = 2;
  const CudaProbe p = interpretCudaRuntime(a);
  EXPECT_TRUE(p.built);
  EXPECT_EQ(p.devices, 2);
  EXPECT_TRUE(p.error.empty());
}

TEST(CudaProbe, DriverTooOldIsAnErrorWithTheVersionsAndWhatToDo) {
  const CudaProbe p = interpretCudaRuntime(
      answer(kCudaErrorInsufficientDriver, "cudaErrorInsufficientDriver",
             "CUDA driver version is insufficient for CUDA runtime version", 12020));
  EXPECT_EQ(p.devices, 0);
  ASSERT_FALSE(p.error.empty());
  EXPECT_NE(p.error.find("cudaErrorInsufficientDriver: CUDA driver version is insufficient"),
            std::string::npos)
      << p.error;
  EXPECT_NE(p.error.find("runtime 13.0"), std::string::npos) << p.error;
  EXPECT_NE(p.error.find("supports CUDA up to 12.2"), std::string::npos) << p.error;
  EXPECT_NE(p.error.find("install a driver that supports CUDA 13.0"), std::string::npos) << p.error;
}

TEST(CudaProbe, OtherRuntimeFailuresAreErrorsNamingCudaVisibleDevices) {
  CudaRuntimeAnswer a = answer(46, "cudaErrorDevicesUnavailable",
                               "CUDA-capable device(s) is/are busy or unavailable", 13000);
  a.visibleDevices = "0";
  const CudaProbe p = interpretCudaRuntime(a);
  EXPECT_EQ(p.devices, 0);
  EXPECT_NE(p.error.find("busy or unavailable"), std::string::npos) << p.error;
  EXPECT_NE(p.error.find("CUDA_VISIBLE_DEVICES=\"0\""), std::string::npos) << p.error;
  EXPECT_NE(p.error.find("nvidia-smi"), std::string::npos) << p.error;
}

TEST(CudaProbe, NoDriverOrNoDeviceIsNoGpuNotAnError) {
  const CudaProbe noDriver = interpretCudaRuntime(answer(
      kCudaErrorInsufficientDriver, "cudaErrorInsufficientDriver", "insufficient driver", 0));
  EXPECT_TRUE(noDriver.error.empty());
  EXPECT_NE(noDriver.note.find("no NVIDIA driver"), std::string::npos);
  CudaRuntimeAnswer a =
      answer(kCudaErrorNoDevice, "cudaErrorNoDevice", "no CUDA-capable device is detected", 13000);
  a.visibleDevices = "";
  const CudaProbe noDevice = interpretCudaRuntime(a);
  EXPECT_TRUE(noDevice.error.empty());
  EXPECT_EQ(noDevice.devices, 0);
  EXPECT_NE(noDevice.note.find("may hide the GPUs"), std::string::npos) << noDevice.note;
}

TEST(CudaProbe, ThisBuildAnswersAndBackendCudaFailsLoudlyWithoutADevice) {
  const CudaProbe p = probeCuda();
  EXPECT_EQ(p.built, cudaBackendBuilt());
  EXPECT_EQ(p.devices, cudaDeviceCount());
  if (p.devices > 0) {
    // A device: the probe says nothing is wrong (the cuda conformance suite runs on it).
    EXPECT_TRUE(p.error.empty()) << p.error;
    return;
  }
  EXPECT_FALSE(p.error.empty() && p.note.empty()); // a reason either way
  DemConfig c;
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {0, 0, 0};
  c.particleSets.push_back(s);
  try {
    DemSystem sys(c, BackendKind::Cuda, 1);
    FAIL() << "backend cuda ran without a device";
  } catch (const coredem::UserError& e) {
    const std::string what = e.what();
    const std::string& reason = p.error.empty() ? p.note : p.error;
    if (p.built) {
      EXPECT_NE(what.find(reason), std::string::npos) << what;
    } else {
      EXPECT_NE(what.find("no CUDA backend"), std::string::npos) << what;
    }
  }
  DemSystem fallback(c, BackendKind::Auto, 1); // auto: the cpu, with the reason logged
  EXPECT_EQ(fallback.backendName(), "cpu");
}
