// case.yaml's inlets and outlets in the OpenFOAM case (openfoam.h): their pre-flight against the
// mesh's patches and the fields of 0/, and the patch entries written into the run's copy of 0/.
#include <cctype>
#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include <coredem/common/log.h>
#include <coredem/common/yaml_section.h>
#include <coredem/orchestrator/preflight_locator.h>
#include <coredem/participant/foam_field.h>
#include <coredem/participant/foam_patches.h>
#include <coredem/participant/openfoam.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

// ------------------------------------------------------- OpenFOAM dictionary text, simply

/// Index of the next character of `t` from `i` that is neither white space nor inside a comment.
std::size_t skipSpace(const std::string& t, std::size_t i) {
  while (i < t.size()) {
    if (std::isspace(static_cast<unsigned char>(t[i]))) {
      ++i;
    } else if (t.compare(i, 2, "//") == 0) {
      i = t.find('\n', i);
      i = i == std::string::npos ? t.size() : i;
    } else if (t.compare(i, 2, "/*") == 0) {
      i = t.find("*/", i + 2);
      i = i == std::string::npos ? t.size() : i + 2;
    } else {
      break;
    }
  }
  return i;
}

bool isDelimiter(char c) {
  return std::isspace(static_cast<unsigned char>(c)) || c == '{' || c == '}' || c == '(' ||
         c == ')' || c == ';';
}

/// The token of `t` at `i` (after skipSpace): a delimiter character, a quoted string (with its
/// quotes) or a word; `end` is set past it.
std::string token(const std::string& t, std::size_t i, std::size_t& end) {
  if (i >= t.size()) {
    end = i;
    return {};
  }
  if (isDelimiter(t[i])) {
    end = i + 1;
    return t.substr(i, 1);
  }
  if (t[i] == '"') {
    const std::size_t close = t.find('"', i + 1);
    end = close == std::string::npos ? t.size() : close + 1;
    return t.substr(i, end - i);
  }
  end = i;
  while (end < t.size() && !isDelimiter(t[end])) {
    ++end;
  }
  return t.substr(i, end - i);
}

/// Past the bracket that closes the one at `open` ('{' or '('), comments and strings skipped.
std::size_t matching(const std::string& t, std::size_t open) {
  const char o = t[open], c = o == '{' ? '}' : ')';
  int depth = 0;
  std::size_t i = open;
  while (i < t.size()) {
    i = skipSpace(t, i);
    std::size_t end = i;
    const std::string tok = token(t, i, end);
    if (tok.size() == 1 && tok[0] == o) {
      ++depth;
    } else if (tok.size() == 1 && tok[0] == c && --depth == 0) {
      return end;
    }
    i = end;
  }
  return std::string::npos;
}

/// The entries of the dictionary whose '{' is at `open`: (keyword, begin of the keyword, end of
/// the entry) of every sub-dictionary entry; other entries and directives are skipped.
struct DictEntry {
  std::string keyword;
  std::size_t begin = 0, end = 0, open = 0;
};

std::vector<DictEntry> subDictionaries(const std::string& t, std::size_t open) {
  std::vector<DictEntry> out;
  std::size_t i = open + 1;
  while (true) {
    i = skipSpace(t, i);
    std::size_t end = i;
    const std::string key = token(t, i, end);
    if (key.empty() || key == "}") {
      return out;
    }
    if (key[0] == '#') { // #includeEtc "...": a directive to the end of its line
      i = t.find('\n', i);
      if (i == std::string::npos) {
        return out;
      }
      continue;
    }
    const std::size_t next = skipSpace(t, end);
    std::size_t after = next;
    const std::string tok = token(t, next, after);
    if (tok == "{") {
      const std::size_t close = matching(t, next);
      if (close == std::string::npos) {
        return out;
      }
      out.push_back({key, i, close, next});
      i = close;
    } else { // keyword value ...;
      const std::size_t semi = t.find(';', end);
      if (semi == std::string::npos) {
        return out;
      }
      i = semi + 1;
    }
  }
}

