// Triangle-mesh walls on the host: STL reading/writing, welding, topology, checks, generators
// (coredem/dem/triangle_mesh.h).
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

namespace coredem::dem {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}

/// Relative weld tolerance: vertices closer than this x the bounding-box diagonal are one.
constexpr double kWeldTolerance = 1e-9;
/// A triangle is degenerate when its area <= this x (longest edge)².
constexpr double kDegenerateArea = 1e-12;
/// A mesh whose bounding-box diagonal exceeds this x the domain's is probably in millimetres.
constexpr double kUnitsRatio = 20.0;
/// Bytes of a binary STL: an 80-byte header and a uint32 count, then 50 bytes a triangle.
constexpr std::uint64_t kBinaryHeader = 84;
constexpr std::uint64_t kBinaryRecord = 50;

std::string label(const TriangleMesh& mesh) {
  return mesh.name.empty() ? "(unnamed mesh)" : mesh.name;
}

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw MeshError(where + ": " + what);
}

std::string number(double x) {
  std::ostringstream s;
  s.precision(9);
  s << x;
  return s.str();
}

std::string pointText(const Vec3& p) {
  return "(" + number(p[0]) + ", " + number(p[1]) + ", " + number(p[2]) + ")";
}

std::string boxText(const std::array<double, 6>& box) {
  return "[" + pointText({box[0], box[1], box[2]}) + " .. " + pointText({box[3], box[4], box[5]}) +
         "] m";
}

double boxDiagonal(const std::array<double, 6>& box) {
  return norm({box[3] - box[0], box[4] - box[1], box[5] - box[2]});
}

Vec3 vertexAt(const TriangleMesh& mesh, std::int32_t v) {
  const auto i = 3 * static_cast<std::size_t>(v);
  return {mesh.vertices[i], mesh.vertices[i + 1], mesh.vertices[i + 2]};
}

std::int32_t corner(const TriangleMesh& mesh, std::size_t t, int k) {
  return mesh.triangles[3 * t + static_cast<std::size_t>(k)];
}

/// "triangle 7 (vertices (x, y, z), (x, y, z), (x, y, z) m)", numbered from 1 as in the file.
std::string triangleText(const TriangleMesh& mesh, std::size_t t) {
  return "triangle " + std::to_string(t + 1) + " (vertices " +
         pointText(vertexAt(mesh, corner(mesh, t, 0))) + ", " +
         pointText(vertexAt(mesh, corner(mesh, t, 1))) + ", " +
         pointText(vertexAt(mesh, corner(mesh, t, 2))) + " m)";
}

/// Vertex indices in range and coordinates finite (meshes built by hand, not only read).
void checkIndicesAndCoordinates(const TriangleMesh& mesh) {
  if (mesh.vertices.size() % 3 != 0 || mesh.triangles.size() % 3 != 0) {
    fail(label(mesh), "malformed mesh: " + std::to_string(mesh.vertices.size()) +
                          " vertex coordinates and " + std::to_string(mesh.triangles.size()) +
                          " triangle indices (both must be multiples of 3)");
  }
  const auto vertexCount = static_cast<std::int64_t>(mesh.vertexCount());
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = corner(mesh, t, k);
      if (v < 0 || v >= vertexCount) {
        fail(label(mesh), "triangle " + std::to_string(t + 1) + " refers to vertex " +
                              std::to_string(v) + ", but the mesh has " +
                              std::to_string(vertexCount) +
                              " vertices (indices 0 .. n-1); fix the triangle list");
      }
    }
  }
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = vertexAt(mesh, corner(mesh, t, k));
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
        fail(label(mesh), "triangle " + std::to_string(t + 1) +
                              " has a non-finite coordinate in its vertex " +
                              std::to_string(k + 1) + " " + pointText(p) +
                              "; repair the surface or export it again");
      }
    }
  }
}

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

// ---- checks -------------------------------------------------------------------------------

