// Contact laws as a model family (kernels/contact_law.h): the registry and the `models:` key
// `contact`, its validation and hash, the pair table's rows, and the family mechanism with a
// second, test-only law (a frictionless linear spring) in a test list: ids, visitModel,
// Dispatch, rows of two laws, the pair kernel and the wall kernel for it, its lanes.
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "config_setup.h"
#include "contact_pairs.h"
#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "coredem/dem/models.h"

using namespace coredem::dem;
namespace k = coredem::dem::kernels;
using k::Vec3;
using k::Vec3T;

namespace {

using Lsd = k::LinearSpringDashpot;

/// A second law for the tests only: a linear normal spring without damping or friction,
/// f = −k_n δ_n n, no tangential history.
template <class S>
struct SpringPairT {
  S kn; ///< N/m
};
struct SpringContact {
  static constexpr const char* name = "test-spring";
  static constexpr const char* doc = "linear normal spring, no damping, no friction (test)";
  struct Params {};
  static constexpr auto params() { return k::noParams<Params>(); }
  template <class S>
  using PairT = SpringPairT<S>;
  using Pair = PairT<double>;
  template <class S>
  using ContactT = SpringPairT<S>;

  template <class Material>
  static Pair mix(const Params&, const Material& a, const Material& b) {
    return Pair{0.5 * (a.kn + b.kn)};
  }
  static double collisionTime(const Params&, const Pair& p, double meff, double) {
    return 3.14159265358979323846 * std::sqrt(meff / p.kn);
  }
  static double stableStep(const Params&, const Pair& p, double meff, double) {
    return 2.0 * std::sqrt(meff / p.kn);
  }
  template <class S, class Load>
  static PairT<S> gather(const Load& load) {
    return PairT<S>{load(&Pair::kn)};
  }
  template <class S>
  static ContactT<S> contact(const PairT<S>& p, S, S) {
    return p;
  }
  template <class S>
  static k::ContactResultT<S> evaluate(const ContactT<S>& c, Vec3T<S> n, S deltaN, Vec3T<S>, S lij,
                                       Vec3T<S>, double) {
    const Vec3T<S> zero{S{}, S{}, S{}};
    k::ContactResultT<S> r;
    r.force = (-c.kn * deltaN) * n;
    r.nxft = zero;
    r.torque = lij * r.nxft;
    r.deltaT = zero;
    return r;
  }
};

using TestLaws = k::ModelList<Lsd, SpringContact>;

/// A family whose kernel returns the law's name (Dispatch).
struct NameOf {
  template <class Law>
  static const char* evaluate(const int&) {
    return Law::name;
  }
};

void expectSameBits(double a, double b, const char* what) {
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a), std::bit_cast<std::uint64_t>(b))
      << what << ": " << a << " vs " << b;
}

} // namespace

// The registry lists every law of ContactLaws under its declared name.
TEST(ContactLaw, RegistryListsTheLaws) {
  const ModelFamily<k::ContactLaw>& f = contactModels();
  ASSERT_EQ(f.entries.size(), static_cast<std::size_t>(k::ContactLaws::size));
  ASSERT_NE(f.find("linear-spring-dashpot"), nullptr);
  EXPECT_EQ(f.find("linear_spring_dashpot")->value, k::ContactLaw::LinearSpringDashpot);
  EXPECT_EQ(f.nameOf(k::ContactLaw::LinearSpringDashpot), "linear-spring-dashpot");
  EXPECT_FALSE(f.entries[0].doc.empty());
  EXPECT_EQ(k::contactLaw<Lsd>(), k::ContactLaw::LinearSpringDashpot);
  // One law: a row of the pair table is LSD's row, no larger.
  EXPECT_EQ(sizeof(k::ContactPair), sizeof(Lsd::Pair));
}

// `models: {contact: …}`: the default, its spelling with '_', and an unknown law refused with
// the allowed names (as the server and `coredem check` report it).
TEST(ContactLaw, ModelsKeyIsValidated) {
  const ModelOption* o = findModelOption("contact");
  ASSERT_NE(o, nullptr);
  EXPECT_EQ(o->defaultValue, "linear-spring-dashpot");
  EXPECT_EQ(o->family, "contact");
  DemConfig c;
  EXPECT_TRUE(applyModelOption(c, "contact", "linear_spring_dashpot"));
  EXPECT_EQ(c.contact, k::ContactLaw::LinearSpringDashpot);
  EXPECT_THROW(applyModelOption(c, "contact", "hertz"), coredem::UserError);
  EXPECT_TRUE(applyModelOption(c, "contact", "hertz_mindlin"));
  EXPECT_EQ(c.contact, k::ContactLaw::HertzMindlin);
  const std::vector<std::pair<std::string, std::string>> models = {
      {"contact", "linear-spring-dashpot"}, {"contact", "linear-spring-dashpt"}, {"contact", "x"}};
  const std::vector<ModelIssue> issues = validateModels(models);
  ASSERT_EQ(issues.size(), 2u);
  EXPECT_EQ(issues[0].index, 1u);
  EXPECT_FALSE(issues[0].unknownKey);
  EXPECT_NE(issues[0].message.find("did you mean 'linear-spring-dashpot'?"), std::string::npos)
      << issues[0].message;
  EXPECT_NE(issues[1].message.find("allowed: linear-spring-dashpot"), std::string::npos)
      << issues[1].message;
}

