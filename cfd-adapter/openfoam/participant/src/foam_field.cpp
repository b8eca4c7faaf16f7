// OpenFOAM field files read simply (foam_field.h): comments stripped, the FoamFile class, the
// dimensions, and the uniform scalars of internalField and of the fixedValue patches.
#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include <coredem/participant/foam_field.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

/// `text` with // and /* */ comments replaced by spaces (newlines kept, so offsets keep their
/// lines).
std::string withoutComments(std::string text) {
  for (std::size_t i = 0; i + 1 < text.size(); ++i) {
    if (text[i] == '"') { // a string: skip to its end
      const auto end = text.find('"', i + 1);
      i = end == std::string::npos ? text.size() : end;
      continue;
    }
    if (text[i] == '/' && text[i + 1] == '/') {
      for (; i < text.size() && text[i] != '\n'; ++i) {
        text[i] = ' ';
      }
    } else if (text[i] == '/' && text[i + 1] == '*') {
      for (; i < text.size() && !(text[i] == '*' && i + 1 < text.size() && text[i + 1] == '/');
           ++i) {
        if (text[i] != '\n') {
          text[i] = ' ';
        }
      }
      if (i + 1 < text.size()) {
        text[i] = text[i + 1] = ' ';
      }
    }
  }
  return text;
}

int lineAt(const std::string& text, std::size_t pos) {
  return 1 + int(std::count(text.begin(), text.begin() + std::ptrdiff_t(pos), '\n'));
}

/// The value of "uniform X" when X is one number.
std::optional<double> uniformScalar(const std::string& value) {
  std::istringstream in(value);
  double v = 0.0;
  std::string rest;
  if (in >> v && !(in >> rest)) {
    return v;
  }
  return std::nullopt;
}

std::string readAll(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

} // namespace

FoamFieldValues readFoamField(const fs::path& file) {
  FoamFieldValues out;
  std::ifstream probe(file);
  if (!fs::is_regular_file(file) || !probe) {
    return out;
  }
  out.found = true;
  // Scanned by hand, not with std::regex: a nonuniform list can be megabytes long.
  const std::string text = withoutComments(readAll(file));
  const auto isWord = [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '_';
  };
  // Position after the whole word `key` at or after `from` (npos: none before `to`).
  const auto findWord = [&](const std::string& key, std::size_t from, std::size_t to) {
    for (std::size_t p = text.find(key, from); p != std::string::npos && p < to;
         p = text.find(key, p + 1)) {
      const std::size_t e = p + key.size();
      if ((p == 0 || !isWord(text[p - 1])) && e < text.size() && !isWord(text[e])) {
        return e;
      }
    }
    return std::string::npos;
  };
  const auto skipSpace = [&](std::size_t p) {
    while (p < text.size() && std::isspace(static_cast<unsigned char>(text[p])) != 0) {
      ++p;
    }
    return p;
  };
  // "uniform X;" or "nonuniform ...;" after a keyword ending at `p`: the value and whether it
  // is a scalar (nullopt: a vector or something else, left out).
  const auto valueAt = [&](std::size_t p,
                           const std::string& patch) -> std::optional<FoamFieldValue> {
    FoamFieldValue v;
    v.patch = patch;
    v.line = lineAt(text, p);
    p = skipSpace(p);
    std::size_t e = p;
    while (e < text.size() && isWord(text[e])) {
      ++e;
    }
    const std::string kind = text.substr(p, e - p);
    if (kind == "nonuniform") {
      v.uniform = false;
      return v;
    }
    const std::size_t semi = text.find(';', e);
    if (kind != "uniform" || semi == std::string::npos) {
      return std::nullopt;
    }
    const auto x = uniformScalar(text.substr(e, semi - e));
    if (!x) {
      return std::nullopt;
    }
    v.value = *x;
    return v;
  };
  const std::size_t internal = findWord("internalField", 0, text.size());
  const std::size_t head = internal == std::string::npos ? text.size() : internal;
  if (const std::size_t p = findWord("class", 0, head); p != std::string::npos) {
    const std::size_t b = skipSpace(p);
    std::size_t e = b;
    while (e < text.size() && isWord(text[e])) {
      ++e;
    }
    out.className = text.substr(b, e - b);
  }
  if (const std::size_t p = findWord("dimensions", 0, head); p != std::string::npos) {
    const std::size_t open = text.find('[', p), shut = text.find(']', p);
    if (open != std::string::npos && shut != std::string::npos && open < shut) {
      std::istringstream in(text.substr(open + 1, shut - open - 1));
      std::string word, dims;
      while (in >> word) {
        dims += (dims.empty() ? "" : " ") + word;
      }
      out.dimensions = dims;
      out.dimensionsLine = lineAt(text, p);
    }
  }
  if (internal != std::string::npos) {
    if (const auto v = valueAt(internal, "internalField")) {
      out.values.push_back(*v);
    }
  }
  // boundaryField { name { ... } ... }: the fixedValue patches.
  const auto bf = findWord("boundaryField", 0, text.size());
  const auto open = bf == std::string::npos ? bf : text.find('{', bf);
  if (open == std::string::npos) {
    return out;
  }
  std::size_t i = open + 1;
  while (true) {
    i = skipSpace(i);
    if (i >= text.size() || text[i] == '}') {
      break;
    }
    const auto brace = text.find('{', i);
    if (brace == std::string::npos) {
      break;
    }
    std::string name = text.substr(i, brace - i);
    while (!name.empty() && std::isspace(static_cast<unsigned char>(name.back())) != 0) {
      name.pop_back();
    }
    int depth = 0;
    std::size_t end = brace;
    for (; end < text.size(); ++end) {
      depth += text[end] == '{' ? 1 : text[end] == '}' ? -1 : 0;
      if (depth == 0) {
        break;
      }
    }
    const std::size_t type = findWord("type", brace + 1, end);
    if (type != std::string::npos) {
      const std::size_t b = skipSpace(type);
      std::size_t e = b;
      while (e < end && isWord(text[e])) {
        ++e;
      }
      out.patchTypes.emplace_back(name, text.substr(b, e - b));
      const std::size_t value = findWord("value", brace + 1, end);
      if (text.compare(b, e - b, "fixedValue") == 0 && e - b == 10 && value != std::string::npos) {
        if (const auto v = valueAt(value, name)) {
          out.values.push_back(*v);
        }
      }
    }
    i = end + 1;
  }
  return out;
}

bool isZeroGaugeKinematicPressure(const FoamFieldValues& p) {
  if (!p.found || p.dimensions != kKinematicPressureDimensions || p.values.empty()) {
    return false;
  }
  for (const auto& v : p.values) {
    if (!v.uniform || v.value != 0.0) {
      return false;
    }
  }
  static const std::vector<std::string> valueless = {
      "fixedValue", "fixedFluxPressure", "zeroGradient",  "calculated",
      "empty",      "symmetry",          "symmetryPlane", "wedge",
      "cyclic",     "processor",         "cyclicAMI"};
  for (const auto& [patch, type] : p.patchTypes) {
    if (std::find(valueless.begin(), valueless.end(), type) == valueless.end()) {
      return false;
    }
  }
  return true;
}

} // namespace coredem::orchestrator
