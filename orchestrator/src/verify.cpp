// `coredem verify` (docs/verification.md): the docs/physics.md §8 verification cases through the
// real processes, compared with the analytic solutions of dem/verification/analytic.h.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <coredem/common/hdf5.h>
#include <coredem/common/log.h>
#include <coredem/common/process.h>
#include <coredem/dem/verification/analytic.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/orchestrator/session.h>
#include <coredem/orchestrator/verify.h>

namespace fs = std::filesystem;
namespace va = coredem::dem::verification;
namespace kn = coredem::dem::kernels;

namespace coredem::orchestrator {
namespace {

using Clock = std::chrono::steady_clock;

/// The families `verify` knows (verify.yaml `family:`), each with its analytic solution.
const std::vector<std::string> kFamilies = {"contact-conduction", "gas-lens", "convection",
                                            "radiation", "reaction"};

/// cases/verification/<name>/verify.yaml: what the case checks and against what.
struct CaseSpec {
  std::string name;
  fs::path dir;
  std::string family;
  std::string reference;        ///< docs/physics.md section and reference values (free text)
  double tolerance = 0.0;       ///< primary metric (relative unless the metric says)
  double secondTolerance = 0.0; ///< energy drift (conduction) or mass fractions (reaction)
  std::string skip;             ///< non-empty: not run, reported as skipped (the reason)
};

/// One comparison of summary.json.
struct Metric {
  std::string name;
  std::string metric;
  double value = 0.0;
  double tolerance = 0.0;
  bool pass = false;
};

[[noreturn]] void bad(const fs::path& file, const std::string& what) {
  throw CaseError(fmt::format("{}: {}", file.string(), what));
}

CaseSpec loadSpec(const fs::path& dir) {
  const fs::path file = dir / "verify.yaml";
  YAML::Node n;
  try {
    n = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    bad(file, fmt::format("cannot read: {}", e.what()));
  }
  if (!n.IsMap()) {
    bad(file, "expected a mapping with keys family, reference, tolerance[, energy_tolerance, "
              "fraction_tolerance, skip]");
  }
  const std::set<std::string> allowed = {"family",           "reference",          "tolerance",
                                         "energy_tolerance", "fraction_tolerance", "skip"};
  for (const auto& kv : n) {
    if (!allowed.count(kv.first.Scalar())) {
      bad(file, fmt::format("unknown key '{}'; allowed: family, reference, tolerance, "
                            "energy_tolerance, fraction_tolerance, skip",
                            kv.first.Scalar()));
    }
  }
  CaseSpec s;
  s.name = dir.filename().string();
  s.dir = dir;
  s.family = n["family"] ? n["family"].Scalar() : "";
  if (std::find(kFamilies.begin(), kFamilies.end(), s.family) == kFamilies.end()) {
    bad(file, fmt::format("family '{}' is not known; use one of contact-conduction, gas-lens, "
                          "convection, radiation, reaction",
                          s.family));
  }
  s.reference = n["reference"] ? n["reference"].Scalar() : "";
  auto number = [&](const char* key, bool required, double def) {
    if (!n[key]) {
      if (required) {
        bad(file, fmt::format("missing '{}' (a number > 0)", key));
      }
      return def;
    }
    double v = 0.0;
    try {
      v = n[key].as<double>();
    } catch (const YAML::Exception&) {
      v = -1.0;
    }
    if (!(v > 0.0) || !std::isfinite(v)) {
      bad(file, fmt::format("'{}' must be a number > 0, got '{}'", key, n[key].Scalar()));
    }
    return v;
  };
  s.tolerance = number("tolerance", true, 0.0);
  if (s.family == "contact-conduction" || s.family == "gas-lens") {
    s.secondTolerance = number("energy_tolerance", false, 1e-12);
  } else if (s.family == "reaction") {
    s.secondTolerance = number("fraction_tolerance", false, 3e-5);
  }
  s.skip = n["skip"] ? n["skip"].Scalar() : "";
  return s;
}

std::vector<CaseSpec> discover(const fs::path& root) {
  std::vector<CaseSpec> out;
  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(root)) {
    if (e.is_directory() && fs::exists(e.path() / "verify.yaml") &&
        fs::exists(e.path() / "case.yaml")) {
      dirs.push_back(e.path());
    }
  }
  std::sort(dirs.begin(), dirs.end());
  for (const auto& d : dirs) {
    out.push_back(loadSpec(d));
  }
  // Family order of kFamilies, names sorted within a family.
  std::stable_sort(out.begin(), out.end(), [](const CaseSpec& a, const CaseSpec& b) {
    auto rank = [](const std::string& f) {
      return std::find(kFamilies.begin(), kFamilies.end(), f) - kFamilies.begin();
    };
    return rank(a.family) < rank(b.family);
  });
  return out;
}

// ---- what the analytic solutions need from the case -------------------------------------

struct Particle {
  double d = 0.0;
  va::Material material{};
  double t0 = 0.0;
  Vec3 x{};
  std::vector<std::pair<std::string, double>> composition;
};

/// The particles in global-id order (sets in order, positions in order). Needs explicit
/// positions: the analytic cases have exactly placed particles.
std::vector<Particle> particlesOf(const CaseConfig& c) {
  std::vector<Particle> out;
  for (const auto& ps : c.particles) {
    if (ps.positions.empty()) {
      bad(c.caseFile, fmt::format("particle set '{}': verification cases need explicit "
                                  "'positions' (the analytic solutions depend on them)",
                                  ps.name));
    }
    const auto& m = c.materials[std::size_t(materialIndex(c, ps.material))];
    for (const auto& x : ps.positions) {
      Particle p;
      p.d = ps.diameter;
      p.material = {ps.density > 0 ? ps.density : m.density, m.conductivity, m.cp, m.emissivity};
      p.t0 = ps.temperature;
      p.x = x;
      p.composition = ps.composition;
      out.push_back(p);
    }
  }
  return out;
}

/// The constant, uniform gas of the coredem-gas section.
struct Gas {
  Vec3 u{0, 0, 0};
  double T = 293.15, rho = 1.204, mu = 1.81e-5, kappa = 0.0257, cp = 1005.0;
};

Gas gasOf(const CaseConfig& c) {
  const YAML::Node root = YAML::Load(c.text);
  const YAML::Node g = root[c.cfd.gasKey];
  Gas gas;
  if (!g || !g.IsMap()) {
    return gas;
  }
  if (g["regions"]) {
    bad(c.caseFile, "gas.regions: verification cases need a uniform gas (no regions)");
  }
  auto scalar = [&](const char* key, double& v) {
    if (!g[key]) {
      return;
    }
    if (!g[key].IsScalar()) {
      bad(c.caseFile, fmt::format("gas.{}: verification cases need a constant value", key));
    }
    v = g[key].as<double>();
  };
  scalar("T_g", gas.T);
  scalar("rho_g", gas.rho);
  scalar("mu_g", gas.mu);
  scalar("kappa_g", gas.kappa);
  scalar("cp_g", gas.cp);
  if (g["u_g"]) {
    if (!g["u_g"].IsSequence() || g["u_g"].size() != 3) {
      bad(c.caseFile, "gas.u_g: verification cases need a constant vector [x, y, z]");
    }
    for (std::size_t i = 0; i < 3; ++i) {
      gas.u[i] = g["u_g"][i].as<double>();
    }
  }
  return gas;
}

std::optional<std::string> model(const CaseConfig& c, const std::string& key) {
  for (const auto& [k, v] : c.models) {
    if (k == key) {
      return v;
    }
  }
  return std::nullopt;
}

double modelNumber(const CaseConfig& c, const std::string& key, double def) {
  const auto v = model(c, key);
  return v ? std::stod(*v) : def;
}

std::int64_t cellOf(const CaseConfig& c, const Vec3& x) {
  std::int64_t idx[3];
  for (int d = 0; d < 3; ++d) {
    idx[d] = std::int64_t(std::floor((x[d] - c.grid.origin[d]) / c.grid.spacing[d]));
    if (idx[d] < 0 || idx[d] >= std::int64_t(c.grid.cells[d])) {
      return -1;
    }
  }
  return idx[0] + std::int64_t(c.grid.cells[0]) * (idx[1] + std::int64_t(c.grid.cells[1]) * idx[2]);
}

/// PCM gas fraction of the cell holding particle i (docs/physics.md §1.1).
double cellVoidage(const CaseConfig& c, const std::vector<Particle>& ps, std::size_t i) {
  const std::int64_t cell = cellOf(c, ps[i].x);
  if (cell < 0) {
    bad(c.caseFile, "a particle lies outside the coupling grid");
  }
  double vp = 0.0;
  for (const auto& p : ps) {
    if (cellOf(c, p.x) == cell) {
      vp += va::sphereVolume(p.d);
    }
  }
  return 1.0 - vp / (c.grid.spacing[0] * c.grid.spacing[1] * c.grid.spacing[2]);
}

// ---- snapshots ----------------------------------------------------------------------------

struct Snapshot {
  double t = 0.0;
  std::vector<double> temperature; ///< by global id
  std::vector<double> mass;        ///< by global id
  std::vector<double> species;     ///< by global id, nSpecies columns
  std::size_t nSpecies = 0;
};

std::vector<Snapshot> readSnapshots(const fs::path& runDir) {
  const fs::path index = runDir / "snapshots" / "index.csv";
  std::ifstream in(index);
  COREDEM_CHECK(in.good(), "{}: missing; a verification case needs output.every > 0",
                index.string());
  std::string line;
  std::getline(in, line); // header: step,time_hex,file
  std::vector<Snapshot> out;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  while (std::getline(in, line)) {
    if (line.empty()) {
      continue;
    }
    const auto c1 = line.find(',');
    const auto c2 = line.find(',', c1 + 1);
    COREDEM_CHECK(c1 != std::string::npos && c2 != std::string::npos, "{}: bad line '{}'",
                  index.string(), line);
    Snapshot s;
    s.t = std::strtod(line.substr(c1 + 1, c2 - c1 - 1).c_str(), nullptr);
    const fs::path file = runDir / line.substr(c2 + 1);
    const h5::Handle f = h5::openFile(file);
    const std::string what = file.string();
    const auto gid = h5::readDataset<std::int64_t>(f, "/particles/global_id", what);
    const auto t = h5::readDataset<double>(f, "/particles/temperature", what);
    const auto m = h5::readDataset<double>(f, "/particles/mass", what);
    const auto y = h5::readDataset<double>(f, "/particles/species", what);
    const std::vector<hsize_t> dims = h5::datasetShape(f, "/particles/species", what);
    const std::size_t n = gid.size();
    s.nSpecies = dims.size() == 2 ? std::size_t(dims[1]) : 0;
    s.temperature.assign(n, 0.0);
    s.mass.assign(n, 0.0);
    s.species.assign(n * s.nSpecies, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      const auto g = std::size_t(gid[i]);
      COREDEM_CHECK(g < n, "{}: global id {} out of range", file.string(), g);
      s.temperature[g] = t[i];
      s.mass[g] = m[i];
      for (std::size_t k = 0; k < s.nSpecies; ++k) {
        s.species[g * s.nSpecies + k] = y[i * s.nSpecies + k];
      }
    }
    out.push_back(std::move(s));
  }
  COREDEM_CHECK(!out.empty(), "{}: no snapshots", index.string());
  return out;
}

// ---- series CSV (for the plots) -----------------------------------------------------------

struct Series {
  std::vector<std::string> columns; ///< first "t"
  std::vector<std::vector<double>> rows;
};

void writeSeries(const fs::path& file, const CaseSpec& spec, const std::string& quantity,
                 const Series& s) {
  std::ofstream out(file);
  out << "# case=" << spec.name << ";family=" << spec.family << ";quantity=" << quantity << "\n";
  for (std::size_t i = 0; i < s.columns.size(); ++i) {
    out << (i ? "," : "") << s.columns[i];
  }
  out << "\n";
  char buf[32];
  for (const auto& r : s.rows) {
    for (std::size_t i = 0; i < r.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%.17g", r[i]);
      out << (i ? "," : "") << buf;
    }
    out << "\n";
  }
}

// ---- the families -------------------------------------------------------------------------

/// Two fixed particles exchanging heat by contact or lens conduction (§8.1, §8.2).
std::vector<Metric> checkTwoParticle(const CaseSpec& spec, const CaseConfig& c,
                                     const std::vector<Snapshot>& snaps, Series& series) {
  const auto ps = particlesOf(c);
  if (ps.size() != 2) {
    bad(c.caseFile,
        fmt::format("family {} needs exactly 2 particles, got {}", spec.family, ps.size()));
  }
  const double l =
      std::hypot(ps[1].x[0] - ps[0].x[0], ps[1].x[1] - ps[0].x[1], ps[1].x[2] - ps[0].x[2]);
  va::ExchangeCoefficients k{};
  if (spec.family == "contact-conduction") {
    k = va::contactConductionCoefficients(ps[0].d, ps[0].material, ps[1].d, ps[1].material, l);
  } else {
    kn::GasLensParams p;
    p.lensFraction = modelNumber(c, "flpc", 0.2);
    p.minSeparation = modelNumber(c, "s_min", 1e-6);
    p.relTol = 1e-11; // the reference integral, tighter than the simulation's lens_rel_tol
    k = va::gasLensCoefficients(ps[0].d, ps[0].material, ps[1].d, ps[1].material, l, gasOf(c).kappa,
                                p);
  }
  series.columns = {"t", "sim:T1", "ref:T1", "sim:T2", "ref:T2", "error"};
  double maxErr = 0.0;
  double maxDrift = 0.0;
  const double e0 = snaps.front().mass[0] * ps[0].material.cp * snaps.front().temperature[0] +
                    snaps.front().mass[1] * ps[1].material.cp * snaps.front().temperature[1];
  for (const auto& s : snaps) {
    const va::TwoTemperatures ref = va::twoParticleExchange(k.a, k.b, ps[0].t0, ps[1].t0, s.t);
    const double err = std::max(std::abs(s.temperature[0] - ref.t1) / ref.t1,
                                std::abs(s.temperature[1] - ref.t2) / ref.t2);
    const double e = s.mass[0] * ps[0].material.cp * s.temperature[0] +
                     s.mass[1] * ps[1].material.cp * s.temperature[1];
    maxErr = std::max(maxErr, err);
    maxDrift = std::max(maxDrift, std::abs(e - e0) / std::abs(e0));
    series.rows.push_back({s.t, s.temperature[0], ref.t1, s.temperature[1], ref.t2, err});
  }
  return {{spec.name, "max relative error of T_1, T_2", maxErr, spec.tolerance,
           maxErr <= spec.tolerance},
          {spec.name, "energy drift |sum m c T - E0|/E0", maxDrift, spec.secondTolerance,
           maxDrift <= spec.secondTolerance}};
}

/// One fixed particle in a uniform gas (§8.3).
std::vector<Metric> checkConvection(const CaseSpec& spec, const CaseConfig& c,
                                    const std::vector<Snapshot>& snaps, Series& series) {
  const auto ps = particlesOf(c);
  if (ps.size() != 1) {
    bad(c.caseFile, fmt::format("family convection needs exactly 1 particle, got {}", ps.size()));
  }
  const Gas gas = gasOf(c);
  kn::ConvectionParams p;
  const std::string corr = model(c, "convection").value_or("li-mason");
  if (corr == "ranz-marshall" || corr == "ranz_marshall") {
    p.model = kn::NusseltModel::RanzMarshall;
  } else if (corr == "li-mason" || corr == "li_mason") {
    p.model = kn::NusseltModel::LiMason;
  } else {
    bad(c.caseFile, fmt::format("models.convection = '{}': the convection family needs "
                                "li-mason or ranz-marshall",
                                corr));
  }
  const std::string re = model(c, "convection_reynolds").value_or("with-voidage");
  p.reynoldsWithVoidage = !(re == "without-voidage" || re == "without_voidage");
  p.voidageExponent = modelNumber(c, "nusselt_exponent", 3.5);
  const double eps = cellVoidage(c, ps, 0);
  const kn::GasState g{gas.rho, gas.mu, gas.kappa, gas.cp, gas.T, eps};
  const double slip = std::hypot(gas.u[0], gas.u[1], gas.u[2]);
  const double k = va::convectionCoefficient(p, g, ps[0].d, ps[0].material, slip);
  series.columns = {"t", "sim:T", "ref:T", "error"};
  double maxErr = 0.0;
  for (const auto& s : snaps) {
    const double ref = va::convectionTemperature(gas.T, ps[0].t0, k, s.t);
    const double err = std::abs(s.temperature[0] - ref) / ref;
    maxErr = std::max(maxErr, err);
    series.rows.push_back({s.t, s.temperature[0], ref, err});
  }
  return {
      {spec.name, "max relative error of T_p", maxErr, spec.tolerance, maxErr <= spec.tolerance}};
}

/// Two particles in one cell radiating to T_env = ε_g T_g + (1 − ε_g) T̄_p (§8.4), RK4 reference.
std::vector<Metric> checkRadiation(const CaseSpec& spec, const CaseConfig& c,
                                   const std::vector<Snapshot>& snaps, Series& series) {
  const auto ps = particlesOf(c);
  if (ps.size() != 2 || cellOf(c, ps[0].x) != cellOf(c, ps[1].x)) {
    bad(c.caseFile, "family radiation needs exactly 2 particles in one coupling cell");
  }
  va::RadiationCase rc{ps[0].d,    ps[0].material, ps[1].d, ps[1].material, cellVoidage(c, ps, 0),
                       gasOf(c).T, ps[0].t0,       ps[1].t0};
  std::vector<double> times;
  for (const auto& s : snaps) {
    times.push_back(s.t);
  }
  const auto ref = va::radiationReferenceRK4(rc, times, 1.0e-3);
  series.columns = {"t", "sim:T1", "ref:T1", "sim:T2", "ref:T2", "error"};
  double maxErr = 0.0;
  for (std::size_t i = 0; i < snaps.size(); ++i) {
    const auto& s = snaps[i];
    const double err = std::max(std::abs(s.temperature[0] - ref[i].t1) / ref[i].t1,
                                std::abs(s.temperature[1] - ref[i].t2) / ref[i].t2);
    maxErr = std::max(maxErr, err);
    series.rows.push_back({s.t, s.temperature[0], ref[i].t1, s.temperature[1], ref[i].t2, err});
  }
  return {{spec.name, "max relative error of T_1, T_2 vs RK4", maxErr, spec.tolerance,
           maxErr <= spec.tolerance}};
}

/// A(g) + 2B(s) → C(g) + D(s) at a constant rate on one particle (§8.5), schema of
/// docs/case-schema.md (species, solid_species, reactions[0] with a constant rate).
std::vector<Metric> checkReaction(const CaseSpec& spec, const CaseConfig& c,
                                  const std::vector<Snapshot>& snaps, Series& series) {
  const auto ps = particlesOf(c);
  if (ps.size() != 1) {
    bad(c.caseFile, fmt::format("family reaction needs exactly 1 particle, got {}", ps.size()));
  }
  const YAML::Node root = YAML::Load(c.text);
  std::map<std::string, double> gasM;
  std::map<std::string, double> solidM;
  std::vector<std::string> solidOrder;
  for (const auto& s : root["species"]) {
    gasM[s["name"].Scalar()] = s["molar_mass"].as<double>();
  }
  for (const auto& s : root["solid_species"]) {
    solidM[s["name"].Scalar()] = s["molar_mass"].as<double>();
    solidOrder.push_back(s["name"].Scalar());
  }
  const YAML::Node rx = root["reactions"];
  if (!rx || !rx.IsSequence() || rx.size() != 1) {
    bad(c.caseFile, "family reaction needs exactly one entry in 'reactions'");
  }
  va::ReactionCase r{};
  std::string nameB, nameD;
  for (const auto& t : rx[0]["terms"]) {
    const std::string sp = t["species"].Scalar();
    const double nu = t["nu"].as<double>();
    const bool solid = solidM.count(sp) > 0;
    if (!solid && nu == -1.0) {
      r.molarA = gasM.at(sp);
    } else if (solid && nu == -2.0) {
      r.molarB = solidM.at(sp);
      nameB = sp;
    } else if (!solid && nu == 1.0) {
      r.molarC = gasM.at(sp);
    } else if (solid && nu == 1.0) {
      r.molarD = solidM.at(sp);
      nameD = sp;
    } else {
      bad(c.caseFile,
          "family reaction knows A(g) + 2 B(s) -> C(g) + D(s) only (docs/physics.md §8.5)");
    }
  }
  if (nameB.empty() || nameD.empty() || !(r.molarA > 0) || !(r.molarC > 0)) {
    bad(c.caseFile,
        "family reaction knows A(g) + 2 B(s) -> C(g) + D(s) only (docs/physics.md §8.5)");
  }
  const YAML::Node rate = rx[0]["rate"];
  if (!rate || rate["law"].Scalar() != "constant") {
    bad(c.caseFile, "family reaction needs rate: {law: constant, A: mol/s}");
  }
  r.omega = rate["A"].as<double>();
  r.m0 = va::sphereMass(ps[0].material, ps[0].d);
  std::string nameI;
  for (const auto& [n, f] : ps[0].composition) {
    if (n == nameB) {
      r.xB0 = f;
    } else if (n == nameD) {
      r.xD0 = f;
    } else {
      r.xI0 += f;
      nameI = n;
    }
  }
  auto column = [&](const std::string& n) {
    const auto it = std::find(solidOrder.begin(), solidOrder.end(), n);
    if (it == solidOrder.end()) {
      bad(c.caseFile, fmt::format("solid species '{}' is not in solid_species", n));
    }
    return std::size_t(it - solidOrder.begin());
  };
  const std::size_t cB = column(nameB), cD = column(nameD);
  const std::size_t cI = nameI.empty() ? cB : column(nameI);
  series.columns = {"t",       "sim:m",   "ref:m",   "sim:X_B", "ref:X_B",       "sim:X_D",
                    "ref:X_D", "sim:X_I", "ref:X_I", "error",   "fraction_error"};
  double maxErr = 0.0;
  double maxFrac = 0.0;
  for (const auto& s : snaps) {
    if (s.nSpecies != solidOrder.size()) {
      bad(c.caseFile, fmt::format("snapshots have {} species columns, solid_species lists {}",
                                  s.nSpecies, solidOrder.size()));
    }
    const va::ReactionState ref = va::reactionAnalytic(r, s.t);
    const double* y = &s.species[0];
    const double xB = y[cB], xD = y[cD], xI = nameI.empty() ? 0.0 : y[cI];
    const double err = std::abs(s.mass[0] - ref.m) / ref.m;
    const double frac = std::max({std::abs(xB - ref.xB), std::abs(xD - ref.xD),
                                  nameI.empty() ? 0.0 : std::abs(xI - ref.xI)});
    maxErr = std::max(maxErr, err);
    maxFrac = std::max(maxFrac, frac);
    series.rows.push_back({s.t, s.mass[0], ref.m, xB, ref.xB, xD, ref.xD, xI, ref.xI, err, frac});
  }
  return {{spec.name, "max relative error of the particle mass", maxErr, spec.tolerance,
           maxErr <= spec.tolerance},
          {spec.name, "max absolute error of the mass fractions", maxFrac, spec.secondTolerance,
           maxFrac <= spec.secondTolerance}};
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      char b[8];
      std::snprintf(b, sizeof b, "\\u%04x", static_cast<unsigned>(ch));
      out += b;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string jsonNumber(double v) {
  if (!std::isfinite(v)) {
    return "null";
  }
  char b[32];
  const auto r = std::to_chars(b, b + sizeof b, v); // shortest text that reads back exactly
  return std::string(b, r.ptr);
}

void writeSummary(const fs::path& file, const std::vector<Metric>& ms, bool allPass) {
  std::ostringstream o;
  o << "{\"cases\":[";
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const auto& m = ms[i];
    o << (i ? ",\n  " : "\n  ") << "{\"name\":" << jsonString(m.name)
      << ",\"metric\":" << jsonString(m.metric) << ",\"value\":" << jsonNumber(m.value)
      << ",\"tolerance\":" << jsonNumber(m.tolerance) << ",\"pass\":" << (m.pass ? "true" : "false")
      << "}";
  }
  o << "\n],\"all_pass\":" << (allPass ? "true" : "false") << "}\n";
  const fs::path tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << o.str();
  }
  fs::rename(tmp, file);
}

