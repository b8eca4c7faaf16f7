// The prescribed gas of coredem-gas (docs/client.md, "coredem-gas input").
#include "coredem/gas/gas_model.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "coredem/common/check.h"
#include "coredem/common/yaml_section.h"

namespace coredem::gas {

std::array<double, 3> CartesianGrid::cellCentre(std::int64_t c) const {
  const std::int64_t i = c % counts[0];
  const std::int64_t j = (c / counts[0]) % counts[1];
  const std::int64_t k = c / (counts[0] * counts[1]);
  return {origin[0] + (static_cast<double>(i) + 0.5) * spacing[0],
          origin[1] + (static_cast<double>(j) + 0.5) * spacing[1],
          origin[2] + (static_cast<double>(k) + 0.5) * spacing[2]};
}

template <int D>
TimeSeries<D>::TimeSeries(std::vector<double> times, std::vector<Value> values)
    : _times(std::move(times))
    , _values(std::move(values)) {
  COREDEM_ASSERT(!_times.empty() && _times.size() == _values.size());
}

template <int D>
typename TimeSeries<D>::Value TimeSeries<D>::at(double t) const {
  if (_times.size() == 1 || t <= _times.front()) {
    return _values.front();
  }
  if (t >= _times.back()) {
    return _values.back();
  }
  const auto it = std::upper_bound(_times.begin(), _times.end(), t);
  const std::size_t hi = static_cast<std::size_t>(it - _times.begin());
  const std::size_t lo = hi - 1;
  const double w = (t - _times[lo]) / (_times[hi] - _times[lo]);
  Value v{};
  for (int d = 0; d < D; ++d) {
    v[d] = _values[lo][d] + w * (_values[hi][d] - _values[lo][d]);
  }
  return v;
}

template class TimeSeries<1>;
template class TimeSeries<3>;

namespace {

enum Field { kUg = 0, kGradP, kTg, kRhoG, kMuG, kKappaG, kCpG, kYg, kFieldCount };
constexpr const char* kFieldNames[kFieldCount] = {"u_g",  "grad_p",  "T_g",  "rho_g",
                                                  "mu_g", "kappa_g", "cp_g", "Y_g"};
constexpr const char* kUnits[kFieldCount] = {"m/s",  "Pa/m",  "K",      "kg/m^3",
                                             "Pa s", "W/m/K", "J/kg/K", "-"};

bool isVectorField(int f) {
  return f == kUg || f == kGradP;
}

/// Tolerance on the sum of mass fractions (docs/client.md).
constexpr double kCompositionTolerance = 1e-9;

std::string allowedKeys(bool region) {
  std::string s;
  if (region) {
    s = "name, box, ";
  }
  for (int f = 0; f < kFieldCount; ++f) {
    s += kFieldNames[f];
    s += ", ";
  }
  s += region ? "(no nested regions)" : "regions";
  return s;
}

/// Location of a node for messages: "file:line:col" (as the orchestrator's case schema).
struct Ctx {
  std::string where;
  std::string at(const YAML::Node& n) const {
    const auto m = n.Mark();
    if (m.line < 0) {
      return where;
    }
    return fmt::format("{}:{}:{}", where, m.line + 1, m.column + 1);
  }
};

double parseNumber(const Ctx& ctx, const YAML::Node& n, const std::string& key, const char* what) {
  COREDEM_CHECK(n.IsScalar(), "{}: key '{}': expected {} (a number), got a {}", ctx.at(n), key,
                what,
                n.IsSequence() ? "sequence"
                : n.IsMap()    ? "mapping"
                               : "null value");
  double v = 0.0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    COREDEM_CHECK(false, "{}: key '{}': '{}' is not a number (expected {})", ctx.at(n), key,
                  n.Scalar(), what);
  }
  COREDEM_CHECK(std::isfinite(v), "{}: key '{}': value {} is not finite", ctx.at(n), key, v);
  return v;
}

template <int D>
typename TimeSeries<D>::Value parseValue(const Ctx& ctx, const YAML::Node& n,
                                         const std::string& key) {
  typename TimeSeries<D>::Value v{};
  if constexpr (D == 1) {
    v[0] = parseNumber(ctx, n, key, "a scalar");
  } else {
    COREDEM_CHECK(n.IsSequence() && n.size() == D,
                  "{}: key '{}': expected a {}-vector like [0.0, 0.0, 1.0]", ctx.at(n), key, D);
    for (int d = 0; d < D; ++d) {
      v[d] = parseNumber(ctx, n[d], key, "a vector component");
    }
  }
  return v;
}

/// A literal or {table: [[t, v], ...]}.
template <int D>
TimeSeries<D> parseSeries(const Ctx& ctx, const YAML::Node& n, const std::string& key) {
  if (!n.IsMap()) {
    return TimeSeries<D>(parseValue<D>(ctx, n, key));
  }
  for (const auto& kv : n) {
    const auto k = kv.first.as<std::string>();
    COREDEM_CHECK(k == "table",
                  "{}: key '{}.{}' is not allowed: a time-dependent value is "
                  "written {{table: [[t0, v0], [t1, v1], ...]}}",
                  ctx.at(kv.first), key, k);
  }
  const auto table = n["table"];
  COREDEM_CHECK(table.IsSequence() && table.size() >= 1,
                "{}: key '{}.table': expected a non-empty list of [t, value] pairs", ctx.at(n),
                key);
  std::vector<double> times;
  std::vector<typename TimeSeries<D>::Value> values;
  for (std::size_t i = 0; i < table.size(); ++i) {
    const auto row = table[i];
    const std::string rk = fmt::format("{}.table[{}]", key, i);
    COREDEM_CHECK(row.IsSequence() && row.size() == 2,
                  "{}: key '{}': expected a pair [t, value] (t in s)", ctx.at(row), rk);
    const double t = parseNumber(ctx, row[0], rk, "a time in s");
    COREDEM_CHECK(times.empty() || t > times.back(),
                  "{}: key '{}': times must be strictly increasing ({} after {})", ctx.at(row), rk,
                  t, times.empty() ? 0.0 : times.back());
    times.push_back(t);
    values.push_back(parseValue<D>(ctx, row[1], rk));
  }
  return TimeSeries<D>(std::move(times), std::move(values));
}

/// All breakpoints of a set of series (the sum of piecewise-linear functions is piecewise
/// linear with breakpoints in this union).
std::vector<double> breakpoints(const std::map<std::string, TimeSeries<1>>& ys) {
  std::set<double> ts;
  for (const auto& [name, s] : ys) {
    ts.insert(s.times().begin(), s.times().end());
  }
  return {ts.begin(), ts.end()};
}

struct FieldSet {
  std::optional<TimeSeries<3>> vec[2];              // u_g, grad_p
  std::optional<TimeSeries<1>> scalar[kFieldCount]; // T_g .. cp_g (indices kTg..kCpG)
  std::optional<std::map<std::string, TimeSeries<1>>> Y;
  int yLine = 0;

