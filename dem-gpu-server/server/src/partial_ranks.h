#pragma once
// Partial-rank combining (docs/protocol.md "Decomposed CFD"): the K partial GasFields of a
// decomposed CFD participant, each holding volume-weighted sums over the coupling cells its
// rank touches, become the whole-grid gas of the step.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "coredem/protocol/protocol.h"
#include "replies.h"
#include "reply_text.h"

namespace coredem::server {

/// Why the partial GasFields of a step cannot be combined.
struct CombineFailure {
  enum class Kind {
    /// The ranks' fluid volumes touch no cell or overlap: the step fails (logged, `stepText` to
    /// the grant), then each rank gets `rankText`.
    Volumes,
    /// The combined gas is out of its physical ranges: each rank, then the grant, gets
    /// `stepText`.
    Ranges,
  };
  Kind kind = Kind::Volumes;
  v1::ErrorCode code = v1::ERROR_CODE_NONE;
  std::string stepText;
  std::string rankText;
};

/// The result of combining: the gas of the step, or why not.
struct Combined {
  std::optional<protocol::Message> gas;
  CombineFailure failure; ///< when !gas
};

/// Combines the partial GasFields `to` (in rank order, independent of their arrival order) of a
/// grid of `grid.cells` cells of volume `cellVolume`: V_g = sum_r V_r,g, f_g = sum_r S_r,g / V_g,
/// fluid fraction V_g / V_c (exactly 1 within 1e-12 of V_c, 0 for cells no rank touches, whose gas
/// is the volume-weighted average of all cells; sent only when some cell is not all fluid). The
/// extensive Q_split (v1.5) of a cell is the sum of the ranks' values (sent when any rank sent it).
/// `rankCount` names the ranks in a failure's text.
Combined combinePartialGasFields(const std::vector<StepReply>& to, const GridShape& grid,
                                 double cellVolume, std::uint32_t rankCount);

} // namespace coredem::server
