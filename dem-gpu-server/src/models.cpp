// Model registries and the `models:` key table (coredem/dem/models.h).
#include "coredem/dem/models.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <utility>

#include "coredem/common/check.h"
#include "coredem/common/log.h"
#include "coredem/common/switch.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/pressure_gradient.h"
#include "model_registry.h"

namespace coredem::dem {

// ------------------------------------------------------------------ family registries
namespace {

using registry::entriesOf;
using registry::number;

constexpr auto kDrag = entriesOf<kernels::DragLaw>(kernels::DragLaws{});
constexpr auto kNusselt = entriesOf<kernels::NusseltModel>(kernels::NusseltModels{});
constexpr ModelEntry<ReynoldsDefinition> kReynolds[] = {
    {"with-voidage", ReynoldsDefinition::WithVoidage, "Re = ε ρ_g d |Δu|/μ_g, as the drag"},
    {"without-voidage", ReynoldsDefinition::WithoutVoidage, "Re = ρ_g d |Δu|/μ_g"},
};
constexpr ModelEntry<MotionModel> kMotion[] = {
    {"free", MotionModel::Free, "forces, torques and gravity move the particles"},
    {"frozen", MotionModel::Frozen,
     "particles held in place, velocities zeroed (MFiX verification cases)"},
};
constexpr auto kRateLaw = entriesOf<kernels::RateLaw>(kernels::RateLaws{});
constexpr auto kWgs = entriesOf<kernels::WgsEquilibrium>(kernels::WgsEquilibria{});

/// '_' as '-' (model names accept either).
std::string normalise(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c == '_')
      c = '-';
  return out;
}

std::string joinOr(std::span<const std::string_view> names) {
  std::string s;
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (k > 0)
      s += k + 1 == names.size() ? " or " : ", ";
    s += names[k];
  }
  return s;
}

std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

} // namespace

template <class E>
const ModelEntry<E>* ModelFamily<E>::find(std::string_view model) const {
  const std::string want = normalise(model);
  for (const ModelEntry<E>& e : entries)
    if (normalise(e.name) == want)
      return &e;
  return nullptr;
}

template <class E>
std::string_view ModelFamily<E>::nameOf(E value) const {
  for (const ModelEntry<E>& e : entries)
    if (e.value == value)
      return e.name;
  return "?";
}

template <class E>
std::string ModelFamily<E>::allowed() const {
  std::vector<std::string_view> names;
  for (const ModelEntry<E>& e : entries)
    names.push_back(e.name);
  return joinOr(names);
}

template struct ModelFamily<kernels::DragLaw>;
template struct ModelFamily<kernels::NusseltModel>;
template struct ModelFamily<ReynoldsDefinition>;
template struct ModelFamily<MotionModel>;
template struct ModelFamily<kernels::RateLaw>;
template struct ModelFamily<kernels::WgsEquilibrium>;

const ModelFamily<kernels::DragLaw>& dragModels() {
  static const ModelFamily<kernels::DragLaw> f{"drag", kDrag};
  return f;
}
const ModelFamily<kernels::NusseltModel>& nusseltModels() {
  static const ModelFamily<kernels::NusseltModel> f{"convection", kNusselt};
  return f;
}
const ModelFamily<ReynoldsDefinition>& reynoldsModels() {
  static const ModelFamily<ReynoldsDefinition> f{"convection_reynolds", kReynolds};
  return f;
}
const ModelFamily<MotionModel>& motionModels() {
  static const ModelFamily<MotionModel> f{"motion", kMotion};
  return f;
}
const ModelFamily<kernels::RateLaw>& rateLawModels() {
  static const ModelFamily<kernels::RateLaw> f{"rate law", kRateLaw};
  return f;
}
const ModelFamily<kernels::WgsEquilibrium>& wgsEquilibriumModels() {
  static const ModelFamily<kernels::WgsEquilibrium> f{"wgs_equilibrium", kWgs};
  return f;
}

// --- contact laws (kernels/contact_law.h)
namespace {
constexpr auto kContact = entriesOf<kernels::ContactLaw>(kernels::ContactLaws{});
} // namespace

template struct ModelFamily<kernels::ContactLaw>;

const ModelFamily<kernels::ContactLaw>& contactModels() {
  static const ModelFamily<kernels::ContactLaw> f{"contact", kContact};
  return f;
}

double particleMass(double rho, double d) {
  return rho * kernels::sphereVolume(0.5 * d);
}

