#pragma once
/// @file
/// Protocol version and the negotiation rule (docs/protocol.md):
/// same major -> accept and use min(minor); different major -> reject naming both versions.

#include <cstdint>
#include <string>

#include <coredem/protocol/status.h>

namespace coredem::protocol {

struct Version {
  std::uint32_t major = 0;
  std::uint32_t minor = 0;
  friend bool operator==(const Version&, const Version&) = default;
  /// "1.0"
  [[nodiscard]] std::string toString() const;
};

/// The version this build speaks.
inline constexpr Version kProtocolVersion{1, 6};

/// First minor version with the fluid_fraction array and the decomposed (M:1) exchange: rank
/// identity in Hello, partial GasFields/Sources (docs/protocol.md "Decomposed CFD").
inline constexpr std::uint32_t kMinorDecomposed = 2;

/// First minor version with the Sources array Q_rad (the radiation heat the particles gave the
/// gas): the DEM server sends it only to a CFD peer whose agreed minor is at least this; below,
/// the radiation heat stays with the particles' environment (docs/heat-coupling.md).
inline constexpr std::uint32_t kMinorRadiation = 3;

/// First minor version with cylinder, cone and triangle-mesh walls (Configure.walls.revolved and
/// .meshes). An older server ignores them, so the orchestrator refuses to send a case with such
/// walls to a DEM server whose agreed minor is below this.
inline constexpr std::uint32_t kMinorWallShapes = 4;

/// First minor version with the Sources array mom_p (the momentum of the mass the particles give
/// the gas, fields::kReleasedMomentum): the DEM server sends it only to a CFD peer whose agreed
/// minor is at least this; below, the released mass enters the gas at the gas velocity as before.
inline constexpr std::uint32_t kMinorReleasedMomentum = 5;

/// First minor version with the GasFields array Q_split (heat the gas removed from a cell beyond
/// what the DEM booked, to be given to the cell's particles, fields::kHeatToParticles). An older
/// DEM server would ignore it (the heat would be lost), so the coupling client refuses to send it
/// to a DEM server whose agreed minor is below this.
inline constexpr std::uint32_t kMinorHeatToParticles = 5;

/// First minor version with the contact materials: Material.youngs_modulus and .poisson_ratio
/// (the Hertz–Mindlin law), Configure.material_pairs and the walls' material_id (Box, Plane,
/// RevolvedWall, MeshWall). An older DEM server ignores them, so the orchestrator refuses to send
/// a case with material pairs, wall materials or the hertz-mindlin law to a DEM server whose
/// agreed minor is below this.
inline constexpr std::uint32_t kMinorContactMaterials = 6;

/// Outcome of a handshake.
struct Negotiation {
  bool accepted = false;
  Version agreed; ///< valid when accepted: {major, min(minor_ours, minor_theirs)}
  Status status;  ///< ERROR_CODE_VERSION with a message naming both versions if refused
};

/// Applies the rule. `ours` is the server's version, `theirs` the client's Hello.
/// @post accepted == (ours.major == theirs.major)
Negotiation negotiate(Version ours, Version theirs);

} // namespace coredem::protocol
