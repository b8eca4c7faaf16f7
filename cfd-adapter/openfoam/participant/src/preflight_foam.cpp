// Pre-flight of the OpenFOAM participant's case (openfoam.h): its dictionaries and fields read
// simply (readFoamField), gravity, gas properties, gas state and decomposition against case.yaml.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numeric>
#include <regex>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include <coredem/common/log.h>
#include <coredem/common/yaml_section.h>
#include <coredem/orchestrator/gas_data.h>
#include <coredem/orchestrator/preflight_locator.h>
#include <coredem/participant/foam_field.h>
#include <coredem/participant/openfoam.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

using preflight::dot;
using preflight::fmtVec;
using preflight::Locator;

// ------------------------------------------------------------------------- OpenFOAM files

/// A keyword entry "key value;" of an OpenFOAM dictionary file: the value text and its line.
struct FoamEntry {
  std::string value;
  int line = 0;
};

std::optional<FoamEntry> foamEntry(const fs::path& file, const std::string& key) {
  std::ifstream in(file);
  if (!in) {
    return std::nullopt;
  }
  std::string line;
  int n = 0;
  const std::regex re("^\\s*" + key + "\\s+([^;]*);");
  while (std::getline(in, line)) {
    ++n;
    std::smatch m;
    if (std::regex_search(line, m, re)) {
      return FoamEntry{m[1].str(), n};
    }
  }
  return std::nullopt;
}

/// The last number of an entry's value ("[0 2 -1 0 0 0 0] 1.5e-05" or "1.5e-05").
std::optional<double> foamScalar(const std::string& value) {
  std::istringstream in(
      value.substr(value.find(']') == std::string::npos ? 0 : value.find(']') + 1));
  double v = 0.0;
  std::optional<double> last;
  while (in >> v) {
    last = v;
  }
  return last;
}

bool close(double a, double b) {
  return std::abs(a - b) <= kFoamEqualityRelTol * std::max(std::abs(a), std::abs(b));
}

/// The bounding box of an OpenFOAM case's mesh points, from constant/polyMesh/points (ASCII) or,
/// before meshing, from the vertices of system/blockMeshDict (times its scale); the file it came
/// from. nullopt when neither can be read simply (binary or compressed points, macros, ...).
struct MeshBounds {
  Vec3 lo, hi;
  std::string from;
  /// False for a blockMeshDict with curved edges: its vertices bound the mesh from inside only.
  bool exact = true;
};

std::optional<MeshBounds> foamMeshBounds(const fs::path& dir) {
  auto read = [](const fs::path& file) -> std::optional<std::string> {
    std::ifstream in(file);
    if (!in) {
      return std::nullopt;
    }
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  };
  auto bounds = [](const std::string& list, double scale) -> std::optional<std::pair<Vec3, Vec3>> {
    static const std::regex point("\\(\\s*([-+0-9.eE]+)\\s+([-+0-9.eE]+)\\s+([-+0-9.eE]+)\\s*\\)");
    Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    std::size_t n = 0;
    for (std::sregex_iterator it(list.begin(), list.end(), point), end; it != end; ++it, ++n) {
      for (int d = 0; d < 3; ++d) {
        const double v = std::strtod((*it)[d + 1].str().c_str(), nullptr) * scale;
        lo[d] = std::min(lo[d], v);
        hi[d] = std::max(hi[d], v);
      }
    }
    if (n == 0) {
      return std::nullopt;
    }
    return std::make_pair(lo, hi);
  };
  const fs::path pointsFile = dir / "constant" / "polyMesh" / "points";
  if (const auto text = read(pointsFile)) {
    if (text->find("binary") != std::string::npos) {
      return std::nullopt;
    }
    const auto open = text->find('(', text->find('}') == std::string::npos ? 0 : text->find('}'));
    if (open == std::string::npos) {
      return std::nullopt;
    }
    if (const auto b = bounds(text->substr(open + 1), 1.0)) {
      return MeshBounds{b->first, b->second, pointsFile.string()};
    }
    return std::nullopt;
  }
  const fs::path dictFile = dir / "system" / "blockMeshDict";
  const auto text = read(dictFile);
  if (!text || text->find('$') != std::string::npos ||
      text->find("#include") != std::string::npos || text->find("#calc") != std::string::npos) {
    return std::nullopt;
  }
  double scale = 1.0;
  for (const char* key : {"scale", "convertToMeters"}) {
    if (const auto e = foamEntry(dictFile, key)) {
      if (const auto v = foamScalar(e->value)) {
        scale = *v;
      }
    }
  }
  const auto v = text->find("vertices");
  const auto open = v == std::string::npos ? v : text->find('(', v);
  const auto shut = open == std::string::npos ? open : text->find(");", open);
  if (shut == std::string::npos) {
    return std::nullopt;
  }
  if (const auto b = bounds(text->substr(open + 1, shut - open - 1), scale)) {
    static const std::regex curved(R"(\b(arc|spline|simpleSpline|polyLine|BSpline|project)\b)");
    return MeshBounds{b->first, b->second, dictFile.string(),
                      !std::regex_search(*text, curved)};
  }
  return std::nullopt;
}