std::pair<Material, Material> pairMaterials(const DemConfig& config, std::size_t a, std::size_t b) {
  std::pair<Material, Material> m{config.materials[a], config.materials[b]};
  for (const MaterialPair& p : config.materialPairs) {
    const auto ia = static_cast<std::size_t>(p.a), ib = static_cast<std::size_t>(p.b);
    if (!((ia == a && ib == b) || (ia == b && ib == a)))
      continue;
    if (!std::isnan(p.en))
      m.first.en = m.second.en = p.en;
    if (!std::isnan(p.mu))
      m.first.mu = m.second.mu = p.mu;
  }
  return m;
}

std::vector<int> wallMaterialsOf(const DemConfig& config, int a) {
  std::vector<int> out;
  auto add = [&](int w) {
    const int k = w < 0 ? a : w;
    if (std::find(out.begin(), out.end(), k) == out.end())
      out.push_back(k);
  };
  for (const Wall& w : config.walls)
    add(w.material);
  for (const MeshWall& w : config.meshes)
    add(w.material);
  std::sort(out.begin(), out.end());
  return out;
}

double dtDemMax(const DemConfig& config, std::span<const double> minMass,
                std::span<const double> minRadius) {
  const std::size_t nm = config.materials.size();
  COREDEM_ASSERT(minMass.size() == nm);
  COREDEM_ASSERT(minRadius.empty() || minRadius.size() == nm);
  const auto radius = [&](std::size_t a) { return minRadius.empty() ? 1.0 : minRadius[a]; };
  // Over the rows present: the smallest contact time scale (resolved in dt_factor steps) and
  // the smallest stability limit of the integrator (a bound of its own, whatever dt_factor).
  double tcol = std::numeric_limits<double>::infinity();
  double stable = std::numeric_limits<double>::infinity();
  kernels::visitModel(kernels::ContactLaws{}, static_cast<int>(config.contact), [&](auto law) {
    using Law = typename decltype(law)::type;
    const typename Law::Params& params = config.contactLaws.template of<Law>();
    // The row of materials a and b (the law's mixing) with effective mass meff, radius reff.
    const auto row = [&](std::size_t a, std::size_t b, double meff, double reff) {
      const auto [ma, mb] = pairMaterials(config, a, b);
      const auto p = Law::mix(params, ma, mb);
      tcol = std::min(tcol, Law::collisionTime(params, p, meff, reff));
      stable = std::min(stable, Law::stableStep(params, p, meff, reff));
    };
    for (std::size_t a = 0; a < nm; ++a) {
      if (!std::isfinite(minMass[a]))
        continue;
      for (std::size_t b = 0; b < nm; ++b) {
        if (!std::isfinite(minMass[b]))
          continue;
        row(a, b, kernels::effectiveMass(minMass[a], minMass[b]),
            kernels::effectiveMass(radius(a), radius(b)));
      }
      for (const int w : wallMaterialsOf(config, static_cast<int>(a)))
        row(a, static_cast<std::size_t>(w), minMass[a], radius(a));
    }
  });
  if (config.frozenMotion)
    return std::numeric_limits<double>::max(); // held: no collision limit
  return std::isfinite(tcol) ? std::min(tcol / config.dtFactor, stable)
                             : std::numeric_limits<double>::infinity();
}

std::string didYouMean(std::string_view word, std::span<const std::string_view> candidates) {
  const std::string w = normalise(word);
  std::size_t best = std::max<std::size_t>(1, w.size() / 3) + 1;
  std::string_view pick;
  for (std::string_view c : candidates) {
    const std::size_t d = editDistance(w, normalise(c));
    if (d < best) {
      best = d;
      pick = c;
    }
  }
  return std::string(pick);
}