fs::path findPlotScript() {
  const fs::path installed =
      executableDir().parent_path() / "share" / "coredem" / "scripts" / "plot" / "verify_plots.py";
  if (fs::exists(installed)) {
    return installed;
  }
  return COREDEM_VERIFY_PLOT_SCRIPT;
}

void makePlots(const fs::path& out) {
  const fs::path python = COREDEM_PYTHON;
  const fs::path script = findPlotScript();
  if (python.empty() || !fs::exists(python) || !fs::exists(script)) {
    std::printf("no plots: python ('%s') or %s not found\n", python.c_str(), script.c_str());
    return;
  }
  ChildProcess plot("verify plots", {python.string(), script.string(), out.string()}, {},
                    out / "plot.log");
  if (!plot.waitFor(std::chrono::seconds(300))) {
    plot.stop();
  }
  if (plot.exitCode() != 0) {
    std::printf("plot script failed (see %s)\n", (out / "plot.log").c_str());
    return;
  }
  std::printf("plots: %s\n", (out / "plots").c_str());
}

} // namespace

fs::path findVerificationCases(const fs::path& casesDir) {
  if (!casesDir.empty()) {
    if (!fs::is_directory(casesDir)) {
      throw CaseError(fmt::format("--cases {}: not a folder", casesDir.string()));
    }
    return fs::absolute(casesDir);
  }
  const fs::path installed =
      executableDir().parent_path() / "share" / "coredem" / "cases" / "verification";
  if (fs::is_directory(installed)) {
    return installed;
  }
  const fs::path source = COREDEM_VERIFY_CASES;
  if (fs::is_directory(source)) {
    return source;
  }
  throw CaseError(fmt::format("no verification cases: neither {} nor {} exists; give --cases DIR",
                              installed.string(), source.string()));
}

