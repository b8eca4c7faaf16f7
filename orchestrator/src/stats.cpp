// `coredem stats` (stats.h, docs/orchestrator.md "Time-averaged results"): column statistics of
// timeseries.csv over a window and time-averaged coupling-cell fields from the snapshots.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

#include <coredem/common/check.h>
#include <coredem/common/files.h>
#include <coredem/common/hdf5.h>
#include <coredem/common/json.h>
#include <coredem/dem/kernels/pcm.h>
#include <coredem/orchestrator/outputs.h>
#include <coredem/orchestrator/stats.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A cell of a CSV row as a number; NaN when empty or not a number.
double numberOf(const std::string& text) {
  if (text.empty()) {
    return kNaN;
  }
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end != nullptr && *end == '\0' ? v : kNaN;
}

struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
};

Table readTable(const fs::path& file) {
  std::ifstream in(file);
  COREDEM_CHECK(in.good(),
                "{}: no such file: give a run folder written by coredem run (it holds "
                "timeseries.csv)",
                file.string());
  Table t;
  std::string line;
  COREDEM_CHECK(std::getline(in, line) && !line.empty(),
                "{}: empty file: the run has not finished a step yet", file.string());
  t.columns = csvFields(line);
  while (std::getline(in, line)) {
    if (line.empty()) {
      continue;
    }
    const auto cells = csvFields(line);
    if (cells.size() != t.columns.size()) {
      continue; // a torn last line of a crashed run
    }
    std::vector<double> row(cells.size());
    std::transform(cells.begin(), cells.end(), row.begin(), numberOf);
    t.rows.push_back(std::move(row));
  }
  COREDEM_CHECK(!t.rows.empty(), "{}: no rows: the run has not finished a step yet", file.string());
  return t;
}

std::size_t columnIndex(const Table& t, const std::string& name, const fs::path& file) {
  const auto at = std::find(t.columns.begin(), t.columns.end(), name);
  COREDEM_CHECK(at != t.columns.end(), "{}: no column '{}' (not a coredem timeseries?)",
                file.string(), name);
  return std::size_t(at - t.columns.begin());
}

/// The time each row stands for: from the previous row's t (the first row: its own dt) to its
/// t, clipped to the window. Rows outside the window (t <= from or t > to) get a negative weight.
std::vector<double> rowWeights(const Table& t, std::size_t ct, std::size_t cdt, double from,
                               double to) {
  std::vector<double> w(t.rows.size(), -1.0);
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const double ti = t.rows[i][ct];
    double prev = i > 0 ? t.rows[i - 1][ct] : ti - t.rows[i][cdt];
    if (!std::isfinite(prev) || prev > ti) {
      prev = ti;
    }
    const double tol = 1e-12 * std::max(1.0, std::abs(ti));
    if (!(ti > from + tol) || ti > to + tol) {
      continue;
    }
    w[i] = ti - std::max(prev, from);
  }
  return w;
}

ColumnStats columnStats(const Table& t, std::size_t c, const std::vector<double>& w) {
  ColumnStats s;
  s.name = t.columns[c];
  double sw = 0.0, swx = 0.0;
  s.min = HUGE_VAL;
  s.max = -HUGE_VAL;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const double x = t.rows[i][c];
    if (w[i] < 0.0 || !std::isfinite(x)) {
      continue;
    }
    ++s.rows;
    sw += w[i];
    swx += w[i] * x;
    s.min = std::min(s.min, x);
    s.max = std::max(s.max, x);
  }
  if (s.rows == 0) {
    s.mean = s.std = s.min = s.max = kNaN;
    return s;
  }
  // Zero total weight (a single row of zero span): the rows count equally.
  const bool equal = !(sw > 0.0);
  auto weight = [&](std::size_t i) { return equal ? 1.0 : w[i]; };
  double total = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    if (w[i] >= 0.0 && std::isfinite(t.rows[i][c])) {
      total += weight(i);
      sum += weight(i) * t.rows[i][c];
    }
  }
  s.mean = sum / total;
  double var = 0.0;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    if (w[i] >= 0.0 && std::isfinite(t.rows[i][c])) {
      var += weight(i) * (t.rows[i][c] - s.mean) * (t.rows[i][c] - s.mean);
    }
  }
  s.std = std::sqrt(var / total);
  if (s.min == s.max) { // a constant column: no round-off of the weights in mean and std
    s.mean = s.min;
    s.std = 0.0;
  }
  return s;
}

} // namespace

