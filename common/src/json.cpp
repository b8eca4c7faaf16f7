#include <cmath>
#include <cstdio>

#include <spdlog/fmt/fmt.h>

#include <coredem/common/check.h>
#include <coredem/common/json.h>

namespace coredem {

std::string jsonEscape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (const char c : s) {
    switch (c) {
    case '"':
      out += "\\\"";
      break;
    case '\\':
      out += "\\\\";
      break;
    case '\n':
      out += "\\n";
      break;
    case '\t':
      out += "\\t";
      break;
    case '\r':
      out += "\\r";
      break;
    default:
      if (static_cast<unsigned char>(c) < 0x20) {
        out += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
      } else {
        out += c;
      }
    }
  }
  return out;
}

JsonWriter::JsonWriter(int indent)
    : _indent(indent) {}

void JsonWriter::newline() {
  if (_indent > 0) {
    _out += '\n';
    _out.append(_stack.size() * static_cast<std::size_t>(_indent), ' ');
  }
}

void JsonWriter::beforeValue() {
  if (_stack.empty()) {
    if (_done) {
      throw InternalError("JsonWriter: a second top-level value");
    }
    _done = true;
    return;
  }
  Level& top = _stack.back();
  if (top.isObject) {
    if (!top.keyPending) {
      throw InternalError("JsonWriter: a value inside an object needs a key first");
    }
    top.keyPending = false;
    return;
  }
  if (!top.empty) {
    _out += ',';
  }
  top.empty = false;
  newline();
}

JsonWriter& JsonWriter::key(std::string_view k) {
  if (_stack.empty() || !_stack.back().isObject || _stack.back().keyPending) {
    throw InternalError("JsonWriter: key() outside an object or twice in a row");
  }
  Level& top = _stack.back();
  if (!top.empty) {
    _out += ',';
  }
  top.empty = false;
  top.keyPending = true;
  newline();
  _out += '"';
  _out += jsonEscape(k);
  _out += _indent > 0 ? "\": " : "\":";
  return *this;
}

JsonWriter& JsonWriter::beginObject() {
  beforeValue();
  _out += '{';
  _stack.push_back({true});
  return *this;
}

JsonWriter& JsonWriter::beginArray() {
  beforeValue();
  _out += '[';
  _stack.push_back({false});
  return *this;
}

JsonWriter& JsonWriter::endObject() {
  if (_stack.empty() || !_stack.back().isObject || _stack.back().keyPending) {
    throw InternalError("JsonWriter: endObject() without an open object (or after a bare key)");
  }
  const bool empty = _stack.back().empty;
  _stack.pop_back();
  if (!empty) {
    newline();
  }
  _out += '}';
  return *this;
}

JsonWriter& JsonWriter::endArray() {
  if (_stack.empty() || _stack.back().isObject) {
    throw InternalError("JsonWriter: endArray() without an open array");
  }
  const bool empty = _stack.back().empty;
  _stack.pop_back();
  if (!empty) {
    newline();
  }
  _out += ']';
  return *this;
}

JsonWriter& JsonWriter::value(std::string_view v) {
  beforeValue();
  _out += '"';
  _out += jsonEscape(v);
  _out += '"';
  return *this;
}

JsonWriter& JsonWriter::value(double v) {
  if (!std::isfinite(v)) {
    return null();
  }
  beforeValue();
  _out += fmt::format("{}", v); // shortest representation that round-trips
  return *this;
}

JsonWriter& JsonWriter::value(std::int64_t v) {
  beforeValue();
  _out += fmt::format("{}", v);
  return *this;
}

JsonWriter& JsonWriter::value(std::uint64_t v) {
  beforeValue();
  _out += fmt::format("{}", v);
  return *this;
}

JsonWriter& JsonWriter::value(bool v) {
  beforeValue();
  _out += v ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::null() {
  beforeValue();
  _out += "null";
  return *this;
}

JsonWriter& JsonWriter::raw(std::string_view json) {
  beforeValue();
  _out += json;
  return *this;
}

std::string JsonWriter::str() const {
  if (!_stack.empty() || !_done) {
    throw InternalError("JsonWriter: str() before the document is complete");
  }
  return _out + "\n";
}

} // namespace coredem
