#pragma once
// Helpers of the case-file unit tests: parse a case text and return its error, edit a case text.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "coredem/orchestrator/case_config.h"

namespace coredem::orchestrator::test {

/// The CaseError message of parsing `text` as cases/x/case.yaml ("" if it parses).
inline std::string errorOf(const std::string& text) {
  try {
    parseCase(text, "cases/x/case.yaml", std::filesystem::temp_directory_path());
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}

/// `s` with the first `from` replaced by `to`; a test failure if `from` is not there.
inline std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos == std::string::npos)
    return s;
  return s.replace(pos, from.size(), to);
}

} // namespace coredem::orchestrator::test