// ------------------------------------------------------------------ value parsers
namespace {

std::string withSuggestion(std::string_view value, std::span<const std::string_view> names,
                           const std::string& allowed) {
  const std::string guess = didYouMean(value, names);
  return coredem::format(
      "'{}' is not allowed{}; allowed: {}", value,
      guess.empty() ? std::string() : coredem::format(" (did you mean '{}'?)", guess), allowed);
}

/// The family entry named `value`, or the message saying what is allowed (`extra`: further
/// accepted words such as "off", listed after the family's names).
template <class E>
std::optional<E> choice(const ModelFamily<E>& f, std::string_view value, std::string& error,
                        std::span<const std::string_view> extra = {}) {
  if (const ModelEntry<E>* e = f.find(value))
    return e->value;
  std::vector<std::string_view> names;
  for (const ModelEntry<E>& e : f.entries)
    names.push_back(e.name);
  names.insert(names.end(), extra.begin(), extra.end());
  error = withSuggestion(value, names, joinOr(names));
  return std::nullopt;
}

/// on/true/yes/1 or off/false/no/0 (coredem::parseSwitch, the one spelling of a switch).
std::optional<bool> onOff(std::string_view value, std::string& error) {
  if (const auto b = parseSwitch(value))
    return b;
  static constexpr std::string_view kNames[] = {"on", "off"};
  error = withSuggestion(value, kNames, "on or off");
  return std::nullopt;
}

/// An integer in [lo, hi].
std::optional<int> integer(std::string_view value, int lo, int hi, std::string_view what,
                           std::string& error) {
  int v = 0;
  const char* end = value.data() + value.size();
  const auto r = std::from_chars(value.data(), end, v);
  if (r.ec == std::errc() && r.ptr == end && v >= lo && v <= hi)
    return v;
  error = coredem::format("'{}' is not allowed; expected {}", value, what);
  return std::nullopt;
}

constexpr double kHuge = 1.0e300;
constexpr std::string_view kOff[] = {"off"};

/// A row whose value is on/off, stored in the bool that `field` selects.
template <bool HeatOptions::*Field>
std::string heatSwitch(DemConfig& c, std::string_view v) {
  std::string e;
  if (const auto b = onOff(v, e))
    c.heat.*Field = *b;
  return e;
}

/// One `models:` row per declared parameter of every model of `List`, stored in the family's
/// ParamPack std::invoke(Pack, DemConfig&) (a member pointer, or a function for a nested one).
template <class List, auto Pack>
void addParamRowsOf(std::vector<ModelOption>& o, std::string_view family) {
  for (registry::ParamRow<DemConfig>& r : registry::paramRowsOf<DemConfig, List, Pack>(family))
    o.push_back({std::move(r.key), std::move(r.family), std::move(r.values),
                 std::move(r.defaultValue), std::move(r.doc), r.apply});
}

kernels::ParamPack<kernels::NusseltModels>& nusseltParamsOf(DemConfig& c) {
  return c.heat.nusseltModels;
}

/// The `models:` rows of the drag law, its ε_min clip and its laws' parameters.
void addDragRows(std::vector<ModelOption>& o) {
  // --- drag
  o.push_back({"drag", "drag", dragModels().allowed(), "gidaspow",
               "drag law of the gas force on the particles", [](DemConfig& c, std::string_view v) {
                 std::string e;
                 if (const auto law = choice(dragModels(), v, e))
                   c.drag = *law;
                 return e;
               }});
  auto epsMin = [](DemConfig& c, std::string_view v) {
    std::string e;
    if (const auto x = number(v, 0.0, true, 1.0 - 1e-15, "a number in (0, 1) (ε_min, 0.35)", e))
      c.epsMinDrag = *x;
    return e;
  };
  // One clip of ε_g for both sides: the orchestrator also gives it to the CFD participant
  // (coredemFoam's alphacMin, docs/physics.md §1.1).
  o.push_back({"eps_min", "drag", "number in (0, 1)", "0.35",
               "lower clip ε_min of ε_g in the drag, the Nusselt correlation and the gas equations",
               epsMin});
  o.push_back({"dem.eps_min_drag", "drag", "number in (0, 1)", "0.35",
               "deprecated spelling of eps_min", epsMin, "eps_min"});
  o.push_back({"eps_min_drag", "drag", "number in (0, 1)", "0.35", "deprecated spelling of eps_min",
               epsMin, "eps_min"});
  addParamRowsOf<kernels::DragLaws, &DemConfig::dragLaws>(o, "drag");
}

/// The `models:` rows of the heat-transfer switches and parameters: convection, conduction,
/// radiation.
void addHeatRows(std::vector<ModelOption>& o) {
  const std::string onOffText = "on, off";
  // --- heat master switch
  o.push_back({"heat", "heat", onOffText, "on", "off: temperatures stay constant, H = H_Tp = 0",
               heatSwitch<&HeatOptions::enabled>});
  // --- convection
  o.push_back({"convection", "convection", nusseltModels().allowed() + " or off", "li-mason",
               "Nusselt correlation of the particle–gas convection (off: no convection)",
               [](DemConfig& c, std::string_view v) {
                 std::string e;
                 if (normalise(v) == "off") {
                   c.heat.convection = false;
                 } else if (const auto m = choice(nusseltModels(), v, e, kOff)) {
                   c.heat.convection = true;
                   c.heat.nusselt = *m;
                 }
                 return e;
               }});
  o.push_back({"convection_reynolds", "convection", reynoldsModels().allowed(), "with-voidage",
               "Reynolds number of the Nusselt correlation (with ε as the drag, or without)",
               [](DemConfig& c, std::string_view v) {
                 std::string e;
                 if (const auto m = choice(reynoldsModels(), v, e))
                   c.heat.reynoldsWithVoidage = *m == ReynoldsDefinition::WithVoidage;
                 return e;
               }});
  o.push_back({"nusselt_exponent", "convection", "number in [0, 10]", "3.5", "n of εⁿ in Li–Mason",
               [](DemConfig& c, std::string_view v) {
                 std::string e;
                 if (const auto x =
                         number(v, 0.0, false, 10.0, "a number in [0, 10] (Li–Mason n, 3.5)", e))
                   c.heat.voidageExponent = *x;
                 return e;
               }});
  addParamRowsOf<kernels::NusseltModels, &nusseltParamsOf>(o, "convection");
  // --- conduction
  o.push_back({"contact_conduction", "conduction", onOffText, "on",
               "particle–particle conduction through the contact area",
               heatSwitch<&HeatOptions::contactConduction>});
  o.push_back({"lens_conduction", "conduction", onOffText, "on",
               "conduction through the gas lens between neighbours (coupled runs only)",
               heatSwitch<&HeatOptions::lensConduction>});
  o.push_back({"flpc", "conduction", "number in [0, 1]", "0.2", "lens radius (1 + FLPC) R_L",
               [](DemConfig& c, std::string_view v) {
                 std::string e;
                 if (const auto x = number(v, 0.0, false, 1.0,
                                           "a number in [0, 1] (lens radius (1+FLPC) R_L, 0.2)", e))
                   c.heat.lensFraction = *x;
                 return e;
               }});
  o.push_back({"s_min", "conduction", "length in (0, 1e-3] m", "1e-6",
               "minimum conduction distance in the lens (m)", [](DemConfig& c, std::string_view v) {
                 std::string e;
                 if (const auto x =
                         number(v, 0.0, true, 1.0e-3, "a length in (0, 1e-3] m (1e-6)", e))
                   c.heat.minSeparation = *x;
                 return e;
               }});
  o.push_back({"lens_rel_tol", "conduction", "number in [1e-14, 1e-3]", "1e-8",
               "accepted for compatibility (the lens integral is in closed form)",
               [](DemConfig& c, std::string_view v) {
                 std::string e;
                 if (const auto x = number(v, 1.0e-14, false, 1.0e-3,
                                           "a tolerance in [1e-14, 1e-3] (1e-8)", e))
                   c.heat.lensRelTol = *x;
                 return e;
               }});
  o.push_back({"wall_conduction", "conduction", onOffText, "on",
               "contact conduction to fixed-temperature walls",
               heatSwitch<&HeatOptions::wallConduction>});
  o.push_back({"wall_lens_conduction", "conduction", onOffText, "on",
               "gas-lens conduction to fixed-temperature walls (coupled runs only)",
               heatSwitch<&HeatOptions::wallLensConduction>});
  // --- radiation
  o.push_back({"radiation", "radiation", onOffText, "on",
               "radiation of materials with emissivity > 0 (environment: ε_g T_g + (1 − ε_g) "
               "cell-mean T_p)",
               heatSwitch<&HeatOptions::radiation>});
}

/// The `models:` rows of particle motion and the contact law with its parameters.
void addMotionAndContactRows(std::vector<ModelOption>& o) {
  // --- motion
  o.push_back(
      {"motion", "motion", motionModels().allowed(), "free",
       "frozen: particles held in place (MFiX verification cases); set the step with time.dt_dem",
       [](DemConfig& c, std::string_view v) {
         std::string e;
         if (const auto m = choice(motionModels(), v, e))
           c.frozenMotion = *m == MotionModel::Frozen;
         return e;
       }});
  // --- contact law of particles and walls (kernels/contact_law.h)
  o.push_back({"contact", "contact", contactModels().allowed(),
               std::string(contactModels().nameOf(kernels::ContactLaw::LinearSpringDashpot)),
               "contact law of the particle–particle and particle–wall contacts",
               [](DemConfig& c, std::string_view v) {
                 std::string e;
                 if (const auto law = choice(contactModels(), v, e))
                   c.contact = *law;
                 return e;
               }});
  addParamRowsOf<kernels::ContactLaws, &DemConfig::contactLaws>(o, "contact");
}

/// The `models:` rows of the numerics of the DEM step.
void addNumericsRows(std::vector<ModelOption>& o) {
  // --- numerics of the DEM step
  auto dtFactor = [](DemConfig& c, std::string_view v) {
    std::string e;
    if (const auto x =
            number(v, 1.0, false, kHuge, "a number >= 1 (Δt_DEM,max = t_col/dt_factor, 50)", e))
      c.dtFactor = *x;
    return e;
  };
  o.push_back({"dem.dt_factor", "numerics", "number >= 1", "50", "Δt_DEM,max = t_col / dt_factor",
               dtFactor});
  o.push_back({"dt_factor", "numerics", "number >= 1", "50", "deprecated spelling of dem.dt_factor",
               dtFactor, "dem.dt_factor"});
  o.push_back({"dem.skin_factor", "numerics", "number >= 0", "0.1",
               "Verlet skin = skin_factor · d_max (neighbour lists)",
               [](DemConfig& c, std::string_view v) {
                 std::string e;
                 if (const auto x = number(v, 0.0, false, kHuge, "a number >= 0 (0.1)", e))
                   c.neighbour.skinFactor = *x;
                 return e;
               }});
  o.push_back(
      {"dem.history_slots", "numerics", coredem::format("integer in [1, {}]", kMaxHistorySlots),
       "12", "tangential-history slots per particle (the contacts it owns, walls included)",
       [](DemConfig& c, std::string_view v) {
         std::string e;
         const std::string what = coredem::format("an integer in [1, {}] (12)", kMaxHistorySlots);
         if (const auto x = integer(v, 1, kMaxHistorySlots, what, e))
           c.neighbour.historySlots = *x;
         return e;
       }});
}

std::vector<ModelOption> makeOptions() {
  std::vector<ModelOption> o;
  addDragRows(o);
  addHeatRows(o);
  addMotionAndContactRows(o);
  addNumericsRows(o);
  return o;
}

} // namespace

