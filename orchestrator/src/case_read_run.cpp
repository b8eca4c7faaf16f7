// The run's sections of the case file: name, time, grid, gravity, models, dem, cfd, coupling,
// checkpoint, output (docs/case-schema.md).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <coredem/common/log.h>
#include <coredem/dem/dem_config.h>
#include <coredem/dem/drag_calibration.h>
#include <coredem/dem/models.h>
#include <coredem/orchestrator/participants.h>

#include "case_read.h"

namespace fs = std::filesystem;

namespace coredem::orchestrator::caseread {

using yaml::join;

/// name, description
void readName(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  c.name = top.string("name", std::nullopt, "the case name, used for the run folder");
  // The name names the run folder, the logs and HDF5 attributes: printable, one line, a
  // file name's length.
  const bool printable = std::all_of(c.name.begin(), c.name.end(), [](char ch) {
    return static_cast<unsigned char>(ch) >= 0x20 && ch != 0x7f;
  });
  if (c.name.empty() || c.name.find('/') != std::string::npos || !printable ||
      c.name.size() > kMaxCaseNameBytes || c.name == "." || c.name == "..") {
    top.fail(top.markOf("name"), "name",
             fmt::format("must be a non-empty name of at most {} bytes, without '/' or control "
                         "characters (newline, tab, NUL), and not '.' or '..' (got {} bytes)",
                         kMaxCaseNameBytes, c.name.size()));
  }
  c.description = top.string("description", std::string(), "free text");
  if (c.description.size() > kMaxCaseDescriptionBytes) {
    top.fail(top.markOf("description"), "description",
             fmt::format("{} bytes: at most {} (a line or a paragraph for the run's summary)",
                         c.description.size(), kMaxCaseDescriptionBytes));
  }
}

/// time: end, dt, adaptive (Courant) policy, forced DEM step
void readTime(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  top.require("time", "end time and time step");
  {
    const Section t = top.section("time", {"end", "dt", "adaptive", "dt_dem"});
    c.endTime = t.number("end", std::nullopt, 0.0, kBig, "simulated end time in s, > 0", true);
    c.dt.dt = t.number("dt", std::nullopt, 0.0, kBig,
                       "CFD time step in s, > 0 (the first step when adaptive)", true);
    if (t.has("adaptive")) {
      const Section a = t.section("adaptive", {"courant", "dt_min", "dt_max", "max_growth"});
      c.dt.kind = DtPolicyConfig::Kind::Courant;
      c.dt.courant = a.number("courant", std::nullopt, 0.0, 100.0, "target Courant number", true);
      c.dt.dtMin = a.number("dt_min", std::nullopt, 0.0, kBig, "smallest CFD step in s", true);
      c.dt.dtMax = a.number("dt_max", std::nullopt, 0.0, kBig, "largest CFD step in s", true);
      c.dt.maxGrowth = a.number("max_growth", 1.2, 1.0, 10.0, "largest step-to-step growth factor");
      if (c.dt.dtMin > c.dt.dtMax) {
        a.fail(a.markOf("dt_min"), "time.adaptive.dt_min",
               fmt::format("{} is larger than dt_max = {}; need dt_min <= dt_max", c.dt.dtMin,
                           c.dt.dtMax));
      }
      if (c.dt.dt < c.dt.dtMin || c.dt.dt > c.dt.dtMax) {
        t.fail(t.markOf("dt"), "time.dt",
               fmt::format("{} must lie in [dt_min, dt_max] = [{}, {}] when adaptive", c.dt.dt,
                           c.dt.dtMin, c.dt.dtMax));
      }
    }
    if (t.has("dt_dem")) {
      c.dtDem = t.number("dt_dem", std::nullopt, 0.0, kBig,
                         "forced DEM step in s, > 0; time.dt must be an integer multiple", true);
      if (t.has("adaptive")) {
        t.fail(t.markOf("dt_dem"), "time.dt_dem",
               "a forced DEM step needs a fixed time.dt; remove 'adaptive' or 'dt_dem'");
      }
      const double ratio = c.dt.dt / c.dtDem;
      const double n = std::round(ratio);
      if (n < 1.0 || std::abs(ratio - n) > 1e-9 * n) {
        t.fail(t.markOf("dt_dem"), "time.dt_dem",
               fmt::format("time.dt / time.dt_dem = {} / {} = {:.12g} is not an integer >= 1; "
                           "choose dt_dem = dt / n_sub for an integer n_sub (e.g. {:.6g})",
                           c.dt.dt, c.dtDem, ratio, c.dt.dt / std::max(1.0, std::ceil(ratio))));
      }
    }
  }
}

/// grid: the coupling grid
void readGrid(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  top.require("grid", "the coupling grid");
  {
    const Section g = top.section("grid", {"origin", "spacing", "cells"});
    c.grid.origin = g.vec3("origin", Vec3{0, 0, 0}, "m, lower corner");
    c.grid.spacing = g.vec3("spacing", std::nullopt, "cell size in m, > 0", 0.0, kBig, true);
    const Vec3 cells = g.vec3("cells", std::nullopt, "cells per axis, integers >= 1", 1.0, 1e6);
    for (int i = 0; i < 3; ++i) {
      if (cells[i] != std::floor(cells[i])) {
        g.fail(g.markOf("cells"), "grid.cells", "cell counts must be integers >= 1");
      }
      c.grid.cells[i] = std::uint64_t(cells[i]);
    }
  }
}

void readGravity(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  c.gravity = top.vec3("gravity", Vec3{0.0, 0.0, -9.81}, "m/s2");
}

/// models, checked against the DEM server's model registry
void readModels(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (top.has("models")) {
    const YAML::Node m = top.raw("models");
    if (!m.IsMap()) {
      top.fail(top.markOf("models"), "models",
               "expected a mapping name -> model, e.g. {drag: gidaspow}");
    }
    std::vector<YAML::Mark> keyMarks, valueMarks;
    for (const auto& kv : m) {
      if (!kv.second.IsScalar()) {
        top.fail(kv.second.Mark(), "models." + kv.first.Scalar(), "expected a model name");
      }
      c.models.emplace_back(kv.first.Scalar(), kv.second.Scalar());
      keyMarks.push_back(kv.first.Mark());
      valueMarks.push_back(kv.second.Mark());
    }
    // The Syamlal–O'Brien calibration to U_mf is the reader's (calibrateDrag), not the server's.
    for (std::size_t i = 0; i < c.models.size();) {
      const std::string& key = c.models[i].first;
      if (key == "drag.syamlal-obrien.u_mf" || key == "drag.syamlal-obrien.eps_mf") {
        const bool velocity = key == "drag.syamlal-obrien.u_mf";
        const double v = top.numberOf(m[key], "models." + key, 0.0, velocity ? 1e3 : 0.85,
                                      velocity ? "m/s, > 0 (the measured U_mf)"
                                               : "the bed's voidage at U_mf, in (0, 0.85]",
                                      true);
        r.dragCalibration.push_back({key, v, keyMarks[i]});
        c.models.erase(c.models.begin() + std::ptrdiff_t(i));
        keyMarks.erase(keyMarks.begin() + std::ptrdiff_t(i));
        valueMarks.erase(valueMarks.begin() + std::ptrdiff_t(i));
      } else {
        ++i;
      }
    }
    // The DEM server's model registry (coredem/dem/models.h): every key and value it would refuse
    // or ignore fails here, before anything starts.
    const std::vector<dem::ModelIssue> issues = dem::validateModels(c.models);
    if (!issues.empty()) {
      const dem::ModelIssue& bad = issues.front();
      top.fail(bad.unknownKey ? keyMarks[bad.index] : valueMarks[bad.index], "models." + bad.key,
               bad.message);
    }
    // The clip of ε_g (one value for the DEM and the CFD): one spelling only.
    std::size_t clipKeys = 0;
    dem::DemConfig d;
    for (std::size_t i = 0; i < c.models.size(); ++i) {
      const std::string& key = c.models[i].first;
      if (key != "eps_min" && key != "dem.eps_min_drag" && key != "eps_min_drag") {
        continue;
      }
      if (++clipKeys > 1) {
        top.fail(keyMarks[i], "models." + key,
                 "the clip of the gas fraction is given twice: write models: {eps_min: ...} once");
      }
      dem::applyModelOption(d, key, c.models[i].second);
      c.epsMin = d.epsMinDrag;
    }
  }
}

/// models: {drag.syamlal-obrien.u_mf, drag.syamlal-obrien.eps_mf}: the Syamlal–O'Brien constants
/// c1, d1 for which the law fluidizes the case's particles at the measured U_mf and ε_mf in its
/// gas (dem/drag_calibration.h), added to the models sent to the DEM server.
void calibrateDrag(CaseReading& r) {
  if (r.dragCalibration.empty()) {
    return;
  }
  CaseConfig& c = r.c;
  const auto& first = r.dragCalibration.front();
  const auto fail = [&](const std::string& what) {
    r.top.fail(first.mark, "models." + first.key, what);
  };
  double uMf = 0.0, epsMf = 0.0;
  for (const auto& k : r.dragCalibration) {
    (k.key == "drag.syamlal-obrien.u_mf" ? uMf : epsMf) = k.value;
  }
  if (uMf <= 0.0 || epsMf <= 0.0) {
    fail("the Syamlal-O'Brien calibration needs both drag.syamlal-obrien.u_mf (the measured "
         "minimum fluidization velocity, m/s) and drag.syamlal-obrien.eps_mf (the bed's voidage "
         "at it)");
  }
  std::string drag = "gidaspow";
  for (const auto& [key, value] : c.models) {
    if (key == "drag") {
      drag = value;
    }
    if (key == "drag.syamlal-obrien.c1" || key == "drag.syamlal-obrien.d1") {
      fail(fmt::format("give either u_mf and eps_mf (c1 and d1 are then calibrated from them) or "
                       "c1 and d1, not both ({} is given too)",
                       key));
    }
  }
  if (drag != "syamlal-obrien") {
    fail(fmt::format("calibrates the syamlal-obrien drag law, but models.drag is '{}': write "
                     "drag: syamlal-obrien, or remove the calibration",
                     drag));
  }
  if (c.particles.empty()) {
    fail("the calibration needs the particles' diameter and density, and this case starts from "
         "initial_state; give drag.syamlal-obrien.c1 and d1 instead (coredem check of the case "
         "that made the state prints them)");
  }
  const auto densityOf = [&](const ParticleSetConfig& p) {
    return p.density > 0.0 ? p.density
                           : c.materials[std::size_t(materialIndex(c, p.material))].density;
  };
  const ParticleSetConfig& p0 = c.particles.front();
  const double dp = p0.diameter, rhoP = densityOf(p0);
  for (const ParticleSetConfig& p : c.particles) {
    if (std::abs(p.diameter / dp - 1.0) > 1e-12 || std::abs(densityOf(p) / rhoP - 1.0) > 1e-12) {
      fail(fmt::format("the calibration is for one kind of particle, but particle sets '{}' "
                       "({} m, {} kg/m3) and '{}' ({} m, {} kg/m3) differ; give "
                       "drag.syamlal-obrien.c1 and d1 instead",
                       p0.name, dp, rhoP, p.name, p.diameter, densityOf(p)));
    }
  }
  const double g = std::hypot(c.gravity[0], c.gravity[1], c.gravity[2]);
  const double rhoG = c.gasProperties.density, muG = c.gasProperties.viscosity;
  if (g <= 0.0 || rhoP <= rhoG) {
    fail("the calibration balances the bed's buoyant weight, and here it has none (gravity 0 or "
         "particles no denser than the gas)");
  }
  const auto cal = dem::calibrateSyamlal(uMf, epsMf, dp, rhoP, rhoG, muG, g);
  if (!cal) {
    fail(fmt::format("no c1 in [0.001, 1.2] makes the Syamlal-O'Brien law fluidize {} m "
                     "particles of {} kg/m3 at U_mf = {} m/s with voidage {} (gas {} kg/m3, {} "
                     "Pa s): check U_mf (m/s) and eps_mf",
                     dp, rhoP, uMf, epsMf, rhoG, muG));
  }
  c.models.emplace_back("drag.syamlal-obrien.c1", fmt::format("{:.17g}", cal->c1));
  c.models.emplace_back("drag.syamlal-obrien.d1", fmt::format("{:.17g}", cal->d1));
  logger("orchestrator")
      ->info("models: Syamlal-O'Brien drag calibrated to U_mf = {} m/s at voidage {} ({} m "
             "particles of {} kg/m3 in gas of {} kg/m3, {} Pa s): c1 = {:.6g}, d1 = {:.6g} "
             "(defaults 0.8, 2.65)",
             uMf, epsMf, dp, rhoP, rhoG, muG, cal->c1, cal->d1);
}

/// dem: endpoint, backend, keys
void readDem(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (top.has("dem")) {
    const Section d = top.section("dem", {"endpoint", "backend", "threads", "timeout_s",
                                          "server_key", "client_key", "timers"});
    c.dem.endpoint = d.string("endpoint", std::string(),
                              "endpoint of a running coredem-dem, e.g. tcp://127.0.0.1:5555");
    if (!c.dem.endpoint.empty() && c.dem.endpoint.rfind("tcp://", 0) != 0 &&
        c.dem.endpoint.rfind("ipc://", 0) != 0) {
      d.fail(d.markOf("endpoint"), "dem.endpoint", "must start with tcp:// or ipc://");
    }
    c.dem.backend = d.choice("backend", std::string("cpu"), {"cpu", "cuda", "auto"});
    c.dem.threads = int(d.integer("threads", 0, 0, 4096, "OpenMP threads, 0 = default"));
    c.dem.timeoutSeconds = d.number("timeout_s", 60.0, 0.0, kBig, "deadline in s", true);
    c.dem.timers = d.onOff("timers", false);
    if (d.has("server_key")) {
      const std::string rel =
          d.string("server_key", std::nullopt,
                   "file with the DEM server's CURVE public key (server.public)");
      c.dem.serverKey = fs::absolute(c.caseDir / rel);
      if (!fs::is_regular_file(c.dem.serverKey)) {
        d.fail(d.markOf("server_key"), "dem.server_key",
               fmt::format("file '{}' not found (looked for {}); give the server.public file that "
                           "'coredem-dem --generate-curve-keys DIR' wrote",
                           rel, c.dem.serverKey.string()));
      }
      if (c.dem.endpoint.empty()) {
        d.fail(d.markOf("server_key"), "dem.server_key",
               "only used with dem.endpoint (a server started elsewhere with --curve-keys)");
      }
    }
    if (d.has("client_key")) {
      const std::string rel = d.string(
          "client_key", std::nullopt,
          "this client's secret key file (client.secret) or the folder holding it, written by "
          "'coredem-dem --generate-client-key DIR'");
      c.dem.clientKey = fs::absolute(c.caseDir / rel);
      if (!fs::exists(c.dem.clientKey)) {
        d.fail(d.markOf("client_key"), "dem.client_key",
               fmt::format("'{}' not found (looked for {}); give the client.secret file (or its "
                           "folder) that 'coredem-dem --generate-client-key DIR' wrote",
                           rel, c.dem.clientKey.string()));
      }
      if (!d.has("server_key")) {
        d.fail(d.markOf("client_key"), "dem.client_key",
               "only used with dem.server_key (a server started with --curve-keys and "
               "--client-keys)");
      }
    }
  }
}

/// cfd: what a participant takes and allows comes from its row of the participant table
void readCfd(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (top.has("cfd")) {
    const Section f =
        top.section("cfd", {"participant", "gas_key", "case", "timeout_s", "timers", "ranks"});
    // What a participant takes and allows comes from its row of the participant table.
    c.cfd.participant = f.choice("participant", c.cfd.participant, participantNames());
    const ParticipantDescriptor& p = participant(c.cfd.participant);
    if (!p.caseFolder.empty()) {
      c.cfd.caseFolder =
          f.string("case", std::nullopt,
                   fmt::format("{} of {}, relative to the case folder", p.caseFolder, p.name));
    }
    c.cfd.gasKey = f.string("gas_key", std::string("gas"), "key of the prescribed-gas section");
    c.cfd.timeoutSeconds = f.number("timeout_s", 60.0, 0.0, kBig, "deadline in s", true);
    c.cfd.timers = f.onOff("timers", false);
    c.cfd.ranks = int(f.integer("ranks", 1, 1, 4096, "MPI ranks of the CFD participant"));
    if (c.cfd.ranks > 1 && p.parallelArgs.empty()) {
      f.fail(f.markOf("ranks"), "cfd.ranks",
             fmt::format("{} runs on one process; a decomposed run (ranks > 1) needs a "
                         "participant that runs under MPI (coredemFoam)",
                         p.name));
    }
    if (c.cfd.timers && !p.hasTimers()) {
      std::vector<std::string> withTimers;
      for (const auto& q : participantTable()) {
        if (q.hasTimers()) {
          withTimers.push_back(q.name);
        }
      }
      f.fail(f.markOf("timers"), "cfd.timers",
             fmt::format("stage timers exist in {} only; remove the key", join(withTimers)));
    }
  }
}

/// coupling.scheme (after gas_properties: staggered needs model constant)
void readCoupling(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (top.has("coupling")) {
    const Section k = top.section("coupling", {"scheme"});
    c.coupling.scheme = k.choice("scheme", c.coupling.scheme, {"sequential", "staggered"});
    if (c.coupling.scheme == "staggered" && c.gasProperties.idealGas()) {
      k.fail(k.markOf("scheme"), "coupling.scheme",
             "staggered is not available with gas_properties.model: ideal_gas yet: the "
             "variable-density gas books the particle heat exchange for the sequential scheme "
             "(docs/coredemFoam.md); use scheme: sequential or model: constant");
    }
  }
}

void readCheckpoint(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (top.has("checkpoint")) {
    const Section k = top.section("checkpoint", {"every_steps", "every_seconds", "keep"});
    c.checkpoint.everySteps =
        k.integer("every_steps", 0, 0, std::numeric_limits<std::int64_t>::max(),
                  "steps between checkpoints, 0 = off");
    c.checkpoint.everySeconds = k.number("every_seconds", 0.0, 0.0, kBig,
                                         "wall-clock seconds between checkpoints, 0 = off");
    c.checkpoint.keep = int(k.integer("keep", 3, 1, 1000000, "checkpoints to keep"));
  }
}

void readOutput(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (top.has("output")) {
    const Section o = top.section("output", {"every", "every_seconds", "timeseries_every"});
    c.output.snapshotEvery =
        o.integer("every", 0, 0, std::numeric_limits<std::int64_t>::max(),
                  "steps between outputs (particle snapshot and CFD fields), 0 = none");
    c.output.everySeconds =
        o.number("every_seconds", 0.0, 0.0, kBig,
                 "simulated seconds between outputs (particle snapshot and CFD fields), 0 = none");
    c.output.timeseriesEvery =
        o.integer("timeseries_every", 1, 1, std::numeric_limits<std::int64_t>::max(),
                  "steps between timeseries.csv rows");
  }
}

} // namespace coredem::orchestrator::caseread