std::string readAll(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}


/// 0/ of the OpenFOAM case: species fields against case.yaml species, and the gas state (T > 0,
/// mass fractions in [0, 1] summing to 1).
void checkFoamGasState(const CaseConfig& c, const Locator& at, const fs::path& dir) {
  auto log = logger("orchestrator");
  const fs::path zero = dir / "0";
  // Species fields: each case.yaml species has 0/<name>.
  for (std::size_t i = 0; i < c.species.size(); ++i) {
    const fs::path f = zero / c.species[i].name;
    if (!fs::is_regular_file(f)) {
      at.fail({"species", std::to_string(i), "name"}, fmt::format("species[{}].name", i),
              fmt::format("gas species '{}', but the OpenFOAM case has no field {} (its initial "
                          "and inlet mass fraction); add the field, or remove the species",
                          c.species[i].name, f.string()));
    }
  }
  // ... and no other mass-fraction field: a dimensionless volScalarField not named alpha* (phase
  // fractions) or Ydefault (OpenFOAM's field for species without their own).
  std::vector<std::string> names;
  for (const auto& s : c.species) {
    names.push_back(s.name);
  }
  if (fs::is_directory(zero)) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(zero)) {
      files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      const std::string name = f.filename().string();
      if (!fs::is_regular_file(f) || name.rfind("alpha", 0) == 0 || name == "Ydefault" ||
          std::find(names.begin(), names.end(), name) != names.end() ||
          (names.empty() && name == kAirSpecies)) {
        continue;
      }
      const FoamFieldValues v = readFoamField(f);
      if (v.className == "volScalarField" && v.dimensions == "0 0 0 0 0 0 0") {
        at.fail({"species"}, "species",
                fmt::format("{}:{}: {} is a dimensionless field (a mass fraction) of the OpenFOAM "
                            "case, but case.yaml has no gas species '{}' (species: {}); add it to "
                            "species, or remove the file",
                            f.string(), v.dimensionsLine, name, name,
                            names.empty() ? std::string("none") : yaml::join(names)));
      }
    }
  }
  // Temperature: every uniform value > 0.
  const fs::path tFile = zero / "T";
  const FoamFieldValues T = readFoamField(tFile);
  for (const auto& v : T.values) {
    if (!v.uniform) {
      log->info("{}:{}: {} of T is non-uniform: not checked before start", tFile.string(), v.line,
                v.patch);
    } else if (!(v.value > 0.0)) {
      at.fail({"cfd", "case"}, "cfd.case",
              fmt::format("{}:{}: {} T = {:.6g} K: the gas temperature must be > 0 K",
                          tFile.string(), v.line, v.patch, v.value));
    }
  }
  // ideal_gas: the initial temperature of case.yaml is the one of 0/T.
  if (c.gasProperties.idealGas() && !T.values.empty() && T.values.front().uniform &&
      T.values.front().patch == "internalField" &&
      !close(T.values.front().value, c.gasProperties.temperature)) {
    const bool has = at.root()["gas_properties"] && at.root()["gas_properties"]["temperature"];
    at.fail({"gas_properties", "temperature"}, "gas_properties.temperature",
            fmt::format("{:.6g} K{} (the initial gas of the ideal-gas model), but {}:{} gives "
                        "internalField T = {:.6g} K; give the same value in both (relative "
                        "tolerance {:.0e})",
                        c.gasProperties.temperature,
                        has ? "" : " (the default; no value in case.yaml)", tFile.string(),
                        T.values.front().line, T.values.front().value, kFoamEqualityRelTol));
  }
  // ideal_gas solves p in Pa: a kinematic 0/p (the constant model's) is accepted only as a zero
  // gauge pressure, which is the same field in Pa (the run's copy gets Pa dimensions).
  const fs::path pFile = zero / "p";
  const FoamFieldValues P = readFoamField(pFile);
  if (c.gasProperties.idealGas() && P.found && P.dimensions == kKinematicPressureDimensions) {
    if (isZeroGaugeKinematicPressure(P)) {
      log->info("{}:{}: p is a zero gauge pressure in m2/s2: the run's copy gets dimensions "
                "[{}] (Pa), which the ideal-gas model solves",
                pFile.string(), P.dimensionsLine, kPressureDimensions);
    } else {
      at.fail({"gas_properties", "model"}, "gas_properties.model",
              fmt::format("ideal_gas solves p in Pa, but {}:{} is the constant model's kinematic "
                          "pressure (dimensions [{}], m2/s2) with values or patch types that are "
                          "not a zero gauge pressure; give 0/p dimensions [{}] and its values in "
                          "Pa",
                          pFile.string(), P.dimensionsLine, kKinematicPressureDimensions,
                          kPressureDimensions));
    }
  }
  if (c.species.empty()) {
    return;
  }
  // Mass fractions: each in [0, 1]; where every species is uniform, they sum to 1.
  std::vector<FoamFieldValues> Y;
  for (const auto& s : c.species) {
    Y.push_back(readFoamField(zero / s.name));
  }
  std::vector<std::string> places; // internalField and the patches, in the first file's order
  for (std::size_t k = 0; k < Y.size(); ++k) {
    const fs::path f = zero / c.species[k].name;
    for (const auto& v : Y[k].values) {
      if (std::find(places.begin(), places.end(), v.patch) == places.end()) {
        places.push_back(v.patch);
      }
      if (!v.uniform) {
        log->info("{}:{}: {} of {} is non-uniform: not checked before start", f.string(), v.line,
                  v.patch, c.species[k].name);
      } else if (!(v.value >= 0.0 && v.value <= 1.0)) {
        at.fail({"cfd", "case"}, "cfd.case",
                fmt::format("{}:{}: {} mass fraction {} = {:.10g}: must lie in [0, 1]", f.string(),
                            v.line, v.patch, c.species[k].name, v.value));
      }
    }
  }
  for (const auto& place : places) {
    double sum = 0.0;
    std::string terms;
    bool all = true;
    for (std::size_t k = 0; k < Y.size() && all; ++k) {
      const auto it = std::find_if(Y[k].values.begin(), Y[k].values.end(),
                                   [&](const FoamFieldValue& v) { return v.patch == place; });
      if (it == Y[k].values.end() || !it->uniform) {
        all = false;
        break;
      }
      sum += it->value;
      terms += fmt::format("{}{} {:.10g} ({}:{})", k ? " + " : "", c.species[k].name, it->value,
                           (zero / c.species[k].name).filename().string(), it->line);
    }
    if (!all) {
      if (place != "internalField") {
        log->info("{}: patch {} is not a uniform fixedValue in every species field: its mass "
                  "fractions are not summed before start",
                  zero.string(), place);
      }
      continue;
    }
    if (std::abs(sum - 1.0) > kMassFractionSumTol) {
      at.fail({"species"}, "species",
              fmt::format("the mass fractions of {} in {} sum to {:.12g}, not 1 (tolerance "
                          "{:.0e}): {}; make them sum to 1",
                          place, zero.string(), sum, kMassFractionSumTol, terms));
    }
  }
}

