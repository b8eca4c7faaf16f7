#pragma once
/// @file
/// User errors vs internal bugs.
///
/// COREDEM_CHECK(cond, fmt, args...) is for anything a user, a case file or a peer can get
/// wrong: it throws coredem::UserError with a formatted message that says what was wrong and
/// what to do. COREDEM_ASSERT(cond) guards internal invariants; it is compiled out in
/// release builds unless COREDEM_ENABLE_ASSERTS is defined.

#include <stdexcept>
#include <string>

#include "coredem/common/format.h"

namespace coredem {

/// A problem caused by input (case file, message, command line), not by a bug.
class UserError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// An internal invariant was violated: a bug in CoReDEM.
class InternalError : public std::logic_error {
public:
  using std::logic_error::logic_error;
};

} // namespace coredem

#define COREDEM_CHECK(cond, ...)                                                                   \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      throw ::coredem::UserError(::coredem::format(__VA_ARGS__));                                  \
    }                                                                                              \
  } while (false)

#if !defined(NDEBUG) || defined(COREDEM_ENABLE_ASSERTS)
#define COREDEM_ASSERT(cond)                                                                       \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      throw ::coredem::InternalError(::coredem::format(                                            \
          "internal error: assertion '{}' failed at {}:{}", #cond, __FILE__, __LINE__));           \
    }                                                                                              \
  } while (false)
#else
#define COREDEM_ASSERT(cond)                                                                       \
  do {                                                                                             \
  } while (false)
#endif
