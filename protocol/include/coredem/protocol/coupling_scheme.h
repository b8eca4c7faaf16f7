#pragma once
/// @file
/// The coupling scheme of a session (docs/coupling-schemes.md), carried in existing fields: the
/// Configure option kCouplingSchemeOption, absent or "sequential" (the CFD applies the sources
/// of the same step) or "staggered" (the DEM answers the GasFields of step n at once with the
/// sources it computed in step n-1, then computes step n); and the StepDone diagnostic
/// kCouplingLagDiagnostic = 1 that a server running the staggered scheme reports in every
/// StepDone, so that an orchestrator never takes a server that ignored the option (an older
/// coredem-dem logs unknown options and runs sequential) for a staggered one.
#include <string_view>

namespace coredem::protocol::fields {

inline constexpr std::string_view kCouplingSchemeOption = "coupling_scheme";
inline constexpr std::string_view kCouplingLagDiagnostic = "coupling_lag_steps";

} // namespace coredem::protocol::fields
