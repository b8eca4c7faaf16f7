// coredem-dem --timers: the per-stage report (timers.h).
#include "timers.h"

#include <filesystem>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "coredem/common/check.h"
#include "coredem/common/files.h"
#include "coredem/common/json.h"

namespace coredem::server {

namespace {

/// StageTimes::chemistry when the DEM core has a chemistry stage, else 0.
template <class T>
double chemistrySeconds(const T& st) {
  if constexpr (requires { st.chemistry; }) {
    return st.chemistry;
  } else {
    return 0.0;
  }
}

struct Row {
  const char* name;
  double seconds;
};

std::vector<Row> demRows(const ExchangeTimes& x, const dem::StageTimes& st) {
  const double chem = chemistrySeconds(st);
  const double named =
      st.neighbour + st.contact + st.drag + st.heat + chem + st.integrate + st.coupling;
  return {{"neighbour", st.neighbour},
          {"contact", st.contact},
          {"drag", st.drag},
          {"heat", st.heat},
          {"chemistry", chem},
          {"integration", st.integrate},
          {"pcm_deposition", st.coupling},
          {"dem_other", x.advance - named}};
}

std::vector<Row> exchangeRows(const ExchangeTimes& x) {
  return {{"wait_for_peer", x.waitPeer}, {"validate", x.validate}, {"unpack", x.unpack},
          {"pack_send", x.packSend},     {"ledgers", x.ledgers},   {"checkpoint", x.checkpoint}};
}

} // namespace

std::string timersReport(const ExchangeTimes& x, const dem::StageTimes& st, double sessionSeconds,
                         bool multiLine) {
  const auto dem = demRows(x, st);
  const auto ex = exchangeRows(x);
  const double total = sessionSeconds > 0 ? sessionSeconds : 1.0;
  const double rate = x.advance > 0 ? static_cast<double>(x.particleSubSteps) / x.advance : 0.0;
  std::string s;
  if (!multiLine) {
    s = fmt::format("timers after {} steps ({:.1f} s): DEM {:.1f}% [", x.steps, sessionSeconds,
                    100.0 * x.advance / total);
    for (std::size_t k = 0; k < dem.size(); ++k) {
      s += fmt::format("{}{} {:.1f}%", k ? ", " : "", dem[k].name, 100.0 * dem[k].seconds / total);
    }
    s += "], exchange [";
    for (std::size_t k = 0; k < ex.size(); ++k) {
      s += fmt::format("{}{} {:.1f}%", k ? ", " : "", ex[k].name, 100.0 * ex[k].seconds / total);
    }
    s += fmt::format("], {:.3e} particle-steps/s in the DEM", rate);
    return s;
  }
  s = fmt::format("timers: {} CFD steps, {:.3f} s in the session, {:.3e} particle sub-steps per "
                  "DEM second ({} rebuilds)\n",
                  x.steps, sessionSeconds, rate, st.rebuilds);
  s += fmt::format("  {:<22} {:>10} {:>7} {:>12}\n", "stage", "s", "%", "ms/step");
  const double steps = x.steps > 0 ? static_cast<double>(x.steps) : 1.0;
  auto line = [&](const char* name, double sec) {
    s += fmt::format("  {:<22} {:>10.3f} {:>6.1f}% {:>12.3f}\n", name, sec, 100.0 * sec / total,
                     1e3 * sec / steps);
  };
  line("DEM advance", x.advance);
  for (const Row& r : dem)
    line((std::string("  ") + r.name).c_str(), r.seconds);
  double exSum = 0.0;
  for (const Row& r : ex)
    exSum += r.seconds;
  line("exchange", exSum);
  for (const Row& r : ex)
    line((std::string("  ") + r.name).c_str(), r.seconds);
  line("other (server)", sessionSeconds - x.advance - exSum);
  return s;
}

std::string timersJson(const ExchangeTimes& x, const dem::StageTimes& st, double sessionSeconds,
                       const std::string& session, const std::string& backend, int threads) {
  JsonWriter w(0);
  w.beginObject()
      .field("program", "coredem-dem")
      .field("session", session)
      .field("backend", backend)
      .field("threads", threads)
      .field("steps", static_cast<std::int64_t>(x.steps))
      .field("particle_sub_steps", static_cast<std::uint64_t>(x.particleSubSteps))
      .field("rebuilds", static_cast<std::uint64_t>(st.rebuilds))
      .field("session_s", sessionSeconds)
      .field("advance_s", x.advance);
  w.key("dem_s").beginObject();
  for (const Row& r : demRows(x, st)) {
    w.field(r.name, r.seconds);
  }
  w.endObject();
  w.key("exchange_s").beginObject();
  double exSum = 0.0;
  for (const Row& r : exchangeRows(x)) {
    w.field(r.name, r.seconds);
    exSum += r.seconds;
  }
  w.endObject();
  w.field("exchange_total_s", exSum).field("server_other_s", sessionSeconds - x.advance - exSum);
  w.endObject();
  return w.str();
}

void writeTextFile(const std::string& path, const std::string& text) {
  const std::filesystem::path p(path);
  if (p.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(p.parent_path(), ec);
  }
  coredem::writeFileAtomic(p, text);
}

} // namespace coredem::server
