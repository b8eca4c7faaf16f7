// Chemistry through coredem-dem's session (real ZeroMQ tcp loopback, ephemeral port, real DEM
// core): a v1.1 Configure with solid species and a reaction -> Sources.R_species and the StepDone
// ledger.
#include <cmath>
#include <numbers>
#include <thread>

#include <gtest/gtest.h>

#include "../client/mini_orchestrator.h"
#include "../dem-server/server_thread.h"
#include "coredem/server/dem_server.h"

using namespace coredem::testing;

namespace {

constexpr int kN = 40;
constexpr double kD = 1e-3, kBox = 6e-3, kOmega = 1e-7; // ω: mol/s per particle
constexpr int kCells = 3;

v1::Configure reactingCase() {
  v1::Configure c = smallCase(kN, kD, kBox, kCells, {"A", "C"});
  c.mutable_species(0)->set_molar_mass(0.025);
  c.mutable_species(1)->set_molar_mass(0.030);
  for (auto [name, molar] : {std::pair{"B", 0.015}, {"D", 0.025}, {"I", 0.020}}) {
    auto* s = c.add_solid_species();
    s->set_name(name);
    s->set_molar_mass(molar);
  }
  auto* ps = c.mutable_particle_sets(0);
  for (auto [name, f] : {std::pair{"B", 0.5}, {"I", 0.5}}) {
    auto* nv = ps->add_composition();
    nv->set_name(name);
    nv->set_value(f);
  }
  auto* r = c.add_reactions();
  r->set_name("rc");
  for (auto [sp, nu] : {std::pair{"A", -1.0}, {"B", -2.0}, {"C", 1.0}, {"D", 1.0}}) {
    auto* t = r->add_terms();
    t->set_species(sp);
    t->set_nu(nu);
  }
  r->mutable_rate()->set_law(v1::RATE_LAW_CONSTANT);
  r->mutable_rate()->set_a(kOmega);
  r->set_heat_of_reaction(0.0);
  c.mutable_chemistry()->set_reaction_heat(false);
  auto* opt = c.add_options();
  opt->set_key("heat");
  opt->set_value("off");
  return c;
}

} // namespace

TEST(DemServerChemistry, SourcesCarryTheParticlesSpeciesRatesAndTheLedgerTheConvertedMass) {
  ServerThread server(600.0, 60.0); // the server defaults
  MiniOrchestrator o(server.endpoint(), reactingCase());
  ASSERT_EQ(o.particles(), static_cast<std::uint64_t>(kN));
  proto::Client cfd;
  cfd.connect(server.endpoint());
  auto hello = proto::makeHello(v1::ROLE_CFD, "test cfd");
  hello.setSessionId(o.session());
  proto::expectType(cfd.request(std::move(hello), 10s), v1::MESSAGE_TYPE_WELCOME);

  const std::size_t n = kCells * kCells * kCells, ns = 2;
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  auto g = proto::makeStepGrant(1, 0.0, dt, nSub, dt / nSub);
  g.setSessionId(o.session());
  o.dem().send(std::move(g));
  namespace f = proto::fields;
  auto m = proto::makeGasFields(1, 0.0, dt, n, static_cast<std::uint32_t>(ns));
  m.setSessionId(o.session());
  const std::vector<double> zero3(3 * n, 0.0), T(n, 300.0), rho(n, 1.2), mu(n, 1.8e-5),
      kap(n, 0.026), cp(n, 1005.0);
  std::vector<double> Y(n * ns, 0.5);
  m.addArray(f::kGasVelocity, zero3, {n, 3});
  m.addArray(f::kPressureGradient, zero3, {n, 3});
  m.addArray(f::kGasTemperature, T, {n});
  m.addArray(f::kGasDensity, rho, {n});
  m.addArray(f::kGasViscosity, mu, {n});
  m.addArray(f::kGasConductivity, kap, {n});
  m.addArray(f::kGasHeatCapacity, cp, {n});
  m.addArray(f::kGasMassFractions, Y, {n, ns});
  auto src = cfd.request(std::move(m), 20s);
  proto::expectType(src, v1::MESSAGE_TYPE_SOURCES);
  // Σ_c R_A V_c = −N M_A ω, Σ_c R_C V_c = N M_C ω (every particle is inside the grid; 1e-12).
  const auto r = src.values<double>(f::kSpeciesSources);
  ASSERT_EQ(r.size(), n * ns);
  const double vc = std::pow(kBox / kCells, 3);
  double a = 0.0, c = 0.0;
  for (std::size_t k = 0; k < n; ++k)
    a += r[k * ns] * vc, c += r[k * ns + 1] * vc;
  EXPECT_NEAR(a, -kN * 0.025 * kOmega, 1e-12 * kN * 0.025 * kOmega);
  EXPECT_NEAR(c, kN * 0.030 * kOmega, 1e-12 * kN * 0.030 * kOmega);
  // StepDone ledger: converted mass per gas species and the particle mass loss (2 M_B − M_D) ω.
  auto d = o.dem().receive(20s);
  ASSERT_TRUE(d.has_value());
  proto::expectType(*d, v1::MESSAGE_TYPE_STEP_DONE);
  const auto& l = d->envelope().step_done().ledger();
  EXPECT_NEAR(named(l.species(), "dem.solid_to_gas.A_kg"), -kN * 0.025 * kOmega * dt,
              1e-12 * kN * 0.025 * kOmega * dt);
  EXPECT_NEAR(named(l.species(), "dem.solid_to_gas.C_kg"), kN * 0.030 * kOmega * dt,
              1e-12 * kN * 0.030 * kOmega * dt);
  const double m0 = kN * 2500.0 * std::numbers::pi * kD * kD * kD / 6.0;
  EXPECT_NEAR(named(l.mass(), "dem.particle_mass_kg"), m0 - kN * (2 * 0.015 - 0.025) * kOmega * dt,
              1e-13 * m0);
  EXPECT_EQ(named(l.mass(), "dem.removed_mass_kg"), 0.0);
  EXPECT_EQ(named(l.energy(), "dem.reaction_heat_J"), 0.0);
  // Sensible enthalpy of the moved mass (docs/physics.md §3.5): the gas-side total is the transfer
  // part of the Q_hom it was sent (no WGS here; 1e-12 rel), the particle side is Δm c_p T_p with
  // c_p T_p = E/m (identical particles; heat and reaction heat off, so T_p stays put). Δm is the
  // change of the stored masses (what Σ m c_p T sees): it matches the analytic Δm to the round-off
  // of the particle masses, hence the same 1e-13 m0 as the mass check above (times c_p T_p).
  const auto qh = src.values<double>(f::kHomogeneousHeat);
  ASSERT_EQ(qh.size(), n);
  double qSum = 0.0;
  for (double v : qh)
    qSum += v * vc * dt;
  const double gasSens = named(l.energy(), "dem.gas_sensible_heat_J");
  EXPECT_NEAR(gasSens, qSum, 1e-12 * std::fabs(qSum));
  const double cT =
      named(l.energy(), "dem.thermal_energy_J") / named(l.mass(), "dem.particle_mass_kg");
  const double dm = -kN * (2 * 0.015 - 0.025) * kOmega * dt;
  EXPECT_NEAR(named(l.energy(), "dem.sensible_mass_enthalpy_J"), dm * cT, 1e-13 * m0 * cT);
  EXPECT_LT(named(l.energy(), "dem.sensible_mass_enthalpy_J"), 0.0);
  o.shutdown();
}
