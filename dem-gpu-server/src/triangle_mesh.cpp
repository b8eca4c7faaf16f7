// Triangle-mesh walls on the host: STL reading/writing and welding (coredem/dem/triangle_mesh.h);
// topology and checks in mesh_checks.cpp, generators in mesh_generators.cpp.
#include "coredem/dem/triangle_mesh.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <utility>

#include "mesh_common.h"

namespace coredem::dem {
namespace {

using namespace mesh_detail;

// ---- reading ------------------------------------------------------------------------------

std::string readWholeFile(const std::filesystem::path& file) {
  const std::string where = file.string();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    fail(where, "STL file not found; check the wall's file path (a relative path is taken from "
                "the current folder)");
  }
  if (std::filesystem::is_directory(file, ec)) {
    fail(where, "is a folder, not an STL file; give the path of the .stl file");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    fail(where, "cannot open the STL file (" + std::string(std::strerror(errno)) +
                    "); check its permissions");
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) {
    fail(where, "error while reading the STL file; check the disk and the file");
  }
  return std::move(buffer).str();
}

std::uint32_t littleEndian32(const char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) {
    v = (v << 8) | static_cast<unsigned char>(p[i]);
  }
  return v;
}

float littleEndianFloat(const char* p) {
  return std::bit_cast<float>(littleEndian32(p));
}

bool startsWithSolid(std::string_view text) {
  const auto begin = text.find_first_not_of(" \t\r\n\f\v");
  if (begin == std::string_view::npos || text.size() - begin < 5) {
    return false;
  }
  static constexpr std::string_view kSolid = "solid";
  for (std::size_t i = 0; i < kSolid.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(text[begin + i])) != kSolid[i]) {
      return false;
    }
  }
  const std::size_t after = begin + kSolid.size();
  return after == text.size() || std::isspace(static_cast<unsigned char>(text[after]));
}

/// Text only: no control bytes but whitespace (binary float data nearly always has some).
bool isText(std::string_view text) {
  return std::none_of(text.begin(), text.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return (u < 0x20 && u != '\t' && u != '\n' && u != '\r' && u != '\f' && u != '\v') || u == 0x7f;
  });
}

/// Triangle soup, 9 coordinates a triangle, numbered from 1 in messages.
using Soup = std::vector<double>;

void checkFinite(const std::string& where, const Soup& soup, std::size_t t,
                 const std::string& line) {
  for (int k = 0; k < 3; ++k) {
    const double* p = &soup[9 * t + 3 * static_cast<std::size_t>(k)];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      fail(where, "triangle " + std::to_string(t + 1) + line + " has a non-finite coordinate in " +
                      "its vertex " + std::to_string(k + 1) + " " + pointText({p[0], p[1], p[2]}) +
                      "; the exporter wrote an invalid number: repair the surface or export it "
                      "again");
    }
  }
}

Soup parseBinary(const std::string& where, std::string_view data, std::uint32_t count) {
  Soup soup(9 * static_cast<std::size_t>(count));
  for (std::size_t t = 0; t < count; ++t) {
    // 12 floats: the stored normal (ignored: the winding decides), then 3 vertices.
    const char* record = data.data() + kBinaryHeader + kBinaryRecord * t;
    for (int i = 0; i < 9; ++i) {
      soup[9 * t + static_cast<std::size_t>(i)] =
          static_cast<double>(littleEndianFloat(record + 12 + 4 * i));
    }
    checkFinite(where, soup, t, "");
  }
  return soup;
}

/// Tokens of an ASCII STL file with their line numbers.
class AsciiReader {
public:
  struct Token {
    std::string_view text; ///< empty at the end of the file
    int line = 0;
  };

  AsciiReader(std::string_view text, std::string where)
      : _text(text)
      , _where(std::move(where)) {}