// The default law adds nothing to the configuration hash (earlier hashes stay), and its rows
// and Δt_DEM,max are those of the mixing rules written out.
TEST(ContactLaw, DefaultLawKeepsHashAndRows) {
  DemConfig a;
  DemConfig b;
  ASSERT_TRUE(applyModelOption(b, "contact", "linear-spring-dashpot"));
  EXPECT_EQ(cfg::hashConfig(a), cfg::hashConfig(b));
  EXPECT_EQ(modelParamsHashText(b), "");

  DemConfig c;
  c.materials = {Material{}, Material{}};
  c.materials[1].kn = 3000.0, c.materials[1].en = 0.5, c.materials[1].mu = 0.4;
  c.materials[1].ktFactor = 0.4, c.materials[1].etatFactor = 0.3;
  EngineSetup es;
  cfg::setUpContacts(c, es);
  ASSERT_EQ(es.pairs.size(), 4u);
  EXPECT_EQ(es.contactLaw, k::ContactLaw::LinearSpringDashpot);
  const Material& m0 = c.materials[0];
  const Material& m1 = c.materials[1];
  const Lsd::Pair& p01 = es.pairs[1].of<Lsd>();
  const double kn = 2.0 * m0.kn * m1.kn / (m0.kn + m1.kn);
  expectSameBits(p01.kn, kn, "k_n");
  expectSameBits(p01.kt, 0.5 * (m0.ktFactor + m1.ktFactor) * kn, "k_t");
  expectSameBits(p01.dampFactor, k::dampingFactor(std::min(m0.en, m1.en)), "damping");
  expectSameBits(p01.etatFactor, 0.5 * (m0.etatFactor + m1.etatFactor), "η_t factor");
  expectSameBits(p01.mu, std::min(m0.mu, m1.mu), "μ");
  // Δt_DEM,max: the smallest undamped contact duration π √(m_eff/k_n) of the pairs over
  // dt_factor (docs/physics.md §2.1; the stability limit is far larger at dt_factor 50).
  const double masses[2] = {1e-6, 2e-6};
  double tcol = HUGE_VAL;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const Lsd::Pair& p = es.pairs[2 * i + j].of<Lsd>();
      const double meff = masses[i] * masses[j] / (masses[i] + masses[j]);
      tcol = std::min(tcol, 3.14159265358979323846 * std::sqrt(meff / p.kn));
    }
  expectSameBits(dtDemMax(c, masses), tcol / c.dtFactor, "Δt_DEM,max");
}

// A tiny restitution does not stretch Δt_DEM,max: the damped t_col = √(m/k)·√(π² + ln² e_n)
// grows without bound as e_n → 0, the undamped π √(m/k) does not. For e_n = 1e-30 and 1e-10
// Δt_DEM,max is π √(m/k) / dt_factor to round-off (1e-15), and so is it for e_n = 0.9; with
// dt_factor 1 the integrator's stability limit Δt_s = 2 (√(1 + ζ²) − ζ)/ω_0 of the stiffest
// damped oscillator (the tangential one here, ζ_t = 7/4 ζ_n → 1.75) binds instead.
TEST(DtDem, TinyRestitutionKeepsTheUndampedPeriod) {
  const double m = 1e-6, kn = 1000.0, t0 = 3.14159265358979323846 * std::sqrt(m / kn);
  for (double en : {1e-30, 1e-10, 0.9}) {
    DemConfig c;
    c.materials[0].kn = kn;
    c.materials[0].en = en;
    const double masses[1] = {2 * m}; // m_eff = m
    const double dt = dtDemMax(c, masses);
    EXPECT_NEAR(dt, t0 / 50, 1e-15 * t0)
        << "e_n = " << en << ": Δt_DEM,max / (t_0/50) = " << dt / (t0 / 50);
  }
  DemConfig c;
  c.materials[0].kn = kn;
  c.materials[0].en = 1e-30;
  c.dtFactor = 1;
  const double masses[1] = {2 * m};
  // ζ_n = c(e_n)/2 (Eq. 13); ζ_t = η_t/(2√(k_t m_t)) with η_t = ½ η_n, k_t = 2/7 k_n and the
  // contact point's tangential mass m_t = 2/7 m (rotation included): ζ_t = 7/4 ζ_n.
  const double w0 = std::sqrt(kn / m), zetaT = 1.75 * 0.5 * k::dampingFactor(1e-30);
  const double limit = 2 * (std::sqrt(1 + zetaT * zetaT) - zetaT) / w0;
  EXPECT_NEAR(dtDemMax(c, masses), limit, 1e-12 * limit);
}