  bool has(int f) const {
    if (isVectorField(f)) {
      return vec[f].has_value();
    }
    if (f == kYg) {
      return Y.has_value();
    }
    return scalar[f].has_value();
  }
};

void parseField(const Ctx& ctx, FieldSet& fs, int f, const YAML::Node& n, const std::string& key) {
  if (isVectorField(f)) {
    fs.vec[f] = parseSeries<3>(ctx, n, key);
    return;
  }
  if (f != kYg) {
    auto s = parseSeries<1>(ctx, n, key);
    for (double t : s.times()) {
      const double v = s.at(t)[0];
      COREDEM_CHECK(v > 0.0, "{}: key '{}': {} must be > 0 {} (got {} at t = {} s)", ctx.at(n), key,
                    kFieldNames[f], kUnits[f], v, t);
    }
    fs.scalar[f] = std::move(s);
    return;
  }
  COREDEM_CHECK(n.IsMap() && n.size() >= 1,
                "{}: key '{}': expected a mapping species name -> mass fraction, e.g. {{N2: 1.0}}",
                ctx.at(n), key);
  std::map<std::string, TimeSeries<1>> ys;
  for (const auto& kv : n) {
    const auto name = kv.first.as<std::string>();
    const std::string sk = fmt::format("{}.{}", key, name);
    auto s = parseSeries<1>(ctx, kv.second, sk);
    for (double t : s.times()) {
      const double v = s.at(t)[0];
      COREDEM_CHECK(v >= 0.0 && v <= 1.0,
                    "{}: key '{}': a mass fraction must be in [0, 1] (got {} "
                    "at t = {} s)",
                    ctx.at(kv.second), sk, v, t);
    }
    ys.emplace(name, std::move(s));
  }
  for (double t : breakpoints(ys)) {
    double sum = 0.0;
    for (const auto& [name, s] : ys) {
      sum += s.at(t)[0];
    }
    COREDEM_CHECK(std::abs(sum - 1.0) <= kCompositionTolerance,
                  "{}: key '{}': the mass fractions sum to {:.12g} at t = {} s; they must sum to 1 "
                  "(within {})",
                  ctx.at(n), key, sum, t, kCompositionTolerance);
  }
  fs.Y = std::move(ys);
  fs.yLine = n.Mark().line + 1;
}

int fieldIndex(const std::string& k) {
  for (int f = 0; f < kFieldCount; ++f) {
    if (k == kFieldNames[f]) {
      return f;
    }
  }
  return -1;
}

struct Region {
  std::string name;
  std::array<double, 3> lo{}, hi{};
  FieldSet fields;
};

std::array<double, 3> parseVec3(const Ctx& ctx, const YAML::Node& n, const std::string& key) {
  return parseValue<3>(ctx, n, key);
}

} // namespace

