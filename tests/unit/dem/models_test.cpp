// Model registries (coredem/dem/models.h): every row parses its own default, every family name
// maps to its enum and back, the kernels dispatch on each enum, and bad keys/values are reported
// with the allowed ones.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/convection.h"
#include "coredem/dem/kernels/drag.h"
#include "coredem/dem/kernels/reaction_generic.h"
#include "coredem/dem/kernels/wgs.h"
#include "coredem/dem/models.h"

using namespace coredem::dem;
namespace k = coredem::dem::kernels;

namespace {

template <class E>
void expectRoundTrip(const ModelFamily<E>& f, std::size_t expectedCount) {
  ASSERT_EQ(f.entries.size(), expectedCount) << f.name;
  std::set<int> values;
  for (const ModelEntry<E>& e : f.entries) {
    ASSERT_NE(f.find(e.name), nullptr) << e.name;
    EXPECT_EQ(f.find(e.name)->value, e.value) << e.name;
    EXPECT_EQ(f.nameOf(e.value), e.name);
    EXPECT_FALSE(e.doc.empty()) << e.name;
    values.insert(static_cast<int>(e.value));
    EXPECT_NE(f.allowed().find(e.name), std::string::npos) << f.allowed();
  }
  EXPECT_EQ(values.size(), expectedCount) << f.name << ": two names for one enum value";
}

} // namespace

// The names users write, one per enumerator ('_' and '-' alike on input).
TEST(ModelRegistry, FamiliesMapNamesToEnums) {
  expectRoundTrip(dragModels(), 9);
  expectRoundTrip(nusseltModels(), 5);
  expectRoundTrip(reynoldsModels(), 2);
  expectRoundTrip(motionModels(), 2);
  expectRoundTrip(rateLawModels(), 2);
  expectRoundTrip(wgsEquilibriumModels(), 3);
  EXPECT_EQ(dragModels().find("gidaspow")->value, k::DragLaw::Gidaspow);
  EXPECT_EQ(nusseltModels().find("li_mason")->value, k::NusseltModel::LiMason);
  EXPECT_EQ(nusseltModels().find("ranz-marshall")->value, k::NusseltModel::RanzMarshall);
  EXPECT_EQ(wgsEquilibriumModels().find("yoon_denn")->value, k::WgsEquilibrium::YoonDenn);
  EXPECT_EQ(wgsEquilibriumModels().find("seed")->value, k::WgsEquilibrium::Seed);
  EXPECT_EQ(wgsEquilibriumModels().find("thermodynamic")->value, k::WgsEquilibrium::Thermodynamic);
  EXPECT_EQ(rateLawModels().find("constant")->value, k::RateLaw::Constant);
  EXPECT_EQ(rateLawModels().find("arrhenius")->value, k::RateLaw::Arrhenius);
  EXPECT_EQ(motionModels().find("frozen")->value, MotionModel::Frozen);
  EXPECT_EQ(nusseltModels().find("nusselt-magic"), nullptr);
}

// Every `models:` row: unique key, doc, allowed values, and its default parses and leaves a
// default DemConfig unchanged (the documented default is the built-in one).
TEST(ModelRegistry, EveryRowParsesItsDefault) {
  std::set<std::string> keys;
  const DemConfig reference;
  for (const ModelOption& o : modelOptions()) {
    EXPECT_TRUE(keys.insert(o.key).second) << "duplicate key " << o.key;
    EXPECT_FALSE(o.doc.empty()) << o.key;
    EXPECT_FALSE(o.values.empty()) << o.key;
    EXPECT_FALSE(o.family.empty()) << o.key;
    ASSERT_NE(o.apply, nullptr) << o.key;
    DemConfig c;
    EXPECT_EQ(o.apply(c, o.defaultValue), "") << o.key << " = " << o.defaultValue;
    EXPECT_EQ(findModelOption(o.key), &o);
    EXPECT_EQ(c.drag, reference.drag) << o.key;
    EXPECT_EQ(c.epsMinDrag, reference.epsMinDrag) << o.key;
    EXPECT_EQ(c.dtFactor, reference.dtFactor) << o.key;
    EXPECT_EQ(c.frozenMotion, reference.frozenMotion) << o.key;
    EXPECT_EQ(c.neighbour.skinFactor, reference.neighbour.skinFactor) << o.key;
    EXPECT_EQ(c.neighbour.historySlots, reference.neighbour.historySlots) << o.key;
    const HeatOptions& h = c.heat;
    const HeatOptions& r = reference.heat;
    EXPECT_TRUE(
        h.enabled == r.enabled && h.convection == r.convection && h.nusselt == r.nusselt &&
        h.reynoldsWithVoidage == r.reynoldsWithVoidage && h.voidageExponent == r.voidageExponent &&
        h.contactConduction == r.contactConduction && h.lensConduction == r.lensConduction &&
        h.lensFraction == r.lensFraction && h.minSeparation == r.minSeparation &&
        h.lensRelTol == r.lensRelTol && h.radiation == r.radiation &&
        h.wallConduction == r.wallConduction && h.wallLensConduction == r.wallLensConduction)
        << o.key << ": the default '" << o.defaultValue << "' is not the built-in default";
  }
  // The keys that cases use today.
  for (const char* key :
       {"drag", "heat", "convection", "convection_reynolds", "nusselt_exponent",
        "contact_conduction", "lens_conduction", "flpc", "s_min", "lens_rel_tol", "radiation",
        "wall_conduction", "wall_lens_conduction", "motion", "dem.dt_factor", "eps_min",
        "dem.eps_min_drag", "dem.skin_factor", "dem.history_slots"})
    EXPECT_TRUE(keys.count(key)) << key;
}