void checkUnits(const TriangleMesh& mesh, const std::array<double, 6>& domain) {
  const double domainDiagonal = boxDiagonal(domain);
  if (!(domainDiagonal > 0.0)) {
    return; // no extent to compare with
  }
  const std::array<double, 6> box = boundingBox(mesh);
  const double diagonal = boxDiagonal(box);
  if (diagonal > kUnitsRatio * domainDiagonal) {
    fail(label(mesh), "the STL is probably in millimetres: its bounding box " + boxText(box) +
                          " has a diagonal of " + number(diagonal) + " m, more than " +
                          number(kUnitsRatio) + " times the domain's " + boxText(domain) +
                          " (diagonal " + number(domainDiagonal) +
                          " m); set `scale: 0.001` for this wall (or check the domain)");
  }
}

void checkDegenerate(const TriangleMesh& mesh) {
  const double weld = kWeldTolerance * boxDiagonal(boundingBox(mesh));
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const std::int32_t a = corner(mesh, t, 0), b = corner(mesh, t, 1), c = corner(mesh, t, 2);
    if (a == b || b == c || a == c) {
      fail(label(mesh), "degenerate " + triangleText(mesh, t) +
                            ": two of its vertices are the same point after welding (vertices "
                            "closer than " +
                            number(weld) +
                            " m are merged); remove the triangle or repair the mesh (remove "
                            "zero-area faces) and export it again");
    }
    const Vec3 pa = vertexAt(mesh, a), pb = vertexAt(mesh, b), pc = vertexAt(mesh, c);
    const double area = 0.5 * norm(cross(sub(pb, pa), sub(pc, pa)));
    const double longest = std::max({norm(sub(pb, pa)), norm(sub(pc, pb)), norm(sub(pa, pc))});
    if (area <= kDegenerateArea * longest * longest) {
      fail(label(mesh), "degenerate " + triangleText(mesh, t) + ": its area " + number(area) +
                            " m² is zero for its size (vertices on one line); remove the "
                            "triangle or repair the mesh (remove zero-area faces) and export it "
                            "again");
    }
  }
}

/// The two triangles of an edge and whether each traverses it from its lower vertex index up.
struct EdgeSides {
  std::size_t triangle[2] = {0, 0};
  bool upward[2] = {false, false};
};

std::string edgeText(const TriangleMesh& mesh, const MeshTopology& topology, std::int32_t e) {
  const auto i = 2 * static_cast<std::size_t>(e);
  return pointText(vertexAt(mesh, topology.edgeVertices[i])) + "–" +
         pointText(vertexAt(mesh, topology.edgeVertices[i + 1])) + " m";
}

void checkManifold(const TriangleMesh& mesh, const MeshTopology& topology) {
  if (std::all_of(topology.edgeUse.begin(), topology.edgeUse.end(),
                  [](std::int32_t use) { return use <= 2; })) {
    return;
  }
  // The first triangle, in file order, that is the third on one of its edges.
  const auto edges = static_cast<std::size_t>(topology.edgeCount);
  std::vector<std::size_t> firstTwo(2 * edges, 0);
  std::vector<int> seen(edges, 0);
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      const auto e = static_cast<std::size_t>(topology.triangleEdges[3 * t + k]);
      const int s = seen[e]++;
      if (s < 2) {
        firstTwo[2 * e + static_cast<std::size_t>(s)] = t;
        continue;
      }
      fail(label(mesh),
           "non-manifold edge " + edgeText(mesh, topology, static_cast<std::int32_t>(e)) +
               " shared by " + std::to_string(topology.edgeUse[e]) +
               " triangles: " + triangleText(mesh, t) + " is the third on it, after triangles " +
               std::to_string(firstTwo[2 * e] + 1) + " and " +
               std::to_string(firstTwo[2 * e + 1] + 1) +
               "; a wall edge may join at most two triangles: split the surface into "
               "separate walls or repair the mesh");
    }
  }
}

