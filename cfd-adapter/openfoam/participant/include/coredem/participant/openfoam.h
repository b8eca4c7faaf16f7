#pragma once
/// @file
/// The OpenFOAM solver coredemFoam as the orchestrator knows it: its row of the participant
/// table (participants.h) and the hooks the row points to, all plain C++ on the OpenFOAM case's
/// text files (no OpenFOAM library): the pre-flight of the case against case.yaml, the
/// dictionaries coredem writes into the run's copy of it, its decomposition for a run on K
/// ranks, the walls from its mesh's patches (foam_patches.h) and its initial gas composition
/// (foam_field.h).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <coredem/orchestrator/participant_descriptor.h>

namespace coredem::orchestrator {

/// The row of coredemFoam (docs/coredemFoam.md).
ParticipantDescriptor openFoamParticipant();

// ------------------------------------------------------------------------ pre-flight

/// Relative tolerance of the equality of case.yaml and OpenFOAM values (gravity, gas
/// properties): the OpenFOAM files are usually written with 4–5 significant digits.
inline constexpr double kFoamEqualityRelTol = 1e-3;

/// Mass fractions must sum to 1 within this.
inline constexpr double kMassFractionSumTol = 1e-9;

/// PIMPLE outer correctors a reacting ideal-gas case needs (docs/coredemFoam.md: with fewer,
/// species mass is conserved only to O(Δt) of the density change).
inline constexpr int kMinOuterCorrectorsReacting = 3;

/// Pre-flight of the OpenFOAM participant (the row's `preflight`), each failure a CaseError
/// naming both values and both places (docs/orchestrator.md "One source of truth"):
/// - gravity of case.yaml equals `cfd.case`/constant/g;
/// - model constant: gas_properties (density, viscosity = nu·rho, cp, conductivity) equal
///   constant/transportProperties (rho, nu, cp, kappa) within kFoamEqualityRelTol, and there is
///   no constant/thermophysicalProperties (it would make the gas model ambiguous);
/// - model ideal_gas: no constant/thermophysicalProperties unless it is exactly the one coredem
///   writes (thermophysicalPropertiesText), and 0/T's uniform internalField equals
///   gas_properties.temperature;
/// - the case's species are the mass-fraction fields of 0/ (each species has 0/<name>; no other
///   dimensionless volScalarField but alpha* and Ydefault);
/// - the gas state of 0/ (uniform internalField and fixedValue patch values): T > 0, every mass
///   fraction in [0, 1], and where all species are uniform they sum to 1 within
///   kMassFractionSumTol (non-uniform values are skipped with an info line);
/// - the coupling grid covers the mesh, the mesh covers walls.box, and cfd.ranks fits the mesh
///   and system/decomposeParDict;
/// - model ideal_gas with reactions: system/fvSolution's nOuterCorrectors is at least
///   kMinOuterCorrectorsReacting.
void checkOpenFoamCase(const CaseConfig& config);

namespace preflight {
class Locator;
}
/// Part of checkOpenFoamCase: every finite DEM cylinder and cone with side inside lies within the
/// boundary of the mesh in `dir`/constant/polyMesh (its wall and patch patches), sampled by rays
/// from the axis; fails naming the wall, its radius and the boundary's distance (a faceted CFD
/// wall's inscribed radius). Skipped without a readable mesh (made at the run).
void checkRevolvedWallsInsideFoamMesh(const CaseConfig& config, const preflight::Locator& at,
                                      const std::filesystem::path& dir);

// ------------------------------------------------------------------ generated files

/// The text of constant/thermophysicalProperties for a case with gas_properties.model ideal_gas
/// (docs/case-schema.md "The generated dictionary"). Numbers are written in the shortest form
/// that reads back to the same double. Throws CaseError naming a species without data.
std::string thermophysicalPropertiesText(const CaseConfig& config);

/// File name of the generated dictionary inside an OpenFOAM case.
inline const std::filesystem::path kThermophysicalProperties =
    std::filesystem::path("constant") / "thermophysicalProperties";

/// The field 0/air of an ideal-gas case without species: mass fraction 1 everywhere (every patch
/// `calculated`, constraint patches from OpenFOAM's caseDicts/setConstraintTypes).
std::string airFieldText(const CaseConfig& config);

/// case.yaml's inlets and outlets against the case in `dir` (part of checkOpenFoamCase): each
/// patch is a patch of type `patch` of the mesh (constant/polyMesh/boundary, or before meshing
/// system/blockMeshDict's boundary list; skipped when neither can be read simply), the case does
/// not fix the other variable there (p at an inlet, U at an outlet), an inlet's temperature has
/// a 0/T and its mass fractions a 0/<species>. Throws CaseError naming the key and the file.
void checkFoamBoundaries(const CaseConfig& config, const preflight::Locator& at,
                         const std::filesystem::path& dir);

/// `text` (an OpenFOAM field file, `file` its name for messages) with the boundaryField entry of
/// `patch` replaced by `lines` (the entry's body, one keyword per line), or inserted first when
/// the file has no entry of that exact name (patterns such as "(inlet|outlet)" match after exact
/// names). Throws UserError when the text has no boundaryField.
std::string replaceFoamPatchEntry(const std::string& text, const std::string& patch,
                                  const std::string& lines, const std::string& file);

/// Writes case.yaml's inlets and outlets into workDir/0 (docs/case-schema.md "Inlets and
/// outlets"): an inlet's U as interstitialInletVelocity (the superficial velocity over the gas
/// fraction alphac at the face) or, with a table, uniformFixedValue; its T and mass fractions as
/// fixedValue; an outlet's p fixedValue 0 and U pressureInletOutletVelocity.
void writeFoamBoundaries(const CaseConfig& config, const std::filesystem::path& workDir);

/// Writes `text` into `file` through a temporary file renamed over it (UserError when it cannot).
void writeFoamFile(const std::filesystem::path& file, const std::string& text);

/// The row's `generate`: writeFoamBoundaries; then, for ideal_gas only: writes
/// thermophysicalPropertiesText(config) into workDir/constant/thermophysicalProperties, 0/p of a
/// zero gauge kinematic pressure with the dimensions of a pressure and, for a case without
/// species whose copy has neither 0/air nor 0/Ydefault, airFieldText(config) into workDir/0/air
/// (OpenFOAM's mixture reads a field per species).
void writeGeneratedFoamDictionaries(const CaseConfig& config, const std::filesystem::path& workDir);

// ------------------------------------------------------------- the row's other hooks

/// The row's `decompose`: coredemFoam on `ranks` processes: the mesh (blockMesh when the case
/// has none), system/decomposeParDict (written when the case has none: method simple, `ranks`
/// slabs along x; Debian's OpenFOAM builds scotch as a dummy library) and decomposePar, unless
/// processor0 .. processor<ranks-1> exist already (a resumed run keeps its decomposition).
void decomposeOpenFoamCase(const std::filesystem::path& workDir, int ranks,
                           const std::filesystem::path& logDir);

/// The row's `meshPatches`: readFoamPatches (foam_patches.h) of the case folder.
CfdPatchSurface openFoamMeshPatches(const std::filesystem::path& caseFolder,
                                    const std::vector<std::string>& patches);

/// The row's `initialMassFractions`: the uniform internalField of 0/<species> of `cfd.case`
/// (readFoamField) for every species, when each is a number >= 0 and they sum to 1 within
/// kMassFractionSumTol; else nullopt.
std::optional<std::vector<double>> openFoamInitialMassFractions(
    const CaseConfig& config, const std::vector<std::string>& species);

} // namespace coredem::orchestrator