/// constant/thermophysicalProperties of the OpenFOAM case: with ideal_gas coredem writes it (a
/// user's copy must be exactly that one); with constant it must not exist (it would select the
/// variable-density solver).
void checkThermophysicalProperties(const CaseConfig& c, const Locator& at, const fs::path& dir) {
  const fs::path file = dir / kThermophysicalProperties;
  if (!fs::exists(file)) {
    return;
  }
  const bool has = at.root()["gas_properties"] && at.root()["gas_properties"]["model"];
  if (!c.gasProperties.idealGas()) {
    at.fail({"gas_properties", "model"}, "gas_properties.model",
            fmt::format("constant{} (properties from constant/transportProperties), but {}:1 "
                        "exists and would select the ideal-gas solver: the gas model is "
                        "ambiguous; set gas_properties.model: ideal_gas (coredem then writes that "
                        "file from case.yaml) or remove the file",
                        has ? "" : " (the default; no model in case.yaml)", file.string()));
  }
  const std::string user = readAll(file), generated = thermophysicalPropertiesText(c);
  if (user == generated) {
    return;
  }
  // The first line that differs, for the message.
  std::istringstream a(user), b(generated);
  std::string la, lb;
  int line = 0;
  while (true) {
    ++line;
    const bool ga = bool(std::getline(a, la)), gb = bool(std::getline(b, lb));
    if (!ga || !gb || la != lb) {
      break;
    }
  }
  at.fail({"gas_properties", "model"}, "gas_properties.model",
          fmt::format("ideal_gas: coredem writes constant/thermophysicalProperties from case.yaml "
                      "into the run, but the OpenFOAM case has its own ({}:{} reads '{}', coredem "
                      "would write '{}'), which would be overwritten: remove it; case.yaml "
                      "defines the gas",
                      file.string(), line, la, lb));
}

} // namespace

