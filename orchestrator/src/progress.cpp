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

Progress::Sample Progress::rateAnchor(Clock::time_point now) const {
  for (const Sample& s : _samples) {
    if (std::chrono::duration<double>(now - s.wall).count() <= kRateWindowSeconds) {
      return s;
    }
  }
  return _samples.empty() ? Sample{_start, _t0, _step0} : _samples.back();
}

std::string Progress::line(std::int64_t step, double time, Clock::time_point now) const {
  // The recent rate: from the anchor (at most kRateWindowSeconds ago) to now.
  Sample a = rateAnchor(now);
  if (a.step >= step || !(now > a.wall)) {
    a = Sample{_start, _t0, _step0};
  }
  const double wall = std::chrono::duration<double>(now - a.wall).count();
  const double rate = wall > 0.0 ? double(step - a.step) / wall : 0.0;
  const double simRate = wall > 0.0 ? (time - a.time) / wall : 0.0; // simulated s per wall s
  const double pct = 100.0 * std::clamp((time - 0.0) / (_tEnd > 0.0 ? _tEnd : 1.0), 0.0, 1.0);
  std::string eta = "?";
  if (simRate > 0.0) {
    eta = formatDuration(std::max(0.0, _tEnd - time) / simRate);
  }
  return fmt::format("step {}  t = {:.4e} / {:.4e} s ({:.1f}%)  {:.1f} steps/s  ETA {}", step, time,
                     _tEnd, pct, rate, eta);
}

void Progress::update(std::int64_t step, double time, Clock::time_point now) {
  if (_samples.empty() ||
      std::chrono::duration<double>(now - _samples.back().wall).count() >= 0.5) {
    _samples.push_back({now, time, step});
    // keep one sample older than the window (the anchor until a newer one is old enough)
    while (_samples.size() > 2 &&
           std::chrono::duration<double>(now - _samples[1].wall).count() > kRateWindowSeconds) {
      _samples.pop_front();
    }
  }
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