TEST(ModelRegistry, ApplySetsTheConfig) {
  DemConfig c;
  EXPECT_TRUE(applyModelOption(c, "motion", "frozen"));
  EXPECT_TRUE(c.frozenMotion);
  EXPECT_TRUE(applyModelOption(c, "convection", "off"));
  EXPECT_FALSE(c.heat.convection);
  EXPECT_TRUE(applyModelOption(c, "convection", "ranz_marshall"));
  EXPECT_TRUE(c.heat.convection);
  EXPECT_EQ(c.heat.nusselt, k::NusseltModel::RanzMarshall);
  EXPECT_TRUE(applyModelOption(c, "convection_reynolds", "without-voidage"));
  EXPECT_FALSE(c.heat.reynoldsWithVoidage);
  EXPECT_TRUE(applyModelOption(c, "dem.history_slots", "16"));
  EXPECT_EQ(c.neighbour.historySlots, 16);
  EXPECT_TRUE(applyModelOption(c, "dt_factor", "40"));
  EXPECT_EQ(c.dtFactor, 40.0);
  EXPECT_TRUE(applyModelOption(c, "heat", "off"));
  EXPECT_FALSE(c.heat.enabled);
  EXPECT_FALSE(applyModelOption(c, "no_such_key", "1")); // the server warns and ignores it
  EXPECT_THROW(applyModelOption(c, "dem.history_slots", "33"), coredem::UserError);
  EXPECT_TRUE(applyModelOption(c, "drag", "wen-yu"));
  EXPECT_EQ(c.drag, k::dragLaw<k::WenYuDrag>());
  EXPECT_THROW(applyModelOption(c, "drag", "stokes"), coredem::UserError);
}

// `coredem check` input: a misspelled key and a bad value, each named with the allowed ones.
TEST(ModelRegistry, ValidateNamesKeyValueAndAllowed) {
  const std::vector<std::pair<std::string, std::string>> models = {{"motion", "frozen"},
                                                                   {"convecton", "li-mason"},
                                                                   {"convection", "li-masn"},
                                                                   {"flpc", "2"},
                                                                   {"drag", "gidaspow"}};
  const std::vector<ModelIssue> issues = validateModels(models);
  ASSERT_EQ(issues.size(), 3u);
  EXPECT_EQ(issues[0].index, 1u);
  EXPECT_EQ(issues[0].key, "convecton");
  EXPECT_TRUE(issues[0].unknownKey);
  EXPECT_NE(issues[0].message.find("did you mean 'convection'?"), std::string::npos)
      << issues[0].message;
  EXPECT_NE(issues[0].message.find("allowed keys: drag, "), std::string::npos) << issues[0].message;
  EXPECT_EQ(issues[1].index, 2u);
  EXPECT_FALSE(issues[1].unknownKey);
  EXPECT_NE(issues[1].message.find("'li-masn' is not allowed (did you mean 'li-mason'?)"),
            std::string::npos)
      << issues[1].message;
  EXPECT_NE(
      issues[1].message.find("allowed: li-mason, ranz-marshall, gunn, deen, tavassoli or off"),
      std::string::npos)
      << issues[1].message;
  EXPECT_EQ(issues[2].key, "flpc");
  EXPECT_NE(issues[2].message.find("[0, 1]"), std::string::npos) << issues[2].message;
  EXPECT_TRUE(validateModels(std::vector<std::pair<std::string, std::string>>{}).empty());
}

TEST(ModelRegistry, DidYouMean) {
  const std::vector<std::string_view> c = {"convection", "contact_conduction", "radiation"};
  EXPECT_EQ(didYouMean("convecton", c), "convection");
  EXPECT_EQ(didYouMean("radiaton", c), "radiation");
  EXPECT_EQ(didYouMean("xyz", c), "");
}