/// Cells of the CFD mesh: the note "nCells:N" of constant/polyMesh/owner, else the product of
/// the cell counts of every hex block of system/blockMeshDict; nullopt when neither says.
std::optional<long long> foamCellCount(const fs::path& dir) {
  std::ifstream owner(dir / "constant" / "polyMesh" / "owner");
  std::string text((std::istreambuf_iterator<char>(owner)), std::istreambuf_iterator<char>());
  std::smatch m;
  const std::string head = text.substr(0, 4096);
  if (std::regex_search(head, m, std::regex("nCells:\\s*([0-9]+)"))) {
    return std::stoll(m[1].str());
  }
  std::ifstream dict(dir / "system" / "blockMeshDict");
  text.assign((std::istreambuf_iterator<char>(dict)), std::istreambuf_iterator<char>());
  const std::regex hex(
      "hex\\s*\\([^)]*\\)\\s*(?:\\w+\\s*)?\\(\\s*([0-9]+)\\s+([0-9]+)\\s+([0-9]+)\\s*\\)");
  long long cells = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), hex); it != std::sregex_iterator();
       ++it) {
    cells += std::stoll((*it)[1].str()) * std::stoll((*it)[2].str()) * std::stoll((*it)[3].str());
  }
  if (cells > 0) {
    return cells;
  }
  return std::nullopt;
}

/// cfd.ranks > 1: at most one rank per mesh cell, and a system/decomposeParDict of the case (when
/// it has one) for the same number of subdomains with a method (coredem writes one, method
/// simple, when the case has none).
void checkDecomposition(const CaseConfig& c, const Locator& at, const fs::path& dir) {
  if (c.cfd.ranks <= 1) {
    return;
  }
  if (const auto cells = foamCellCount(dir); cells && c.cfd.ranks > *cells) {
    at.fail({"cfd", "ranks"}, "cfd.ranks",
            fmt::format("{} ranks for a mesh of {} cells ({}): every rank needs cells; use at "
                        "most {} ranks",
                        c.cfd.ranks, *cells, dir.string(), *cells));
  }
  const fs::path dict = dir / "system" / "decomposeParDict";
  if (!fs::exists(dict)) {
    return;
  }
  const auto n = foamEntry(dict, "numberOfSubdomains");
  const auto method = foamEntry(dict, "method");
  if (!method || method->value.empty()) {
    at.fail({"cfd", "ranks"}, "cfd.ranks",
            fmt::format("{} names no decomposition method (method simple with simpleCoeffs, "
                        "hierarchical, ...): add one, or remove the file and coredem writes one",
                        dict.string()));
  }
  if (!n || std::atoi(n->value.c_str()) != c.cfd.ranks) {
    at.fail({"cfd", "ranks"}, "cfd.ranks",
            fmt::format("{} ranks, but {}:{} decomposes into {} subdomains: give the same number "
                        "in both",
                        c.cfd.ranks, dict.string(), n ? n->line : 0,
                        n ? n->value : std::string("(no numberOfSubdomains)")));
  }
}