struct GasModel::Impl {
  std::string where;
  FieldSet domain;
  std::vector<Region> regions;

  // Bound state.
  bool bound = false;
  CartesianGrid grid;
  std::vector<std::string> species;
  /// owner[f][c]: 0 = domain value, r+1 = region r. Empty when no region sets field f.
  std::vector<std::int32_t> owner[kFieldCount];

  const FieldSet& source(int s) const { return s == 0 ? domain : regions[s - 1].fields; }
  std::string sourceName(int s) const {
    return s == 0 ? std::string("domain") : fmt::format("region '{}'", regions[s - 1].name);
  }
};

GasModel::GasModel(std::unique_ptr<Impl> impl)
    : _impl(std::move(impl)) {}
GasModel::GasModel(GasModel&&) noexcept = default;
GasModel& GasModel::operator=(GasModel&&) noexcept = default;
GasModel::~GasModel() = default;

GasModel GasModel::fromYaml(const YAML::Node& node, const std::string& where) {
  auto impl = std::make_unique<Impl>();
  impl->where = where;
  const Ctx ctx{where};
  COREDEM_CHECK(node.IsMap(), "{}: the gas description must be a mapping with keys {}",
                ctx.at(node), allowedKeys(false));
  // Defaults: air at 20 °C, at rest (docs/client.md).
  auto& d = impl->domain;
  d.vec[kUg] = TimeSeries<3>({0.0, 0.0, 0.0});
  d.vec[kGradP] = TimeSeries<3>({0.0, 0.0, 0.0});
  d.scalar[kTg] = TimeSeries<1>({293.15});
  d.scalar[kRhoG] = TimeSeries<1>({1.204});
  d.scalar[kMuG] = TimeSeries<1>({1.81e-5});
  d.scalar[kKappaG] = TimeSeries<1>({0.0257});
  d.scalar[kCpG] = TimeSeries<1>({1005.0});

  for (const auto& kv : node) {
    const auto key = kv.first.as<std::string>();
    if (key == "regions") {
      continue;
    }
    const int f = fieldIndex(key);
    COREDEM_CHECK(f >= 0, "{}: unknown key '{}' in the gas description; allowed keys: {}",
                  ctx.at(kv.first), key, allowedKeys(false));
    parseField(ctx, d, f, kv.second, key);
  }
  if (const auto rs = node["regions"]) {
    COREDEM_CHECK(rs.IsSequence(),
                  "{}: key 'regions': expected a list of regions, each "
                  "{{name, box: {{min: [x,y,z], max: [x,y,z]}}, <fields>}}",
                  ctx.at(rs));
    for (std::size_t i = 0; i < rs.size(); ++i) {
      const auto rn = rs[i];
      const std::string rk = fmt::format("regions[{}]", i);
      COREDEM_CHECK(rn.IsMap(), "{}: key '{}': expected a mapping with keys {}", ctx.at(rn), rk,
                    allowedKeys(true));
      Region r;
      r.name = rn["name"] ? rn["name"].as<std::string>() : fmt::format("#{}", i);
      bool hasBox = false;
      for (const auto& kv : rn) {
        const auto key = kv.first.as<std::string>();
        const std::string fk = fmt::format("{}.{}", rk, key);
        if (key == "name") {
          continue;
        }
        if (key == "box") {
          const auto b = kv.second;
          COREDEM_CHECK(b.IsMap() && b["min"] && b["max"] && b.size() == 2,
                        "{}: key '{}': expected {{min: [x, y, z], max: [x, y, z]}} (m)", ctx.at(b),
                        fk);
          r.lo = parseVec3(ctx, b["min"], fk + ".min");
          r.hi = parseVec3(ctx, b["max"], fk + ".max");
          for (int a = 0; a < 3; ++a) {
            COREDEM_CHECK(r.lo[a] < r.hi[a],
                          "{}: key '{}': min must be < max on every axis "
                          "(axis {}: {} >= {})",
                          ctx.at(b), fk, a, r.lo[a], r.hi[a]);
          }
          hasBox = true;
          continue;
        }
        const int f = fieldIndex(key);
        COREDEM_CHECK(f >= 0, "{}: unknown key '{}'; allowed keys: {}", ctx.at(kv.first), fk,
                      allowedKeys(true));
        parseField(ctx, r.fields, f, kv.second, fk);
      }
      COREDEM_CHECK(hasBox,
                    "{}: key '{}' (region '{}') has no 'box: {{min: [x,y,z], max: "
                    "[x,y,z]}}'",
                    ctx.at(rn), rk, r.name);
      impl->regions.push_back(std::move(r));
    }
  }
  return GasModel(std::move(impl));
}