void checkWinding(const TriangleMesh& mesh, const MeshTopology& topology) {
  const auto edges = static_cast<std::size_t>(topology.edgeCount);
  std::vector<EdgeSides> sides(edges);
  std::vector<int> filled(edges, 0);
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const auto e =
          static_cast<std::size_t>(topology.triangleEdges[3 * t + static_cast<std::size_t>(k)]);
      const int s = filled[e]++;
      if (s < 2) { // more: non-manifold, reported before
        sides[e].triangle[s] = t;
        sides[e].upward[s] = corner(mesh, t, k) < corner(mesh, t, (k + 1) % 3);
      }
    }
  }
  // Flood each connected surface (triangles joined by edges of two) from its first triangle:
  // +1 keeps that triangle's winding, -1 is its opposite.
  std::vector<int> orientation(mesh.triangleCount(), 0);
  std::vector<std::size_t> component, queue;
  for (std::size_t start = 0; start < mesh.triangleCount(); ++start) {
    if (orientation[start] != 0) {
      continue;
    }
    component.clear();
    queue.assign(1, start);
    orientation[start] = 1;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const std::size_t t = queue[q];
      component.push_back(t);
      for (std::size_t k = 0; k < 3; ++k) {
        const auto e = static_cast<std::size_t>(topology.triangleEdges[3 * t + k]);
        if (filled[e] != 2) {
          continue;
        }
        const int self = sides[e].triangle[0] == t ? 0 : 1;
        const std::size_t other = sides[e].triangle[1 - self];
        // Consistent neighbours traverse a shared edge in opposite directions.
        const bool same = sides[e].upward[0] == sides[e].upward[1];
        const int wanted = same ? -orientation[t] : orientation[t];
        if (orientation[other] == 0) {
          orientation[other] = wanted;
          queue.push_back(other);
        } else if (orientation[other] != wanted) {
          fail(label(mesh), "the surface around " + triangleText(mesh, other) +
                                " cannot be oriented consistently (a Möbius-like strip: every "
                                "choice of winding inverts some triangle); repair the mesh");
        }
      }
    }
    const auto flipped = static_cast<std::size_t>(std::count_if(
        component.begin(), component.end(), [&](std::size_t t) { return orientation[t] < 0; }));
    if (flipped == 0 || flipped == component.size()) {
      continue;
    }
    const int majority = 2 * flipped > component.size() ? -1 : 1;
    const std::size_t minority = majority > 0 ? flipped : component.size() - flipped;
    // The first triangle against the majority that borders one with it (one always exists).
    std::sort(component.begin(), component.end());
    for (const std::size_t t : component) {
      if (orientation[t] == majority) {
        continue;
      }
      for (std::size_t k = 0; k < 3; ++k) {
        const auto e = static_cast<std::size_t>(topology.triangleEdges[3 * t + k]);
        if (filled[e] != 2) {
          continue;
        }
        const std::size_t other = sides[e].triangle[sides[e].triangle[0] == t ? 1 : 0];
        if (orientation[other] == majority) {
          fail(label(mesh),
               "inverted " + triangleText(mesh, t) + ": it traverses its edge " +
                   edgeText(mesh, topology, static_cast<std::int32_t>(e)) +
                   " in the same direction as its neighbour triangle " + std::to_string(other + 1) +
                   ", so its normal points the other way; " + std::to_string(minority) +
                   " of the " + std::to_string(component.size()) +
                   " triangles of its connected surface are wound against the others: flip "
                   "them (reverse their vertex order, e.g. \"unify normals\" in the mesh tool) "
                   "and export the surface again");
        }
      }
    }
  }
}

void checkClosed(const TriangleMesh& mesh, const MeshTopology& topology) {
  std::size_t open = 0;
  std::int32_t first = -1;
  for (std::int32_t e = 0; e < topology.edgeCount; ++e) {
    if (topology.edgeUse[static_cast<std::size_t>(e)] == 1) {
      open += 1;
      first = first < 0 ? e : first;
    }
  }
  if (open == 0) {
    return;
  }
  std::size_t triangle = 0;
  for (std::size_t i = 0; i < topology.triangleEdges.size(); ++i) {
    if (topology.triangleEdges[i] == first) {
      triangle = i / 3;
      break;
    }
  }
  fail(label(mesh), "the surface is not closed: " + std::to_string(open) +
                        " open edge(s) (an edge of only one triangle), the first the edge " +
                        edgeText(mesh, topology, first) + " of " + triangleText(mesh, triangle) +
                        "; a closed wall is required here: fill the hole (e.g. add the missing "
                        "cap) or export the surface again as a closed solid");
}