/// Position of the '{' or '(' that follows the top-level keyword `key`, or npos.
std::size_t blockOf(const std::string& t, const std::string& key, char bracket) {
  std::size_t i = 0;
  while (i < t.size()) {
    i = skipSpace(t, i);
    std::size_t end = i;
    const std::string tok = token(t, i, end);
    if (tok.empty()) {
      break;
    }
    if (tok == key) {
      const std::size_t next = skipSpace(t, end);
      return next < t.size() && t[next] == bracket ? next : std::string::npos;
    }
    if (tok == "{" || tok == "(") {
      end = matching(t, i);
      if (end == std::string::npos) {
        break;
      }
    }
    i = end;
  }
  return std::string::npos;
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// (name, type) of the patches of the case's mesh (constant/polyMesh/boundary) or, before
/// meshing, of system/blockMeshDict's `boundary` list; `from` names the file. Empty when neither
/// can be read simply.
std::vector<std::pair<std::string, std::string>> patchTypes(const fs::path& dir,
                                                            std::string& from) {
  std::vector<std::pair<std::string, std::string>> out;
  if (fs::exists(dir / "constant" / "polyMesh" / "boundary")) {
    from = (dir / "constant" / "polyMesh" / "boundary").string();
    try {
      for (const FoamPatch& p : readFoamBoundary(dir)) {
        out.emplace_back(p.name, p.type);
      }
    } catch (const FoamMeshError&) {
      out.clear();
    }
    return out;
  }
  from = (dir / "system" / "blockMeshDict").string();
  const std::string t = readText(from);
  const std::size_t open = blockOf(t, "boundary", '(');
  if (open == std::string::npos) {
    return out;
  }
  const std::size_t close = matching(t, open);
  std::size_t i = open + 1;
  while (close != std::string::npos && i < close) {
    i = skipSpace(t, i);
    std::size_t end = i;
    const std::string name = token(t, i, end);
    const std::size_t brace = skipSpace(t, end);
    if (name == ")" || brace >= t.size() || t[brace] != '{') {
      break;
    }
    const std::size_t shut = matching(t, brace);
    const std::string body = t.substr(brace, shut - brace);
    std::string type;
    const std::size_t k = body.find("type");
    if (k != std::string::npos) {
      std::size_t e = 0;
      type = token(body, skipSpace(body, k + 4), e);
    }
    out.emplace_back(name, type);
    i = shut;
  }
  return out;
}

std::string vec(const Vec3& v) {
  return fmt::format("({} {} {})", v[0], v[1], v[2]);
}

/// The patch entry's lines for 0/U of an inlet.
std::string inletVelocityEntry(const InletConfig& in, std::size_t i) {
  if (in.velocityTable.empty()) {
    // The face velocity is the superficial one over the gas fraction of the cell at the face.
    return fmt::format("        // coredem: inlets[{}] of case.yaml, superficial velocity {} m/s\n"
                       "        type            interstitialInletVelocity;\n"
                       "        inletVelocity   uniform {};\n"
                       "        alpha           alphac;\n"
                       "        value           uniform {};\n",
                       i, vec(in.velocity), vec(in.velocity), vec(in.velocity));
  }
  std::string rows;
  for (const auto& r : in.velocityTable) {
    rows += fmt::format(" ({} {})", r[0], vec({r[1], r[2], r[3]}));
  }
  return fmt::format("        // coredem: inlets[{}] of case.yaml, superficial velocity table (t, m/s)\n"
                     "        type            uniformFixedValue;\n"
                     "        uniformValue    table ({} );\n"
                     "        value           uniform {};\n",
                     i, rows, vec(in.velocity));
}

std::string fixedValueEntry(double v, const std::string& what) {
  return fmt::format("        // coredem: {}\n"
                     "        type            fixedValue;\n"
                     "        value           uniform {};\n",
                     what, v);
}

/// Rewrites the patch entries of the field file `file` (entries: patch -> lines).
void rewriteField(const fs::path& file,
                  const std::vector<std::pair<std::string, std::string>>& entries) {
  if (entries.empty()) {
    return;
  }
  std::string text = readText(file);
  for (const auto& [patch, lines] : entries) {
    text = replaceFoamPatchEntry(text, patch, lines, file.string());
  }
  writeFoamFile(file, text);
}

} // namespace

std::string replaceFoamPatchEntry(const std::string& text, const std::string& patch,
                                  const std::string& lines, const std::string& file) {
  const std::size_t open = blockOf(text, "boundaryField", '{');
  if (open == std::string::npos) {
    throw UserError(fmt::format("{}: no boundaryField {{ ... }} found; coredem writes the patch "
                                "'{}' there (case.yaml inlets/outlets)",
                                file, patch));
  }
  const std::string entry = fmt::format("    {}\n    {{\n{}    }}", patch, lines);
  for (const DictEntry& e : subDictionaries(text, open)) {
    if (e.keyword == patch || e.keyword == "\"" + patch + "\"") {
      return text.substr(0, e.begin) + entry.substr(4) + text.substr(e.end);
    }
  }
  // Only matched by a pattern ("(inlet|outlet)", ".*") or not at all: an exact name comes first.
  return text.substr(0, open + 1) + "\n" + entry + "\n" + text.substr(open + 1);
}

