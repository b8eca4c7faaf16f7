#pragma once
/// @file
/// The prescribed gas of `coredem-gas`: uniform or per-region (axis-aligned boxes) values of the
/// GasFields (u_g, grad_p, T_g, rho_g, mu_g, kappa_g, cp_g, Y_g), each a constant or a
/// piecewise-linear time table, read from a YAML mapping (docs/client.md, "coredem-gas input").
///
/// Usage:
/// @code
///   auto model = coredem::gas::GasModel::fromFile("case.yaml", "gas");  // validates the YAML
///   model.bind(grid, {"CO", "CO2", "N2"});   // checks species names, assigns cells to regions
///   coredem::gas::GasFieldArrays f;
///   model.evaluate(t, f);                    // fills every array for time t (checked values)
/// @endcode
/// Every user error (bad key, wrong type, unsorted table, unknown species, a composition that
/// does not sum to 1, ...) throws coredem::UserError naming the file, line, key and what is
/// allowed.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace coredem::gas {

/// Uniform Cartesian coupling grid; cell index = i + nx*(j + ny*k).
struct CartesianGrid {
  std::array<double, 3> origin{0.0, 0.0, 0.0};  ///< m, corner of cell (0,0,0)
  std::array<double, 3> spacing{1.0, 1.0, 1.0}; ///< m
  std::array<std::int64_t, 3> counts{1, 1, 1};

  std::int64_t cellCount() const { return counts[0] * counts[1] * counts[2]; }
  double cellVolume() const { return spacing[0] * spacing[1] * spacing[2]; }
  /// Centre of cell c on axis a.
  std::array<double, 3> cellCentre(std::int64_t c) const;
};

/// Per-cell arrays in the layout of the protocol's GasFields (row-major, cell first).
struct GasFieldArrays {
  std::vector<double> u_g;     ///< [N,3] m/s
  std::vector<double> grad_p;  ///< [N,3] Pa/m
  std::vector<double> T_g;     ///< [N] K
  std::vector<double> rho_g;   ///< [N] kg/m^3
  std::vector<double> mu_g;    ///< [N] Pa s
  std::vector<double> kappa_g; ///< [N] W/m/K
  std::vector<double> cp_g;    ///< [N] J/kg/K
  std::vector<double> Y_g;     ///< [N, n_species] mass fractions
};

/// A piecewise-linear function of time with D components; one point = a constant.
template <int D>
class TimeSeries {
public:
  using Value = std::array<double, D>;
  TimeSeries() = default;
  explicit TimeSeries(Value constant)
      : _times{0.0}
      , _values{constant} {}
  /// @pre times strictly increasing, times.size() == values.size() >= 1
  TimeSeries(std::vector<double> times, std::vector<Value> values);

  /// Linear interpolation; held constant before the first and after the last point.
  Value at(double t) const;
  const std::vector<double>& times() const { return _times; }

private:
  std::vector<double> _times;
  std::vector<Value> _values;
};

class GasModel {
public:
  /// Parse and validate `node` (the gas mapping); `where` names the file for messages.
  static GasModel fromYaml(const YAML::Node& node, const std::string& where = "<yaml>");
  /// Load `file` and take the mapping at the dot-separated `key` (e.g. "gas").
  static GasModel fromFile(const std::string& file, const std::string& key = "gas");

  GasModel(GasModel&&) noexcept;
  GasModel& operator=(GasModel&&) noexcept;
  ~GasModel();

  /// Attach to the coupling grid and the case's species list (from Configure): validates the
  /// species names of every Y_g and assigns each cell, field by field, to the last region
  /// that contains its centre. May be called again for another grid.
  void bind(const CartesianGrid& grid, const std::vector<std::string>& species);

  /// Fill `out` with every field at time t (s). Throws UserError when a time table takes a
  /// value out of its physical bounds or a composition stops summing to 1 at this t.
  /// @pre bind() was called
  void evaluate(double t, GasFieldArrays& out) const;

  /// Number of regions (for logs).
  std::size_t regionCount() const;
  /// Human-readable summary (one line per region) for the log.
  std::string describe() const;

private:
  struct Impl;
  explicit GasModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> _impl;
};

} // namespace coredem::gas
