// inlets and outlets: the CFD boundary conditions declared in case.yaml and written into the CFD
// participant's case (docs/case-schema.md "Inlets and outlets").
#include <algorithm>
#include <cmath>
#include <set>

#include <yaml-cpp/yaml.h>

#include <coredem/common/limits.h>
#include <coredem/orchestrator/participants.h>

#include "case_read.h"

namespace coredem::orchestrator::caseread {

using yaml::join;

namespace {

/// "the list, e.g. [0.0, 1.2, 0.0]" for messages about a value of the wrong shape.
std::string shapeOf(const YAML::Node& n) {
  if (n.IsScalar()) {
    return fmt::format("'{}'", n.Scalar());
  }
  return n.IsSequence() ? fmt::format("a list of {}", n.size()) : std::string("a mapping");
}

Vec3 readVelocity(const Section& s) {
  const YAML::Node v = s.raw("superficial_velocity");
  const std::string key = s.full("superficial_velocity");
  if (!v.IsSequence() || v.size() != 3) {
    s.fail(s.markOf("superficial_velocity"), key,
           fmt::format("expected the superficial gas velocity [ux, uy, uz] in m/s (the gas volume "
                       "flow per unit area of the patch), got {}",
                       shapeOf(v)));
  }
  const double max = GasRanges{}.speedMax;
  Vec3 u{};
  for (std::size_t d = 0; d < 3; ++d) {
    u[d] = s.numberOf(v[d], fmt::format("{}[{}]", key, d), -max, max, "m/s");
  }
  return u;
}

std::vector<std::array<double, 4>> readVelocityTable(const Section& s) {
  const YAML::Node t = s.raw("superficial_velocity_table");
  const std::string key = s.full("superficial_velocity_table");
  if (!t.IsSequence() || t.size() < 2) {
    s.fail(s.markOf("superficial_velocity_table"), key,
           "expected at least two rows [t, ux, uy, uz] (s, m/s), e.g. [[0, 0, 0, 0], "
           "[0.2, 0, 1.2, 0]]: linear in between, held beyond the ends");
  }
  const double max = GasRanges{}.speedMax;
  std::vector<std::array<double, 4>> rows;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const std::string row = fmt::format("{}[{}]", key, k);
    if (!t[k].IsSequence() || t[k].size() != 4) {
      s.fail(t[k].Mark(), row,
             fmt::format("expected a row [t, ux, uy, uz] (s, m/s), got {}", shapeOf(t[k])));
    }
    std::array<double, 4> r{};
    r[0] = s.numberOf(t[k][0], row + "[0]", 0.0, kBig, "time in s, >= 0");
    for (std::size_t d = 1; d < 4; ++d) {
      r[d] = s.numberOf(t[k][d], fmt::format("{}[{}]", row, d), -max, max, "m/s");
    }
    if (!rows.empty() && r[0] <= rows.back()[0]) {
      s.fail(t[k][0].Mark(), row + "[0]",
             fmt::format("times must increase: {} s follows {} s", r[0], rows.back()[0]));
    }
    rows.push_back(r);
  }
  return rows;
}

std::vector<double> readMassFractions(const Section& s, const CaseConfig& c) {
  const YAML::Node m = s.raw("mass_fractions");
  const std::string key = s.full("mass_fractions");
  std::vector<std::string> names;
  for (const auto& sp : c.species) {
    names.push_back(sp.name);
  }
  if (c.species.empty()) {
    s.fail(s.markOf("mass_fractions"), key,
           "the case has no gas species (case.yaml species); remove the key");
  }
  if (!m.IsMap()) {
    s.fail(s.markOf("mass_fractions"), key,
           fmt::format("expected a mapping species -> mass fraction of every species ({})",
                       join(names)));
  }
  std::vector<double> y(c.species.size(), -1.0);
  double sum = 0.0;
  for (const auto& kv : m) {
    const std::string name = kv.first.Scalar();
    const auto at = std::find(names.begin(), names.end(), name);
    if (at == names.end()) {
      s.fail(kv.first.Mark(), key + "." + name,
             fmt::format("unknown species; the case's species are {}", join(names)));
    }
    y[std::size_t(at - names.begin())] =
        s.numberOf(kv.second, key + "." + name, 0.0, 1.0, "mass fraction in [0, 1]");
    sum += y[std::size_t(at - names.begin())];
  }
  for (std::size_t i = 0; i < y.size(); ++i) {
    if (y[i] < 0.0) {
      s.fail(s.markOf("mass_fractions"), key,
             fmt::format("'{}' is missing: give the mass fraction of every species ({})", names[i],
                         join(names)));
    }
  }
  if (std::abs(sum - 1.0) > 1e-9) {
    s.fail(s.markOf("mass_fractions"), key,
           fmt::format("mass fractions sum to {:.12g}, must sum to 1 (within 1e-9)", sum));
  }
  return y;
}

} // namespace

/// inlets, outlets: patches of the CFD participant's mesh with their gas state
void readBoundaries(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (!top.has("inlets") && !top.has("outlets")) {
    return;
  }
  const char* section = top.has("inlets") ? "inlets" : "outlets";
  if (!participant(c.cfd.participant).takesBoundaries) {
    std::vector<std::string> with;
    for (const auto& p : participantTable()) {
      if (p.takesBoundaries) {
        with.push_back(p.name);
      }
    }
    top.fail(top.markOf(section), section,
             fmt::format("{} takes no boundary conditions from case.yaml (its gas is given in "
                         "its own section); inlets and outlets are written into the case of {}",
                         c.cfd.participant, join(with)));
  }
  std::set<std::string> patches;
  const auto patchOf = [&](const Section& s) {
    const std::string name = s.string("patch", std::nullopt, "a patch of the CFD mesh");
    if (!patches.insert(name).second) {
      s.fail(s.markOf("patch"), s.full("patch"),
             fmt::format("patch '{}' is given twice among inlets and outlets", name));
    }
    return name;
  };
  if (top.has("inlets")) {
    for (const Section& s : top.list("inlets",
                                     {"patch", "superficial_velocity", "superficial_velocity_table",
                                      "temperature", "mass_fractions"},
                                     "gas inlets")) {
      InletConfig in;
      in.patch = patchOf(s);
      const bool constant = s.has("superficial_velocity"),
                 table = s.has("superficial_velocity_table");
      if (constant == table) {
        s.fail(s.markOf(constant ? "superficial_velocity_table" : "patch"), s.path(),
               "give one of superficial_velocity: [ux, uy, uz] (m/s) or "
               "superficial_velocity_table: [[t, ux, uy, uz], ...]");
      }
      if (constant) {
        in.velocity = readVelocity(s);
      } else {
        in.velocityTable = readVelocityTable(s);
        const auto& first = in.velocityTable.front();
        in.velocity = {first[1], first[2], first[3]};
      }
      if (s.has("temperature")) {
        const GasRanges g;
        in.temperature = s.number(
            "temperature", std::nullopt, g.temperatureMin, g.temperatureMax,
            fmt::format("K, the DEM's gas range [{}, {}]", g.temperatureMin, g.temperatureMax));
      }
      if (s.has("mass_fractions")) {
        in.massFractions = readMassFractions(s, c);
      }
      c.inlets.push_back(in);
    }
  }
  if (top.has("outlets")) {
    for (const Section& s : top.list("outlets", {"patch"}, "gas outlets")) {
      c.outlets.push_back(OutletConfig{patchOf(s)});
    }
  }
}

} // namespace coredem::orchestrator::caseread
