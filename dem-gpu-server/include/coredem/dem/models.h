#pragma once
/// @file
/// Model registries of the DEM server: one table per model family, and the table of the keys of
/// case.yaml `models:` (= `Configure.options`) that select and parametrise them.
///
/// A family registry lists {name, id, one-line doc}; the kernels dispatch on the id (e.g.
/// kernels/drag.h on kernels::DragLaw). The registries of the drag laws, Nusselt correlations,
/// rate laws and WGS equilibrium constants are generated from their type lists
/// (kernels/model_list.h; src/model_registry.h). A `models:` key row holds the key, the family it
/// belongs to, the allowed values and the default as users read them, a one-line doc and the
/// parser that checks a value and stores it in a DemConfig. The DEM server applies `models:`
/// with applyModelOption(); `coredem check` / `coredem run` validate the whole mapping with
/// validateModels() before anything starts: the same rows, the same parsers, the same messages.
///
/// This library (target coredem::dem_models) needs neither CUDA nor the protocol nor the engine:
/// only the plain-data headers dem_system.h and the kernels' enums.
///
/// Adding a drag law (a Nusselt correlation): its kernel header (the model's declaration), its
/// name in the type list kernels::DragLaws (kernels/drag.h; kernels::NusseltModels,
/// kernels/convection.h), its test and its docs/case-schema.md rows: the family registry, its
/// `models:` value, the rows of its parameters ("drag.<law>.<parameter>",
/// "convection.<model>.<parameter>"), their validation and hashing are generated from the list
/// here (docs/architecture.md).

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/convection.h"
#include "coredem/dem/kernels/drag.h"
#include "coredem/dem/kernels/reaction_generic.h"
#include "coredem/dem/kernels/wgs.h"

namespace coredem::dem {

struct DemConfig;
struct Material;

/// `models: {motion: ...}`.
enum class MotionModel : int {
  Free = 0,  ///< forces move the particles (default)
  Frozen = 1 ///< held in place, velocities zeroed every sub-step (DemConfig::frozenMotion)
};

/// `models: {convection_reynolds: ...}`: the Reynolds number of the Nusselt correlation.
enum class ReynoldsDefinition : int {
  WithVoidage = 0,   ///< Re = ε ρ_g d |Δu|/μ_g, as the drag (default)
  WithoutVoidage = 1 ///< Re = ρ_g d |Δu|/μ_g (Kratos form)
};

/// One model of a family.
template <class E>
struct ModelEntry {
  std::string_view name; ///< as written in case.yaml; '_' and '-' are interchangeable on input
  E value;               ///< what the kernels dispatch on
  std::string_view doc;  ///< one line
};

/// The registry of one model family: its models in enum order.
template <class E>
struct ModelFamily {
  std::string_view name;                  ///< family name, e.g. "drag"
  std::span<const ModelEntry<E>> entries; ///< every model of the family

