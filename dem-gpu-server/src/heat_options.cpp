// Parsing of the heat-transfer model switches (Configure.options / case.yaml `models:`).
#include "coredem/dem/heat_options.h"

#include "coredem/common/check.h"

#include <charconv>
#include <cmath>

namespace coredem::dem {
namespace {

bool onOff(const std::string& key, const std::string& value) {
  if (value == "on" || value == "true" || value == "yes" || value == "1") return true;
  if (value == "off" || value == "false" || value == "no" || value == "0") return false;
  throw UserError("model option " + key + " = '" + value + "': use on or off");
}

double number(const std::string& key, const std::string& value, double lo, bool loOpen, double hi,
              const char* what) {
  double v = 0.0;
  const char* end = value.data() + value.size();
  const auto r = std::from_chars(value.data(), end, v);
  const bool inRange = std::isfinite(v) && (loOpen ? v > lo : v >= lo) && v <= hi;
  COREDEM_CHECK(r.ec == std::errc() && r.ptr == end && inRange,
                "model option {} = '{}': expected {}", key, value, what);
  return v;
}

} // namespace

bool setHeatOption(HeatOptions& o, const std::string& key, const std::string& value) {
  if (key == "heat") {
    o.enabled = onOff(key, value);
  } else if (key == "convection") {
    if (value == "li-mason" || value == "li_mason") {
      o.convection = true;
      o.ranzMarshall = false;
    } else if (value == "ranz-marshall" || value == "ranz_marshall") {
      o.convection = true;
      o.ranzMarshall = true;
    } else if (value == "off") {
      o.convection = false;
    } else {
      throw UserError("model option convection = '" + value +
                      "': use li-mason (default), ranz-marshall or off");
    }
  } else if (key == "convection_reynolds") {
    if (value == "with-voidage" || value == "with_voidage") {
      o.reynoldsWithVoidage = true;
    } else if (value == "without-voidage" || value == "without_voidage") {
      o.reynoldsWithVoidage = false;
    } else {
      throw UserError("model option convection_reynolds = '" + value +
                      "': use with-voidage (default, Re = ε ρ d |Δu|/μ) or without-voidage");
    }
  } else if (key == "nusselt_exponent") {
    o.voidageExponent = number(key, value, 0.0, false, 10.0, "a number in [0, 10] (Li–Mason n, 3.5)");
  } else if (key == "contact_conduction") {
    o.contactConduction = onOff(key, value);
  } else if (key == "lens_conduction") {
    o.lensConduction = onOff(key, value);
  } else if (key == "flpc") {
    o.lensFraction = number(key, value, 0.0, false, 1.0, "a number in [0, 1] (lens radius (1+FLPC) R_L, 0.2)");
  } else if (key == "s_min") {
    o.minSeparation = number(key, value, 0.0, true, 1.0e-3, "a length in (0, 1e-3] m (1e-6)");
  } else if (key == "lens_rel_tol") {
    o.lensRelTol = number(key, value, 1.0e-14, false, 1.0e-3, "a tolerance in [1e-14, 1e-3] (1e-8)");
  } else if (key == "wall_conduction") {
    o.wallConduction = onOff(key, value);
  } else if (key == "wall_lens_conduction") {
    o.wallLensConduction = onOff(key, value);
  } else if (key == "radiation") {
    o.radiation = onOff(key, value);
  } else if (key == "radiation_environment") {
    COREDEM_CHECK(value == "cell-mean" || value == "cell_mean",
                  "model option radiation_environment = '{}': the DEM step implements cell-mean "
                  "(PHYSICS §3.4 (a)) only; neighbour-mean is a kernel option not yet integrated", value);
  } else {
    return false;
  }
  return true;
}

} // namespace coredem::dem
