// The cpu (OpenMP) instantiation of the shared engine: the reference backend.
#include "../../engine_impl.h"
#include "coredem/common/check.h"
#include "cpu_exec.h"

namespace coredem::dem {

namespace backend {
void raiseUserError(const std::string& message) {
  throw ::coredem::UserError(message);
}
} // namespace backend

std::unique_ptr<Engine> makeCpuEngine(const EngineSetup& setup) {
  return std::make_unique<EngineImpl<backend::CpuExec>>(setup);
}

} // namespace coredem::dem
