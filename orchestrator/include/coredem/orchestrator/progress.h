#pragma once
/// @file
/// The progress report of a run: simulated time, steps/s and ETA. On a terminal one line is
/// rewritten in place (at most 5 times a second); otherwise a log line every `logInterval`.
/// Steps/s and the ETA come from the recent rate: the simulated time and steps advanced over
/// the last `kRateWindowSeconds` of wall time (since the start while the run is younger), so a
/// run that slows down (a bed that settles, more contacts) gets an ETA that follows it.

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <string>

namespace coredem::orchestrator {

/// Formats a duration in seconds as "1h02m", "3m05s", "12.3s".
std::string formatDuration(double seconds);

class Progress {
public:
  using Clock = std::chrono::steady_clock;
  /// The wall-time window of the rate behind steps/s and the ETA (s).
  static constexpr double kRateWindowSeconds = 30.0;
  /// @param startTime / endTime simulated times [s]; @param tty rewrite one line on stderr
  /// when true, else log periodically. @param logIntervalSeconds period of log lines.
  Progress(double startTime, double endTime, std::int64_t startStep, bool tty,
           double logIntervalSeconds = 10.0);

  /// Reports the state after `step` reached simulated time `time` (and remembers it for the
  /// recent rate, at most one sample every 0.5 s). Prints when due.
  void update(std::int64_t step, double time, Clock::time_point now = Clock::now());
  /// Final line (always printed).
  void finish(std::int64_t step, double time, Clock::time_point now = Clock::now());

  /// The text of one progress report (no newline), e.g.
  /// "step 120  t = 1.200e-02 / 5.000e-02 s (24.0%)  85.3 steps/s  ETA 4.5s".
  std::string line(std::int64_t step, double time, Clock::time_point now) const;

  /// Redirects output (tests); default writes to stderr / the "orchestrator.progress" logger.
  void setSink(std::function<void(const std::string&, bool inPlace)> sink);

private:
  struct Sample {
    Clock::time_point wall;
    double time;
    std::int64_t step;
  };
  /// The oldest remembered sample no older than the rate window (the start when none).
  Sample rateAnchor(Clock::time_point now) const;

  double _t0, _tEnd;
  std::int64_t _step0;
  bool _tty;
  double _interval;
  Clock::time_point _start, _lastPrint;
  bool _printedOnce = false;
  std::int64_t _lastPrintedStep = -1;
  std::function<void(const std::string&, bool)> _sink;
  std::deque<Sample> _samples; ///< oldest first, about 0.5 s apart
};

} // namespace coredem::orchestrator