TimeseriesStats timeseriesStats(const fs::path& runDir, const TimeWindow& window) {
  const fs::path file = runDir / "timeseries.csv";
  COREDEM_CHECK(fs::is_directory(runDir),
                "{}: not a folder: give a run folder written by "
                "coredem run",
                runDir.string());
  const Table t = readTable(file);
  const std::size_t ct = columnIndex(t, "t", file);
  const std::size_t cdt = columnIndex(t, "dt", file);
  TimeseriesStats s;
  const double dt0 = std::isfinite(t.rows.front()[cdt]) ? t.rows.front()[cdt] : 0.0;
  s.runStart = t.rows.front()[ct] - dt0;
  s.runEnd = t.rows.back()[ct];
  s.from = window.from.value_or(s.runStart);
  s.to = window.to.value_or(s.runEnd);
  const std::string range =
      fmt::format("the run covers t = {:.6g} to {:.6g} s", s.runStart, s.runEnd);
  COREDEM_CHECK(std::isfinite(s.from) && std::isfinite(s.to),
                "--from and --to must be finite times in s ({})", range);
  COREDEM_CHECK(s.from < s.runEnd,
                "--from {:.6g} s is at or beyond the run's last row ({}); "
                "choose an earlier --from, or continue the run (coredem resume) first",
                s.from, range);
  COREDEM_CHECK(s.to > s.from,
                "--to {:.6g} s is not after --from {:.6g} s: give a window with "
                "from < to ({})",
                s.to, s.from, range);
  const std::vector<double> w = rowWeights(t, ct, cdt, s.from, s.to);
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    if (w[i] >= 0.0) {
      s.firstRow = s.rows == 0 ? t.rows[i][ct] : s.firstRow;
      s.lastRow = t.rows[i][ct];
      ++s.rows;
    }
  }
  COREDEM_CHECK(s.rows > 0, "no timeseries row has t in ({:.6g}, {:.6g}] s ({}): widen the window",
                s.from, s.to, range);
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    if (t.columns[c] != "step" && t.columns[c] != "t") {
      s.columns.push_back(columnStats(t, c, w));
    }
  }
  return s;
}

// ---- time-averaged fields ---------------------------------------------------------------

namespace {

/// Sums of one cell over the samples.
struct CellSums {
  double eps = 0, eps2 = 0, mass = 0, mT = 0, massTheta = 0, samples = 0;
  double mv[3] = {0, 0, 0};
};

struct SnapshotRef {
  std::int64_t step;
  double time;
  std::string file;
};

std::vector<SnapshotRef> snapshotsOf(const fs::path& runDir) {
  std::vector<SnapshotRef> out;
  std::ifstream in(runDir / "outputs.csv");
  std::string line;
  if (!in || !std::getline(in, line)) {
    return out;
  }
  while (std::getline(in, line)) {
    const auto cells = csvFields(line);
    if (cells.size() >= 3 && !cells[2].empty()) {
      out.push_back({std::stoll(cells[0]), numberOf(cells[1]), cells[2]});
    }
  }
  return out;
}

/// Adds one snapshot's per-cell quantities to `sums`.
void addSnapshot(const fs::path& file, const GridConfig& g, std::vector<CellSums>& sums) {
  const h5::Handle f = h5::openFile(file);
  const h5::Handle p = h5::openGroup(f, "particles", file.string());
  const auto pos = h5::readDataset<double>(p, "position", file.string());
  const std::int64_t n = std::int64_t(pos.size() / 3);
  const auto vel = h5::readDataset<double>(p, "velocity", file.string(), 3 * n);
  const auto radius = h5::readDataset<double>(p, "radius", file.string(), n);
  const auto mass = h5::readDataset<double>(p, "mass", file.string(), n);
  const auto temp = h5::readDataset<double>(p, "temperature", file.string(), n);
  namespace k = coredem::dem::kernels;
  const k::GridParams gp{{g.origin[0], g.origin[1], g.origin[2]},
                         {1.0 / g.spacing[0], 1.0 / g.spacing[1], 1.0 / g.spacing[2]},
                         int(g.cells[0]),
                         int(g.cells[1]),
                         int(g.cells[2])};
  const std::size_t cells = sums.size();
  std::vector<double> vs(cells, 0.0), m(cells, 0.0), mt(cells, 0.0), mv2(cells, 0.0);
  std::vector<double> mv(3 * cells, 0.0);
  std::vector<long long> cellOf(std::size_t(n), -1);
  for (std::int64_t i = 0; i < n; ++i) {
    const std::size_t u = std::size_t(i);
    const long long c = k::pcmCell(gp, {pos[3 * u], pos[3 * u + 1], pos[3 * u + 2]});
    cellOf[u] = c;
    if (c < 0) {
      continue;
    }
    const std::size_t cc = std::size_t(c);
    vs[cc] += 4.0 / 3.0 * M_PI * radius[u] * radius[u] * radius[u];
    m[cc] += mass[u];
    mt[cc] += mass[u] * temp[u];
    for (int d = 0; d < 3; ++d) {
      mv[3 * cc + d] += mass[u] * vel[3 * u + d];
    }
  }
  // Θ about this sample's cell velocity (a second pass: no cancellation of large means).
  for (std::int64_t i = 0; i < n; ++i) {
    const std::size_t u = std::size_t(i);
    if (cellOf[u] < 0) {
      continue;
    }
    const std::size_t cc = std::size_t(cellOf[u]);
    double d2 = 0.0;
    for (int d = 0; d < 3; ++d) {
      const double dv = vel[3 * u + d] - mv[3 * cc + d] / m[cc];
      d2 += dv * dv;
    }
    mv2[cc] += mass[u] * d2;
  }
  const double volume = g.spacing[0] * g.spacing[1] * g.spacing[2];
  for (std::size_t c = 0; c < cells; ++c) {
    const double eps = k::pcmGasFraction(vs[c], volume);
    sums[c].eps += eps;
    sums[c].eps2 += eps * eps;
    if (m[c] > 0.0) {
      sums[c].samples += 1.0;
      sums[c].mass += m[c];
      sums[c].mT += mt[c];
      sums[c].massTheta += mv2[c] / 3.0; // M_c Θ_c
      for (int d = 0; d < 3; ++d) {
        sums[c].mv[d] += mv[3 * c + d];
      }
    }
  }
}

} // namespace

