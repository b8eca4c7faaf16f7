// coredem-gas: the prescribed-gas participant (docs/client.md). It sends prescribed gas fields
// every granted step through the coupling client, receives the DEM sources, integrates what a
// prescribed gas can (heat, species and momentum given to the gas) into ledgers for the
// orchestrator's balances, and writes its small state on checkpoints.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>

#include <CLI/CLI.hpp>

#include "coredem/client/participant.h"
#include "coredem/common/check.h"
#include "coredem/common/compensated_sum.h"
#include "coredem/common/log.h"
#include "coredem/common/version.h"
#include "coredem/gas/gas_model.h"
#include "gas_state.h"

namespace {

namespace gas = coredem::gas;
namespace client = coredem::client;

enum class Kind { Mass, Energy, Species, Diagnostic };

/// Cumulative ledgers with compensated (Kahan) summation, in a fixed order.
class Ledgers {
public:
  void define(const std::string& name, Kind kind) {
    _index[name] = _names.size();
    _names.push_back(name);
    _kinds.push_back(kind);
    _sum.emplace_back();
  }
  void add(const std::string& name, double v) { _sum[_index.at(name)].add(v); }
  void set(const std::string& name, double v) {
    _sum[_index.at(name)] = coredem::CompensatedSum(v);
  }
  client::Ledgers report() const {
    client::Ledgers l;
    for (std::size_t i = 0; i < _names.size(); ++i) {
      const std::pair<std::string, double> e{_names[i], _sum[i].value()};
      switch (_kinds[i]) {
      case Kind::Mass:
        l.mass.push_back(e);
        break;
      case Kind::Energy:
        l.energy.push_back(e);
        break;
      case Kind::Species:
        l.species.push_back(e);
        break;
      case Kind::Diagnostic:
        l.diagnostics.push_back(e);
        break;
      }
    }
    return l;
  }
  void save(gas::GasState& s) const {
    s.names = _names;
    s.values.clear();
    s.compensation.clear();
    for (const auto& sum : _sum) {
      s.values.push_back(sum.value());
      s.compensation.push_back(sum.compensation());
    }
  }
  void restore(const gas::GasState& s) {
    for (std::size_t i = 0; i < s.names.size(); ++i) {
      const auto it = _index.find(s.names[i]);
      COREDEM_CHECK(it != _index.end(),
                    "restart file has ledger '{}', which this case does not "
                    "produce (another case or species list?)",
                    s.names[i]);
      _sum[it->second] = coredem::CompensatedSum(s.values[i], s.compensation[i]);
    }
  }

private:
  std::map<std::string, std::size_t> _index;
  std::vector<std::string> _names;
  std::vector<Kind> _kinds;
  std::vector<coredem::CompensatedSum> _sum;
};

constexpr const char* kAxes[3] = {"x", "y", "z"};

/// The participant's ledgers: heat, mass and species the particles gave the gas, the momentum
/// they exchanged with it and their volume.
Ledgers defineLedgers(const std::vector<std::string>& species) {
  Ledgers ledgers;
  ledgers.define("gas.heat_from_particles_J", Kind::Energy);
  ledgers.define("gas.heat_homogeneous_J", Kind::Energy);
  // Radiation heat the particles gave the gas, ∫ Σ_c Q_rad V_c dt (protocol 1.3; stays 0 with an
  // older DEM server, whose particles radiate to an environment outside the system).
  ledgers.define("gas.heat_radiation_J", Kind::Energy);
  ledgers.define("gas.mass_from_particles_kg", Kind::Mass);
  for (const auto& s : species) {
    ledgers.define("gas.species." + s + "_kg", Kind::Species);
  }
  for (const char* a : kAxes) {
    ledgers.define(std::string("gas.momentum_from_particles_") + a + "_Ns", Kind::Diagnostic);
  }
  // The momentum of the mass the particles released, ∫ Σ_c mom_p V_c dt (protocol 1.5; stays 0
  // with an older DEM server), also inside gas.momentum_from_particles_*.
  for (const char* a : kAxes) {
    ledgers.define(std::string("gas.momentum_released_") + a + "_Ns", Kind::Diagnostic);
  }
  ledgers.define("gas.solid_volume_m3", Kind::Diagnostic);
  return ledgers;
}

/// Adds what the DEM sources s of a step of dt gave the gas (fields f, n cells of volume vc)
/// to the ledgers.
void bookSources(Ledgers& ledgers, const client::Sources& s, const gas::GasFieldArrays& f,
                 const std::vector<std::string>& species, std::size_t n, double vc, double dt) {
  const std::size_t ns = species.size();
  const auto eps = s.field("eps_g"), k = s.field("K_sl"), kus = s.field("K_sl_Us"),
             h = s.field("H"), htp = s.field("H_Tp"), r = s.field("R_species"),
             q = s.field("Q_hom");
  const auto qrad = s.radiationHeat();    // empty below protocol 1.3
  const auto momP = s.releasedMomentum(); // empty below protocol 1.5
  double heat = 0.0, hom = 0.0, solid = 0.0, rad = 0.0;
  double mom[3] = {0.0, 0.0, 0.0}, released[3] = {0.0, 0.0, 0.0};
  std::vector<double> spec(ns, 0.0);
  for (std::size_t c = 0; c < n; ++c) {
    heat += htp[c] - h[c] * f.T_g[c];
    hom += q[c];
    if (qrad.size == n)
      rad += qrad[c];
    solid += 1.0 - eps[c];
    for (int a = 0; a < 3; ++a) {
      mom[a] += kus[3 * c + a] - k[c] * f.u_g[3 * c + a];
      if (momP.size == 3 * n) {
        mom[a] += momP[3 * c + a];
        released[a] += momP[3 * c + a];
      }
    }
    for (std::size_t j = 0; j < ns; ++j)
      spec[j] += r[c * ns + j];
  }
  ledgers.add("gas.heat_from_particles_J", heat * vc * dt);
  ledgers.add("gas.heat_homogeneous_J", hom * vc * dt);
  ledgers.add("gas.heat_radiation_J", rad * vc * dt);
  double mass = 0.0;
  for (std::size_t j = 0; j < ns; ++j) {
    ledgers.add("gas.species." + species[j] + "_kg", spec[j] * vc * dt);
    mass += spec[j];
  }
  ledgers.add("gas.mass_from_particles_kg", mass * vc * dt);
  for (int a = 0; a < 3; ++a) {
    ledgers.add(std::string("gas.momentum_from_particles_") + kAxes[a] + "_Ns", mom[a] * vc * dt);
    ledgers.add(std::string("gas.momentum_released_") + kAxes[a] + "_Ns", released[a] * vc * dt);
  }
  ledgers.set("gas.solid_volume_m3", solid * vc);
}

/// Writes the checkpoint the grant asks for (gas.h5: the ledgers at t + dt); returns its files.
std::vector<std::string> writeCheckpoint(client::Participant& p, const std::string& caseKey,
                                         const Ledgers& ledgers, double t, double dt,
                                         const std::shared_ptr<spdlog::logger>& log) {
  std::vector<std::string> files;
  if (p.requiresCheckpoint()) {
    const std::string dir = p.checkpointDir();
    std::filesystem::create_directories(dir);
    gas::GasState st;
    st.time = t + dt;
    st.step = p.step();
    st.caseKey = caseKey;
    ledgers.save(st);
    gas::writeGasState((std::filesystem::path(dir) / "gas.h5").string(), st);
    files.push_back("gas.h5");
    log->info("checkpoint of step {} written to {}/gas.h5", p.step(), dir);
  }
  return files;
}

int runParticipant(const std::string& caseFile, const std::string& key, client::Options opts,
                   const std::string& restart) {
  auto log = coredem::logger("gas");
  auto model = gas::GasModel::fromFile(caseFile, key);
  client::Participant p(opts);
  p.initialize();
  if (!p.isRunning()) {
    log->info("the orchestrator ended the run before the first step: {}", p.shutdownReason());
    p.finalize();
    return 0;
  }
  const auto& g = p.grid();
  gas::CartesianGrid grid;
  for (int a = 0; a < 3; ++a) {
    grid.origin[a] = g.origin[a];
    grid.spacing[a] = g.spacing[a];
    grid.counts[a] = g.counts[a];
  }
  model.bind(grid, g.species);
  log->info("{}", model.describe());
  const auto n = static_cast<std::size_t>(grid.cellCount());
  const double vc = grid.cellVolume();

  Ledgers ledgers = defineLedgers(g.species);
  if (!restart.empty()) {
    const auto s = gas::readGasState(restart);
    COREDEM_CHECK(s.step == p.startStep(),
                  "restart file {} is of step {}, but the orchestrator "
                  "restarts from step {}: pass the coredem-gas checkpoint of that step",
                  restart, s.step, p.startStep());
    ledgers.restore(s);
    log->info("restarted from {} (step {}, t = {} s)", restart, s.step, s.time);
  }

  // Courant number: Δt · max_c (|u_x|/Δx + |u_y|/Δy + |u_z|/Δz).
  auto courant = [&](const std::vector<double>& u, double dt) {
    double m = 0.0;
    for (std::size_t c = 0; c < n; ++c) {
      double s = 0.0;
      for (int a = 0; a < 3; ++a)
        s += std::abs(u[3 * c + a]) / grid.spacing[a];
      m = std::max(m, s);
    }
    return m * dt;
  };

  gas::GasFieldArrays f;
  std::int64_t steps = 0;
  // Wall time split, reported at the end: evaluating the gas, the exchange with D (includes
  // D's n_sub sub-steps), the ledgers, and advance (StepDone -> next grant from O).
  using Clock = std::chrono::steady_clock;
  double tEval = 0.0, tExchange = 0.0, tLedger = 0.0, tAdvance = 0.0;
  client::ExchangeTimes tSplit; // the exchange's split (client library), summed
  auto since = [](Clock::time_point a) {
    return std::chrono::duration<double>(Clock::now() - a).count();
  };
  while (p.isRunning()) {
    const double t = p.time();
    const double dt = p.dt();
    auto t0 = Clock::now();
    model.evaluate(t, f);
    tEval += since(t0);
    t0 = Clock::now();
    const auto& s = p.exchange(p.step(), dt,
                               {{"u_g", f.u_g},
                                {"grad_p", f.grad_p},
                                {"T_g", f.T_g},
                                {"rho_g", f.rho_g},
                                {"mu_g", f.mu_g},
                                {"kappa_g", f.kappa_g},
                                {"cp_g", f.cp_g},
                                {"Y_g", f.Y_g}});
    tExchange += since(t0);
    const auto x = p.lastExchangeTimes();
    tSplit.serialise += x.serialise;
    tSplit.send += x.send;
    tSplit.wait += x.wait;
    tSplit.receive += x.receive;
    t0 = Clock::now();
    bookSources(ledgers, s, f, g.species, n, vc, dt);

    const std::vector<std::string> files =
        writeCheckpoint(p, caseFile + ":" + key, ledgers, t, dt, log);
    const double co = courant(f.u_g, dt);
    const auto report = ledgers.report();
    tLedger += since(t0);
    t0 = Clock::now();
    p.advance(co, report, files);
    tAdvance += since(t0);
    ++steps;
  }
  log->info("run finished after {} steps: {}", steps, p.shutdownReason());
  if (steps > 0) {
    const double k = 1e3 / static_cast<double>(steps);
    log->info(
        "per step ({} cells): gas evaluation {:.3f} ms, exchange with D {:.3f} ms (incl. "
        "D's sub-steps), ledgers+checkpoints {:.3f} ms, advance (StepDone -> grant) {:.3f} ms",
        n, tEval * k, tExchange * k, tLedger * k, tAdvance * k);
    log->info("exchange per step: serialise {:.3f} ms, send {:.3f} ms, wait for D {:.3f} ms "
              "(transfer both ways + D's work), receive {:.3f} ms",
              tSplit.serialise * k, tSplit.send * k, tSplit.wait * k, tSplit.receive * k);
  }
  p.finalize();
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"coredem-gas: prescribed-gas CFD participant of a CoReDEM run (docs/client.md)"};
  std::string caseFile, key = "gas", restart;
  client::Options opts;
  opts.name = "coredem-gas";
  opts.softwareVersion = std::string("coredem-gas ") + coredem::kVersion;
  bool check = false;
  app.add_option("--case", caseFile, "case YAML file")->required();
  app.add_option("--key", key, "dot-separated key of the gas description in the case file")
      ->capture_default_str();
  app.add_option("--control", opts.controlEndpoint,
                 "orchestrator control endpoint (else COREDEM_CONTROL_ENDPOINT)");
  app.add_option("--dem", opts.demEndpoint, "DEM server endpoint (else COREDEM_DEM_ENDPOINT)");
  app.add_option("--session", opts.sessionId, "session id (else COREDEM_SESSION)");
  app.add_option("--timeout-s", opts.timeoutSeconds,
                 "per-request deadline in s (else COREDEM_TIMEOUT_S or 60)")
      ->check(CLI::PositiveNumber);
  app.add_option("--restart", restart,
                 "coredem-gas checkpoint (gas.h5) to restore the ledgers from");
  app.add_flag("--check", check, "validate the gas description and exit (0 valid, 2 invalid)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  auto log = coredem::logger("gas");
  try {
    if (check) {
      gas::GasModel::fromFile(caseFile, key);
      log->info("{}: the '{}' section is valid", caseFile, key);
      return 0;
    }
    return runParticipant(caseFile, key, opts, restart);
  } catch (const client::ClientError& e) {
    log->error("{}", e.what());
    return e.code() == client::ErrorCode::Argument ? 2 : 1;
  } catch (const coredem::UserError& e) {
    log->error("{}", e.what());
    return 2;
  } catch (const std::exception& e) {
    log->error("internal error: {}", e.what());
    return 1;
  }
}