/// ideal_gas with chemistry: coredemFoam solves Y and T with the mass flux of the previous outer
/// iteration, so one outer corrector conserves species mass only to O(Δt) of the density change
/// (docs/coredemFoam.md "Variable-density gas"); reacting cases need nOuterCorrectors >=
/// kMinOuterCorrectorsReacting in system/fvSolution (OpenFOAM's default, without the entry, is 1).
void checkOuterCorrectors(const CaseConfig& c, const Locator& at, const fs::path& dir) {
  if (!c.gasProperties.idealGas() || !c.usesChemistry() || c.species.empty()) {
    return;
  }
  const fs::path file = dir / "system" / "fvSolution";
  if (!fs::exists(file)) {
    return; // coredemFoam refuses a case without fvSolution itself
  }
  const auto e = foamEntry(file, "nOuterCorrectors");
  const int n = e ? std::atoi(e->value.c_str()) : 1;
  if (n >= kMinOuterCorrectorsReacting) {
    return;
  }
  at.fail({"gas_properties", "model"}, "gas_properties.model",
          fmt::format("ideal_gas with reactions needs at least {} PIMPLE outer correctors, but "
                      "{}{} gives nOuterCorrectors {}{}: with fewer, the species and energy "
                      "equations use the last step's mass flux and species mass is conserved "
                      "only to O(dt) of the density change; set nOuterCorrectors {} in its PIMPLE "
                      "dictionary",
                      kMinOuterCorrectorsReacting, file.string(),
                      e ? fmt::format(":{}", e->line) : std::string(), n,
                      e ? "" : " (no entry: OpenFOAM's default)", kMinOuterCorrectorsReacting));
}