GasModel GasModel::fromFile(const std::string& file, const std::string& key) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    COREDEM_CHECK(false, "cannot read the case file '{}': check the path (--case)", file);
  } catch (const YAML::Exception& e) {
    COREDEM_CHECK(false, "{}:{}:{}: YAML syntax error: {}", file, e.mark.line + 1,
                  e.mark.column + 1, e.msg);
  }
  yaml::checkUniqueKeys(root, file); // a key given twice: refused (ConfigError, a UserError)
  YAML::Node node = root;
  std::string done;
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) {
    COREDEM_CHECK(node.IsMap() && node[part],
                  "{}: no key '{}{}' (the gas description is taken "
                  "from --key '{}')",
                  file, done, part, key);
    node = node[part];
    done += part + ".";
  }
  return fromYaml(node, file);
}

void GasModel::bind(const CartesianGrid& grid, const std::vector<std::string>& species) {
  auto& m = *_impl;
  for (int a = 0; a < 3; ++a) {
    COREDEM_CHECK(grid.counts[a] >= 1 && grid.spacing[a] > 0.0,
                  "coupling grid: counts must be >= 1 and spacing > 0 on every axis (axis {}: "
                  "count {}, spacing {})",
                  a, grid.counts[a], grid.spacing[a]);
  }
  const std::set<std::string> known(species.begin(), species.end());
  auto checkNames = [&](const FieldSet& fs, const std::string& owner) {
    if (!fs.Y) {
      return;
    }
    for (const auto& [name, s] : *fs.Y) {
      COREDEM_CHECK(known.count(name) == 1,
                    "{}:{}: {} Y_g names species '{}', which is not in "
                    "the case's species list [{}]",
                    m.where, fs.yLine, owner, name, fmt::join(species, ", "));
    }
  };
  checkNames(m.domain, "the domain");
  for (const auto& r : m.regions) {
    checkNames(r.fields, fmt::format("region '{}'", r.name));
  }

  const std::int64_t n = grid.cellCount();
  for (int f = 0; f < kFieldCount; ++f) {
    m.owner[f].clear();
    const bool anyRegion = std::any_of(m.regions.begin(), m.regions.end(),
                                       [&](const Region& r) { return r.fields.has(f); });
    const bool domainHas = m.domain.has(f);
    if (!anyRegion && domainHas) {
      continue;
    }
    if (f == kYg && species.empty()) {
      continue;
    }
    m.owner[f].assign(static_cast<std::size_t>(n), domainHas ? 0 : -1);
    for (std::int64_t c = 0; c < n; ++c) {
      const auto x = grid.cellCentre(c);
      for (std::size_t r = 0; r < m.regions.size(); ++r) {
        const auto& reg = m.regions[r];
        if (reg.fields.has(f) && x[0] >= reg.lo[0] && x[0] < reg.hi[0] && x[1] >= reg.lo[1] &&
            x[1] < reg.hi[1] && x[2] >= reg.lo[2] && x[2] < reg.hi[2]) {
          m.owner[f][static_cast<std::size_t>(c)] = static_cast<std::int32_t>(r + 1);
        }
      }
      COREDEM_CHECK(m.owner[f][static_cast<std::size_t>(c)] >= 0,
                    "{}: the case has species [{}] but no Y_g is given for cell {} (centre {}, "
                    "{}, {} m): add a domain-wide 'Y_g: {{name: fraction, ...}}'",
                    m.where, fmt::join(species, ", "), c, x[0], x[1], x[2]);
    }
  }
  m.grid = grid;
  m.species = species;
  m.bound = true;
}

