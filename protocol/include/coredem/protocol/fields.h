#pragma once
/// @file
/// Names, shapes and units of the per-cell coupling arrays: the one place where they are fixed.
///
/// Every array is float64, little-endian, one row per coupling cell in the cell order of
/// `v1::CartesianGrid` (flat index i + nx*(j + ny*k)). Shapes: EXTENT_SCALAR -> [N],
/// EXTENT_VECTOR3 -> [N,3], EXTENT_SPECIES -> [N, n_species] (columns in Configure.species order).
///
/// Usage (sender):
/// @code
///   Message m = makeGasFields(step, time, dt, cells, nSpecies);
///   m.addArray(fields::kGasVelocity, uGas /* span<const double>, 3*N values */,
///              fields::shapeOf(fields::kGasVelocity, cells, nSpecies));
/// @endcode

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <coredem/v1/common.pb.h>

namespace coredem::protocol::fields {

// GasFields (CFD -> DEM)
inline constexpr std::string_view kGasVelocity = "u_g";         ///< [N,3] m/s
inline constexpr std::string_view kPressureGradient = "grad_p"; ///< [N,3] Pa/m
inline constexpr std::string_view kGasTemperature = "T_g";      ///< [N] K
inline constexpr std::string_view kGasDensity = "rho_g";        ///< [N] kg/m3
inline constexpr std::string_view kGasViscosity = "mu_g";       ///< [N] Pa s
inline constexpr std::string_view kGasConductivity = "kappa_g"; ///< [N] W/m/K
inline constexpr std::string_view kGasHeatCapacity = "cp_g";    ///< [N] J/kg/K
inline constexpr std::string_view kGasMassFractions = "Y_g";    ///< [N,n_species] -
/// Optional: the fraction of each coupling cell's volume that is fluid, in [0, 1] (absent: 1
/// everywhere). Sent by a CFD participant whose mesh does not fill the coupling grid; the DEM
/// server then takes the PCM gas fraction of the fluid volume, 1 − V_s/(φ_f V_c), in its
/// closures (drag, heat, WGS) and refuses a particle in a cell without fluid. Its Sources stay
/// per coupling-cell volume V_c (the CFD side divides by φ_f).
inline constexpr std::string_view kFluidFraction = "fluid_fraction"; ///< [N] -
/// Optional (v1.5, fields::optionalGasFields()): the heat the gas removed from each coupling cell
/// in its last step beyond what the DEM booked, per coupling-cell volume (J/m3 of V_c, NOT of the
/// fluid volume), to be given to the cell's particles at the start of the DEM window that
/// receives it (either sign; absent = 0; a prescribed-gas participant never sends it). The DEM
/// server gives Q_split V_c to the particles of the cell in proportion to their gas conductance
/// h_i A_i (all zero: to m_i c_p,i) and books it in dem.heat_from_gas_J; in a cell without
/// particles it is booked as unassigned (dem.heat_split_unassigned_J). Sent only to a DEM server
/// of agreed minor >= kMinorHeatToParticles.
/// EXTENSIVE in a partial GasFields (v1.2, decomposed CFD): each rank sends its OWN contribution,
/// still in J per m3 of the coupling cell's volume V_c (not fluid-volume weighted like the
/// intensive fields above), and the server SUMS the ranks' values of a cell (it does not divide
/// by the fluid volume).
inline constexpr std::string_view kHeatToParticles = "Q_split"; ///< [N] J/m3

// Partial GasFields / Sources (v1.2, one rank of a decomposed CFD participant; body.partial):
// every array above has M = body.touched_count rows instead of N, one per listed coupling cell.
/// The coupling cells of the message, strictly ascending, each < N. dtype int64.
inline constexpr std::string_view kTouchedCells = "cells"; ///< [M] -
/// GasFields only: the rank's fluid volume in each listed coupling cell (> 0, at most the cell's
/// volume); the gas fields are then volume-weighted sums sum_c A(c, g) f_c over its cells.
inline constexpr std::string_view kFluidVolume = "fluid_volume"; ///< [M] m3

// Sources (DEM -> CFD), averaged over the n_sub DEM sub-steps of the CFD step
inline constexpr std::string_view kVoidFraction = "eps_g";             ///< [N] -
inline constexpr std::string_view kDragCoefficient = "K_sl";           ///< [N] kg/m3/s
inline constexpr std::string_view kDragCoefficientTimesUs = "K_sl_Us"; ///< [N,3] N/m3
inline constexpr std::string_view kHeatCoefficient = "H";              ///< [N] W/m3/K (implicit)
inline constexpr std::string_view kHeatCoefficientTimesTp = "H_Tp";    ///< [N] W/m3 (explicit)
inline constexpr std::string_view kSpeciesSources = "R_species";       ///< [N,n_species] kg/m3/s
inline constexpr std::string_view kHomogeneousHeat = "Q_hom";          ///< [N] W/m3
/// Optional (v1.3, fields::optionalSourceFields()): the net radiation heat the particles of each
/// coupling cell gave their environment, per coupling-cell volume, averaged over the sub-steps
/// like H and H_Tp (positive = heat to the gas). Σ_c Q_rad V_c Δt_CFD is the radiation heat the
/// particles lost in the step. Sent only to a CFD peer of agreed minor >= kMinorRadiation.
inline constexpr std::string_view kRadiationHeat = "Q_rad"; ///< [N] W/m3
/// Optional (v1.5, fields::optionalSourceFields()): the momentum of the mass the particles of each
/// coupling cell give the gas, Σ_i ṁ_i u_i / V_c (ṁ_i: the net gas mass particle i releases, kg/s,
/// negative when it takes gas; u_i its velocity), averaged over the sub-steps like R_species:
/// released mass leaves a particle at the particle's velocity. The gas adds mom_p − S_m U to its
/// momentum equation (S_m = Σ_k R_species; the mass then enters with the particles' momentum
/// instead of at the gas velocity). Sent only to a CFD peer of agreed minor >=
/// kMinorReleasedMomentum.
inline constexpr std::string_view kReleasedMomentum = "mom_p"; ///< [N,3] N/m3

/// One coupling field.
struct FieldSpec {
  std::string_view name;
  v1::Extent extent;
  std::string_view unit;
  std::string_view description;
};

/// The arrays a GasFields message must carry, in the canonical order.
std::span<const FieldSpec> gasFields();
/// The arrays a GasFields message may carry besides (fluid_fraction; v1.5: Q_split).
std::span<const FieldSpec> optionalGasFields();
/// The arrays a Sources message must carry, in the canonical order.
std::span<const FieldSpec> sourceFields();
/// The arrays a Sources message may carry besides (v1.3: Q_rad; v1.5: mom_p); validated like the
/// required ones (dtype float64, one row per cell or listed cell, finite) when present.
std::span<const FieldSpec> optionalSourceFields();
/// The spec of a GasFields or Sources field by name; nullptr if the name is not one of them.
const FieldSpec* findField(std::string_view name);

/// Shape of an array of the given extent: [cells], [cells,3] or [cells,species].
std::vector<std::uint64_t> shapeOf(v1::Extent extent, std::uint64_t cells, std::uint64_t species);
/// Shape of a named field; throws coredem::UserError for an unknown name.
std::vector<std::uint64_t> shapeOf(std::string_view name, std::uint64_t cells,
                                   std::uint64_t species);
/// Values per cell of an extent (1, 3 or species).
std::uint64_t componentsOf(v1::Extent extent, std::uint64_t species);

} // namespace coredem::protocol::fields