// The drag dispatcher with DragLaw::Gidaspow against the published Gidaspow (1994) law written out
// here, independently of the kernels (docs/physics.md §2.2): ε clipped to 0.35; Ergun
//   β = 150 (1−ε)² μ/(ε d²) + 1.75 (1−ε) ρ |Δu|/d            for ε ≤ 0.8,
// Wen–Yu β = ¾ C_D ε (1−ε) ρ |Δu| ε^−2.65/d, C_D = 24/Re (1 + 0.15 Re^0.687) (Re < 1000, else
// 0.44), Re = ε ρ d |Δu|/μ, above; the per-particle coefficient β V_p/(1−ε). Air-like gas, 1 mm
// particle, at gas fractions on both sides of the switch, slips from creeping (Re 0.07) to Re >
// 1000 (Newton regime). Only the operation order differs: 1e-13 relative.
TEST(ModelDispatch, DragLawIsGidaspowsPublishedFormula) {
  const k::DragParams p{k::DragLaw::Gidaspow, k::GidaspowParams{}};
  const double rho = 1.2, mu = 1.8e-5, d = 1e-3, v = 5e-10;
  auto published = [&](double epsCell, double slip) {
    const double eps = std::max(epsCell, 0.35);
    double beta = 0.0;
    if (eps <= 0.8) {
      beta = 150.0 * (1 - eps) * (1 - eps) * mu / (eps * d * d) + 1.75 * (1 - eps) * rho * slip / d;
    } else {
      const double re = eps * rho * d * slip / mu;
      const double cd = re < 1000.0 ? 24.0 / re * (1.0 + 0.15 * std::pow(re, 0.687)) : 0.44;
      beta = 0.75 * cd * eps * (1 - eps) * rho * slip * std::pow(eps, -2.65) / d;
    }
    return beta * v / (1 - eps);
  };
  int points = 0;
  for (double eps : {0.3, 0.35, 0.5, 0.8, 0.80001, 0.9, 0.999}) {
    for (double slip : {1e-3, 0.7, 5.0, 20.0}) {
      SCOPED_TRACE(::testing::Message() << "eps " << eps << " slip " << slip);
      const double want = published(eps, slip);
      EXPECT_NEAR(k::particleDragCoefficient(p, eps, rho, mu, d, v, slip), want, 1e-13 * want);
      ++points;
    }
  }
  EXPECT_EQ(points, 28);
  // Re = 0.999·1.2·1e-3·20/1.8e-5 = 1332 > 1000: the Newton branch (C_D = 0.44) was reached.
  EXPECT_GT(0.999 * rho * d * 20.0 / mu, 1000.0);
}

TEST(ModelDispatch, NusseltModel) {
  const k::GasState g{1.2, 1.8e-5, 0.026, 1005.0, 400.0, 0.9};
  double nu[2];
  for (const auto& e : nusseltModels().entries) {
    k::ConvectionParams p;
    p.model = e.value;
    nu[static_cast<int>(e.value)] = k::convection(p, g, 1e-3, 1.0, 300.0).conductance;
  }
  EXPECT_NE(nu[0], nu[1]); // Li–Mason has εⁿ, Ranz–Marshall not
}

TEST(ModelDispatch, WgsEquilibrium) {
  std::set<double> keq;
  for (const auto& e : wgsEquilibriumModels().entries) {
    k::WgsParams p;
    p.equilibrium = e.value;
    keq.insert(k::wgsEquilibriumConstant(p, 1100.0));
  }
  EXPECT_EQ(keq.size(), 3u);
}

TEST(ModelDispatch, RateLaw) {
  std::set<double> rates;
  for (const auto& e : rateLawModels().entries) {
    k::HeterogeneousReaction r;
    r.law = e.value;
    r.A = 2.0;
    r.beta = 0.5;
    r.E = 1.0e4;
    const double conc[1] = {0.0};
    const double solid[1] = {1.0};
    rates.insert(k::heterogeneousExtentRate(r, 900.0, conc, solid, 0.0));
  }
  EXPECT_EQ(rates.size(), 2u);
}

// docs/case-schema.md lists every `models:` key of the registry.
TEST(ModelRegistry, CaseSchemaDocumentsEveryKey) {
  std::ifstream in(COREDEM_SOURCE_DIR "/docs/case-schema.md");
  ASSERT_TRUE(in) << "docs/case-schema.md not found";
  std::stringstream text;
  text << in.rdbuf();
  for (const ModelOption& o : modelOptions())
    EXPECT_NE(text.str().find("| `" + o.key + "` |"), std::string::npos)
        << o.key << " is not in docs/case-schema.md";
}
