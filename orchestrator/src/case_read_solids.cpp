// materials, initial_state, particles (docs/case-schema.md).
#include <cmath>
#include <fstream>
#include <limits>

#include <yaml-cpp/yaml.h>

#include "case_read.h"

namespace fs = std::filesystem;

namespace coredem::orchestrator::caseread {

using yaml::describe;
using yaml::join;

/// materials
void readMaterials(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  top.require("materials", "a list of solid materials");
  for (const auto& m :
       top.list("materials",
                {"name", "density", "k_n", "e_n", "friction", "kt_factor", "etat_factor",
                 "youngs_modulus", "poisson_ratio", "cp", "conductivity", "emissivity"},
                "solid materials")) {
    MaterialConfig mc;
    mc.name = m.string("name", std::nullopt, "material name");
    mc.density = m.number("density", std::nullopt, 0.0, kBig, "kg/m3, > 0", true);
    // k_n: required by the linear spring–dashpot law, E and ν by Hertz–Mindlin
    // (checkContactMaterials, once `models` is read).
    if (m.has("k_n")) {
      mc.kN = m.number("k_n", std::nullopt, 0.0, kBig, "normal spring stiffness in N/m, > 0", true);
    }
    if (m.has("youngs_modulus")) {
      mc.youngsModulus =
          m.number("youngs_modulus", std::nullopt, 0.0, kBig, "Young's modulus in Pa, > 0", true);
    }
    if (m.has("poisson_ratio")) {
      mc.poissonRatio =
          m.number("poisson_ratio", std::nullopt, -1.0, 0.5, "Poisson's ratio in (-1, 0.5)", true);
      if (*mc.poissonRatio >= 0.5) {
        m.fail(m.markOf("poisson_ratio"), m.full("poisson_ratio"),
               fmt::format("{} is outside (-1, 0.5)", *mc.poissonRatio));
      }
    }
    mc.eN =
        m.number("e_n", std::nullopt, 0.0, 1.0, "normal restitution coefficient in (0, 1]", true);
    mc.friction = m.number("friction", 0.3, 0.0, kBig, "Coulomb friction coefficient, >= 0");
    if (m.has("kt_factor")) {
      mc.ktFactor = m.number("kt_factor", std::nullopt, 0.0, kBig, "k_t/k_n (default 2/7)", true);
    }
    if (m.has("etat_factor")) {
      mc.etatFactor = m.number("etat_factor", std::nullopt, 0.0, kBig, "eta_t/eta_n (default 1/2)");
    }
    mc.cp = m.number("cp", 840.0, 0.0, kBig, "specific heat in J/kg/K, > 0", true);
    mc.conductivity = m.number("conductivity", 1.0, 0.0, kBig, "W/m/K, > 0", true);
    mc.emissivity = m.number("emissivity", 0.0, 0.0, 1.0, "emissivity in [0, 1]");
    if (materialIndex(c, mc.name) >= 0) {
      m.fail(m.markOf("name"), "materials", fmt::format("material '{}' is defined twice", mc.name));
    }
    c.materials.push_back(mc);
  }
  if (c.materials.empty()) {
    top.fail(top.markOf("materials"), "materials", "needs at least one material");
  }
}

namespace {

/// The state file a new start takes from `path`: the file itself; a checkpoint folder's dem.h5;
/// a run folder's last snapshot (snapshots/index.csv: the run's end), else its newest
/// checkpoint. Empty, with `why`, when there is none.
fs::path initialStateFile(const fs::path& path, std::string& why) {
  if (fs::is_regular_file(path)) {
    return path;
  }
  if (!fs::is_directory(path)) {
    why = "not found";
    return {};
  }
  if (fs::is_regular_file(path / "dem.h5")) {
    return path / "dem.h5"; // a checkpoint folder
  }
  if (std::ifstream index{path / "snapshots" / "index.csv"}) {
    std::string line, last;
    while (std::getline(index, line)) {
      if (!line.empty()) {
        last = line;
      }
    }
    const auto comma = last.rfind(',');
    if (comma != std::string::npos && last.rfind("step,", 0) != 0) {
      const fs::path snapshot = path / last.substr(comma + 1);
      if (fs::is_regular_file(snapshot)) {
        return snapshot;
      }
    }
  }
  fs::path newest;
  if (fs::is_directory(path / "checkpoints")) {
    for (const auto& e : fs::directory_iterator(path / "checkpoints")) {
      if (fs::is_regular_file(e.path() / "manifest.json") &&
          fs::is_regular_file(e.path() / "dem.h5") && e.path() > newest) {
        newest = e.path();
      }
    }
  }
  if (newest.empty()) {
    why = "is a folder without a DEM state (neither a run folder with snapshots or complete "
          "checkpoints nor a checkpoint folder with dem.h5)";
    return {};
  }
  return newest / "dem.h5";
}

} // namespace

/// initial_state: the particles of another run to start from (a state file, a checkpoint
/// folder or a run folder), relative to the case folder
void readInitialState(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (top.has("initial_state")) {
    const std::string rel = top.string("initial_state", std::nullopt,
                                       "another run's DEM state: an HDF5 state file (a snapshot "
                                       "or a checkpoint's dem.h5), a checkpoint folder or a run "
                                       "folder, relative to the case folder");
    const fs::path given = fs::absolute(c.caseDir / rel);
    std::string why;
    c.initialState = initialStateFile(given, why);
    if (c.initialState.empty()) {
      top.fail(top.markOf("initial_state"), "initial_state",
               fmt::format("{}'{}' {} (looked for {}); give a DEM state file (a run's "
                           "snapshots/particles_<step>.h5 or checkpoints/<step>/dem.h5), a "
                           "checkpoint folder or a run folder, relative to the case folder",
                           why == "not found" ? "file " : "", rel, why, given.string()));
    }
  }
}

/// particles (sets of particles; or initial_state)
void readParticles(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (top.has("particles")) {
    for (const auto& p :
         top.list("particles",
                  {"name", "material", "count", "diameter", "density", "temperature", "composition",
                   "packing", "region", "seed", "velocity", "positions"},
                  "particle sets")) {
      ParticleSetConfig ps;
      ps.name = p.string("name", std::string("set") + std::to_string(c.particles.size()),
                         "label for outputs");
      ps.material = p.string("material", std::nullopt, "name of a material in 'materials'");
      if (materialIndex(c, ps.material) < 0) {
        std::vector<std::string> names;
        for (const auto& m : c.materials) {
          names.push_back(m.name);
        }
        p.fail(p.markOf("material"), p.full("material"),
               fmt::format("unknown material '{}'; allowed: {}", ps.material, join(names)));
      }
      if (p.has("positions")) { // explicit packing: one centre per particle
        const YAML::Node pos = p.raw("positions");
        if (!pos.IsSequence() || pos.size() == 0) {
          p.fail(p.markOf("positions"), p.full("positions"),
                 "expected a non-empty list of particle centres [[x, y, z], ...] in m");
        }
        for (std::size_t k = 0; k < pos.size(); ++k) {
          const std::string key = fmt::format("{}[{}]", p.full("positions"), k);
          if (!pos[k].IsSequence() || pos[k].size() != 3) {
            p.fail(pos[k].Mark(), key,
                   fmt::format("expected a centre [x, y, z] in m, got {}", describe(pos[k])));
          }
          Vec3 x{};
          for (std::size_t d = 0; d < 3; ++d) {
            x[d] = p.numberOf(pos[k][d], fmt::format("{}[{}]", key, d), -kBig, kBig, "m");
          }
          ps.positions.push_back(x);
        }
      }
      ps.count =
          ps.positions.empty()
              ? std::uint64_t(p.integer("count", std::nullopt, 1, 100000000, "number of particles"))
              : std::uint64_t(p.integer("count", std::int64_t(ps.positions.size()), 1, 100000000,
                                        "number of particles"));
      if (!ps.positions.empty() && ps.count != ps.positions.size()) {
        p.fail(p.markOf("count"), p.full("count"),
               fmt::format("{} particles but {} positions; with 'positions' leave 'count' out "
                           "(it is the number of positions)",
                           ps.count, ps.positions.size()));
      }
      ps.diameter = p.number("diameter", std::nullopt, 0.0, kBig, "m, > 0", true);
      ps.density = p.number("density", 0.0, 0.0, kBig, "kg/m3 (0 = the material's)");
      ps.temperature = p.number("temperature", 293.15, 0.0, kBig, "initial temperature in K", true);
      if (p.has("composition")) {
        const YAML::Node comp = p.raw("composition");
        if (!comp.IsMap()) {
          p.fail(p.markOf("composition"), p.full("composition"),
                 "expected a mapping species -> mass fraction, e.g. {Fe2O3: 1.0}");
        }
        double sum = 0.0;
        for (const auto& kv : comp) {
          const double f = p.numberOf(kv.second, p.full("composition." + kv.first.Scalar()), 0.0,
                                      1.0, "mass fraction in [0, 1]");
          ps.composition.emplace_back(kv.first.Scalar(), f);
          sum += f;
        }
        if (std::abs(sum - 1.0) > 1e-9) {
          p.fail(p.markOf("composition"), p.full("composition"),
                 fmt::format("mass fractions sum to {}, must sum to 1", sum));
        }
      }
      if (!ps.positions.empty()) {
        ps.packing = p.choice("packing", std::string("explicit"), {"explicit"});
        if (p.has("region")) {
          p.fail(p.markOf("region"), p.full("region"),
                 "not used with 'positions' (explicit packing); remove one of them");
        }
      } else {
        ps.packing = p.choice("packing", std::string("lattice"), {"lattice", "random"});
        p.require("region", "box {min: [x,y,z], max: [x,y,z]} in m to fill, or 'positions'");
        const Section r = p.section("region", {"min", "max"});
        ps.regionMin = r.vec3("min", std::nullopt, "m");
        ps.regionMax = r.vec3("max", std::nullopt, "m");
        for (int i = 0; i < 3; ++i) {
          if (ps.regionMax[i] <= ps.regionMin[i]) {
            r.fail(r.markOf("max"), r.full("max"), "every component must exceed the one of 'min'");
          }
        }
      }
      ps.seed = std::uint64_t(
          p.integer("seed", 1, 0, std::numeric_limits<std::int64_t>::max(), "random seed"));
      ps.velocity = p.vec3("velocity", Vec3{0, 0, 0}, "initial velocity in m/s");
      c.particles.push_back(ps);
    }
  }
  if (c.particles.empty() && c.initialState.empty()) {
    top.fail(top.mark(), "particles",
             "the case needs 'particles' (a list of particle sets) or 'initial_state'");
  }
}

} // namespace coredem::orchestrator::caseread
