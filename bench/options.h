#pragma once
/// @file
/// Command-line options of a `coredem-bench` command, without a third-party library (the DEM
/// core's benchmarks build where nothing but a compiler and CUDA is installed):
///
///   bench::Args args{"what the command measures", "coredem-bench dem"};
///   args.option("--particles", n, "number of particles").range(1, 2e9);
///   args.option("--backend", backend, "cpu | cuda").oneOf({"cpu", "cuda"});
///   args.flag("--json", json, "print one JSON object");
///   if (const int rc = args.parse(argc, argv); rc >= 0) return rc;  // --help: 0, error: 2
///
/// Values are given as `--name value` or `--name=value`; a repeated option takes the last value;
/// a std::vector<std::string> option takes a comma-separated list.

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <deque>
#include <functional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace coredem::bench {

/// One option; its checks run on the parsed value.
class Opt {
public:
  /// Numbers only: lo ≤ value ≤ hi.
  Opt& range(double lo, double hi) {
    _checks.push_back([lo, hi](double v, std::string_view) -> std::string {
      if (v >= lo && v <= hi)
        return {};
      char buf[96];
      std::snprintf(buf, sizeof buf, "must be in [%g, %g]", lo, hi);
      return buf;
    });
    return *this;
  }
  Opt& positive() {
    _checks.push_back([](double v, std::string_view) -> std::string {
      return v > 0 ? std::string() : std::string("must be positive");
    });
    return *this;
  }
  Opt& nonNegative() {
    _checks.push_back([](double v, std::string_view) -> std::string {
      return v >= 0 ? std::string() : std::string("must not be negative");
    });
    return *this;
  }
  /// Text only: the value is one of `allowed`.
  Opt& oneOf(std::vector<std::string> allowed) {
    _checks.push_back([allowed](double, std::string_view v) -> std::string {
      std::string list;
      for (const auto& a : allowed) {
        if (a == v)
          return {};
        list += (list.empty() ? "" : ", ") + a;
      }
      return "must be one of " + list;
    });
    return *this;
  }
  const std::string& name() const { return _name; }
  /// How many times the option was given.
  std::size_t count() const { return _count; }

private:
  friend class Args;
  using Check = std::function<std::string(double number, std::string_view text)>;
  std::string _name, _help;
  bool _flag = false;
  std::size_t _count = 0;
  /// Parses and stores one value; returns an error ("" on success). Numbers pass `number`.
  std::function<std::string(std::string_view value, double& number)> _set;
  std::vector<Check> _checks;
};

class Args {
public:
  Args(std::string description, std::string command)
      : _description(std::move(description))
      , _command(std::move(command)) {}
  Args(const Args&) = delete;
  Args& operator=(const Args&) = delete;

  /// A value option bound to `target` (integers, floating point, std::string, or a
  /// std::vector<std::string> given as a comma-separated list).
  template <typename T>
  Opt& option(std::string name, T& target, std::string help) {
    Opt& o = add(std::move(name), std::move(help));
    o._set = [&target](std::string_view v, double& number) -> std::string {
      using U = std::remove_cvref_t<T>;
      if constexpr (std::is_same_v<U, std::string>) {
        target = std::string(v);
      } else if constexpr (std::is_same_v<U, std::vector<std::string>>) {
        target.clear();
        for (std::size_t at = 0;;) {
          const std::size_t comma = v.find(',', at);
          target.emplace_back(v.substr(at, comma - at));
          if (comma == std::string_view::npos)
            break;
          at = comma + 1;
        }
      } else {
        static_assert(std::is_arithmetic_v<U>, "bench::Args: numbers, text or text lists");
        U value{};
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), value);
        if (ec != std::errc() || end != v.data() + v.size())
          return std::string("'") + std::string(v) + "' is not " +
                 (std::is_integral_v<U> ? "an integer" : "a number") +
                 (std::is_unsigned_v<U> ? " >= 0" : "");
        target = value;
        number = static_cast<double>(value);
      }
      return {};
    };
    return o;
  }

  /// A switch: present = true.
  Opt& flag(std::string name, bool& target, std::string help) {
    Opt& o = add(std::move(name), std::move(help));
    o._flag = true;
    o._set = [&target](std::string_view, double&) -> std::string {
      target = true;
      return {};
    };
    return o;
  }

  /// How many times option `name` was given.
  std::size_t count(std::string_view name) const {
    for (const Opt& o : _options)
      if (o._name == name)
        return o._count;
    return 0;
  }

  /// Parses argv[1..] (argv[0] is the command's name). Returns -1 to go on, 0 after --help, 2
  /// after an error (printed with the usage).
  int parse(int argc, char** argv) {
    for (int k = 1; k < argc; ++k) {
      std::string_view a = argv[k];
      if (a == "--help" || a == "-h") {
        usage(stdout);
        return 0;
      }
      std::string_view value;
      bool inlineValue = false;
      if (const std::size_t eq = a.find('='); a.starts_with("--") && eq != std::string_view::npos) {
        value = a.substr(eq + 1);
        a = a.substr(0, eq);
        inlineValue = true;
      }
      Opt* o = find(a);
      if (!o)
        return fail("unknown option '" + std::string(a) + "'");
      if (o->_flag) {
        if (inlineValue)
          return fail(o->_name + " takes no value");
      } else if (!inlineValue) {
        if (k + 1 >= argc)
          return fail(o->_name + " needs a value");
        value = argv[++k];
      }
      double number = 0;
      std::string error = o->_set(value, number);
      for (const auto& check : o->_checks)
        if (error.empty())
          error = check(number, value);
      if (!error.empty())
        return fail(o->_name + " " + std::string(value) + ": " + error);
      ++o->_count;
    }
    return -1;
  }

private:
  Opt& add(std::string name, std::string help) {
    Opt& o = _options.emplace_back();
    o._name = std::move(name);
    o._help = std::move(help);
    return o;
  }
  Opt* find(std::string_view name) {
    for (Opt& o : _options)
      if (o._name == name)
        return &o;
    return nullptr;
  }
  int fail(const std::string& message) {
    std::fprintf(stderr, "%s: %s\n\n", _command.c_str(), message.c_str());
    usage(stderr);
    return 2;
  }
  void usage(FILE* out) const {
    std::fprintf(out, "%s\nusage: %s [options]\n\noptions:\n", _description.c_str(),
                 _command.c_str());
    auto shown = [](const Opt& o) { return o._name + (o._flag ? "" : " X"); };
    int width = 10; // "-h, --help"
    for (const Opt& o : _options)
      width = std::max(width, static_cast<int>(shown(o).size()));
    std::fprintf(out, "  %-*s  %s\n", width, "-h, --help", "print this help and exit");
    for (const Opt& o : _options)
      std::fprintf(out, "  %-*s  %s\n", width, shown(o).c_str(), o._help.c_str());
  }

  std::string _description, _command;
  std::deque<Opt> _options; ///< a deque: the references handed out stay valid as options are added
};

} // namespace coredem::bench
