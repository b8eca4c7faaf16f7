// The records of a run: timeseries rows, checkpoint manifests, particle snapshots and their
// index, and the wall-time overhead record.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <coredem/common/json.h>

#include "session_impl.h"

namespace fs = std::filesystem;
namespace v1 = coredem::v1;

namespace coredem::orchestrator {

using protocol::Message;

void collect(const v1::StepDone& done, std::vector<std::pair<std::string, double>>& row) {
  for (const auto& d : done.diagnostics()) {
    row.emplace_back(d.name(), d.value());
  }
  for (const auto* list :
       {&done.ledger().mass(), &done.ledger().energy(), &done.ledger().species()}) {
    for (const auto& v : *list) {
      row.emplace_back(v.name(), v.value());
    }
  }
}

std::vector<SnapshotEntry> readSnapshotIndex(const fs::path& runDir) {
  std::vector<SnapshotEntry> out;
  std::ifstream in(runDir / "snapshots" / "index.csv");
  std::string line;
  std::getline(in, line); // header
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string step, time, file;
    if (std::getline(s, step, ',') && std::getline(s, time, ',') && std::getline(s, file)) {
      out.push_back({std::stoll(step), doubleFromHex(time), file, {}});
    }
  }
  // The gas folders are in outputs.csv (step,time_s,particles,gas).
  std::ifstream outputs(runDir / "outputs.csv");
  std::getline(outputs, line);
  while (std::getline(outputs, line)) {
    std::istringstream s(line);
    std::string step, time, file, gas;
    if (std::getline(s, step, ',') && std::getline(s, time, ',') && std::getline(s, file, ',') &&
        std::getline(s, gas)) {
      for (auto& e : out) {
        if (e.step == std::stoll(step)) {
          e.gas = gas;
        }
      }
    }
  }
  return out;
}

void writeSnapshotIndex(const fs::path& runDir, const std::vector<SnapshotEntry>& snaps) {
  std::string text = "step,time_hex,file\n";
  std::string outputs = "step,time_s,particles,gas\n";
  std::vector<std::pair<double, std::string>> xdmf;
  for (const auto& s : snaps) {
    text += fmt::format("{},{},{}\n", s.step, doubleToHex(s.time), s.file);
    outputs += fmt::format("{},{},{},{}\n", s.step, s.time, s.file, s.gas); // shortest round trip
    xdmf.emplace_back(s.time, s.file);
  }
  writeFileAtomic(runDir / "snapshots" / "index.csv", text);
  writeFileAtomic(runDir / "outputs.csv", outputs);
  writeParticleXdmf(runDir / "particles.xdmf", xdmf);
}

double nextOutputTime(double time, double every) {
  const double k = std::floor(time / every + 1e-9);
  return (k + 1.0) * every;
}

std::string gasOutputFolder(const fs::path& runDir, const std::string& workDir, double time,
                            double dt) {
  if (workDir.empty() || !fs::is_directory(runDir / workDir)) {
    return {};
  }
  // The time folder nearest `time` (within dt/2) in `folder`, relative to the run folder.
  const auto search = [&](const fs::path& folder) {
    std::string best;
    double bestDiff = 0.5 * dt;
    for (const auto& e : fs::directory_iterator(runDir / folder)) {
      if (!e.is_directory()) {
        continue;
      }
      const std::string name = e.path().filename().string();
      char* end = nullptr;
      const double t = std::strtod(name.c_str(), &end);
      if (name.empty() || end != name.c_str() + name.size()) {
        continue; // not a time folder (constant, system, ...)
      }
      const double diff = std::abs(t - time);
      if (diff <= bestDiff) {
        bestDiff = diff;
        best = (folder / name).string();
      }
    }
    return best;
  };
  // A decomposed run (cfd.ranks > 1) writes its time folders per processor: processor0's stands
  // for the decomposed case (ParaView's reader opens the case with Case Type "Decomposed Case").
  if (fs::is_directory(runDir / workDir / "processor0")) {
    return search(fs::path(workDir) / "processor0");
  }
  return search(fs::path(workDir));
}

void OverheadTotals::report(spdlog::logger& log, const fs::path& runDir) const {
  if (measured <= 0) {
    return;
  }
  const double n = double(measured);
  log.info("{} steps: step wall {:.3f} ms, DEM compute {:.3f} ms, coupling overhead (wall - "
           "DEM) {:.3f} ms, orchestrator bookkeeping {:.1f} us per step; checkpoints {:.3f} s, "
           "snapshots {:.3f} s in total",
           measured, 1e3 * stepWall / n, 1e3 * demWall / n, 1e3 * (stepWall - demWall) / n,
           1e6 * overhead / n, checkpoints, snapshots);
  JsonWriter js;
  js.beginObject().field("steps", measured);
  for (const auto& [key, seconds] : {std::pair{"step_wall_s", stepWall / n},
                                     {"dem_compute_s", demWall / n},
                                     {"coupling_overhead_s", (stepWall - demWall) / n},
                                     {"orchestrator_bookkeeping_s", overhead / n},
                                     {"checkpoints_total_s", checkpoints},
                                     {"snapshots_total_s", snapshots}}) {
    js.key(key).raw(fmt::format("{:.9g}", seconds)); // wall times: 9 digits are plenty
  }
  js.endObject();
  writeFileAtomic(runDir / "logs" / "overhead.json", js.str());
}