std::optional<FieldAverages> fieldAverages(const fs::path& runDir, const GridConfig& grid,
                                           double from, double to) {
  std::vector<SnapshotRef> use;
  for (const auto& s : snapshotsOf(runDir)) {
    const double tol = 1e-12 * std::max(1.0, std::abs(s.time));
    if (s.time >= from - tol && s.time <= to + tol) {
      use.push_back(s);
    }
  }
  if (use.empty()) {
    return std::nullopt;
  }
  const std::size_t cells = std::size_t(grid.cells[0] * grid.cells[1] * grid.cells[2]);
  std::vector<CellSums> sums(cells);
  FieldAverages a;
  a.grid = grid;
  for (const auto& s : use) {
    addSnapshot(runDir / s.file, grid, sums);
    a.times.push_back(s.time);
    a.steps.push_back(s.step);
  }
  const double k = double(use.size());
  a.epsG.resize(cells);
  a.epsGStd.resize(cells);
  a.theta.resize(cells);
  a.tp.resize(cells);
  a.samples.resize(cells);
  a.up.resize(3 * cells);
  for (std::size_t c = 0; c < cells; ++c) {
    const CellSums& s = sums[c];
    a.epsG[c] = s.eps / k;
    a.epsGStd[c] = std::sqrt(std::max(0.0, s.eps2 / k - a.epsG[c] * a.epsG[c]));
    a.samples[c] = s.samples;
    const bool solids = s.mass > 0.0;
    a.theta[c] = solids ? s.massTheta / s.mass : kNaN;
    a.tp[c] = solids ? s.mT / s.mass : kNaN;
    for (int d = 0; d < 3; ++d) {
      a.up[3 * c + std::size_t(d)] = solids ? s.mv[d] / s.mass : kNaN;
    }
  }
  return a;
}

namespace {

struct CellField {
  const char* name;
  const char* unit;
  const char* description;
  const std::vector<double>* data;
  int components;
};

std::vector<CellField> cellFields(const FieldAverages& a) {
  return {
      {"eps_g", "-", "time-averaged gas fraction (PCM, geometric cell volume)", &a.epsG, 1},
      {"eps_g_std", "-", "standard deviation of the gas fraction over the samples", &a.epsGStd, 1},
      {"U_p", "m/s", "mass-weighted time-averaged particle velocity", &a.up, 3},
      {"theta", "m^2/s^2", "mass-weighted time-averaged granular temperature", &a.theta, 1},
      {"T_p", "K", "mass-weighted time-averaged particle temperature", &a.tp, 1},
      {"solids_samples", "none", "samples in which the cell held a particle", &a.samples, 1},
  };
}

} // namespace