/// The orthonormal (e1, e2) with e1 x e2 = axis (a unit vector).
std::pair<Vec3, Vec3> perpendicularBasis(const Vec3& axis) {
  const Vec3 helper = std::abs(axis[0]) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  const double along = dot(helper, axis);
  Vec3 e1{helper[0] - along * axis[0], helper[1] - along * axis[1], helper[2] - along * axis[2]};
  const double length = norm(e1);
  e1 = {e1[0] / length, e1[1] / length, e1[2] / length};
  return {e1, cross(axis, e1)};
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

MeshTopology meshTopology(const TriangleMesh& mesh) {
  checkIndicesAndCoordinates(mesh);
  MeshTopology topology;
  topology.triangleEdges.resize(mesh.triangles.size());
  std::unordered_map<std::uint64_t, std::int32_t> ids;
  ids.reserve(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = corner(mesh, t, k), b = corner(mesh, t, (k + 1) % 3);
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                                static_cast<std::uint32_t>(std::max(a, b));
      const auto [it, inserted] = ids.try_emplace(key, topology.edgeCount);
      if (inserted) {
        topology.edgeCount += 1;
        topology.edgeUse.push_back(0);
        topology.edgeVertices.insert(topology.edgeVertices.end(), {a, b});
      }
      topology.edgeUse[static_cast<std::size_t>(it->second)] += 1;
      topology.triangleEdges[3 * t + static_cast<std::size_t>(k)] = it->second;
    }
  }
  return topology;
}

void checkMesh(const TriangleMesh& mesh, const MeshCheckOptions& options) {
  checkIndicesAndCoordinates(mesh);
  if (mesh.triangleCount() == 0) {
    fail(label(mesh), "the mesh holds no triangles; give a wall surface with at least one");
  }
  if (options.domain) {
    checkUnits(mesh, *options.domain);
  }
  checkDegenerate(mesh);
  const MeshTopology topology = meshTopology(mesh);
  checkManifold(mesh, topology);
  checkWinding(mesh, topology);
  if (options.requireClosed) {
    checkClosed(mesh, topology);
  }
}

std::array<double, 6> boundingBox(const TriangleMesh& mesh) {
  if (mesh.vertexCount() == 0) {
    return {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  }
  std::array<double, 6> box{};
  for (std::size_t d = 0; d < 3; ++d) {
    box[d] = box[d + 3] = mesh.vertices[d];
  }
  for (std::size_t v = 0; v < mesh.vertexCount(); ++v) {
    for (std::size_t d = 0; d < 3; ++d) {
      box[d] = std::min(box[d], mesh.vertices[3 * v + d]);
      box[d + 3] = std::max(box[d + 3], mesh.vertices[3 * v + d]);
    }
  }
  return box;
}

TriangleMesh meshRectangle(std::array<double, 3> origin, std::array<double, 3> u,
                           std::array<double, 3> v, int nu, int nv) {
  if (nu < 1 || nv < 1) {
    fail("rectangle",
         "nu = " + std::to_string(nu) + " and nv = " + std::to_string(nv) + " must both be >= 1");
  }
  const double area = norm(cross(u, v));
  if (!(area > kDegenerateArea * std::max(dot(u, u), dot(v, v)))) {
    fail("rectangle", "its sides u " + pointText(u) + " m and v " + pointText(v) +
                          " m are parallel or zero; give two independent directions");
  }
  TriangleMesh mesh;
  mesh.name = "rectangle";
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const double a = static_cast<double>(i) / nu, b = static_cast<double>(j) / nv;
      for (std::size_t d = 0; d < 3; ++d) {
        mesh.vertices.push_back(origin[d] + a * u[d] + b * v[d]);
      }
    }
  }
  const auto index = [&](int i, int j) { return static_cast<std::int32_t>(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const std::int32_t a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1),
                         d = index(i, j + 1);
      mesh.triangles.insert(mesh.triangles.end(), {a, b, c, a, c, d});
    }
  }
  return mesh;
}

