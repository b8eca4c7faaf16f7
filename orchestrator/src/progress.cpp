#include <algorithm>
#include <cmath>
#include <cstdio>

#include <coredem/common/log.h>
#include <coredem/orchestrator/progress.h>

namespace coredem::orchestrator {

std::string formatDuration(double s) {
  if (!std::isfinite(s) || s < 0) {
    return "?";
  }
  if (s < 60.0) {
    return fmt::format("{:.1f}s", s);
  }
  if (s < 3600.0) {
    const int m = int(s / 60.0);
    return fmt::format("{}m{:02d}s", m, int(s - 60.0 * m));
  }
  const int h = int(s / 3600.0);
  return fmt::format("{}h{:02d}m", h, int((s - 3600.0 * h) / 60.0));
}

Progress::Progress(double startTime, double endTime, std::int64_t startStep, bool tty,
                   double logIntervalSeconds)
    : _t0(startTime)
    , _tEnd(endTime)
    , _step0(startStep)
    , _tty(tty)
    , _interval(logIntervalSeconds)
    , _start(Clock::now())
    , _lastPrint(_start) {
  _sink = [](const std::string& text, bool inPlace) {
    if (inPlace) {
      std::fprintf(stderr, "\r%s\033[K", text.c_str());
      std::fflush(stderr);
    } else {
      logger("orchestrator.progress")->info("{}", text);
    }
  };
}

void Progress::setSink(std::function<void(const std::string&, bool)> sink) {
  _sink = std::move(sink);
}

std::string Progress::line(std::int64_t step, double time, Clock::time_point now) const {
  const double wall = std::chrono::duration<double>(now - _start).count();
  const double steps = double(step - _step0);
  const double rate = wall > 0.0 ? steps / wall : 0.0;
  const double span = _tEnd - _t0;
  const double done = span > 0.0 ? (time - _t0) / span : 1.0;
  const double pct = 100.0 * std::clamp((time - 0.0) / (_tEnd > 0.0 ? _tEnd : 1.0), 0.0, 1.0);
  std::string eta = "?";
  if (done > 0.0 && wall > 0.0) {
    eta = formatDuration(wall * (1.0 - done) / done);
  }
  return fmt::format("step {}  t = {:.4e} / {:.4e} s ({:.1f}%)  {:.1f} steps/s  ETA {}", step, time,
                     _tEnd, pct, rate, eta);
}

void Progress::update(std::int64_t step, double time, Clock::time_point now) {
  const double since = std::chrono::duration<double>(now - _lastPrint).count();
  const double due = _tty ? 0.2 : _interval;
  if (_printedOnce && since < due) {
    return;
  }
  if (!_printedOnce && !_tty && since < due) {
    return;
  }
  _printedOnce = true;
  _lastPrint = now;
  _lastPrintedStep = step;
  _sink(line(step, time, now), _tty);
}

void Progress::finish(std::int64_t step, double time, Clock::time_point now) {
  const std::string text = line(step, time, now);
  if (_tty) {
    if (_lastPrintedStep != step) {
      _sink(text, true);
    }
    std::fprintf(stderr, "\n");
  } else {
    _sink(text, false);
  }
}

} // namespace coredem::orchestrator