std::span<const ModelOption> modelOptions() {
  static const std::vector<ModelOption> table = makeOptions();
  return table;
}

const ModelOption* findModelOption(std::string_view key) {
  for (const ModelOption& o : modelOptions())
    if (o.key == key)
      return &o;
  return nullptr;
}

namespace {

/// The warning on an old spelling, once per key and process.
void warnIfDeprecated(const ModelOption& o) {
  if (o.deprecatedFor.empty())
    return;
  static std::mutex mutex;
  static std::set<std::string> warned;
  const std::lock_guard<std::mutex> lock(mutex);
  if (warned.insert(o.key).second)
    logger("dem.models")
        ->warn("models: '{}' is deprecated; write '{}' (same meaning)", o.key, o.deprecatedFor);
}

} // namespace

bool applyModelOption(DemConfig& config, std::string_view key, std::string_view value) {
  const ModelOption* o = findModelOption(key);
  if (o == nullptr)
    return false;
  warnIfDeprecated(*o);
  const std::string error = o->apply(config, value);
  COREDEM_CHECK(error.empty(), "model option {} = '{}': {}", key, value, error);
  return true;
}

std::string modelParamsHashText(const DemConfig& c) {
  return registry::paramsHashText(c.dragLaws, static_cast<int>(c.drag), "drag") +
         registry::paramsHashText(c.heat.nusseltModels, static_cast<int>(c.heat.nusselt),
                                  "convection") +
         registry::paramsHashText(c.contactLaws, static_cast<int>(c.contact), "contact");
}

