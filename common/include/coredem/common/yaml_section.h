#pragma once
/// @file
/// Validating YAML input (case files, sweep files, gas sections) with one error contract:
/// every problem is a ConfigError "file:line:col: key: what is wrong; what is allowed".
///
///   const YAML::Node root = yaml::parse(text, "case.yaml");
///   const yaml::Section top(root, "case.yaml", "", {"name", "time"}, YAML::Mark());
///   const double end = top.section("time", {"end", "dt"}).number("end", std::nullopt, 0, kBig,
///                                                               "s, > 0", true);

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include <coredem/common/check.h>

namespace coredem {

/// An input file (case, sweep, gas section) that does not follow its schema.
class ConfigError : public UserError {
public:
  using UserError::UserError;
};

namespace yaml {

/// "a, b, c"
std::string join(const std::vector<std::string>& items);
/// What a node is, for messages: "a list", "a mapping", "nothing (null)", "'text'".
std::string describe(const YAML::Node& n);
/// Throws ConfigError "file:line:col: key: what" (without line:col when the mark is unknown).
[[noreturn]] void fail(const std::string& file, const YAML::Mark& mark, const std::string& key,
                       const std::string& what);
/// Parses YAML text; a syntax error becomes ConfigError "file:line:col: not valid YAML: ...".
/// Refuses what YAML readers resolve differently: a key given twice in one mapping (naming both
/// lines), a key that is not a plain name ('? [a, b]') and a second, non-empty document after
/// `---` (naming its line).
YAML::Node parse(const std::string& text, const std::string& file);
/// The key checks of parse() (plain, unique keys) on an already parsed node (ConfigError naming
/// the line).
void checkUniqueKeys(const YAML::Node& node, const std::string& file);

/// A mapping with the keys it allows. The constructor refuses unknown keys; every accessor
/// checks type and range and fails with file:line:col, the full key and the allowed values.
class Section {
public:
  /// @param path the full key of this mapping ("" at the top level, "dem", "particles[2]").
  /// @param parentMark where to point when the mapping itself is missing or null.
  Section(YAML::Node node, std::string file, std::string path, std::vector<std::string> allowed,
          const YAML::Mark& parentMark);

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& key,
                         const std::string& what) const {
    yaml::fail(_file, mark, key, what);
  }

  /// path.key
  std::string full(const std::string& key) const { return _path.empty() ? key : _path + "." + key; }
  bool has(const std::string& key) const { return bool(_node[key]); }
  YAML::Node raw(const std::string& key) const { return _node[key]; }
  YAML::Mark mark() const { return _node.Mark(); }
  /// Where key's value is (or the key itself when its value is null; the mapping if absent).
  YAML::Mark markOf(const std::string& key) const;
  const std::string& file() const { return _file; }
  const std::string& path() const { return _path; }

  void require(const std::string& key, const std::string& what) const;

  /// A finite number in [lo, hi] ((lo, hi] with loOpen); def when absent (required if nullopt).
  double number(const std::string& key, std::optional<double> def, double lo, double hi,
                const std::string& what, bool loOpen = false) const;
  double numberOf(const YAML::Node& n, const std::string& key, double lo, double hi,
                  const std::string& what, bool loOpen = false) const;
  std::int64_t integer(const std::string& key, std::optional<std::int64_t> def, std::int64_t lo,
                       std::int64_t hi, const std::string& what) const;
  std::string string(const std::string& key, std::optional<std::string> def,
                     const std::string& what) const;
  /// One of `options`.
  std::string choice(const std::string& key, std::optional<std::string> def,
                     const std::vector<std::string>& options) const;
  /// A switch spelled as parseSwitch() accepts (on/off, true/false, yes/no, 1/0).
  bool onOff(const std::string& key, bool def) const;
  std::array<double, 3> vec3(const std::string& key, std::optional<std::array<double, 3>> def,
                             const std::string& what, double lo = -kMax, double hi = kMax,
                             bool loOpen = false) const;

  /// The nested mapping `key` with its allowed keys.
  Section section(const std::string& key, std::vector<std::string> allowed) const;
  /// The list `key` of mappings, each with the allowed keys.
  std::vector<Section> list(const std::string& key, std::vector<std::string> allowed,
                            const std::string& what) const;

  static constexpr double kMax = 1.7976931348623157e308; ///< DBL_MAX: "no bound"

private:
  YAML::Node _node;
  std::string _file;
  std::string _path;
  std::vector<std::string> _allowed;
};

} // namespace yaml
} // namespace coredem