void checkFoamBoundaries(const CaseConfig& c, const preflight::Locator& at, const fs::path& dir) {
  std::string from;
  const auto patches = patchTypes(dir, from);
  const auto check = [&](const std::string& patch, const char* list, std::size_t index) {
    const bool inlet = std::string(list) == "inlets";
    const std::string key = fmt::format("{}[{}]", list, index);
    const std::vector<std::string> path = {list, std::to_string(index), "patch"};
    if (patches.empty()) {
      return; // the mesh cannot be read simply: coredemFoam refuses an unknown patch at start
    }
    std::vector<std::string> names;
    const std::pair<std::string, std::string>* found = nullptr;
    for (const auto& p : patches) {
      names.push_back(p.first + " (" + p.second + ")");
      found = p.first == patch ? &p : found;
    }
    if (!found) {
      at.fail(path, key + ".patch",
              fmt::format("no patch '{}' in {}; its patches: {}", patch, from, yaml::join(names)));
    }
    if (found->second != "patch") {
      at.fail(path, key + ".patch",
              fmt::format("patch '{}' is of type '{}' in {}; gas enters or leaves through a "
                          "patch of type 'patch'",
                          patch, found->second, from));
    }
    // The field the boundary condition fixes must not be fixed by the case's other field too.
    const fs::path other = dir / "0" / (inlet ? "p" : "U");
    for (const auto& [name, type] : readFoamField(other).patchTypes) {
      const bool fixes = type == "fixedValue" || type == "totalPressure" ||
                         type == "prghPressure" || type == "interstitialInletVelocity" ||
                         type == "flowRateInletVelocity" || type == "uniformFixedValue";
      if (name == patch && fixes) {
        at.fail(path, key + ".patch",
                fmt::format("{} fixes {} at '{}' (type {}), but an {} fixes the {} there: give "
                            "{} ({})",
                            other.string(), inlet ? "the pressure" : "the velocity", patch, type,
                            inlet ? "inlet" : "outlet", inlet ? "velocity" : "pressure",
                            inlet ? "p zeroGradient or fixedFluxPressure there"
                                  : "U zeroGradient or pressureInletOutletVelocity there",
                            "or remove the patch from case.yaml"));
      }
    }
  };
  for (std::size_t i = 0; i < c.inlets.size(); ++i) {
    const InletConfig& in = c.inlets[i];
    const std::string key = fmt::format("inlets[{}]", i);
    check(in.patch, "inlets", i);
    logger("orchestrator")
        ->info("{} (patch {}): {}", key, in.patch,
               in.velocityTable.empty()
                   ? fmt::format("superficial velocity {} m/s, written into the run's 0/U as "
                                 "interstitialInletVelocity (the face velocity is it over the "
                                 "gas fraction there: the inflow is superficial with or without "
                                 "particles in the inlet cells)",
                                 vec(in.velocity))
                   : std::string("superficial velocity table, written into the run's 0/U as "
                                 "uniformFixedValue: the face velocity, superficial only while "
                                 "the inlet cells hold no particles"));
    if (in.temperature && !fs::exists(dir / "0" / "T")) {
      at.fail({"inlets", std::to_string(i), "temperature"}, key + ".temperature",
              fmt::format("the OpenFOAM case has no temperature field ({}); remove the key or "
                          "give the case a 0/T",
                          (dir / "0" / "T").string()));
    }
    for (const auto& sp : in.massFractions.empty() ? std::vector<SpeciesConfig>{} : c.species) {
      if (!fs::exists(dir / "0" / sp.name)) {
        at.fail({"inlets", std::to_string(i), "mass_fractions"}, key + ".mass_fractions",
                fmt::format("the OpenFOAM case has no field {} for species '{}'",
                            (dir / "0" / sp.name).string(), sp.name));
      }
    }
  }
  for (std::size_t i = 0; i < c.outlets.size(); ++i) {
    check(c.outlets[i].patch, "outlets", i);
  }
}

void writeFoamBoundaries(const CaseConfig& c, const fs::path& workDir) {
  const fs::path zero = workDir / "0";
  std::vector<std::pair<std::string, std::string>> u, p, t;
  std::vector<std::vector<std::pair<std::string, std::string>>> y(c.species.size());
  for (std::size_t i = 0; i < c.inlets.size(); ++i) {
    const InletConfig& in = c.inlets[i];
    u.emplace_back(in.patch, inletVelocityEntry(in, i));
    if (in.temperature) {
      t.emplace_back(in.patch,
                     fixedValueEntry(*in.temperature, fmt::format("inlets[{}].temperature", i)));
    }
    for (std::size_t k = 0; k < in.massFractions.size(); ++k) {
      y[k].emplace_back(in.patch,
                        fixedValueEntry(in.massFractions[k],
                                        fmt::format("inlets[{}].mass_fractions.{}", i,
                                                    c.species[k].name)));
    }
  }
  for (std::size_t i = 0; i < c.outlets.size(); ++i) {
    const std::string what = fmt::format("outlets[{}] of case.yaml", i);
    p.emplace_back(c.outlets[i].patch,
                   fixedValueEntry(0.0, what + ": the case's pressure (gauge 0)"));
    u.emplace_back(c.outlets[i].patch,
                   fmt::format("        // coredem: {}\n"
                               "        type            pressureInletOutletVelocity;\n"
                               "        value           uniform (0 0 0);\n",
                               what));
  }
  rewriteField(zero / "U", u);
  rewriteField(zero / "p", p);
  rewriteField(zero / "T", t);
  for (std::size_t k = 0; k < y.size(); ++k) {
    rewriteField(zero / c.species[k].name, y[k]);
  }
}

} // namespace coredem::orchestrator
