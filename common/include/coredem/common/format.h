#pragma once
/// @file
/// coredem::format("{} of {:.3g}", a, b): the project's one formatting call, in fmt's syntax.
///
/// Every build but the DEM core alone has spdlog and therefore fmt: there coredem::format is
/// fmt::format, with the format string checked at compile time. The DEM core built alone
/// (COREDEM_CORE_ONLY: a C++ compiler, CMake, OpenMP and CUDA, no third-party library) has no
/// fmt; there coredem::format is coredem::formatLite below, which understands the replacement
/// fields the core's messages use. formatLite is compiled in every build, and its unit test
/// compares it with fmt::format on the same fields (tests/unit/common/format_test.cpp).
///
/// formatLite understands: `{}` and `{N}` (argument N), `{:spec}` with
/// spec = [[fill]align][sign][#][0][width][.precision][type], `{{` and `}}`.
///   numbers:  type d x X o b (integers), e E f F g G % (floating point); a float with no type
///             prints its shortest round-trip form, fixed for exponents in [-4, 16), else
///             scientific (fmt's rule), with precision it is %g-like;
///   strings:  precision truncates; bool prints true/false; char prints itself;
///   align:    < > ^ (numbers right-aligned, text left-aligned by default).
/// A malformed field or a missing argument throws std::invalid_argument (fmt throws
/// fmt::format_error, or refuses to compile).

#include <array>
#include <charconv>
#include <concepts>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

#if COREDEM_HAVE_FMT
#include <fmt/format.h>
#endif

namespace coredem {

namespace format_detail {

/// One argument, type-erased (by value for numbers, by view for text).
struct Arg {
  enum class Kind { Signed, Unsigned, Float, Double, Text, Bool, Char } kind;
  union {
    long long i;
    unsigned long long u;
    float f;
    double d;
    bool b;
    char c;
  };
  std::string_view text;
};

template <typename T>
Arg makeArg(const T& v) {
  using U = std::remove_cvref_t<T>;
  Arg a{};
  if constexpr (std::is_same_v<U, bool>) {
    a.kind = Arg::Kind::Bool;
    a.b = v;
  } else if constexpr (std::is_same_v<U, char>) {
    a.kind = Arg::Kind::Char;
    a.c = v;
  } else if constexpr (std::is_enum_v<U>) {
    static_assert(!std::is_enum_v<U>, "formatLite: format an enum's name or its underlying value");
  } else if constexpr (std::signed_integral<U>) {
    a.kind = Arg::Kind::Signed;
    a.i = v;
  } else if constexpr (std::unsigned_integral<U>) {
    a.kind = Arg::Kind::Unsigned;
    a.u = v;
  } else if constexpr (std::is_same_v<U, float>) {
    a.kind = Arg::Kind::Float;
    a.f = v;
  } else if constexpr (std::floating_point<U>) {
    a.kind = Arg::Kind::Double;
    a.d = static_cast<double>(v);
  } else {
    static_assert(std::is_convertible_v<const U&, std::string_view>,
                  "formatLite: arguments are numbers, bool, char or text");
    a.kind = Arg::Kind::Text;
    a.text = std::string_view(v);
  }
  return a;
}

/// Formats `f` with `args` (fmt's syntax, the subset in the file comment).
std::string formatArgs(std::string_view f, const Arg* args, std::size_t count);

} // namespace format_detail

/// fmt-syntax formatting without fmt (see the file comment for what it understands).
template <typename... Args>
std::string formatLite(std::string_view f, const Args&... args) {
  const std::array<format_detail::Arg, sizeof...(Args)> erased{format_detail::makeArg(args)...};
  return format_detail::formatArgs(f, erased.data(), erased.size());
}

#if COREDEM_HAVE_FMT
template <typename... Args>
std::string format(fmt::format_string<Args...> f, Args&&... args) {
  return fmt::vformat(f, fmt::make_format_args(args...));
}
#else
template <typename... Args>
std::string format(std::string_view f, const Args&... args) {
  return formatLite(f, args...);
}
#endif

} // namespace coredem
