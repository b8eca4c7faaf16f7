#include "state_meta.h"

#include <cstdlib>

#include "coredem/common/check.h"
#include "coredem/common/hdf5.h"

namespace coredem::server {

void writeServerLedgers(const std::string& path, const ServerLedgers& l, std::int64_t step,
                        const std::string& session) {
  const h5::Handle file = h5::openFile(path, true);
  if (h5::exists(file, "/server")) {
    H5Ldelete(file, "/server", H5P_DEFAULT);
  }
  const h5::Handle group = h5::createGroup(file, "/server");
  h5::writeAttribute(group, "step", step);
  h5::writeAttribute(group, "session", session);
  h5::writeDataset(group, "species_to_gas_kg", l.speciesToGas);
}

ServerLedgers readServerLedgers(const std::string& path, int species) {
  ServerLedgers l;
  l.speciesToGas.assign(static_cast<std::size_t>(species), 0.0);
  const h5::Handle file = h5::openFile(path);
  if (!h5::exists(file, "/server")) {
    return l;
  }
  const h5::Handle group = h5::openGroup(file, "/server", path);
  const std::vector<double> v = h5::readDataset<double>(group, "species_to_gas_kg", path);
  COREDEM_CHECK(v.size() == static_cast<std::size_t>(species),
                "{}: /server/species_to_gas_kg has {} entries, the case has {} gas species: "
                "restart with the case that wrote the file",
                path, v.size(), species);
  l.speciesToGas = v;
  return l;
}

namespace {
/// The Sources arrays of a pending set, by their protocol names.
template <class F>
void forEachPending(F&& f, dem::CellSources& p) {
  f("eps_g", p.epsG, 1);
  f("K_sl", p.kSl, 1);
  f("K_sl_Us", p.kSlUs, 3);
  f("H", p.heatH, 1);
  f("H_Tp", p.heatHTp, 1);
  f("R_species", p.rSpecies, 0); // 0: one column per gas species
  f("Q_hom", p.qHom, 1);
  f("Q_rad", p.qRad, -1); // -1: one per cell, absent from files written before protocol 1.3
  f("mom_p", p.momP, -3); // -3: three per cell, absent from files written before protocol 1.5
}
} // namespace

void writeStaggeredState(const std::string& path, const StaggeredState& s) {
  const h5::Handle file = h5::openFile(path, true);
  const h5::Handle group = h5::createGroup(file, "/server/staggered");
  h5::writeAttribute(group, "has_pending", s.hasPending ? 1 : 0);
  h5::writeAttribute(group, "heat_applied_J", s.heatApplied);
  h5::writeAttribute(group, "pending_dt_s", s.pendingDt);
  h5::writeDataset(group, "species_computed_kg", s.speciesComputed);
  if (s.hasPending) {
    dem::CellSources p = s.pending;
    forEachPending([&](const char* name, std::vector<double>& v,
                       int) { h5::writeDataset(group, std::string("pending_") + name, v); },
                   p);
  }
}

StaggeredState readStaggeredState(const std::string& path, std::uint64_t cells, int species) {
  StaggeredState s;
  s.speciesComputed.assign(static_cast<std::size_t>(species), 0.0);
  const h5::Handle file = h5::openFile(path);
  if (!h5::exists(file, "/server") || !h5::exists(file, "/server/staggered")) {
    return s;
  }
  const h5::Handle group = h5::openGroup(file, "/server/staggered", path);
  s.hasPending = h5::readAttribute<int>(group, "has_pending", path) != 0;
  s.heatApplied = h5::readAttribute<double>(group, "heat_applied_J", path);
  s.pendingDt = h5::readAttribute<double>(group, "pending_dt_s", path);
  s.speciesComputed = h5::readDataset<double>(group, "species_computed_kg", path,
                                              static_cast<std::int64_t>(species));
  if (s.hasPending) {
    forEachPending(
        [&](const char* name, std::vector<double>& v, int width) {
          const std::string dataset = std::string("pending_") + name;
          if (width < 0 && !h5::exists(group, dataset)) { // optional (Q_rad, mom_p): zeros
            v.assign(static_cast<std::size_t>(cells) * static_cast<std::size_t>(-width), 0.0);
            return;
          }
          const auto n = static_cast<std::int64_t>(cells) *
                         (width == 0 ? static_cast<std::int64_t>(species) : std::abs(width));
          v = h5::readDataset<double>(group, dataset, path, n);
        },
        s.pending);
  }
  return s;
}

} // namespace coredem::server
