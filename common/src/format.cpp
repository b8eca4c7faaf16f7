#include <cctype>
#include <cmath>
#include <cstring>

#include <coredem/common/format.h>

namespace coredem::format_detail {
namespace {

[[noreturn]] void bad(std::string_view f, const char* what) {
  throw std::invalid_argument(std::string("format string \"") + std::string(f) + "\": " + what);
}

/// A parsed `[[fill]align][sign][#][0][width][.precision][type]`.
struct Spec {
  char fill = ' ';
  char align = 0; ///< '<', '>', '^' or 0 (the type's default)
  char sign = 0;  ///< '+', ' ' or 0
  bool alt = false;
  bool zero = false;
  int width = 0;
  int precision = -1;
  char type = 0;
};

bool isAlign(char c) {
  return c == '<' || c == '>' || c == '^';
}

Spec parseSpec(std::string_view f, std::string_view s) {
  Spec p;
  std::size_t k = 0;
  if (s.size() >= 2 && isAlign(s[1])) {
    p.fill = s[0];
    p.align = s[1];
    k = 2;
  } else if (!s.empty() && isAlign(s[0])) {
    p.align = s[0];
    k = 1;
  }
  if (k < s.size() && (s[k] == '+' || s[k] == ' ' || s[k] == '-')) {
    p.sign = s[k] == '-' ? 0 : s[k];
    ++k;
  }
  if (k < s.size() && s[k] == '#') {
    p.alt = true;
    ++k;
  }
  if (k < s.size() && s[k] == '0') {
    p.zero = true;
    ++k;
  }
  auto number = [&](int& out) {
    const char* b = s.data() + k;
    const auto [end, ec] = std::from_chars(b, s.data() + s.size(), out);
    if (ec != std::errc())
      bad(f, "a width or precision is not a number");
    k += static_cast<std::size_t>(end - b);
  };
  if (k < s.size() && s[k] >= '1' && s[k] <= '9')
    number(p.width);
  if (k < s.size() && s[k] == '.') {
    ++k;
    if (k >= s.size() || s[k] < '0' || s[k] > '9')
      bad(f, "'.' is not followed by a precision");
    number(p.precision);
  }
  if (k < s.size())
    p.type = s[k++];
  if (k != s.size())
    bad(f,
        "a replacement field's format is not [[fill]align][sign][#][0][width][.precision][type]");
  return p;
}

/// Pads `body` to the spec's width; numbers align right, text left unless told otherwise.
std::string pad(std::string body, const Spec& p, bool numeric) {
  if (p.width <= 0 || static_cast<int>(body.size()) >= p.width)
    return body;
  const std::size_t n = static_cast<std::size_t>(p.width) - body.size();
  if (p.zero && !p.align && numeric) {
    // Zeros go after the sign (and after a 0x prefix): -0012, 0x00ff.
    std::size_t at =
        (!body.empty() && (body[0] == '-' || body[0] == '+' || body[0] == ' ')) ? 1 : 0;
    if (body.size() >= at + 2 && body[at] == '0' &&
        (body[at + 1] == 'x' || body[at + 1] == 'X' || body[at + 1] == 'b' || body[at + 1] == 'B'))
      at += 2;
    body.insert(at, n, '0');
    return body;
  }
  const char align = p.align ? p.align : (numeric ? '>' : '<');
  if (align == '<')
    return body + std::string(n, p.fill);
  if (align == '>')
    return std::string(n, p.fill) + body;
  return std::string(n / 2, p.fill) + body + std::string(n - n / 2, p.fill);
}

std::string withSign(std::string digits, bool negative, const Spec& p) {
  if (negative)
    return "-" + digits;
  if (p.sign)
    return std::string(1, p.sign) + digits;
  return digits;
}

std::string formatInteger(std::string_view f, unsigned long long magnitude, bool negative,
                          const Spec& p) {
  int base = 10;
  const char* prefix = "";
  switch (p.type) {
  case 0:
  case 'd':
    break;
  case 'x':
    base = 16;
    prefix = "0x";
    break;
  case 'X':
    base = 16;
    prefix = "0X";
    break;
  case 'o':
    base = 8;
    prefix = "0";
    break;
  case 'b':
    base = 2;
    prefix = "0b";
    break;
  case 'B':
    base = 2;
    prefix = "0B";
    break;
  default:
    bad(f, "an integer's type is not one of d x X o b B");
  }
  char buf[72];
  const auto r = std::to_chars(buf, buf + sizeof buf, magnitude, base);
  std::string digits(buf, r.ptr);
  if (p.type == 'X')
    for (char& c : digits)
      c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (p.alt && !(base == 8 && digits == "0"))
    digits = prefix + digits;
  return pad(withSign(digits, negative, p), p, true);
}

/// fmt's `{}` for a floating-point value: the shortest digits that read back to the same
/// value, fixed notation for decimal exponents in [-4, 16), scientific otherwise.
template <typename T>
std::string shortest(T v) {
  char sci[64];
  const auto rs = std::to_chars(sci, sci + sizeof sci, v, std::chars_format::scientific);
  const std::string_view s(sci, static_cast<std::size_t>(rs.ptr - sci));
  const std::size_t e = s.find('e');
  if (e == std::string_view::npos)
    return std::string(s); // inf, nan
  int exponent = 0;
  std::from_chars(s.data() + e + 1 + (s[e + 1] == '+'), s.data() + s.size(), exponent);
  if (exponent < -4 || exponent >= 16)
    return std::string(s);
  char fixed[400];
  const auto rf = std::to_chars(fixed, fixed + sizeof fixed, v, std::chars_format::fixed);
  return std::string(fixed, rf.ptr);
}

template <typename T>
std::string formatFloat(std::string_view f, T v, const Spec& p) {
  const bool negative = std::signbit(v);
  const T magnitude = negative ? -v : v;
  std::string body;
  if (p.type == 0 && p.precision < 0) {
    body = shortest(magnitude);
  } else {
    char type = p.type;
    double value = static_cast<double>(magnitude);
    if (type == 0) {
      type = 'g';
    } else if (type == '%') {
      value *= 100;
      type = 'f';
    } else if (!std::strchr("eEfFgG", type)) {
      bad(f, "a floating-point value's type is not one of e E f F g G %");
    }
    char conversion[16];
    std::snprintf(conversion, sizeof conversion, "%%%s.%d%c", p.alt ? "#" : "",
                  p.precision < 0 ? 6 : p.precision, type);
    char buf[512];
    const int n = std::snprintf(buf, sizeof buf, conversion, value);
    body.assign(buf, static_cast<std::size_t>(n > 0 ? n : 0));
    if (p.type == '%')
      body += '%';
  }
  return pad(withSign(body, negative, p), p, true);
}

std::string formatOne(std::string_view f, const Arg& a, const Spec& p) {
  switch (a.kind) {
  case Arg::Kind::Signed: {
    const bool negative = a.i < 0;
    const unsigned long long m = negative ? 0ULL - static_cast<unsigned long long>(a.i)
                                          : static_cast<unsigned long long>(a.i);
    return formatInteger(f, m, negative, p);
  }
  case Arg::Kind::Unsigned:
    return formatInteger(f, a.u, false, p);
  case Arg::Kind::Float:
    return formatFloat(f, a.f, p);
  case Arg::Kind::Double:
    return formatFloat(f, a.d, p);
  case Arg::Kind::Bool:
    if (p.type && p.type != 's')
      return formatInteger(f, a.b ? 1 : 0, false, p);
    return pad(a.b ? "true" : "false", p, false);
  case Arg::Kind::Char:
    if (p.type && p.type != 'c')
      return formatInteger(f, static_cast<unsigned char>(a.c), false, p);
    return pad(std::string(1, a.c), p, false);
  case Arg::Kind::Text: {
    if (p.type && p.type != 's')
      bad(f, "a string's type is not s");
    std::string_view t = a.text;
    if (p.precision >= 0 && static_cast<std::size_t>(p.precision) < t.size())
      t = t.substr(0, static_cast<std::size_t>(p.precision));
    return pad(std::string(t), p, false);
  }
  }
  bad(f, "unknown argument kind");
}

} // namespace

std::string formatArgs(std::string_view f, const Arg* args, std::size_t count) {
  std::string out;
  out.reserve(f.size() + 16 * count);
  std::size_t next = 0; // automatic numbering
  for (std::size_t k = 0; k < f.size(); ++k) {
    const char c = f[k];
    if (c == '}') {
      if (k + 1 < f.size() && f[k + 1] == '}') {
        out += '}';
        ++k;
        continue;
      }
      bad(f, "unmatched '}' (write '}}' for a brace)");
    }
    if (c != '{') {
      out += c;
      continue;
    }
    if (k + 1 < f.size() && f[k + 1] == '{') {
      out += '{';
      ++k;
      continue;
    }
    const std::size_t close = f.find('}', k + 1);
    if (close == std::string_view::npos)
      bad(f, "unmatched '{' (write '{{' for a brace)");
    std::string_view field = f.substr(k + 1, close - k - 1);
    const std::size_t colon = field.find(':');
    const std::string_view id = field.substr(0, colon);
    std::size_t index = next++;
    if (!id.empty()) {
      const auto [end, ec] = std::from_chars(id.data(), id.data() + id.size(), index);
      if (ec != std::errc() || end != id.data() + id.size())
        bad(f, "an argument id is not a number");
    }
    if (index >= count)
      bad(f, "more replacement fields than arguments");
    const Spec spec =
        colon == std::string_view::npos ? Spec{} : parseSpec(f, field.substr(colon + 1));
    out += formatOne(f, args[index], spec);
    k = close;
  }
  return out;
}

} // namespace coredem::format_detail
