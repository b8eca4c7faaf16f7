#pragma once
/// @file
/// Shared by the pre-flight checks (preflight.cpp: the case itself; a participant's pre-flight
/// hook, e.g. the OpenFOAM case's): where a key is in case.yaml, and how vectors are written in
/// messages.
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include <coredem/common/yaml_section.h>
#include <coredem/orchestrator/case_config.h>

namespace coredem::orchestrator::preflight {

/// Where in case.yaml a value comes from: the deepest node of `path` that exists.
class Locator {
public:
  explicit Locator(const CaseConfig& c)
      : _file(c.caseFile.string()) {
    try {
      _root = YAML::Load(c.text);
    } catch (const std::exception&) {
    }
  }

  YAML::Mark mark(const std::vector<std::string>& path) const {
    YAML::Node n;
    n.reset(_root);
    YAML::Mark m;
    for (const auto& key : path) {
      if (!n || !(n.IsMap() || n.IsSequence())) {
        break;
      }
      const YAML::Node& cn = n; // const access: a missing key is not added
      if (cn.IsSequence() && std::stoul(key) >= cn.size()) {
        break;
      }
      // Copy-constructed, not assigned: assigning the invalid node of a missing key throws.
      const YAML::Node next = cn.IsSequence() ? cn[std::stoul(key)] : cn[key];
      if (!next.IsDefined()) {
        break;
      }
      n.reset(next); // rebind (assignment would overwrite the node's value)
      m = n.Mark();
    }
    return m;
  }

  [[noreturn]] void fail(const std::vector<std::string>& path, const std::string& key,
                         const std::string& what) const {
    yaml::fail(_file, mark(path), key, what);
  }

  std::string warning(const std::vector<std::string>& path, const std::string& key,
                      const std::string& what) const {
    const YAML::Mark m = mark(path);
    if (m.line >= 0) {
      return fmt::format("{}:{}:{}: {}: {}", _file, m.line + 1, m.column + 1, key, what);
    }
    return fmt::format("{}: {}: {}", _file, key, what);
  }

  const YAML::Node& root() const { return _root; }

private:
  std::string _file;
  YAML::Node _root;
};

inline std::string fmtVec(const Vec3& v) {
  return fmt::format("[{:.6g}, {:.6g}, {:.6g}]", v[0], v[1], v[2]);
}

inline double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

} // namespace coredem::orchestrator::preflight
