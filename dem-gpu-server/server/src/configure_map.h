#pragma once
// v1::Configure -> dem::DemConfig (the server's only translation between protocol and core).
#include "coredem/dem/dem_system.h"

#include <coredem/v1/configure.pb.h>

#include <string>
#include <vector>

namespace coredem::server {

/// Translates a (validated) Configure. Throws UserError naming the offending entry.
/// `warnings` receives the names of ignored options.
dem::DemConfig toDemConfig(const v1::Configure& c, std::vector<std::string>* warnings);

} // namespace coredem::server
