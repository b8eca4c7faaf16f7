#pragma once
/// @file
/// Time-averaged results of a run folder (`coredem stats`, docs/orchestrator.md "Time-averaged
/// results"): statistics of every timeseries.csv column over a time window, and time-averaged
/// fields per coupling cell computed from the particle snapshots in that window.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <coredem/orchestrator/case_config.h>

namespace coredem::orchestrator {

/// The window (from, to] of simulated time; an unset end is the run's start or end.
struct TimeWindow {
  std::optional<double> from; ///< s
  std::optional<double> to;   ///< s
};

/// Statistics of one timeseries.csv column over a window. Each row stands for the time since
/// the previous row (t_i − t_{i−1}, clipped to the window; the first row of the file for its
/// `dt`), so mean and std are time averages also with an adaptive Δt or `timeseries_every`.
struct ColumnStats {
  std::string name;
  std::size_t rows = 0; ///< rows with a finite value in the window
  double mean = 0, std = 0, min = 0, max = 0;
};

struct TimeseriesStats {
  double from = 0, to = 0;          ///< the window used (s)
  double firstRow = 0, lastRow = 0; ///< t of the first and last row in it
  std::size_t rows = 0;             ///< rows in the window
  double runStart = 0, runEnd = 0;  ///< t of the first and last row of the file (s)
  std::vector<ColumnStats> columns; ///< every column but step and t, in file order
};

/// Reads RUN/timeseries.csv and computes every column's statistics over `window`.
/// Throws UserError when the file is missing or empty, when the window is empty or reversed, or
/// when it starts at or after the run's last row (the message names the run's time range).
TimeseriesStats timeseriesStats(const std::filesystem::path& runDir, const TimeWindow& window);

/// Time-averaged fields per coupling cell (PCM: a particle counts in the cell of its centre, as
/// in the DEM server), from the snapshots whose time lies in [from, to]. Each snapshot is one
/// sample of equal weight (the time average when outputs are equally spaced in time).
///   eps_g       mean over the samples of ε_g = 1 − Σ V_p / V_cell (geometric cell volume)
///   eps_g_std   its standard deviation over the samples
///   U_p         Σ_k Σ_i m_i v_i / Σ_k Σ_i m_i (mass-weighted over particles and samples)
///   theta       Σ_k M_c,k Θ_c,k / Σ_k M_c,k, Θ_c,k = (Σ_i m_i |v_i − U_c,k|²) / (3 M_c,k): the
///               granular temperature about each sample's own cell velocity U_c,k (m²/s²)
///   T_p         Σ_k Σ_i m_i T_i / Σ_k Σ_i m_i (K)
///   solids_samples  number of samples in which the cell held a particle
/// Cells that never held a particle get NaN for U_p, theta and T_p.
struct FieldAverages {
  GridConfig grid;
  std::vector<double> times; ///< the snapshot times used
  std::vector<std::int64_t> steps;
  std::vector<double> epsG, epsGStd, theta, tp, samples; ///< [cells]
  std::vector<double> up;                                ///< [cells × 3]
};

/// Computes the averages from RUN/outputs.csv's snapshots in the window (nullopt when none).
/// Throws UserError when a snapshot cannot be read.
std::optional<FieldAverages> fieldAverages(const std::filesystem::path& runDir,
                                           const GridConfig& grid, double from, double to);

/// Writes `h5` (cell data, datasets as [nz, ny, nx(, 3)]) and `xdmf` (a 3DCoRectMesh of the
/// coupling grid with the cell attributes; ParaView's XDMF reader).
void writeFieldAverages(const FieldAverages& a, const std::filesystem::path& h5,
                        const std::filesystem::path& xdmf);

/// The JSON document of `coredem stats` (written to RUN/stats/stats.json).
std::string statsJson(const TimeseriesStats& s, const std::optional<FieldAverages>& fields,
                      const std::string& fieldsFile);

/// The human table of `coredem stats`.
std::string statsTable(const TimeseriesStats& s);

} // namespace coredem::orchestrator
