#pragma once
/// @file
/// Writing JSON (run.json, manifests, timers, records): one escaper and one small writer, so
/// that no component builds JSON by string concatenation. Reading JSON is done with yaml-cpp
/// (JSON is YAML).
///
///   JsonWriter w;
///   w.beginObject().field("steps", 12).field("case_dir", dir.string()).endObject();
///   writeFileAtomic(path, w.str());

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace coredem {

/// s as the inside of a JSON string literal: quote, backslash and control characters escaped.
std::string jsonEscape(std::string_view s);

/// A streaming JSON writer. Objects and arrays nest; with indent > 0 the output is pretty-printed
/// one member a line. Misuse (a value where a key is expected, unbalanced end) is an internal
/// error (InternalError).
class JsonWriter {
public:
  explicit JsonWriter(int indent = 2);

  JsonWriter& beginObject();
  JsonWriter& endObject();
  JsonWriter& beginArray();
  JsonWriter& endArray();
  /// The key of the next member of the current object.
  JsonWriter& key(std::string_view k);

  JsonWriter& value(std::string_view v);
  JsonWriter& value(const char* v) { return value(std::string_view(v)); }
  JsonWriter& value(const std::string& v) { return value(std::string_view(v)); }
  /// A finite double in the shortest form that reads back to the same bits; NaN/inf as null.
  JsonWriter& value(double v);
  JsonWriter& value(std::int64_t v);
  JsonWriter& value(int v) { return value(static_cast<std::int64_t>(v)); }
  JsonWriter& value(std::uint64_t v);
  JsonWriter& value(bool v);
  JsonWriter& null();
  /// Inserts already-formatted JSON text as a value (e.g. a number with a chosen precision).
  JsonWriter& raw(std::string_view json);

  /// key(k).value(v)
  template <class T>
  JsonWriter& field(std::string_view k, const T& v) {
    key(k);
    return value(v);
  }

  /// The document; all objects and arrays must be closed. Ends with a newline.
  std::string str() const;

private:
  void beforeValue();
  void newline();

  struct Level {
    bool isObject;
    bool empty = true;
    bool keyPending = false;
  };
  std::string _out;
  std::vector<Level> _stack;
  int _indent;
  bool _done = false;
};

} // namespace coredem
