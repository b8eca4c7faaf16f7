#pragma once
/// @file
/// Compensated (Kahan) summation for cumulative ledgers and simulated time: the low-order bits
/// that each addition loses are carried into the next one, so 10^6 tiny increments do not drift.
/// The carry is part of the state: store both value() and compensation() in a checkpoint and
/// construct from both to continue bit-identically. Header-only (also used by OpenFOAM code).

namespace coredem {

class CompensatedSum {
public:
  /// @param value the sum so far; @param compensation its carry (restored from a checkpoint).
  explicit CompensatedSum(double value = 0.0, double compensation = 0.0)
      : _sum(value)
      , _carry(compensation) {}

  /// Adds x (Kahan): _carry holds the part of earlier additions that _sum could not represent.
  void add(double x) {
    const double y = x - _carry;
    const double t = _sum + y;
    _carry = (t - _sum) - y;
    _sum = t;
  }
  CompensatedSum& operator+=(double x) {
    add(x);
    return *this;
  }

  double value() const { return _sum; }
  double compensation() const { return _carry; }

private:
  double _sum;
  double _carry;
};

} // namespace coredem
