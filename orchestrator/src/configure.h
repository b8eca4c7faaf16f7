#pragma once
// Building the Configure message of a run from the case (internal to the orchestrator).

#include <filesystem>

#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/time_handler.h>
#include <coredem/protocol/protocol.h>

#include "dem_step.h"

namespace coredem::orchestrator {

/// Configure of the case (grid, species, gas properties, materials, particle sets, walls,
/// gravity, models, chemistry, output folder) with the given first Δt_CFD and plan.
v1::Configure buildConfigure(const CaseConfig& c, const std::filesystem::path& runDir, double dtCfd,
                             const SubcyclePlan& plan);

/// Why this case cannot be sent to a DEM server that agreed protocol `agreedMajor`.`agreedMinor`
/// (a Configure field it would ignore), or "" when it can: chemistry needs 1.1, cylinder, cone
/// and mesh walls need 1.4 (protocol::kMinorWallShapes), material pairs, wall materials and
/// Hertz–Mindlin 1.6 (protocol::kMinorContactMaterials). The text names both versions, what needs
/// the newer one and what to do.
std::string demVersionRefusal(const CaseConfig& c, std::uint32_t agreedMajor,
                              std::uint32_t agreedMinor);

/// Why `configure` is too large for a DEM server that accepts messages of at most `maxBytes`
/// (coredem-dem --max-message-mb; a larger frame closes the connection without a reply), or ""
/// when it fits. Names the size, the limit and the mesh walls' triangles that make it large.
std::string configureSizeRefusal(const v1::Configure& configure, std::int64_t maxBytes);

/// Why the DEM server's StepDone of `step` does not match the case's coupling scheme
/// (docs/coupling-schemes.md "How the scheme is negotiated"), or "" when it does: a staggered
/// server reports the diagnostic coupling_lag_steps = 1, a sequential one none.
std::string couplingSchemeMismatch(const CaseConfig& c, const v1::StepDone& demDone,
                                   std::int64_t step);

} // namespace coredem::orchestrator