void writeFieldAverages(const FieldAverages& a, const fs::path& h5Path, const fs::path& xdmf) {
  const auto& n = a.grid.cells;
  {
    const fs::path tmp = h5Path.string() + ".tmp";
    const h5::Handle f = h5::createFile(tmp);
    h5::writeAttribute(f, "title", "CoReDEM time-averaged coupling-cell fields (coredem stats)");
    h5::writeAttribute(f, "from", a.times.front());
    h5::writeAttribute(f, "to", a.times.back());
    h5::writeAttribute(f, "samples", std::int64_t(a.times.size()));
    h5::writeDataset(f, "sample_times", a.times);
    h5::writeDataset(f, "sample_steps", a.steps);
    const h5::Handle g = h5::createGroup(f, "cells");
    for (const auto& fld : cellFields(a)) {
      std::vector<hsize_t> dims = {n[2], n[1], n[0]};
      if (fld.components == 3) {
        dims.push_back(3);
      }
      h5::writeDataset(g, fld.name, *fld.data, dims);
      const h5::Handle ds(H5Dopen2(g, fld.name, H5P_DEFAULT), H5Dclose);
      h5::writeAttribute(ds, "unit", fld.unit);
      h5::writeAttribute(ds, "description", fld.description);
    }
    h5::writeAttribute(g, "origin_xyz", fmt::format("{:.17g}", fmt::join(a.grid.origin, " ")));
    h5::writeAttribute(g, "spacing_xyz", fmt::format("{:.17g}", fmt::join(a.grid.spacing, " ")));
  }
  fs::rename(h5Path.string() + ".tmp", h5Path);
  const std::string file = h5Path.filename().string();
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n";
  x << "<Xdmf Version=\"3.0\">\n <Domain>\n";
  x << fmt::format("  <Grid Name=\"averages t={:.6g}..{:.6g} s\" GridType=\"Uniform\">\n",
                   a.times.front(), a.times.back());
  x << fmt::format("   <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{} {} {}\"/>\n",
                   n[2] + 1, n[1] + 1, n[0] + 1);
  x << "   <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n";
  x << fmt::format("    <DataItem Dimensions=\"3\" Format=\"XML\">{:.17g} {:.17g} {:.17g}"
                   "</DataItem>\n",
                   a.grid.origin[2], a.grid.origin[1], a.grid.origin[0]);
  x << fmt::format("    <DataItem Dimensions=\"3\" Format=\"XML\">{:.17g} {:.17g} {:.17g}"
                   "</DataItem>\n",
                   a.grid.spacing[2], a.grid.spacing[1], a.grid.spacing[0]);
  x << "   </Geometry>\n";
  for (const auto& fld : cellFields(a)) {
    const bool vec = fld.components == 3;
    x << fmt::format("   <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Cell\">\n", fld.name,
                     vec ? "Vector" : "Scalar");
    x << fmt::format("    <DataItem Dimensions=\"{} {} {}{}\" NumberType=\"Float\" "
                     "Precision=\"8\" Format=\"HDF\">{}:/cells/{}</DataItem>\n",
                     n[2], n[1], n[0], vec ? " 3" : "", file, fld.name);
    x << "   </Attribute>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
  writeFileAtomic(xdmf, x.str());
}

std::string statsJson(const TimeseriesStats& s, const std::optional<FieldAverages>& fields,
                      const std::string& fieldsFile) {
  JsonWriter w;
  w.beginObject();
  w.key("window").beginObject().field("from", s.from).field("to", s.to).endObject();
  w.key("run").beginObject().field("start", s.runStart).field("end", s.runEnd).endObject();
  w.field("rows", std::uint64_t(s.rows)).field("first_row_t", s.firstRow);
  w.field("last_row_t", s.lastRow);
  w.field("weighting", "each row stands for the time since the previous row (clipped to the "
                       "window): mean and std are time averages");
  w.key("columns").beginObject();
  for (const auto& c : s.columns) {
    w.key(c.name).beginObject();
    w.field("rows", std::uint64_t(c.rows)).field("mean", c.mean).field("std", c.std);
    w.field("min", c.min).field("max", c.max).endObject();
  }
  w.endObject();
  w.key("fields");
  if (!fields) {
    w.null();
  } else {
    w.beginObject().field("file", fieldsFile);
    w.field("samples", std::uint64_t(fields->times.size()));
    w.key("sample_times").beginArray();
    for (double t : fields->times) {
      w.value(t);
    }
    w.endArray().endObject();
  }
  w.endObject();
  return w.str();
}

std::string statsTable(const TimeseriesStats& s) {
  std::size_t width = 6;
  for (const auto& c : s.columns) {
    width = std::max(width, c.name.size());
  }
  std::string out = fmt::format("window t = ({:.6g}, {:.6g}] s: {} rows, t = {:.6g} .. {:.6g} s "
                                "(run: {:.6g} .. {:.6g} s; time-weighted)\n",
                                s.from, s.to, s.rows, s.firstRow, s.lastRow, s.runStart, s.runEnd);
  out += fmt::format("{:<{}}  {:>15} {:>12} {:>15} {:>15}\n", "column", width, "mean", "std", "min",
                     "max");
  for (const auto& c : s.columns) {
    if (c.rows == 0) {
      out += fmt::format("{:<{}}  (no values in the window)\n", c.name, width);
      continue;
    }
    out += fmt::format("{:<{}}  {:>15.8g} {:>12.4g} {:>15.8g} {:>15.8g}\n", c.name, width, c.mean,
                       c.std, c.min, c.max);
  }
  return out;
}

} // namespace coredem::orchestrator
