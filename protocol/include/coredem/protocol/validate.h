#pragma once
/// @file
/// Validation of received messages (docs/protocol.md). Call it on every message before using it;
/// on failure answer `makeError(status, seq, type)` and keep serving (state unchanged).
///
/// @code
///   Expectation e;
///   e.types = {v1::MESSAGE_TYPE_GAS_FIELDS};
///   e.sessionId = session;         // from Welcome
///   e.sequenceAfter = lastSeq;     // per-peer counter: sequence numbers only increase
///   e.step = grantedStep;
///   e.cells = grid cells; e.species = configure.species_size();
///   if (Status s = validate(req.message, e); !s.ok()) { server.reply(peer, makeError(s, ...)); }
/// @endcode

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <coredem/common/limits.h>
#include <coredem/protocol/message.h>
#include <coredem/protocol/status.h>
#include <coredem/v1/configure.pb.h>

namespace coredem::protocol {

/// What the receiver expects; unset members are not checked.
struct Expectation {
  /// Allowed types (UNEXPECTED_MESSAGE otherwise). Empty: any type known to this version.
  std::vector<v1::MessageType> types;
  std::optional<std::uint64_t> sequence;      ///< OUT_OF_ORDER if different
  std::optional<std::uint64_t> sequenceAfter; ///< OUT_OF_ORDER unless sequence > this
  std::optional<std::int64_t> step;           ///< OUT_OF_ORDER if different
  std::optional<std::string> sessionId;       ///< UNKNOWN_SESSION if different
  /// Counts for the shapes of GasFields/Sources arrays (and body.cell_count/species_count).
  /// If unset for a GasFields/Sources message: NOT_CONFIGURED.
  std::optional<std::uint64_t> cells;
  std::optional<std::uint64_t> species;
  /// Reject NaN/Inf in floating-point arrays (NON_FINITE naming the field and first index).
  bool requireFinite = true;
};

/// Checks, in this order: structure (frame count, byte lengths, dtype known), known type
/// (UNKNOWN_TYPE), body matches type (BODY_MISMATCH), allowed type, session, sequence, step,
/// required arrays of GasFields/Sources present (MISSING_FIELD), no duplicates
/// (DUPLICATE_FIELD), dtype float64 (DTYPE), shapes vs counts (SHAPE), finite (NON_FINITE).
/// Arrays not in fields.h are allowed (forward compatibility) but checked for
/// structure and finiteness.
Status validate(const Message& message, const Expectation& expectation);

/// Checks a Configure body for consistency (INVALID_CONFIGURATION): Cartesian mesh with
/// positive counts/spacing and at most kMaxCells cells (an overflowing product is refused), unique
/// species with molar mass > 0, sub-cycling dt_dem*n_sub == dt_cfd (rel. 1e-12), particle sets
/// referencing existing materials with positive diameter, count, region min < max and mass
/// fractions summing to 1 (abs. 1e-9), material parameters in range (k_n > 0, 0 < e_n <= 1,
/// friction >= 0, density > 0).
Status validateConfigure(const v1::Configure& configure);

/// The ranges of the received gas fields: the project's one table (coredem/common/limits.h).
using GasRanges = coredem::GasRanges;

/// Checks a (validated) GasFields message's values against `ranges`: the first value outside
/// is refused (INVALID_CONFIGURATION) naming the array, the cell, the value and the range.
Status validateGasRanges(const Message& gasFields, const GasRanges& ranges = {});

/// Most coupling cells of any Configure (cells are indexed by int in the DEM core); a server
/// may set a lower limit from its memory budget.
inline constexpr std::uint64_t kMaxCells = 2147483647;

/// Number of cells of the coupling mesh (0 if unset; UINT64_MAX if x*y*z overflows 64 bits).
std::uint64_t cellCount(const v1::CouplingMesh& mesh);

} // namespace coredem::protocol
