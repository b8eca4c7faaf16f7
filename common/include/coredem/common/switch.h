#pragma once
/// @file
/// The one spelling of an on/off switch in case files, Configure options and command lines.

#include <optional>
#include <string_view>

namespace coredem {

/// on/true/yes/1 → true, off/false/no/0 → false, anything else → nullopt (the caller reports
/// it, naming the key and "on or off").
inline std::optional<bool> parseSwitch(std::string_view v) {
  if (v == "on" || v == "true" || v == "yes" || v == "1") {
    return true;
  }
  if (v == "off" || v == "false" || v == "no" || v == "0") {
    return false;
  }
  return std::nullopt;
}

} // namespace coredem