  Token next() {
    while (_pos < _text.size() && std::isspace(static_cast<unsigned char>(_text[_pos]))) {
      if (_text[_pos] == '\n') {
        ++_line;
      }
      ++_pos;
    }
    const std::size_t begin = _pos;
    while (_pos < _text.size() && !std::isspace(static_cast<unsigned char>(_text[_pos]))) {
      ++_pos;
    }
    return {_text.substr(begin, _pos - begin), _line};
  }

  /// Skips the rest of the current line (a solid's name).
  void skipRestOfLine() {
    while (_pos < _text.size() && _text[_pos] != '\n') {
      ++_pos;
    }
  }

  static bool is(const Token& token, std::string_view keyword) {
    if (token.text.size() != keyword.size()) {
      return false;
    }
    for (std::size_t i = 0; i < keyword.size(); ++i) {
      if (std::tolower(static_cast<unsigned char>(token.text[i])) != keyword[i]) {
        return false;
      }
    }
    return true;
  }

  [[noreturn]] void syntaxError(const Token& token, const std::string& expected) const {
    const std::string found = token.text.empty()
                                  ? "the end of the file (is the file truncated?)"
                                  : "`" + std::string(token.text.substr(0, 40)) + "`";
    fail(_where, "line " + std::to_string(token.line) + ": ASCII STL syntax error: expected " +
                     expected + ", found " + found +
                     "; an ASCII STL is `solid name`, then facets `facet normal nx ny nz`, "
                     "`outer loop`, three `vertex x y z`, `endloop`, `endfacet`, and "
                     "`endsolid`: fix the line or export the file again (binary STL avoids "
                     "this)");
  }

  void expect(std::string_view keyword) {
    const Token token = next();
    if (!is(token, keyword)) {
      syntaxError(token, "`" + std::string(keyword) + "`");
    }
  }

  double number(const char* what) {
    const Token token = next();
    std::string_view text = token.text;
    if (!text.empty() && text.front() == '+') {
      text.remove_prefix(1);
    }
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size()) {
      syntaxError(token, std::string("a number (") + what + ")" +
                             (ec == std::errc::result_out_of_range ? " within double range" : ""));
    }
    return value;
  }

  int line() const { return _line; }

private:
  std::string_view _text;
  std::string _where;
  std::size_t _pos = 0;
  int _line = 1;
};

Soup parseAscii(const std::string& where, std::string_view text) {
  AsciiReader reader(text, where);
  Soup soup;
  AsciiReader::Token token = reader.next();
  while (!token.text.empty()) {
    if (!AsciiReader::is(token, "solid")) {
      reader.syntaxError(token, "`solid` (a new solid) or the end of the file");
    }
    reader.skipRestOfLine(); // the solid's name
    for (;;) {
      token = reader.next();
      if (AsciiReader::is(token, "endsolid")) {
        reader.skipRestOfLine();
        break;
      }
      if (!AsciiReader::is(token, "facet")) {
        reader.syntaxError(token, "`facet` or `endsolid`");
      }
      const int facetLine = token.line;
      reader.expect("normal");
      for (int i = 0; i < 3; ++i) {
        reader.number("a normal component");
      }
      reader.expect("outer");
      reader.expect("loop");
      for (int k = 0; k < 3; ++k) {
        reader.expect("vertex");
        for (int i = 0; i < 3; ++i) {
          soup.push_back(reader.number("a vertex coordinate"));
        }
      }
      const AsciiReader::Token end = reader.next();
      if (!AsciiReader::is(end, "endloop")) {
        reader.syntaxError(end, AsciiReader::is(end, "vertex")
                                    ? "`endloop` (a facet has exactly 3 vertices: triangulate "
                                      "polygons before exporting)"
                                    : "`endloop`");
      }
      reader.expect("endfacet");
      checkFinite(where, soup, soup.size() / 9 - 1, " (line " + std::to_string(facetLine) + ")");
    }
    token = reader.next();
  }
  return soup;
}

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};

struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    auto h = static_cast<std::uint64_t>(k.x) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint64_t>(k.y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
    h ^= static_cast<std::uint64_t>(k.z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
    return static_cast<std::size_t>(h);
  }
};

/// Welds the soup's points: those within kWeldTolerance x the bounding-box diagonal (a hash grid
/// of that cell size, the 27 cells around a point searched) become the first of them.
TriangleMesh weld(std::string name, const Soup& soup) {
  TriangleMesh mesh;
  mesh.name = std::move(name);
  const std::size_t points = soup.size() / 3;
  mesh.triangles.resize(points);
  Vec3 lo{soup[0], soup[1], soup[2]}, hi = lo;
  for (std::size_t p = 0; p < points; ++p) {
    for (std::size_t d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], soup[3 * p + d]);
      hi[d] = std::max(hi[d], soup[3 * p + d]);
    }
  }
  const double tolerance = kWeldTolerance * norm(sub(hi, lo));
  if (!(tolerance > 0.0)) { // every point the same
    mesh.vertices.assign(lo.begin(), lo.end());
    std::fill(mesh.triangles.begin(), mesh.triangles.end(), 0);
    return mesh;
  }
  const double tolerance2 = tolerance * tolerance;
  std::unordered_map<CellKey, std::int32_t, CellHash> head; // first vertex of a cell
  std::vector<std::int32_t> nextInCell;
  head.reserve(points);
  mesh.vertices.reserve(soup.size());
  for (std::size_t p = 0; p < points; ++p) {
    const Vec3 x{soup[3 * p], soup[3 * p + 1], soup[3 * p + 2]};
    CellKey cell{};
    std::int64_t* c[3] = {&cell.x, &cell.y, &cell.z};
    for (std::size_t d = 0; d < 3; ++d) {
      *c[d] = static_cast<std::int64_t>(std::floor((x[d] - lo[d]) / tolerance));
    }
    std::int32_t found = -1;
    for (std::int64_t dx = -1; dx <= 1 && found < 0; ++dx) {
      for (std::int64_t dy = -1; dy <= 1 && found < 0; ++dy) {
        for (std::int64_t dz = -1; dz <= 1 && found < 0; ++dz) {
          const auto it = head.find({cell.x + dx, cell.y + dy, cell.z + dz});
          for (std::int32_t v = it == head.end() ? -1 : it->second; v >= 0;
               v = nextInCell[static_cast<std::size_t>(v)]) {
            const Vec3 d = sub(x, vertexAt(mesh, v));
            if (dot(d, d) <= tolerance2) {
              found = v;
              break;
            }
          }
        }
      }
    }
    if (found < 0) {
      found = static_cast<std::int32_t>(mesh.vertexCount());
      mesh.vertices.insert(mesh.vertices.end(), x.begin(), x.end());
      const auto [it, inserted] = head.try_emplace(cell, found);
      nextInCell.push_back(inserted ? -1 : it->second);
      it->second = found;
    }
    mesh.triangles[p] = found;
  }
  return mesh;
}

// ---- writing ------------------------------------------------------------------------------

Vec3 unitNormal(const TriangleMesh& mesh, std::size_t t) {
  const Vec3 a = vertexAt(mesh, corner(mesh, t, 0));
  const Vec3 n =
      cross(sub(vertexAt(mesh, corner(mesh, t, 1)), a), sub(vertexAt(mesh, corner(mesh, t, 2)), a));
  const double length = norm(n);
  return length > 0.0 ? Vec3{n[0] / length, n[1] / length, n[2] / length} : Vec3{0.0, 0.0, 0.0};
}

void putLittleEndian32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) {
    out.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
  }
}

void putFloat(std::string& out, double x) {
  putLittleEndian32(out, std::bit_cast<std::uint32_t>(static_cast<float>(x)));
}

/// Shortest text that reads back as the same double.
std::string exact(double x) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, result.ptr);
}
} // namespace

