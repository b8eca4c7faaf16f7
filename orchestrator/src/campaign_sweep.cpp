// Sweep files: parsing, validation, member expansion and case-key substitution (campaign.h).
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include <coredem/common/yaml_section.h>
#include <coredem/orchestrator/campaign.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/preflight.h>

namespace coredem::orchestrator {

namespace {

namespace fs = std::filesystem;

/// One step of a key path: a mapping key, or (index >= 0) a sequence index.
struct PathStep {
  std::string key;
  long index = -1;
};

std::vector<PathStep> parsePath(const std::string& path) {
  static const std::regex segment(R"(([A-Za-z_][A-Za-z0-9_\-]*)((\[[0-9]+\])*))");
  static const std::regex index(R"(\[([0-9]+)\])");
  std::vector<PathStep> steps;
  std::stringstream ss(path);
  std::string part;
  bool any = false;
  while (std::getline(ss, part, '.')) {
    any = true;
    std::smatch m;
    if (!std::regex_match(part, m, segment)) {
      throw CaseError(fmt::format("'{}': not a case key path (write keys separated by '.', "
                                  "list entries as [i], e.g. particles[0].diameter)",
                                  path));
    }
    steps.push_back({m[1].str(), -1});
    const std::string idx = m[2].str();
    for (std::sregex_iterator it(idx.begin(), idx.end(), index), end; it != end; ++it) {
      const std::string digits = (*it)[1].str();
      if (digits.size() > 9) { // beyond any list a case holds (and beyond a long)
        throw CaseError(fmt::format("'{}': list index {} is out of range (a case file's lists "
                                    "are far shorter)",
                                    path, digits));
      }
      steps.push_back({"", std::stol(digits)});
    }
  }
  if (!any || path.back() == '.') {
    throw CaseError(fmt::format("'{}': not a case key path", path));
  }
  return steps;
}

std::string flowYaml(const YAML::Node& n) {
  YAML::Emitter e;
  e.SetMapFormat(YAML::Flow);
  e.SetSeqFormat(YAML::Flow);
  e << n;
  return e.c_str();
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Error helper for the sweep file: "file:line:col: key: what".
struct SweepReader {
  std::string file;
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key,
                         const std::string& what) const {
    yaml::fail(file, at.Mark(), key, what);
  }
  int integer(const YAML::Node& n, const std::string& key, int min, const std::string& what) const {
    try {
      const long v = std::stol(n.as<std::string>());
      std::size_t used = 0;
      (void)std::stol(n.as<std::string>(), &used);
      if (used != n.as<std::string>().size() || v < min || v > 100000) {
        throw std::invalid_argument("range");
      }
      return static_cast<int>(v);
    } catch (const std::exception&) {
      fail(n, key,
           fmt::format("expected an integer >= {} ({}), got '{}'", min, what,
                       n.IsScalar() ? n.as<std::string>() : flowYaml(n)));
    }
  }
};

const std::set<std::string> kTopKeys = {"name",        "description", "base_case", "executor",
                                        "concurrency", "retries",     "grid",      "members",
                                        "collect",     "slurm"};
const std::set<std::string> kReduces = {"final", "max", "min", "mean"};

/// The `slurm:` section (optional: without it every sbatch default applies).
SlurmOptions parseSlurmSection(const YAML::Node& root, const std::string& file) {
  SlurmOptions o;
  if (!root["slurm"]) {
    return o;
  }
  const yaml::Section s(root["slurm"], file, "slurm",
                        {"partition", "time", "cpus_per_task", "gres", "mem", "max_concurrent",
                         "stop_margin", "extra"},
                        root.Mark());
  o.partition = s.string("partition", "", "the Slurm partition (sbatch --partition)");
  o.time = s.string("time", "",
                    "time limit per member task, as sbatch --time: \"30\" minutes, \"2:00:00\", "
                    "\"1-00:00:00\"");
  if (!o.time.empty()) {
    const auto t = parseSlurmTime(o.time);
    if (!t || *t <= 0) {
      s.fail(s.markOf("time"), "slurm.time",
             fmt::format("'{}' is not a Slurm time limit; write minutes (\"30\"), "
                         "minutes:seconds, hours:minutes:seconds or days-hours[:minutes[:seconds]]",
                         o.time));
    }
    o.timeSeconds = *t;
  }
  o.cpusPerTask = static_cast<int>(
      s.integer("cpus_per_task", 0, 1, 100000, "CPUs per member, sbatch --cpus-per-task"));
  o.gres = s.string("gres", "", "generic resources per member, e.g. gpu:1 (sbatch --gres)");
  o.mem = s.string("mem", "", "memory per member, e.g. 4G (sbatch --mem)");
  o.maxConcurrent = static_cast<int>(s.integer(
      "max_concurrent", 0, 1, 100000, "array tasks running at once; default: concurrency"));
  const long defMargin = o.timeSeconds > 0 ? std::min<long>(120, o.timeSeconds / 4) : 120;
  o.stopMargin = static_cast<int>(
      s.integer("stop_margin", defMargin, 1, 65535,
                "seconds before the time limit at which a member writes a checkpoint and stops"));
  if (o.timeSeconds > 0 && o.stopMargin >= o.timeSeconds) {
    s.fail(s.markOf("stop_margin"), "slurm.stop_margin",
           fmt::format("{} s is not less than the time limit ({} = {} s)", o.stopMargin, o.time,
                       o.timeSeconds));
  }
  if (s.has("extra")) {
    const YAML::Node e = s.raw("extra");
    if (!e.IsSequence()) {
      s.fail(e.Mark(), "slurm.extra",
             fmt::format("expected a list of sbatch arguments, e.g. [--account=proj, "
                         "--qos=normal], got {}",
                         yaml::describe(e)));
    }
    for (const auto& a : e) {
      if (!a.IsScalar() || a.Scalar().empty()) {
        s.fail(a.Mark(), "slurm.extra", "each entry is one sbatch argument (a string)");
      }
      const std::string v = a.Scalar();
      for (const char* own : {"--array", "--output", "--error", "--job-name", "--parsable",
                              "--signal", "--wrap", "--chdir"}) {
        if (v.rfind(own, 0) == 0) {
          s.fail(a.Mark(), "slurm.extra",
                 fmt::format("'{}': {} is set by coredem campaign itself", v, own));
        }
      }
      o.extra.push_back(v);
    }
  }
  return o;
}

} // namespace

std::optional<long> parseSlurmTime(const std::string& text) {
  static const std::regex plain(R"(([0-9]+)(:([0-9]+))?(:([0-9]+))?)");
  static const std::regex days(R"(([0-9]+)-([0-9]+)(:([0-9]+))?(:([0-9]+))?)");
  std::smatch m;
  auto num = [&](int i) { return m[i].matched ? std::stol(m[i].str()) : 0L; };
  try {
    if (std::regex_match(text, m, days)) {
      return num(1) * 86400 + num(2) * 3600 + num(4) * 60 + num(6);
    }
    if (std::regex_match(text, m, plain)) {
      if (m[5].matched) { // h:m:s
        return num(1) * 3600 + num(3) * 60 + num(5);
      }
      return num(1) * 60 + num(3); // minutes[:seconds]
    }
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return std::nullopt;
}

std::string ScalarSpec::label() const {
  if (reduce == "final" || (!from && !to)) {
    return baseLabel();
  }
  return fmt::format("{}@{}..{}:{}", reduce, from ? fmt::format("{}", *from) : "",
                     to ? fmt::format("{}", *to) : "", column);
}

ScalarSpec parseScalarLabel(const std::string& text) {
  ScalarSpec spec;
  const auto colon = text.find(':');
  spec.column = colon == std::string::npos ? text : text.substr(colon + 1);
  std::string reduce = colon == std::string::npos ? "final" : text.substr(0, colon);
  const auto at = reduce.find('@');
  const std::string usage =
      fmt::format("'{}': write COLUMN, REDUCE:COLUMN or REDUCE@FROM..TO:COLUMN with REDUCE one "
                  "of final, max, min, mean and a window of simulated time in s (either end may "
                  "be left out, e.g. mean@0.5..:dp; not for final); COLUMN from timeseries.csv",
                  text);
  if (at != std::string::npos) {
    const std::string window = reduce.substr(at + 1);
    reduce = reduce.substr(0, at);
    const auto dots = window.find("..");
    if (dots == std::string::npos || reduce == "final") {
      throw CaseError(usage);
    }
    auto number = [&](const std::string& t) -> std::optional<double> {
      if (t.empty()) {
        return std::nullopt;
      }
      char* end = nullptr;
      const double v = std::strtod(t.c_str(), &end);
      if (end == nullptr || *end != '\0' || !std::isfinite(v)) {
        throw CaseError(usage);
      }
      return v;
    };
    spec.from = number(window.substr(0, dots));
    spec.to = number(window.substr(dots + 2));
    if (spec.from && spec.to && !(*spec.to > *spec.from)) {
      throw CaseError(fmt::format("'{}': the window's end {} s is not after its start {} s", text,
                                  *spec.to, *spec.from));
    }
  }
  spec.reduce = reduce;
  if (!kReduces.count(spec.reduce) || spec.column.empty()) {
    throw CaseError(usage);
  }
  return spec;
}

std::string setCaseKey(const std::string& caseText, const std::string& path,
                       const std::string& valueYaml) {
  const auto steps = parsePath(path);
  YAML::Node root = YAML::Load(caseText);
  const YAML::Node value = YAML::Load(valueYaml);
  YAML::Node cur = root;
  std::string walked;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const bool last = i + 1 == steps.size();
    const PathStep& s = steps[i];
    const std::string here = walked.empty() ? s.key
                                            : (s.index >= 0 ? walked + fmt::format("[{}]", s.index)
                                                            : walked + "." + s.key);
    if (s.index >= 0) {
      if (!cur.IsSequence()) {
        throw CaseError(fmt::format("'{}': '{}' is not a list in the base case", path, walked));
      }
      if (static_cast<std::size_t>(s.index) >= cur.size()) {
        throw CaseError(fmt::format("'{}': index {} out of range ('{}' has {} entries in the "
                                    "base case)",
                                    path, s.index, walked, cur.size()));
      }
      if (last) {
        cur[s.index] = YAML::Clone(value);
      } else {
        YAML::Node next = cur[s.index];
        cur.reset(next);
      }
    } else {
      if (!(cur.IsMap() || cur.IsNull())) {
        throw CaseError(fmt::format("'{}': '{}' is not a mapping in the base case", path,
                                    walked.empty() ? "the case file" : walked));
      }
      if (last) {
        cur[s.key] = YAML::Clone(value);
      } else {
        if (!cur[s.key]) {
          cur[s.key] = YAML::Node(YAML::NodeType::Map);
        }
        YAML::Node next = cur[s.key];
        cur.reset(next);
      }
    }
    walked = here;
  }
  YAML::Emitter e;
  e << root;
  return std::string(e.c_str()) + "\n";
}

namespace {

/// The sweep's settings: known top-level keys, base_case, name, executor (with its slurm
/// section), concurrency and retries.
void readSettings(const YAML::Node& root, const SweepReader& r, Sweep& sw) {
  for (const auto& kv : root) {
    const std::string k = kv.first.as<std::string>();
    if (!kTopKeys.count(k)) {
      r.fail(kv.first, k,
             "unknown key; allowed keys: name, description, base_case, executor, concurrency, "
             "retries, grid, members, collect, slurm");
    }
  }
  // base case
  if (!root["base_case"] || !root["base_case"].IsScalar()) {
    r.fail(root, "base_case",
           "required: the case folder (or case.yaml) to vary, relative to "
           "the sweep file");
  }
  fs::path base = root["base_case"].as<std::string>();
  if (base.is_relative()) {
    base = sw.file.parent_path() / base;
  }
  if (fs::is_regular_file(base)) {
    base = base.parent_path();
  }
  base = fs::weakly_canonical(base);
  if (!fs::is_regular_file(base / "case.yaml")) {
    r.fail(root["base_case"], "base_case", fmt::format("no case.yaml in '{}'", base.string()));
  }
  sw.baseCase = base;
  sw.name = root["name"] ? root["name"].as<std::string>() : sw.file.stem().string();
  if (sw.name.empty() || sw.name.find('/') != std::string::npos) {
    r.fail(root["name"], "name", "expected a name without '/'");
  }
  if (root["executor"]) {
    sw.executor = root["executor"].as<std::string>();
    if (sw.executor != "local" && sw.executor != "slurm") {
      r.fail(root["executor"], "executor",
             fmt::format("unknown executor '{}'; allowed: local, slurm", sw.executor));
    }
  }
  if (root["slurm"] && sw.executor != "slurm") {
    r.fail(root["slurm"], "slurm", "a slurm section needs 'executor: slurm'");
  }
  if (root["concurrency"]) {
    sw.concurrency = r.integer(root["concurrency"], "concurrency", 1, "members run at once");
  }
  if (root["retries"]) {
    sw.retries = r.integer(root["retries"], "retries", 0, "failed attempts retried per member");
  }
  if (sw.executor == "slurm") {
    sw.slurm = parseSlurmSection(root, r.file);
  }
}

/// The members: grid (cartesian product, first key varies slowest) or explicit members; ids
/// m000, m001, ...
void readMembers(const YAML::Node& root, const SweepReader& r, Sweep& sw) {
  const YAML::Node grid = root["grid"], members = root["members"];
  if (static_cast<bool>(grid) == static_cast<bool>(members)) {
    r.fail(root, grid ? "grid" : "members",
           "give exactly one of 'grid' (key: [values], all combinations) or 'members' (a list "
           "of {key: value} mappings)");
  }
  auto checkPath = [&](const YAML::Node& keyNode, const std::string& where) {
    const std::string path = keyNode.as<std::string>();
    try {
      parsePath(path);
    } catch (const CaseError& e) {
      r.fail(keyNode, where + "." + path, e.what());
    }
    return path;
  };
  std::vector<std::vector<std::string>> gridValues;
  if (grid) {
    if (!grid.IsMap() || grid.size() == 0) {
      r.fail(grid, "grid", "expected a mapping of case keys to lists of values");
    }
    for (const auto& kv : grid) {
      const std::string path = checkPath(kv.first, "grid");
      if (!kv.second.IsSequence() || kv.second.size() == 0) {
        r.fail(kv.second, "grid." + path, "expected a non-empty list of values");
      }
      sw.parameters.push_back(path);
      gridValues.emplace_back();
      for (const auto& v : kv.second) {
        gridValues.back().push_back(flowYaml(v));
      }
    }
    std::size_t total = 1;
    for (const auto& g : gridValues) {
      total *= g.size();
    }
    if (total > 10000) {
      r.fail(grid, "grid", fmt::format("{} members; at most 10000 per campaign", total));
    }
    for (std::size_t m = 0; m < total; ++m) {
      SweepMember mem;
      std::size_t rest = m;
      std::vector<std::size_t> idx(gridValues.size());
      for (std::size_t k = gridValues.size(); k-- > 0;) {
        idx[k] = rest % gridValues[k].size();
        rest /= gridValues[k].size();
      }
      for (std::size_t k = 0; k < gridValues.size(); ++k) {
        mem.values.emplace_back(sw.parameters[k], gridValues[k][idx[k]]);
      }
      sw.members.push_back(std::move(mem));
    }
  } else {
    if (!members.IsSequence() || members.size() == 0) {
      r.fail(members, "members", "expected a non-empty list of {key: value} mappings");
    }
    for (std::size_t i = 0; i < members.size(); ++i) {
      const YAML::Node m = members[i];
      const std::string where = fmt::format("members[{}]", i);
      if (!m.IsMap() || m.size() == 0) {
        r.fail(m, where, "expected a mapping {case key: value}");
      }
      SweepMember mem;
      for (const auto& kv : m) {
        const std::string path = checkPath(kv.first, where);
        if (std::find(sw.parameters.begin(), sw.parameters.end(), path) == sw.parameters.end()) {
          sw.parameters.push_back(path);
        }
        mem.values.emplace_back(path, flowYaml(kv.second));
      }
      sw.members.push_back(std::move(mem));
    }
  }
  for (std::size_t i = 0; i < sw.members.size(); ++i) {
    sw.members[i].id = fmt::format("m{:03d}", i);
  }
}

/// A scalar written as a mapping: {mean: column, from: T, to: T} (one reduction key).
ScalarSpec scalarOfMapping(const YAML::Node& v) {
  std::string text;
  std::string window;
  for (const auto& kv : v) {
    const std::string k = kv.first.as<std::string>();
    if (k == "from" || k == "to") {
      continue;
    }
    if (!text.empty() || !kReduces.count(k)) {
      throw CaseError(fmt::format("'{}': a scalar mapping has one of final, max, min, mean "
                                  "(the column) and optionally from, to (s), e.g. {{mean: dp, "
                                  "from: 0.5}}",
                                  k));
    }
    text = k + "@" + (v["from"] ? v["from"].as<std::string>() : "") + ".." +
           (v["to"] ? v["to"].as<std::string>() : "") + ":" + kv.second.as<std::string>();
  }
  if (text.empty()) {
    throw CaseError("a scalar mapping needs one of final, max, min, mean: {mean: COLUMN}");
  }
  ScalarSpec spec = parseScalarLabel(
      text.find("@..:") != std::string::npos ? text.replace(text.find("@..:"), 4, ":") : text);
  return spec;
}

/// collect: the scalars of summary.csv and the plotted pair (defaults: final mean_T_p against
/// the first swept key).
void readCollect(const YAML::Node& root, const SweepReader& r, Sweep& sw) {
  sw.scalars = {parseScalarLabel("mean_T_p")};
  if (const YAML::Node c = root["collect"]) {
    if (!c.IsMap()) {
      r.fail(c, "collect", "expected a mapping with scalars and plot");
    }
    for (const auto& kv : c) {
      const std::string k = kv.first.as<std::string>();
      if (k != "scalars" && k != "plot" && k != "units") {
        r.fail(kv.first, "collect." + k,
               "unknown key; allowed keys in 'collect': scalars, plot, units");
      }
    }
    if (const YAML::Node s = c["scalars"]) {
      if (!s.IsSequence() || s.size() == 0) {
        r.fail(s, "collect.scalars",
               "expected a list like [mean_T_p, max:dem.kinetic_energy_J, {mean: "
               "gas.pressure_drop_Pa, from: 0.5}]");
      }
      sw.scalars.clear();
      for (const auto& v : s) {
        try {
          sw.scalars.push_back(v.IsMap() ? scalarOfMapping(v)
                                         : parseScalarLabel(v.as<std::string>()));
        } catch (const CaseError& e) {
          r.fail(v, "collect.scalars", e.what());
        } catch (const YAML::Exception& e) {
          r.fail(v, "collect.scalars", e.what());
        }
      }
    }
    if (const YAML::Node u = c["units"]) {
      if (!u.IsMap()) {
        r.fail(u, "collect.units",
               "expected a mapping {swept key or column: unit}, e.g. "
               "{param.U_in: m/s}");
      }
      for (const auto& kv : u) {
        sw.units.emplace_back(kv.first.as<std::string>(), kv.second.as<std::string>());
      }
    }
    if (const YAML::Node p = c["plot"]) {
      if (!p.IsMap()) {
        r.fail(p, "collect.plot", "expected {x: <swept key>, y: <scalar>}");
      }
      if (p["x"]) {
        sw.plotX = p["x"].as<std::string>();
        if (std::find(sw.parameters.begin(), sw.parameters.end(), sw.plotX) ==
            sw.parameters.end()) {
          r.fail(p["x"], "collect.plot.x",
                 fmt::format("'{}' is not a swept key; swept: {}", sw.plotX,
                             fmt::join(sw.parameters, ", ")));
        }
      }
      if (p["y"]) {
        sw.plotY = p["y"].as<std::string>();
        bool found = false;
        for (const auto& s : sw.scalars) {
          if (!found && (s.label() == sw.plotY || s.baseLabel() == sw.plotY)) {
            found = true;
            sw.plotY = s.label();
          }
        }
        if (!found) {
          r.fail(p["y"], "collect.plot.y",
                 fmt::format("'{}' is not one of collect.scalars", sw.plotY));
        }
      }
    }
  }
  if (sw.plotX.empty()) {
    sw.plotX = sw.parameters.front();
  }
  if (sw.plotY.empty()) {
    sw.plotY = sw.scalars.front().label();
  }
}

/// Resolves and validates every member's case (nothing is written).
void resolveMembers(const SweepReader& r, Sweep& sw) {
  const fs::path baseFile = sw.baseCase / "case.yaml";
  const std::string baseText = readFile(baseFile);
  for (const auto& mem : sw.members) {
    std::string text = baseText;
    for (const auto& [path, value] : mem.values) {
      if (path.rfind(kParamPrefix, 0) == 0) {
        continue; // a recorded parameter, not a case key
      }
      try {
        text = setCaseKey(text, path, value);
      } catch (const CaseError& e) {
        throw CaseError(
            fmt::format("{}: member {} ({} = {}): {}", r.file, mem.id, path, value, e.what()));
      } catch (const YAML::Exception& e) {
        throw CaseError(
            fmt::format("{}: member {} ({} = {}): {}", r.file, mem.id, path, value, e.what()));
      }
    }
    std::string header = fmt::format("# campaign {}, member {} of the base case {}:\n", sw.name,
                                     mem.id, sw.baseCase.string());
    for (const auto& [path, value] : mem.values) {
      header += fmt::format("#   {} = {}\n", path, value);
    }
    text = header + text;
    try {
      // named as the file it becomes, so that line numbers match
      // and pre-flighted as `coredem check` does (what every member's run would refuse is
      // refused here, once, before anything is launched)
      const CaseConfig member =
          parseCase(text, fs::path("members") / mem.id / "case" / "case.yaml", sw.baseCase);
      (void)checkCaseConsistency(member);
    } catch (const CaseError& e) {
      std::string vals;
      for (const auto& [path, value] : mem.values) {
        vals += (vals.empty() ? "" : ", ") + path + " = " + value;
      }
      throw CaseError(fmt::format("{}: member {} ({}) gives an invalid case: {}", r.file, mem.id,
                                  vals, e.what()));
    }
    sw.resolvedCases.push_back(std::move(text));
  }
}

} // namespace

Sweep loadSweep(const fs::path& sweepFile) {
  Sweep sw;
  sw.file = fs::absolute(sweepFile);
  SweepReader r{sweepFile.string()};
  if (!fs::is_regular_file(sw.file)) {
    throw CaseError(fmt::format("{}: sweep file not found", sweepFile.string()));
  }
  sw.text = readFile(sw.file);
  YAML::Node root;
  try {
    root = yaml::parse(sw.text, r.file); // also refuses duplicate keys and a second document
  } catch (const CaseError& e) {
    const bool flow = std::string(e.what()).find("flow") != std::string::npos;
    throw CaseError(fmt::format("{}{}", e.what(),
                                flow ? " (a key like particles[0].diameter must be written in "
                                       "a block mapping, one key per line, not inside { })"
                                     : ""));
  }
  if (!root.IsMap()) {
    throw CaseError(fmt::format("{}: a sweep file is a mapping with base_case and grid or "
                                "members (docs/campaigns.md)",
                                r.file));
  }
  readSettings(root, r, sw);
  readMembers(root, r, sw);
  readCollect(root, r, sw);
  resolveMembers(r, sw);
  return sw;
}

} // namespace coredem::orchestrator