  /// The entry called `model` ('_' and '-' alike), or nullptr.
  const ModelEntry<E>* find(std::string_view model) const;
  /// The name of `value` ("?" if it has no entry).
  std::string_view nameOf(E value) const;
  /// The names, for messages: "a, b or c".
  std::string allowed() const;
};

/// Drag laws (kernels/drag.h).
const ModelFamily<kernels::DragLaw>& dragModels();
/// Nusselt correlations of the particle–gas convection (kernels::NusseltModels, convection.h).
const ModelFamily<kernels::NusseltModel>& nusseltModels();
/// Reynolds number definitions of the Nusselt correlations.
const ModelFamily<ReynoldsDefinition>& reynoldsModels();
/// Particle motion.
const ModelFamily<MotionModel>& motionModels();
/// Heterogeneous kinetics: rate laws of data-defined reactions (kernels::RateLaws,
/// kernels/reaction_generic.h).
const ModelFamily<kernels::RateLaw>& rateLawModels();
/// Water–gas-shift equilibrium constants (kernels::WgsEquilibria, kernels/wgs.h; case.yaml
/// chemistry.clg.wgs_equilibrium).
const ModelFamily<kernels::WgsEquilibrium>& wgsEquilibriumModels();

/// One key of `models:`.
struct ModelOption {
  std::string key;          ///< e.g. "convection"
  std::string family;       ///< drag, heat, convection, conduction, radiation, motion, numerics
  std::string values;       ///< allowed values as users read them, from the family registry
  std::string defaultValue; ///< as written in case.yaml
  std::string doc;          ///< one line
  /// Checks `value` and stores it in `config`. Returns "" when it is allowed, else what is wrong
  /// with it and the allowed values (and a "did you mean" when a close value exists).
  std::string (*apply)(DemConfig& config, std::string_view value) = nullptr;
  /// Set on an old spelling still accepted: the key to write instead (a warning says so once).
  std::string_view deprecatedFor = {};
};

/// Every `models:` key, in documentation order.
std::span<const ModelOption> modelOptions();
/// The row of `key`, or nullptr.
const ModelOption* findModelOption(std::string_view key);

/// Applies one `models:` entry to `config`. Returns false when `key` is not a model key (the
/// server warns and ignores it); throws coredem::UserError naming the key, the value and the
/// allowed values when the value is not allowed. An old spelling (ModelOption::deprecatedFor)
/// is applied as its new one, with a warning (once per key and process).
bool applyModelOption(DemConfig& config, std::string_view key, std::string_view value);

/// A bad entry of a `models:` mapping.
struct ModelIssue {
  std::size_t index = 0;   ///< position in the mapping given to validateModels
  std::string key;         ///< the key as written
  bool unknownKey = false; ///< true: the key is wrong; false: the value is
  std::string message;     ///< what is wrong and what is allowed (without the key itself)
};

/// Validates a whole `models:` mapping (key, value pairs in file order) with the registry the
/// DEM server uses. Returns one issue per bad entry (none: the mapping is valid): an unknown key
/// lists the allowed keys, a bad value the allowed values, each with a "did you mean" when a
/// close one exists. Old spellings are valid; they are warned about (as applyModelOption).
std::vector<ModelIssue> validateModels(std::span<const std::pair<std::string, std::string>> models);

/// Contact laws of particles and walls (kernels/contact_law.h).
const ModelFamily<kernels::ContactLaw>& contactModels();

/// The DEM step Δt_DEM,max = min(t_0 / `dem.dt_factor`, Δt_s) (docs/physics.md §2.1): t_0 the
/// smallest undamped contact duration and Δt_s the smallest stability limit of the integrator
/// (the contact law's collisionTime and stableStep) over the present material pairs (and each
/// material against the walls, if any; the chosen contact law's mixing rules), with
/// `minMass[a]` the lightest particle of material a (+inf: none present; both grow with m_eff)
/// and `minRadius[a]` its radius (the Hertz time scales grow with m*²/R*; empty: not needed by
/// the law, e.g. linear spring–dashpot; a law that needs it then uses 1 m).
/// The largest finite double with `motion: frozen` (no collision limit); +inf without particles.
/// The one place this is computed: the DEM server reports it in Configured, the orchestrator's
/// provisional plan of the first Configure uses it too.
double dtDemMax(const DemConfig& config, std::span<const double> minMass,
                std::span<const double> minRadius = {});

/// Materials a and b as the contact law's mix() sees them: with a `materialPairs` entry of the
/// pair, its e_n and μ replace both materials' (the laws take the smaller of the two).
std::pair<Material, Material> pairMaterials(const DemConfig& config, std::size_t a, std::size_t b);

/// The material indices the walls (analytic and mesh) meet particles of material a with: each
/// wall's own, or a for a wall without one, each once, ascending.
std::vector<int> wallMaterialsOf(const DemConfig& config, int a);

/// The mass of a particle of density `rho` (kg/m³) and diameter `d` (m), as the DEM computes it
/// (ρ · 4/3 π (d/2)³): for the `minMass` of dtDemMax.
double particleMass(double rho, double d);

/// The configuration-hash text of the registered models' parameters: "|<key>:<value>;" for each
/// parameter of the chosen models that differs from its declared default ("" when none does, so
/// that the hashes of earlier configurations stay).
std::string modelParamsHashText(const DemConfig& config);

/// Throws coredem::UserError naming the key when a chosen model's parameter is outside its
/// declared range (a DemConfig filled in code rather than through applyModelOption).
void checkModelParams(const DemConfig& config);

/// The closest of `candidates` to `word` when it is a plausible typo of it (edit distance at most
/// max(1, |word|/3), '_' and '-' alike), else "".
std::string didYouMean(std::string_view word, std::span<const std::string_view> candidates);

} // namespace coredem::dem