TriangleMesh meshRevolved(std::array<double, 3> origin, std::array<double, 3> axis,
                          const std::vector<std::array<double, 2>>& profile, int segments,
                          bool capStart, bool capEnd) {
  const std::string where = "revolved surface";
  const double axisLength = norm(axis);
  if (!(axisLength > 0.0) || !std::isfinite(axisLength)) {
    fail(where, "its axis " + pointText(axis) + " must be a finite non-zero vector");
  }
  axis = {axis[0] / axisLength, axis[1] / axisLength, axis[2] / axisLength};
  if (segments < 3) {
    fail(where, std::to_string(segments) + " segments around: give at least 3");
  }
  if (profile.size() < 2) {
    fail(where, "its profile has " + std::to_string(profile.size()) +
                    " point(s): give at least 2 (t, r) points");
  }
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const auto [t, r] = profile[i];
    if (!std::isfinite(t) || !std::isfinite(r) || r < 0.0) {
      fail(where, "profile point " + std::to_string(i + 1) + " (t " + number(t) + ", r " +
                      number(r) + ") m: t must be finite and r finite and >= 0");
    }
    if (i > 0 && profile[i] == profile[i - 1]) {
      fail(where, "profile points " + std::to_string(i) + " and " + std::to_string(i + 1) +
                      " are the same point; remove one");
    }
  }
  // The region behind the triangles is the profile closed along the axis: with the winding
  // below, its normals are the profile's tangent (dt, dr) turned to (-dr, dt) in the (t, r) plane,
  // which points out of that region when it runs clockwise (negative shoelace area).
  double twiceArea =
      profile.front()[0] * profile.front()[1] - profile.back()[0] * profile.back()[1];
  for (std::size_t i = 0; i + 1 < profile.size(); ++i) {
    twiceArea += profile[i][0] * profile[i + 1][1] - profile[i + 1][0] * profile[i][1];
  }
  const bool flip = twiceArea > 0.0;

  const auto [e1, e2] = perpendicularBasis(axis);
  TriangleMesh mesh;
  mesh.name = where;
  const auto addVertex = [&](const Vec3& p) {
    mesh.vertices.insert(mesh.vertices.end(), p.begin(), p.end());
    return static_cast<std::int32_t>(mesh.vertexCount() - 1);
  };
  const auto onAxis = [&](double t) {
    return Vec3{origin[0] + t * axis[0], origin[1] + t * axis[1], origin[2] + t * axis[2]};
  };
  const auto seg = static_cast<std::size_t>(segments);
  std::vector<double> cosine(seg), sine(seg);
  for (std::size_t j = 0; j < seg; ++j) {
    const double angle = 2.0 * std::numbers::pi * static_cast<double>(j) / segments;
    cosine[j] = std::cos(angle);
    sine[j] = std::sin(angle);
  }
  // One ring of vertex indices a profile point (all the same for a point on the axis).
  std::vector<std::vector<std::int32_t>> rings;
  for (const auto& [t, r] : profile) {
    const Vec3 centre = onAxis(t);
    if (r == 0.0) {
      rings.emplace_back(seg, addVertex(centre));
      continue;
    }
    std::vector<std::int32_t> ring(seg);
    for (std::size_t j = 0; j < seg; ++j) {
      Vec3 p{};
      for (std::size_t d = 0; d < 3; ++d) {
        p[d] = centre[d] + r * (cosine[j] * e1[d] + sine[j] * e2[d]);
      }
      ring[j] = addVertex(p);
    }
    rings.push_back(std::move(ring));
  }
  const auto addTriangle = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
    if (a == b || b == c || a == c) {
      return; // a corner on the axis
    }
    if (flip) {
      std::swap(b, c);
    }
    mesh.triangles.insert(mesh.triangles.end(), {a, b, c});
  };
  // The band from ring A to ring B: quads (A_j, A_j+1, B_j+1, B_j), triangles with the normal
  // (-dr, dt) of the profile.
  const auto addBand = [&](const std::vector<std::int32_t>& a, const std::vector<std::int32_t>& b) {
    for (std::size_t j = 0; j < seg; ++j) {
      const std::size_t k = (j + 1) % seg;
      addTriangle(a[j], a[k], b[k]);
      addTriangle(a[j], b[k], b[j]);
    }
  };
  if (capStart && profile.front()[1] > 0.0) {
    addBand(std::vector<std::int32_t>(seg, addVertex(onAxis(profile.front()[0]))), rings.front());
  }
  for (std::size_t i = 0; i + 1 < rings.size(); ++i) {
    addBand(rings[i], rings[i + 1]);
  }
  if (capEnd && profile.back()[1] > 0.0) {
    addBand(rings.back(), std::vector<std::int32_t>(seg, addVertex(onAxis(profile.back()[0]))));
  }
  return mesh;
}

} // namespace coredem::dem
