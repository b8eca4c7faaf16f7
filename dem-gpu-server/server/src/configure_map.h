#pragma once
// v1::Configure -> dem::DemConfig (the server's only translation between protocol and core).
#include <string>
#include <vector>

#include <coredem/v1/configure.pb.h>

#include "coredem/dem/dem_system.h"

namespace coredem::server {

/// Translates a (validated) Configure. Throws UserError naming the offending entry.
/// `warnings` receives the names of ignored options.
dem::DemConfig toDemConfig(const v1::Configure& c, std::vector<std::string>* warnings);

} // namespace coredem::server