void GasModel::evaluate(double t, GasFieldArrays& out) const {
  const auto& m = *_impl;
  COREDEM_CHECK(m.bound, "GasModel::evaluate: call bind(grid, species) first");
  const auto n = static_cast<std::size_t>(m.grid.cellCount());
  const std::size_t ns = m.species.size();
  const int nSources = static_cast<int>(m.regions.size()) + 1;

  for (int f = 0; f < kFieldCount; ++f) {
    const std::size_t width = isVectorField(f) ? 3 : (f == kYg ? ns : 1);
    // Value of every source at t (sources that do not set f keep an empty entry).
    std::vector<std::vector<double>> values(static_cast<std::size_t>(nSources));
    for (int s = 0; s < nSources; ++s) {
      const auto& fs = m.source(s);
      if (!fs.has(f)) {
        continue;
      }
      auto& v = values[static_cast<std::size_t>(s)];
      if (isVectorField(f)) {
        const auto a = fs.vec[f]->at(t);
        v.assign(a.begin(), a.end());
      } else if (f == kYg) {
        v.assign(ns, 0.0);
        double sum = 0.0;
        for (std::size_t k = 0; k < ns; ++k) {
          const auto it = fs.Y->find(m.species[k]);
          if (it != fs.Y->end()) {
            v[k] = it->second.at(t)[0];
            sum += v[k];
          }
        }
        COREDEM_CHECK(std::abs(sum - 1.0) <= kCompositionTolerance,
                      "{}: the {} Y_g sums to {:.12g} at t = {} s (must be 1 within {})", m.where,
                      m.sourceName(s), sum, t, kCompositionTolerance);
      } else {
        v.assign(1, fs.scalar[f]->at(t)[0]);
      }
    }
    std::vector<double>* dst = nullptr;
    switch (f) {
    case kUg:
      dst = &out.u_g;
      break;
    case kGradP:
      dst = &out.grad_p;
      break;
    case kTg:
      dst = &out.T_g;
      break;
    case kRhoG:
      dst = &out.rho_g;
      break;
    case kMuG:
      dst = &out.mu_g;
      break;
    case kKappaG:
      dst = &out.kappa_g;
      break;
    case kCpG:
      dst = &out.cp_g;
      break;
    default:
      dst = &out.Y_g;
      break;
    }
    dst->resize(n * width);
    if (width == 0) {
      continue;
    }
    const auto& own = m.owner[f];
    for (std::size_t c = 0; c < n; ++c) {
      const auto s = own.empty() ? 0 : static_cast<std::size_t>(own[c]);
      std::copy(values[s].begin(), values[s].end(),
                dst->begin() + static_cast<std::ptrdiff_t>(c * width));
    }
  }
}

std::size_t GasModel::regionCount() const {
  return _impl->regions.size();
}

std::string GasModel::describe() const {
  const auto& m = *_impl;
  std::string s = fmt::format("gas from {}: domain-wide values", m.where);
  for (const auto& r : m.regions) {
    std::vector<std::string> fs;
    for (int f = 0; f < kFieldCount; ++f) {
      if (r.fields.has(f)) {
        fs.emplace_back(kFieldNames[f]);
      }
    }
    s += fmt::format("; region '{}' [{}, {}, {}]-[{}, {}, {}] sets {}", r.name, r.lo[0], r.lo[1],
                     r.lo[2], r.hi[0], r.hi[1], r.hi[2], fmt::join(fs, ", "));
  }
  return s;
}

} // namespace coredem::gas