// The family mechanism beyond one member: a test list of LSD and the test spring.
TEST(ContactLaw, SecondLawDispatches) {
  static_assert(k::modelId<Lsd, TestLaws> == 0 && k::modelId<SpringContact, TestLaws> == 1);
  std::vector<std::string> seen;
  for (int id : {0, 1, 7}) // 7: out of range, the last law
    k::visitModel(TestLaws{}, id, [&](auto law) { seen.push_back(decltype(law)::type::name); });
  EXPECT_EQ(seen,
            (std::vector<std::string>{"linear-spring-dashpot", "test-spring", "test-spring"}));
  EXPECT_STREQ((k::Dispatch<NameOf, TestLaws>::call(1, 0)), "test-spring");
  EXPECT_STREQ((k::Dispatch<NameOf, TestLaws>::call(0, 0)), "linear-spring-dashpot");

  // Rows of the two laws in one table: each row holds its law's Pair; a row is as large as the
  // largest Pair.
  using Row = k::PairRow<TestLaws>;
  EXPECT_EQ(sizeof(Row), sizeof(Lsd::Pair));
  Material a, b;
  a.kn = 1000.0, b.kn = 3000.0;
  const Row rows[2] = {Row::make<Lsd>(Lsd::mix({}, a, b)),
                       Row::make<SpringContact>(SpringContact::mix({}, a, b))};
  EXPECT_EQ(rows[0].of<Lsd>().kn, 1500.0);
  EXPECT_EQ(rows[1].of<SpringContact>().kn, 2000.0);

  // The pair kernel for the spring: head-on, δ_n = 1e-5 m, f = −k_n δ_n n on i, no torque and
  // no history.
  const double kn = rows[1].of<SpringContact>().kn;
  const double ri = 5e-4, rj = 5e-4;
  const Vec3 d{ri + rj - 1e-5, 0.0, 0.0};
  const Vec3 zero{0.0, 0.0, 0.0};
  const OwnedPair<double> op = ownedPair<SpringContact, double>(
      d, k::dot(d, d), ri, rj, 1e-6, 1e-6, rows[1].of<SpringContact>(), Vec3{0.1, 0.0, 0.0}, zero,
      Vec3{0.0, 0.0, 50.0}, zero, Vec3{0.0, 1e-6, 0.0}, 1e-6);
  EXPECT_NEAR(op.res.force.x, -kn * 1e-5, 1e-12 * kn * 1e-5);
  EXPECT_EQ(op.res.force.y, 0.0);
  EXPECT_EQ(op.res.torque.z, 0.0);
  EXPECT_EQ(op.res.deltaT.y, 0.0);
  // LSD on the same geometry damps the approach and keeps the history: a different force.
  const OwnedPair<double> lsd = ownedPair<Lsd, double>(
      d, k::dot(d, d), ri, rj, 1e-6, 1e-6, rows[0].of<Lsd>(), Vec3{0.1, 0.0, 0.0}, zero,
      Vec3{0.0, 0.0, 50.0}, zero, Vec3{0.0, 1e-6, 0.0}, 1e-6);
  EXPECT_NE(lsd.res.force.x, op.res.force.x);
  EXPECT_NE(lsd.res.deltaT.y, 0.0);

  // The wall kernel for the spring: a floor, overlap 2e-5 m.
  const k::ContactResult w = k::wallContact<SpringContact>(
      SpringContact::contact(rows[1].of<SpringContact>(), 1e-6, ri), Vec3{0.0, 0.0, 1.0}, 2e-5,
      Vec3{0.0, 0.0, -0.1}, zero, ri, zero, 1e-6);
  EXPECT_NEAR(w.force.z, kn * 2e-5, 1e-12 * kn * 2e-5);

#if defined(COREDEM_DEM_DOUBLE2)
  // Its lanes (gather from two rows) give the bits of the scalar path, lane by lane.
  using D = k::Double2;
  const Vec3 d1{0.0, ri + rj - 3e-5, 0.0};
  const auto pairLanes = SpringContact::gather<D>([&](auto member) {
    return D{rows[1].of<SpringContact>().*member, rows[1].of<SpringContact>().*member};
  });
  auto lanes3 = [](Vec3 u, Vec3 v) { return Vec3T<D>{D{u.x, v.x}, D{u.y, v.y}, D{u.z, v.z}}; };
  const Vec3T<D> dd = lanes3(d, d1);
  const OwnedPair<D> two =
      ownedPair<SpringContact, D>(dd, k::dot(dd, dd), D{ri, ri}, D{rj, rj}, D{1e-6, 1e-6},
                                  D{1e-6, 1e-6}, pairLanes, lanes3(zero, zero), lanes3(zero, zero),
                                  lanes3(zero, zero), lanes3(zero, zero), lanes3(zero, zero), 1e-6);
  const OwnedPair<double> one = ownedPair<SpringContact, double>(
      d1, k::dot(d1, d1), ri, rj, 1e-6, 1e-6, rows[1].of<SpringContact>(), zero, zero, zero, zero,
      zero, 1e-6);
  expectSameBits(two.res.force.x[0], op.res.force.x, "lane 0");
  expectSameBits(two.res.force.y[1], one.res.force.y, "lane 1");
#endif
}
