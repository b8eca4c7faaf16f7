#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <spdlog/fmt/fmt.h>

#include <coredem/common/switch.h>
#include <coredem/common/yaml_section.h>

namespace coredem::yaml {
namespace {

std::string rangeText(double lo, double hi, bool loOpen) {
  const double big = std::numeric_limits<double>::max();
  if (hi == big && lo == -big) {
    return "any finite number";
  }
  if (hi == big) {
    return fmt::format("{} {}", loOpen ? ">" : ">=", lo);
  }
  return fmt::format("{} {} and <= {}", loOpen ? ">" : ">=", lo, hi);
}

} // namespace

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    out += (i ? ", " : "") + items[i];
  }
  return out;
}

std::string describe(const YAML::Node& n) {
  switch (n.Type()) {
  case YAML::NodeType::Null:
    return "nothing (null)";
  case YAML::NodeType::Sequence:
    return "a list";
  case YAML::NodeType::Map:
    return "a mapping";
  case YAML::NodeType::Scalar:
    return "'" + n.Scalar() + "'";
  default:
    return "an undefined value";
  }
}

void fail(const std::string& file, const YAML::Mark& mark, const std::string& key,
          const std::string& what) {
  if (mark.line >= 0) {
    throw ConfigError(
        fmt::format("{}:{}:{}: {}: {}", file, mark.line + 1, mark.column + 1, key, what));
  }
  throw ConfigError(fmt::format("{}: {}: {}", file, key, what));
}

void checkUniqueKeys(const YAML::Node& node, const std::string& file) {
  // Iteratively (a deeply nested file must not exhaust the stack): every mapping's keys are
  // plain names (a complex '? [a, b]' key would reach the readers as a list) and unique.
  std::vector<YAML::Node> todo{node};
  while (!todo.empty()) {
    const YAML::Node n = todo.back();
    todo.pop_back();
    if (n.IsSequence()) {
      for (const auto& item : n) {
        todo.push_back(item);
      }
    } else if (n.IsMap()) {
      std::vector<std::pair<std::string, YAML::Mark>> seen;
      for (const auto& kv : n) {
        if (!kv.first.IsScalar() && !kv.first.IsNull()) {
          fail(file, kv.first.Mark(), "key",
               fmt::format("a key must be a plain name, got {} (a '? ' complex key); write "
                           "'name: value'",
                           describe(kv.first)));
        }
        if (kv.first.IsScalar()) {
          const std::string& key = kv.first.Scalar();
          for (const auto& [k, mark] : seen) {
            if (k == key) {
              fail(file, kv.first.Mark(), key,
                   fmt::format("given twice in the same mapping (first at line {}): YAML readers "
                               "disagree on which one counts; keep one",
                               mark.line + 1));
            }
          }
          seen.emplace_back(key, kv.first.Mark());
        }
        todo.push_back(kv.second);
      }
    }
  }
}

YAML::Node parse(const std::string& text, const std::string& file) {
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(fmt::format("{}:{}:{}: not valid YAML: {}", file, e.mark.line + 1,
                                  e.mark.column + 1, e.msg));
  }
  for (std::size_t i = 1; i < docs.size(); ++i) {
    if (!docs[i].IsNull()) {
      fail(file, docs[i].Mark(), "document",
           "a second YAML document (after '---'): the file is read as one document and the rest "
           "would be ignored; remove the '---' separator or the second document");
    }
  }
  if (docs.empty()) {
    return YAML::Node();
  }
  checkUniqueKeys(docs.front(), file);
  return docs.front();
}

Section::Section(YAML::Node node, std::string file, std::string path,
                 std::vector<std::string> allowed, const YAML::Mark& parentMark)
    : _node(std::move(node))
    , _file(std::move(file))
    , _path(std::move(path))
    , _allowed(std::move(allowed)) {
  const YAML::Mark mark = _node.IsDefined() && !_node.IsNull() ? _node.Mark() : parentMark;
  if (!_node.IsMap()) {
    fail(mark, _path.empty() ? "the case file" : _path,
         fmt::format("expected a mapping with keys {}, got {}", join(_allowed), describe(_node)));
  }
  for (const auto& kv : _node) {
    const std::string key = kv.first.Scalar();
    if (std::find(_allowed.begin(), _allowed.end(), key) == _allowed.end()) {
      fail(kv.first.Mark(), full(key),
           fmt::format("unknown key; allowed keys {}: {}",
                       _path.empty() ? "at the top level" : "in '" + _path + "'", join(_allowed)));
    }
  }
}

YAML::Mark Section::markOf(const std::string& key) const {
  for (const auto& kv : _node) {
    if (kv.first.Scalar() == key) {
      return kv.second.IsNull() ? kv.first.Mark() : kv.second.Mark();
    }
  }
  return _node.Mark();
}