int runVerify(const VerifyOptions& options) {
  const fs::path root = findVerificationCases(options.casesDir);
  std::vector<CaseSpec> cases = discover(root);
  if (!options.only.empty()) {
    std::vector<CaseSpec> chosen;
    for (const auto& n : options.only) {
      const auto it =
          std::find_if(cases.begin(), cases.end(), [&](const CaseSpec& s) { return s.name == n; });
      if (it == cases.end()) {
        std::string names;
        for (const auto& s : cases) {
          names += (names.empty() ? "" : ", ") + s.name;
        }
        throw CaseError(fmt::format("--only {}: no such verification case in {}; known: {}", n,
                                    root.string(), names));
      }
      chosen.push_back(*it);
    }
    cases = chosen;
  }
  if (options.list) {
    std::printf("verification cases in %s:\n", root.string().c_str());
    for (const auto& s : cases) {
      std::printf("  %-34s %-19s %s%s\n", s.name.c_str(), s.family.c_str(), s.reference.c_str(),
                  s.skip.empty() ? "" : ("  [" + s.skip + "]").c_str());
    }
    return kExitOk;
  }
  const fs::path out = fs::absolute(options.outDir);
  fs::create_directories(out);
  if (!options.verbose && std::getenv("COREDEM_LOG_LEVEL") == nullptr) {
    // The runs' progress and info lines would bury the table: warnings and errors only (the
    // loggers read the variable when first used; the participants inherit it).
    ::setenv("COREDEM_LOG_LEVEL", "warn", 1);
    spdlog::set_level(spdlog::level::warn);
  }
  std::vector<Metric> metrics;
  std::vector<std::string> skipped;
  const auto tAll = Clock::now();
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const CaseSpec& spec = cases[i];
    std::printf("[%2zu/%zu] %-34s ", i + 1, cases.size(), spec.name.c_str());
    std::fflush(stdout);
    if (!spec.skip.empty()) {
      std::printf("SKIPPED (%s)\n", spec.skip.c_str());
      skipped.push_back(spec.name);
      continue;
    }
    const auto t0 = Clock::now();
    const fs::path runDir = out / spec.name;
    std::vector<Metric> ms;
    try {
      const CaseConfig config = loadCase(spec.dir);
      checkParticipantInput(config);
      fs::remove_all(runDir);
      RunOptions ro;
      ro.runDir = prepareRunDir(config, runDir);
      ro.tty = false;
      const int rc = runSession(config, ro);
      if (rc == kExitInterrupted) {
        std::printf("interrupted\n");
        return kExitInterrupted;
      }
      if (rc != kExitOk) {
        throw UserError(
            fmt::format("the run failed with exit code {} (see {}/logs)", rc, runDir.string()));
      }
      const auto snaps = readSnapshots(runDir);
      Series series;
      std::string quantity = "T (K)";
      if (spec.family == "contact-conduction" || spec.family == "gas-lens") {
        ms = checkTwoParticle(spec, config, snaps, series);
      } else if (spec.family == "convection") {
        ms = checkConvection(spec, config, snaps, series);
      } else if (spec.family == "radiation") {
        ms = checkRadiation(spec, config, snaps, series);
      } else {
        ms = checkReaction(spec, config, snaps, series);
        quantity = "m (kg)";
      }
      writeSeries(runDir / "verify.csv", spec, quantity, series);
    } catch (const std::exception& e) { // UserError, or a malformed value (YAML, number)
      ms = {{spec.name, std::string("run: ") + e.what(), std::nan(""), spec.tolerance, false}};
    }
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    bool pass = true;
    for (const auto& m : ms) {
      pass = pass && m.pass;
    }
    std::printf("%s  %.3g (tol %.3g)  %.1f s\n", pass ? "pass" : "FAIL", ms.front().value,
                ms.front().tolerance, wall);
    std::fflush(stdout);
    metrics.insert(metrics.end(), ms.begin(), ms.end());
  }
  bool allPass = true;
  for (const auto& m : metrics) {
    allPass = allPass && m.pass;
  }
  writeSummary(out / "summary.json", metrics, allPass);

  std::printf("\n%-34s %-44s %11s %9s  %s\n", "case", "metric", "value", "tolerance", "result");
  for (const auto& m : metrics) {
    std::printf("%-34s %-44s %11.3e %9.2e  %s\n", m.name.c_str(), m.metric.substr(0, 44).c_str(),
                m.value, m.tolerance, m.pass ? "pass" : "FAIL");
  }
  for (const auto& s : skipped) {
    std::printf("%-34s %-44s %11s %9s  %s\n", s.c_str(), "-", "-", "-", "skipped");
  }
  for (const auto& m : metrics) {
    if (!m.pass && m.metric.rfind("run: ", 0) == 0) {
      std::printf("%s: %s\n", m.name.c_str(), m.metric.c_str());
    }
  }
  std::printf("\n%zu comparisons, %s; %zu skipped; %.1f s. Summary: %s\n", metrics.size(),
              allPass ? "all pass" : "SOME FAILED", skipped.size(),
              std::chrono::duration<double>(Clock::now() - tAll).count(),
              (out / "summary.json").c_str());
  if (options.plots && !metrics.empty()) {
    makePlots(out);
  }
  return allPass ? kExitOk : kExitFault;
}

} // namespace coredem::orchestrator