void checkModelParams(const DemConfig& c) {
  registry::checkParams(c.dragLaws, static_cast<int>(c.drag), "drag");
  registry::checkParams(c.heat.nusseltModels, static_cast<int>(c.heat.nusselt), "convection");
  registry::checkParams(c.contactLaws, static_cast<int>(c.contact), "contact");
}

std::vector<ModelIssue>
validateModels(std::span<const std::pair<std::string, std::string>> models) {
  std::vector<ModelIssue> issues;
  std::vector<std::string_view> keys;
  for (const ModelOption& o : modelOptions())
    keys.push_back(o.key);
  std::string allKeys;
  for (std::string_view k : keys)
    allKeys += (allKeys.empty() ? "" : ", ") + std::string(k);
  DemConfig scratch;
  for (std::size_t i = 0; i < models.size(); ++i) {
    const auto& [key, value] = models[i];
    const ModelOption* o = findModelOption(key);
    if (o == nullptr) {
      const std::string guess = didYouMean(key, keys);
      issues.push_back(
          {i, key, true,
           coredem::format("unknown model key{}; allowed keys: {}",
                           guess.empty() ? std::string()
                                         : coredem::format(" (did you mean '{}'?)", guess),
                           allKeys)});
      continue;
    }
    warnIfDeprecated(*o);
    std::string error = o->apply(scratch, value);
    if (!error.empty())
      issues.push_back({i, key, false, std::move(error)});
  }
  return issues;
}

} // namespace coredem::dem