void Section::require(const std::string& key, const std::string& what) const {
  if (!has(key)) {
    fail(_node.Mark(), _path.empty() ? "the case file" : _path,
         fmt::format("missing required key '{}' ({})", key, what));
  }
}

double Section::number(const std::string& key, std::optional<double> def, double lo, double hi,
                       const std::string& what, bool loOpen) const {
  if (!has(key)) {
    if (!def) {
      require(key, what);
    }
    return *def;
  }
  return numberOf(_node[key], full(key), lo, hi, what, loOpen);
}

double Section::numberOf(const YAML::Node& n, const std::string& key, double lo, double hi,
                         const std::string& what, bool loOpen) const {
  double v = 0.0;
  bool ok = n.IsScalar();
  if (ok) {
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      ok = false;
    }
  }
  if (!ok || !std::isfinite(v)) {
    fail(n.Mark(), key, fmt::format("expected a number ({}), got {}", what, describe(n)));
  }
  if (v < lo || v > hi || (loOpen && v == lo)) {
    fail(n.Mark(), key,
         fmt::format("{} is out of range; allowed: {} ({})", v, rangeText(lo, hi, loOpen), what));
  }
  return v;
}

std::int64_t Section::integer(const std::string& key, std::optional<std::int64_t> def,
                              std::int64_t lo, std::int64_t hi, const std::string& what) const {
  if (!has(key)) {
    if (!def) {
      require(key, what);
    }
    return *def;
  }
  const YAML::Node n = _node[key];
  std::int64_t v = 0;
  bool ok = n.IsScalar();
  if (ok) {
    try {
      v = n.as<std::int64_t>();
    } catch (const YAML::Exception&) {
      ok = false;
    }
  }
  if (!ok) {
    fail(n.Mark(), full(key), fmt::format("expected an integer ({}), got {}", what, describe(n)));
  }
  if (v < lo || v > hi) {
    fail(n.Mark(), full(key),
         fmt::format("{} is out of range; allowed: {} to {} ({})", v, lo, hi, what));
  }
  return v;
}

std::string Section::string(const std::string& key, std::optional<std::string> def,
                            const std::string& what) const {
  if (!has(key)) {
    if (!def) {
      require(key, what);
    }
    return *def;
  }
  const YAML::Node n = _node[key];
  if (!n.IsScalar()) {
    fail(n.Mark(), full(key), fmt::format("expected a string ({}), got {}", what, describe(n)));
  }
  return n.Scalar();
}

std::string Section::choice(const std::string& key, std::optional<std::string> def,
                            const std::vector<std::string>& options) const {
  const std::string v = string(key, def, "one of " + join(options));
  if (std::find(options.begin(), options.end(), v) == options.end()) {
    fail(markOf(key), full(key), fmt::format("'{}' is not allowed; allowed: {}", v, join(options)));
  }
  return v;
}

bool Section::onOff(const std::string& key, bool def) const {
  if (!has(key)) {
    return def;
  }
  const YAML::Node n = raw(key);
  if (n.IsScalar()) {
    if (const auto v = parseSwitch(n.Scalar())) {
      return *v;
    }
  }
  fail(markOf(key), full(key), fmt::format("expected on or off, got {}", describe(n)));
}

std::array<double, 3> Section::vec3(const std::string& key,
                                    std::optional<std::array<double, 3>> def,
                                    const std::string& what, double lo, double hi,
                                    bool loOpen) const {
  if (!has(key)) {
    if (!def) {
      require(key, what);
    }
    return *def;
  }
  const YAML::Node n = _node[key];
  if (!n.IsSequence() || n.size() != 3) {
    fail(n.Mark(), full(key),
         fmt::format("expected a list of 3 numbers [x, y, z] ({}), got {}", what, describe(n)));
  }
  std::array<double, 3> v{};
  for (std::size_t i = 0; i < 3; ++i) {
    v[i] = numberOf(n[i], fmt::format("{}[{}]", full(key), i), lo, hi, what, loOpen);
  }
  return v;
}

Section Section::section(const std::string& key, std::vector<std::string> allowed) const {
  return Section(_node[key], _file, full(key), std::move(allowed), markOf(key));
}

std::vector<Section> Section::list(const std::string& key, std::vector<std::string> allowed,
                                   const std::string& what) const {
  const YAML::Node n = _node[key];
  if (!n.IsSequence()) {
    fail(markOf(key), full(key), fmt::format("expected a list ({}), got {}", what, describe(n)));
  }
  std::vector<Section> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    out.emplace_back(n[i], _file, fmt::format("{}[{}]", full(key), i), allowed, n.Mark());
  }
  return out;
}

} // namespace coredem::yaml
