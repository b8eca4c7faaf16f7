// coredem::formatLite (the DEM core's formatting without fmt, coredem/common/format.h) against
// fmt::format, the reference it imitates: the same text for every kind of field the project's
// messages use, and an error (not a crash or a silent wrong text) for a malformed one.
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "coredem/common/format.h"

namespace {

/// formatLite and fmt::format agree on f with args.
template <typename... A>
void same(const char* f, const A&... args) {
  const std::string want = fmt::format(fmt::runtime(f), args...);
  EXPECT_EQ(coredem::formatLite(f, args...), want) << "format \"" << f << "\"";
}

TEST(FormatLite, PlainFieldsMatchFmt) {
  same("no fields");
  same("{} of {}", 3, 7);
  same("{}", -42);
  same("{}", std::uint64_t{18446744073709551615ULL});
  same("{}", std::numeric_limits<long long>::min());
  same("'{}' is not allowed", std::string("dt_factor"));
  same("{}{}", "a", std::string_view("b"));
  same("{} {}", true, false);
  same("{}", 'x');
  same("{{literal}} {}", 1);
}

TEST(FormatLite, ShortestFloatingPointMatchesFmt) {
  // fmt's `{}` on a double: the shortest digits that read back, fixed for decimal exponents in
  // [-4, 16), scientific otherwise.
  for (double v :
       {0.0, -0.0, 1.0, 0.1, 1.0 / 3.0, 2.5e-6, 1e-4, 9.99e-5, 123456.789, 1e15, 1e16, 1.5e16,
        6.02214076e23, -7.25e-12, 100000.0, 1e300, 5e-324, std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity()})
    same("{}", v);
  same("{}", std::nan(""));
  same("{}", 0.1f);
  same("{}", 3.4028235e38f);
}

TEST(FormatLite, SpecsMatchFmt) {
  for (double v : {0.0, 1.0, -2.5, 1.6075e-6, 363.15, 12345678.9}) {
    same("{:.3g}", v);
    same("{:.6g}", v);
    same("{:.3e}", v);
    same("{:.2f}", v);
    same("{:10.3f}", v);
    same("{:<12.4g}|", v);
    same("{:^12.2e}|", v);
    same("{:+.1f}", v);
    same("{:.3}", v);
  }
  same("{:5}|{:<5}|{:>5}|{:^5}|", 42, 42, 42, 42);
  same("{:05}", -42);
  same("{:x} {:X} {:#x} {:o} {:b} {:#b}", 255, 255, 255, 8, 5, 5);
  same("{:#06x}", 255);
  same("{:*^9}", std::string("mid"));
  same("{:>8}|{:<8}|", std::string("r"), std::string("l"));
  same("{:.3}", std::string("truncated"));
  same("{1} {0}", "second", "first");
  same("{:>6}", true);
}

TEST(FormatLite, MalformedFieldsThrow) {
  EXPECT_THROW(coredem::formatLite("{} {}", 1), std::invalid_argument); // too few arguments
  EXPECT_THROW(coredem::formatLite("{", 1), std::invalid_argument);
  EXPECT_THROW(coredem::formatLite("}", 1), std::invalid_argument);
  EXPECT_THROW(coredem::formatLite("{:q}", 1), std::invalid_argument);
  EXPECT_THROW(coredem::formatLite("{:.}", 1.0), std::invalid_argument);
  EXPECT_THROW(coredem::formatLite("{:d}", 1.0), std::invalid_argument);
  EXPECT_THROW(coredem::formatLite("{:f}", std::string("text")), std::invalid_argument);
  EXPECT_THROW(coredem::formatLite("{x}", 1), std::invalid_argument);
}

} // namespace
