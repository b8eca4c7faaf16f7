// State files in the DEM core built alone (COREDEM_CORE_ONLY): there is no HDF5 there, so
// writing or reading a state file is refused with a message that says what to build instead.
#include "coredem/common/check.h"
#include "state_io.h"

namespace coredem::dem {

namespace {
[[noreturn]] void unavailable(const std::string& path, const char* verb) {
  throw UserError(coredem::format(
      "cannot {} the state file '{}': this DEM core was built alone (COREDEM_CORE_ONLY), "
      "without HDF5; build the whole project (make build) for state files and checkpoints",
      verb, path));
}
} // namespace

void writeStateFile(const std::string& path, const HostState&, const StateMeta&) {
  unavailable(path, "write");
}

void readStateFile(const std::string& path, HostState&, StateMeta&) {
  unavailable(path, "read");
}

} // namespace coredem::dem
