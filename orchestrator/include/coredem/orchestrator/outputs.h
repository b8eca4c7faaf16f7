#pragma once
/// @file
/// Run outputs (docs/orchestrator.md): timeseries.csv, particle snapshots indexed by an XDMF file
/// that ParaView opens, and the summary printed by `coredem inspect`.

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace coredem::orchestrator {

/// Appends one row per reported step to a CSV file. The columns are fixed by the first row
/// (or read back from an existing file on resume); values of unknown names are dropped,
/// missing ones are written empty. Each row is written with one write() and flushed.
class TimeseriesWriter {
public:
  /// Opens `path`. With `resumeAfterStep >= 0` an existing file is kept up to and including
  /// that step (later rows, written after the checkpoint, are removed) and appended to.
  explicit TimeseriesWriter(std::filesystem::path path, std::int64_t resumeAfterStep = -1);
  ~TimeseriesWriter();

  /// Writes a row; the first call (on a new file) fixes the columns in the given order.
  void write(const std::vector<std::pair<std::string, double>>& row);
  const std::vector<std::string>& columns() const { return _columns; }

private:
  std::filesystem::path _path;
  std::vector<std::string> _columns;
  int _fd = -1;
};

/// One dataset of an HDF5 file.
struct DatasetInfo {
  std::string path; ///< e.g. "/particles/position"
  std::vector<std::uint64_t> dims;
  std::string type; ///< "float64", "int64", "string", ...
  bool numeric = false;
  double min = 0, max = 0, mean = 0; ///< for numeric datasets
  /// For numeric [N, W] datasets: min, mean and max of each column (x, y, z of a vector).
  std::vector<double> columnMin, columnMean, columnMax;
};

struct AttributeInfo {
  std::string path;  ///< object path + "@" + name, e.g. "/meta@time"
  std::string value; ///< as text
};

/// The comma-separated fields of one line of the run's CSV files (timeseries.csv, outputs.csv:
/// no quoting), a trailing '\r' dropped; an empty line is one empty field.
std::vector<std::string> csvFields(const std::string& line);

/// Every dataset (recursively) and attribute of an HDF5 file, with statistics.
/// Throws UserError if the file cannot be opened as HDF5.
void scanHdf5(const std::filesystem::path& file, std::vector<DatasetInfo>& datasets,
              std::vector<AttributeInfo>& attributes, bool statistics = true);

/// Writes `xdmfPath` (atomically) describing the particle snapshots `snapshots` (paths
/// relative to the XDMF's folder, with their times) as a temporal collection of
/// poly-vertex grids: geometry from /particles/position (N×3), and each snapshot field of the
/// DEM particle schema (coredem/dem/particle_schema.h) that the file holds with N rows as node
/// attributes: Scalar for [N], Vector for [N,3], and one Scalar per column for other widths
/// (named `<field>_<column>`, the columns from the dataset's `columns` attribute, e.g.
/// species_Fe2O3), plus diameter and set_index (describeSnapshot). The per-contact-slot and
/// per-neighbour-slot bookkeeping of /contacts is not exposed.
void writeParticleXdmf(const std::filesystem::path& xdmfPath,
                       const std::vector<std::pair<double, std::string>>& snapshots);

/// The names a snapshot cannot know by itself (from the case file), in the order of the DEM
/// server's indices.
struct SnapshotLabels {
  std::vector<std::string> solidSpecies; ///< columns of /particles/species
  std::vector<std::string> sets;         ///< particles[] names (global ids in set order)
  std::vector<std::uint64_t> setCounts;  ///< particles[] counts
  std::vector<std::string> materials;    ///< values of /particles/material
};

/// Makes a particle snapshot (or state file) self-describing, in place: every dataset of the
/// DEM particle schema gets the attributes `unit` and `description` (and `columns`: the species
/// names of /particles/species, the components of other multi-column fields); adds
/// /particles/diameter (2R, m) and /particles/set_index (attribute `names`); and the root gets
/// `title`, `time`, `step`, `species_names`, `set_names`, `material_names` (comma-separated).
void describeSnapshot(const std::filesystem::path& file, const SnapshotLabels& labels);

/// `coredem inspect FILE`: a readable summary of an HDF5 state/snapshot, a manifest.json
/// or a checkpoint folder (with hash verification).
std::string inspectSummary(const std::filesystem::path& file);

} // namespace coredem::orchestrator