void Session::writeTimeseriesRow(std::int64_t step, double dt, const SubcyclePlan& plan,
                                 double wallStep, const v1::StepDone& dd, const v1::StepDone& cd) {
  std::vector<std::pair<std::string, double>> row = {{"step", double(step)},
                                                     {"t", _time.time()},
                                                     {"dt", dt},
                                                     {"n_sub", double(plan.nSub)},
                                                     {"dt_dem", plan.dtDem},
                                                     {"courant", cd.cfl()},
                                                     {"wall_step_s", wallStep},
                                                     {"wall_dem_s", dd.wall_seconds()}};
  collect(dd, row);
  collect(cd, row);
  // Heat balance: what the particles got from the gas (DEM) plus what the gas got from the
  // particles (CFD) is zero when both sides agree. The staggered scheme's lag (heat the particles
  // exchanged whose sources the gas applies one step later, less the first step's initial
  // sources; docs/coupling-schemes.md) is reported by the DEM server and taken off.
  const auto demHeat = protocol::findNamedValue(dd.ledger().energy(), "dem.heat_from_gas_J");
  const auto gasHeat = protocol::findNamedValue(cd.ledger().energy(), "gas.heat_from_particles_J");
  // The variable-density gas takes the exchange at the end of the step, the particles saw it at
  // its start: the difference goes to the particles with the next step (Q_split, protocol 1.5)
  // and is reported meanwhile as gas.heat_in_flight_J (docs/coredemFoam.md): taken off the same
  // way.
  const auto inFlight = protocol::findNamedValue(dd.ledger().energy(), "dem.heat_in_flight_J");
  const auto gasInFlight = protocol::findNamedValue(cd.ledger().energy(), "gas.heat_in_flight_J");
  // The heat split the gas sent (protocol 1.5 Q_split) for coupling cells without particles is
  // given to nobody: the DEM books it apart (dem.heat_split_unassigned_J), on its side.
  const auto unassigned =
      protocol::findNamedValue(dd.ledger().energy(), "dem.heat_split_unassigned_J");
  if (demHeat && gasHeat) {
    row.emplace_back("balance.heat_residual_J", *demHeat + unassigned.value_or(0.0) + *gasHeat -
                                                    inFlight.value_or(0.0) -
                                                    gasInFlight.value_or(0.0));
  }
  // Radiation (protocol 1.3): what the particles radiated is what the gas received.
  const auto demRad = protocol::findNamedValue(dd.ledger().energy(), "dem.heat_radiation_J");
  const auto gasRad = protocol::findNamedValue(cd.ledger().energy(), "gas.heat_radiation_J");
  if (demRad && gasRad) {
    row.emplace_back("balance.radiation_residual_J", *demRad + *gasRad);
  }
  _timeseries->write(row);
}

void Session::writeCheckpoint(std::int64_t step, const fs::path& ckDir, const v1::StepDone& dd,
                              const v1::StepDone& cd) {
  std::vector<std::pair<std::string, std::string>> files;
  for (const auto& f : dd.checkpoint().files()) {
    files.emplace_back(f, "dem");
  }
  for (const auto& f : cd.checkpoint().files()) {
    files.emplace_back(f, "cfd");
  }
  if (dd.checkpoint().files().empty()) {
    throw ParticipantFault(kDemName, fmt::format("wrote no checkpoint file for step {}", step));
  }
  Manifest m;
  m.step = step;
  m.time = _time.time();
  m.timeCompensation = _time.compensation();
  m.lastDt = _policy.lastDt();
  m.lastCourant = _lastCourant;
  m.softwareVersion = kVersion;
  m.protocolVersion = protocol::kProtocolVersion.toString();
  m.configHash = _c.configHash;
  writeManifest(ckDir, m, files);
  for (const auto& removed : pruneCheckpoints(_o.runDir, _c.checkpoint.keep)) {
    _log->debug("removed old checkpoint {}", removed.string());
  }
  _log->debug("checkpoint {} written", ckDir.string());
}

void Session::takeSnapshot(std::int64_t step, double time, double dt) {
  const fs::path tmp = _o.runDir / "snapshots" / ".incoming";
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  Message req = protocol::makeCheckpointRequest(step, fs::absolute(tmp).string(), "snapshot");
  req.setSessionId(_session).setTime(time);
  _dem->send(std::move(req));
  Message done = receiveFromDem(std::chrono::milliseconds(int(_c.dem.timeoutSeconds * 1000)),
                                "CheckpointDone of a snapshot");
  if (done.type() != v1::MESSAGE_TYPE_CHECKPOINT_DONE ||
      done.envelope().checkpoint_done().files().empty()) {
    throw ParticipantFault(kDemName, "answered a snapshot request without a file");
  }
  const std::string rel = fmt::format("snapshots/particles_{:08d}.h5", step);
  fs::rename(tmp / done.envelope().checkpoint_done().files(0), _o.runDir / rel);
  SnapshotLabels labels;
  for (const auto& sp : _c.solidSpecies) {
    labels.solidSpecies.push_back(sp.name);
  }
  for (const auto& set : _c.particles) {
    labels.sets.push_back(set.name);
    labels.setCounts.push_back(set.positions.empty() ? set.count : set.positions.size());
  }
  for (const auto& m : _c.materials) {
    labels.materials.push_back(m.name);
  }
  describeSnapshot(_o.runDir / rel, labels);
  fs::remove_all(tmp);
  _snapshots.push_back({step, time, rel, gasOutputFolder(_o.runDir, _cfd.workDir, time, dt)});
  writeSnapshotIndex(_o.runDir, _snapshots);
}

} // namespace coredem::orchestrator