TriangleMesh readStl(const std::filesystem::path& file, const StlOptions& options) {
  const std::string where = file.string();
  if (!std::isfinite(options.scale) || !(options.scale > 0.0)) {
    fail(where, "scale " + number(options.scale) +
                    " must be a finite number > 0 (1: file in metres, 0.001: in millimetres)");
  }
  const std::string data = readWholeFile(file);
  if (data.empty()) {
    fail(where, "the STL file is empty (0 bytes); export the wall surface again");
  }
  const std::uint64_t size = data.size();
  const std::uint64_t count = size >= kBinaryHeader ? littleEndian32(data.data() + 80) : 0;
  const std::uint64_t expected = kBinaryHeader + kBinaryRecord * count;
  Soup soup;
  if (size >= kBinaryHeader && size == expected) {
    soup = parseBinary(where, data, static_cast<std::uint32_t>(count));
  } else if (startsWithSolid(data) && isText(data)) {
    soup = parseAscii(where, data);
  } else if (size < kBinaryHeader) {
    fail(where, "not an STL file: " + std::to_string(size) +
                    " bytes, too short for a binary STL (an 84-byte header) and it does not "
                    "begin with `solid` as an ASCII STL does; export the surface as STL again");
  } else {
    fail(where,
         "truncated or damaged binary STL: expected " + std::to_string(expected) +
             " bytes for its triangle count " + std::to_string(count) + " (84 + 50 x " +
             std::to_string(count) + "), found " + std::to_string(size) +
             (startsWithSolid(data) ? " (it begins with `solid` but holds binary data)" : "") +
             "; copy or export the file again");
  }
  if (soup.empty()) {
    fail(where, "the STL file holds no triangles; export the wall surface again (is the right "
                "part selected?)");
  }
  if (options.scale != 1.0) {
    for (double& x : soup) {
      x *= options.scale;
    }
  }
  return weld(where, soup);
}

void writeStl(const TriangleMesh& mesh, const std::filesystem::path& file, bool binary) {
  const std::string where = file.string();
  checkIndicesAndCoordinates(mesh);
  std::string out;
  std::string solid = std::filesystem::path(mesh.name).stem().string();
  std::replace_if(
      solid.begin(), solid.end(),
      [](char c) { return std::isspace(static_cast<unsigned char>(c)); }, '_');
  if (solid.empty()) {
    solid = "coredem";
  }
  if (binary) {
    std::string header = "CoReDEM binary STL " + solid; // never begins with "solid"
    header.resize(80, ' ');
    out = header;
    putLittleEndian32(out, static_cast<std::uint32_t>(mesh.triangleCount()));
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
      for (const double x : unitNormal(mesh, t)) {
        putFloat(out, x);
      }
      for (int k = 0; k < 3; ++k) {
        for (const double x : vertexAt(mesh, corner(mesh, t, k))) {
          putFloat(out, x);
        }
      }
      out.append(2, '\0'); // attribute byte count
    }
  } else {
    out = "solid " + solid + "\n";
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
      const Vec3 n = unitNormal(mesh, t);
      out += "  facet normal " + exact(n[0]) + " " + exact(n[1]) + " " + exact(n[2]) +
             "\n    outer loop\n";
      for (int k = 0; k < 3; ++k) {
        const Vec3 p = vertexAt(mesh, corner(mesh, t, k));
        out += "      vertex " + exact(p[0]) + " " + exact(p[1]) + " " + exact(p[2]) + "\n";
      }
      out += "    endloop\n  endfacet\n";
    }
    out += "endsolid " + solid + "\n";
  }
  std::ofstream stream(file, std::ios::binary | std::ios::trunc);
  if (!stream) {
    fail(where, "cannot write the STL file (" + std::string(std::strerror(errno)) +
                    "); check that its folder exists and is writable");
  }
  stream.write(out.data(), static_cast<std::streamsize>(out.size()));
  stream.close();
  if (!stream) {
    fail(where, "error while writing the STL file (disk full?)");
  }
}
} // namespace coredem::dem