void checkOpenFoamCase(const CaseConfig& c) {
  const Locator at(c);
  const fs::path dir = c.caseDir / c.cfd.caseFolder;
  const fs::path gFile = dir / "constant" / "g";
  if (const auto g = foamEntry(gFile, "value")) {
    const auto open = g->value.find('('), shut = g->value.find(')');
    std::istringstream in(open != std::string::npos && shut != std::string::npos
                              ? g->value.substr(open + 1, shut - open - 1)
                              : std::string());
    Vec3 foam{};
    if (in >> foam[0] >> foam[1] >> foam[2]) {
      const double norm =
          std::max(std::sqrt(dot(foam, foam)), std::sqrt(dot(c.gravity, c.gravity)));
      bool same = true;
      for (int d = 0; d < 3; ++d) {
        same = same && std::abs(foam[d] - c.gravity[d]) <= kFoamEqualityRelTol * norm;
      }
      if (!same) {
        at.fail({"gravity"}, "gravity",
                fmt::format("{} m/s2 (the DEM), but {}:{} gives ({:.6g} {:.6g} {:.6g}) (the "
                            "gas); give the same vector in both",
                            fmtVec(c.gravity), gFile.string(), g->line, foam[0], foam[1], foam[2]));
      }
    }
  }
  const fs::path tFile = dir / "constant" / "transportProperties";
  // With ideal_gas the properties are computed: no constant values to compare.
  const bool constant = !c.gasProperties.idealGas();
  auto scalar = [&](const std::string& key) -> std::optional<std::pair<double, int>> {
    if (!constant) {
      return std::nullopt;
    }
    const auto e = foamEntry(tFile, key);
    if (!e) {
      return std::nullopt;
    }
    const auto v = foamScalar(e->value);
    if (!v) {
      return std::nullopt;
    }
    return std::make_pair(*v, e->line);
  };
  const auto rho = scalar("rho"), nu = scalar("nu"), cp = scalar("cp"), kappa = scalar("kappa");
  const auto& gp = c.gasProperties;
  const bool given = bool(at.root()["gas_properties"]);
  auto compare = [&](const char* key, double yamlValue, double foamValue, const std::string& what,
                     int line, const char* unit) {
    if (close(yamlValue, foamValue)) {
      return;
    }
    const bool has = given && at.root()["gas_properties"][key];
    at.fail({"gas_properties", key}, fmt::format("gas_properties.{}", key),
            fmt::format("{:.6g} {}{} (the DEM's drag and heat transfer), but {}:{} gives {} = "
                        "{:.6g} {} (the gas); give the same value in both (relative tolerance "
                        "{:.0e})",
                        yamlValue, unit, has ? "" : " (the default; no value in case.yaml)",
                        tFile.string(), line, what, foamValue, unit, kFoamEqualityRelTol));
  };
  if (rho) {
    compare("density", gp.density, rho->first, "rho", rho->second, "kg/m3");
  }
  if (nu && rho) {
    compare("viscosity", gp.viscosity, nu->first * rho->first,
            fmt::format("nu·rho = {:.6g}·{:.6g}", nu->first, rho->first), nu->second, "Pa s");
  }
  if (cp) {
    compare("cp", gp.cp, cp->first, "cp", cp->second, "J/kg/K");
  }
  if (kappa) {
    compare("conductivity", gp.conductivity, kappa->first, "kappa", kappa->second, "W/m/K");
  }
  // One clip of the gas fraction (models: {eps_min}, passed as coredemFoam -epsMin): an old
  // alphacMin of transportProperties must equal it.
  if (const auto a = scalar("alphacMin"); a && a->first != c.epsMin) {
    at.fail({"models", "eps_min"}, "models.eps_min",
            fmt::format("{} (the clip of the gas fraction for the DEM's drag and the gas), but "
                        "{}:{} gives alphacMin = {}: remove alphacMin there (the case's value "
                        "reaches coredemFoam) or set models: {{eps_min: {}}}",
                        c.epsMin, tFile.string(), a->second, a->first, a->first));
  }
  // The coupling grid covers the fluid domain: the mesh's points lie in the grid's box (the grid
  // is a box, so that is enough; coredemFoam checks every cell's volume again at start). Curved
  // blockMesh edges can bulge beyond the vertices: coredemFoam catches those.
  if (const auto mesh = foamMeshBounds(dir)) {
    for (int d = 0; d < 3; ++d) {
      const double lo = c.grid.origin[d];
      const double hi = lo + c.grid.spacing[d] * double(c.grid.cells[d]);
      const double tol = 1e-6 * c.grid.spacing[d];
      if (mesh->lo[d] < lo - tol || mesh->hi[d] > hi + tol) {
        const char* axis[] = {"x", "y", "z"};
        at.fail({"grid"}, "grid",
                fmt::format("the coupling grid spans {} = [{:.6g}, {:.6g}] m but the CFD mesh "
                            "({}) spans [{:.6g}, {:.6g}] m: the coupling grid must cover the "
                            "fluid domain; enlarge grid.cells or move grid.origin",
                            axis[d], lo, hi, mesh->from, mesh->lo[d], mesh->hi[d]));
      } else if (mesh->exact && (mesh->lo[d] - lo > c.grid.spacing[d] + tol ||
                                 hi - mesh->hi[d] > c.grid.spacing[d] + tol)) {
        // A grid rounded up to whole cells may overhang the mesh by up to one cell; more is a
        // spacing, count or origin that does not fit the mesh (20 % too coarse, or 2^31 m).
        const char* axis[] = {"x", "y", "z"};
        at.fail({"grid"}, "grid",
                fmt::format("the coupling grid spans {} = [{:.6g}, {:.6g}] m, more than one grid "
                            "cell ({:.6g} m) beyond the CFD mesh ({}), which spans [{:.6g}, {:.6g}] "
                            "m: its coupling cells outside the fluid would map the particles' "
                            "sources onto too few gas cells; fit grid.spacing, grid.cells and "
                            "grid.origin to the mesh",
                            axis[d], lo, hi, c.grid.spacing[d], mesh->from, mesh->lo[d],
                            mesh->hi[d]));
      }
    }
    // The particles' walls inside the CFD domain: particles beyond the mesh would sit in coupling
    // cells without fluid (the DEM server refuses them at the first step).
    if (c.walls.box) {
      for (int d = 0; d < 3; ++d) {
        const double tol = 1e-6 * c.grid.spacing[d];
        if (c.walls.box->first[d] < mesh->lo[d] - tol ||
            c.walls.box->second[d] > mesh->hi[d] + tol) {
          const char* axis[] = {"x", "y", "z"};
          at.fail({"walls", "box"}, "walls.box",
                  fmt::format("the particle walls span {} = [{:.6g}, {:.6g}] m but the CFD mesh "
                              "({}) spans [{:.6g}, {:.6g}] m: particles beyond the mesh get no "
                              "gas; shrink walls.box or enlarge the mesh",
                              axis[d], c.walls.box->first[d], c.walls.box->second[d], mesh->from,
                              mesh->lo[d], mesh->hi[d]));
        }
      }
    }
  }
  checkRevolvedWallsInsideFoamMesh(c, at, dir);
  checkThermophysicalProperties(c, at, dir);
  checkFoamGasState(c, at, dir);
  checkDecomposition(c, at, dir);
  checkOuterCorrectors(c, at, dir);
  checkFoamBoundaries(c, at, dir);
}

} // namespace coredem::orchestrator
