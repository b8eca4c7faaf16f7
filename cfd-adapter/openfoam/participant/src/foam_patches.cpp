// Triangle surfaces from the patches of an OpenFOAM mesh (foam_patches.h): a small reader of the
// ASCII polyMesh files (FoamFile header, `N ( ... )` lists, faces as `n(a b c ...)`, the boundary
// dictionary list) and the fan triangulation of the patch faces.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string_view>

#include <fmt/format.h>

#include <coredem/participant/foam_patches.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

/// A fan triangle whose area is at most this x its longest edge² is degenerate (collinear
/// corners); the fan then starts from another vertex. Above the DEM's own limit (1e-12), so a
/// fan chosen here passes checkMesh.
constexpr double kFlatTriangle = 1e-10;

/// What to do with a mesh this reader cannot read (binary, compressed).
std::string asciiHint(const fs::path& foamCase) {
  return fmt::format(
      "convert the mesh to ASCII (set `writeFormat ascii;` and `writeCompression off;` in "
      "{0}/system/controlDict, then run `foamFormatConvert -constant -case {0}`), or export the "
      "patches as an STL (`foamToSurface` or `surfaceMeshExtract -patches '(NAMES)'`) and give "
      "it as walls.meshes[].file instead",
      foamCase.string());
}

/// The mesh of `foamCase` is not there: how to make it.
[[noreturn]] void notMeshed(const fs::path& foamCase, const fs::path& missing) {
  std::string how;
  if (fs::exists(foamCase / "Allmesh")) {
    how = fmt::format("run the case's mesh script {} first", (foamCase / "Allmesh").string());
  } else if (fs::exists(foamCase / "system" / "blockMeshDict")) {
    how = fmt::format("mesh it first with `blockMesh -case {0}` (Debian's OpenFOAM: "
                      "`scripts/openfoam-env.sh blockMesh -case {0}`)",
                      foamCase.string());
  } else {
    how = fmt::format("mesh it first (blockMesh, snappyHexMesh, ...) into {}",
                      (foamCase / "constant" / "polyMesh").string());
  }
  throw FoamMeshError(fmt::format(
      "{} not found: the CFD mesh is not made yet, and from_cfd builds the DEM walls from it "
      "before anything starts (the blockMesh coredemFoam runs at its own start comes too late); "
      "{}",
      missing.string(), how));
}

/// The text of constant/polyMesh/<name>; refuses a missing, compressed or unreadable file.
std::string readMeshFile(const fs::path& foamCase, const std::string& name) {
  const fs::path file = foamCase / "constant" / "polyMesh" / name;
  if (!fs::exists(file)) {
    const fs::path gz = file.string() + ".gz";
    if (fs::exists(gz)) {
      throw FoamMeshError(fmt::format("{} is compressed (gzip); from_cfd reads ASCII mesh files "
                                      "only: {}",
                                      gz.string(), asciiHint(foamCase)));
    }
    notMeshed(foamCase, file);
  }
  // A FIFO, a device (a link to /dev/zero) or a directory would hang or grow without bound.
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    throw FoamMeshError(fmt::format("{} is not a regular file (a directory, a FIFO, a device or "
                                    "a broken link): from_cfd reads the mesh files OpenFOAM "
                                    "wrote",
                                    file.string()));
  }
  const auto bytes = fs::file_size(file, ec);
  if (ec || bytes > kMaxFoamMeshFileBytes) {
    throw FoamMeshError(fmt::format("{}: {} bytes, more than the {} GiB from_cfd reads (an ASCII "
                                    "mesh of ~10^8 faces); use an STL of the wall instead",
                                    file.string(), ec ? std::string("unknown size, ") : std::to_string(bytes),
                                    kMaxFoamMeshFileBytes >> 30));
  }
  std::ifstream in(file, std::ios::binary);
  std::string text(std::istreambuf_iterator<char>(in), {});
  if (!in.good() && !in.eof()) {
    throw FoamMeshError(fmt::format("{}: cannot read the file", file.string()));
  }
  if (text.size() >= 2 && static_cast<unsigned char>(text[0]) == 0x1f &&
      static_cast<unsigned char>(text[1]) == 0x8b) {
    throw FoamMeshError(fmt::format("{} is compressed (gzip); from_cfd reads ASCII mesh files "
                                    "only: {}",
                                    file.string(), asciiHint(foamCase)));
  }
  return text;
}

/// A cursor over one OpenFOAM file: tokens, lists and dictionaries, errors with the line.
class FoamParser {
public:
  FoamParser(std::string text, fs::path file, fs::path foamCase)
      : _text(std::move(text))
      , _file(std::move(file))
      , _case(std::move(foamCase)) {}

  [[noreturn]] void fail(const std::string& what) const {
    const auto line =
        1 + std::count(_text.begin(), _text.begin() + std::ptrdiff_t(std::min(_pos, _text.size())),
                       '\n');
    throw FoamMeshError(fmt::format("{}:{}: {}; is it a mesh file OpenFOAM wrote in ASCII?",
                                    _file.string(), line, what));
  }

  /// Skips white space and // and /* */ comments.
  void skipSpace() {
    while (_pos < _text.size()) {
      const char c = _text[_pos];
      if (std::isspace(static_cast<unsigned char>(c))) {
        ++_pos;
      } else if (c == '/' && _pos + 1 < _text.size() && _text[_pos + 1] == '/') {
        const auto end = _text.find('\n', _pos);
        _pos = end == std::string::npos ? _text.size() : end;
      } else if (c == '/' && _pos + 1 < _text.size() && _text[_pos + 1] == '*') {
        const auto end = _text.find("*/", _pos + 2);
        _pos = end == std::string::npos ? _text.size() : end + 2;
      } else {
        return;
      }
    }
  }

  /// The next character after white space (0 at the end).
  char peek() {
    skipSpace();
    return _pos < _text.size() ? _text[_pos] : '\0';
  }

  void expect(char c) {
    if (peek() != c) {
      fail(_pos < _text.size() ? fmt::format("expected '{}', found '{}'", c, _text[_pos])
                               : fmt::format("expected '{}', found the end of the file", c));
    }
    ++_pos;
  }

  /// A keyword or name (or a "quoted" string, without its quotes).
  std::string word() {
    skipSpace();
    if (_pos < _text.size() && _text[_pos] == '"') {
      const auto end = _text.find('"', _pos + 1);
      if (end == std::string::npos) {
        fail("unterminated string");
      }
      std::string w = _text.substr(_pos + 1, end - _pos - 1);
      _pos = end + 1;
      return w;
    }
    const std::size_t start = _pos;
    while (_pos < _text.size() && !std::isspace(static_cast<unsigned char>(_text[_pos])) &&
           std::string_view("{}();\"").find(_text[_pos]) == std::string_view::npos) {
      ++_pos;
    }
    if (_pos == start) {
      fail("expected a name");
    }
    return _text.substr(start, _pos - start);
  }

  std::int64_t label() {
    skipSpace();
    const char* begin = _text.c_str() + _pos;
    char* end = nullptr;
    const long long v = std::strtoll(begin, &end, 10);
    if (end == begin) {
      fail("expected an integer");
    }
    _pos += std::size_t(end - begin);
    return v;
  }

  double scalar() {
    skipSpace();
    const char* begin = _text.c_str() + _pos;
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    if (end == begin || !std::isfinite(v)) {
      fail("expected a finite number");
    }
    _pos += std::size_t(end - begin);
    return v;
  }

  /// The entries of a dictionary whose '{' was read, up to and with its '}': key -> value text
  /// (a sub-dictionary's value is "{}").
  std::map<std::string, std::string> dictionary() {
    std::map<std::string, std::string> entries;
    while (true) {
      const char c = peek();
      if (c == '\0') {
        fail("unterminated dictionary (no closing '}')");
      }
      if (c == '}') {
        ++_pos;
        return entries;
      }
      const std::string key = word();
      if (peek() == '{') {
        ++_pos;
        (void)dictionary();
        entries[key] = "{}";
        continue;
      }
      // The value: up to ';' outside parentheses (inGroups 1(wall);).
      const std::size_t start = _pos;
      int depth = 0;
      for (; _pos < _text.size(); ++_pos) {
        const char v = _text[_pos];
        if (v == '(') {
          ++depth;
        } else if (v == ')') {
          --depth;
        } else if (v == '}' && depth == 0) {
          break;
        } else if (v == ';' && depth == 0) {
          break;
        }
      }
      if (_pos >= _text.size() || _text[_pos] != ';') {
        fail(fmt::format("entry '{}' has no closing ';'", key));
      }
      std::string value = _text.substr(start, _pos - start);
      ++_pos;
      const auto first = value.find_first_not_of(" \t\r\n");
      const auto last = value.find_last_not_of(" \t\r\n");
      entries[key] = first == std::string::npos ? "" : value.substr(first, last - first + 1);
    }
  }

  /// The FoamFile header: refuses a binary file; the class ("faceList", "vectorField", ...).
  std::string header() {
    if (word() != "FoamFile") {
      _pos = 0;
      fail("no FoamFile header at its start");
    }
    expect('{');
    const auto entries = dictionary();
    const auto format = entries.find("format");
    if (format != entries.end() && format->second != "ascii") {
      throw FoamMeshError(fmt::format("{} is written in {} format; from_cfd reads ASCII mesh "
                                      "files only: {}",
                                      _file.string(), format->second, asciiHint(_case)));
    }
    const auto cls = entries.find("class");
    return cls == entries.end() ? std::string() : cls->second;
  }

  /// The start of a list: "N (" or "(" (count -1); the '(' is read. A count the rest of the file
  /// cannot hold (each item takes at least minItemBytes characters) fails before anything is
  /// allocated for it.
  std::int64_t listStart(std::size_t minItemBytes = 2) {
    std::int64_t n = -1;
    if (std::isdigit(static_cast<unsigned char>(peek()))) {
      n = label();
      if (peek() == '{') {
        fail("a uniform list N{...} is not a mesh list");
      }
      checkCount(n, minItemBytes, "items");
    }
    expect('(');
    return n;
  }

  /// Fails when `n` items of at least minItemBytes characters each cannot fit in the rest of
  /// the file.
  void checkCount(std::int64_t n, std::size_t minItemBytes, const char* what) const {
    const std::size_t left = _text.size() - std::min(_pos, _text.size());
    if (n < 0 || std::uint64_t(n) > left / minItemBytes) {
      fail(fmt::format("a count of {} {}, but only {} bytes of the file follow", n, what, left));
    }
  }

  /// True at the ')' that ends a list of `n` items (n < 0: unknown) after `read` items; fails
  /// at a ')' before n items or when an item follows the n-th.
  bool listEnd(std::int64_t n, std::int64_t read) {
    const char c = peek();
    if (n >= 0 && read == n) {
      if (c != ')') {
        fail(fmt::format("the list holds more than the {} items its size says", n));
      }
      return true;
    }
    if (c == ')') {
      if (n >= 0) {
        fail(fmt::format("the list ends after {} of its {} items", read, n));
      }
      return true;
    }
    if (c == '\0') {
      fail("the list has no closing ')'");
    }
    return false;
  }

  void skip() { ++_pos; }

private:
  std::string _text;
  fs::path _file;
  fs::path _case;
  std::size_t _pos = 0;
};

using Point = std::array<double, 3>;

std::vector<Point> readPoints(const fs::path& foamCase) {
  const fs::path file = foamCase / "constant" / "polyMesh" / "points";
  FoamParser p(readMeshFile(foamCase, "points"), file, foamCase);
  (void)p.header();
  std::vector<Point> points;
  const std::int64_t n = p.listStart(7); // "(0 0 0)"
  if (n > 0) {
    points.reserve(std::size_t(n));
  }
  while (!p.listEnd(n, std::int64_t(points.size()))) {
    p.expect('(');
    Point x{};
    for (double& v : x) {
      v = p.scalar();
    }
    p.expect(')');
    points.push_back(x);
  }
  return points;
}

/// The faces 0 .. needed-1 of constant/polyMesh/faces (faceList or faceCompactList).
std::vector<std::vector<std::int64_t>> readFaces(const fs::path& foamCase, std::int64_t needed) {
  const fs::path file = foamCase / "constant" / "polyMesh" / "faces";
  FoamParser p(readMeshFile(foamCase, "faces"), file, foamCase);
  const std::string cls = p.header();
  std::vector<std::vector<std::int64_t>> faces;
  if (cls == "faceCompactList") {
    // Two lists: the offsets (faces + 1) and the point labels of every face, one after another.
    std::vector<std::int64_t> offsets, labels;
    const std::int64_t n = p.listStart();
    while (!p.listEnd(n, std::int64_t(offsets.size()))) {
      offsets.push_back(p.label());
    }
    p.skip();
    const std::int64_t m = p.listStart();
    while (!p.listEnd(m, std::int64_t(labels.size()))) {
      labels.push_back(p.label());
    }
    for (std::size_t f = 0; f + 1 < offsets.size() && std::int64_t(f) < needed; ++f) {
      if (offsets[f] < 0 || offsets[f] > offsets[f + 1] ||
          offsets[f + 1] > std::int64_t(labels.size())) {
        p.fail(fmt::format("face {}: offsets {} .. {} do not fit the {} point labels", f,
                           offsets[f], offsets[f + 1], labels.size()));
      }
      faces.emplace_back(labels.begin() + offsets[f], labels.begin() + offsets[f + 1]);
    }
    return faces;
  }
  const std::int64_t n = p.listStart(8); // "3(0 1 2)"
  if (n >= 0 && n < needed) {
    p.fail(fmt::format("the list holds {} faces, but the boundary file's patches end at face {}",
                       n, needed));
  }
  faces.reserve(std::size_t(std::max<std::int64_t>(0, std::min(needed, n < 0 ? needed : n))));
  while (std::int64_t(faces.size()) < needed && !p.listEnd(n, std::int64_t(faces.size()))) {
    const std::int64_t k = p.label();
    if (k < 0) {
      p.fail(fmt::format("face {} has {} vertices", faces.size(), k));
    }
    p.checkCount(k, 2, "vertices");
    std::vector<std::int64_t> face(std::size_t(k), 0);
    p.expect('(');
    for (auto& v : face) {
      v = p.label();
    }
    p.expect(')');
    faces.push_back(std::move(face));
  }
  return faces;
}

double norm(const Point& a) {
  return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

Point sub(const Point& a, const Point& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

/// False for a triangle with two equal corners or whose corners lie (nearly) on one line.
bool fanTriangleOk(const std::vector<Point>& points, std::int64_t a, std::int64_t b,
                   std::int64_t c) {
  if (a == b || b == c || a == c) {
    return false;
  }
  const Point& pa = points[std::size_t(a)];
  const Point& pb = points[std::size_t(b)];
  const Point& pc = points[std::size_t(c)];
  const Point u = sub(pb, pa), v = sub(pc, pa);
  const Point n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double longest = std::max({norm(u), norm(v), norm(sub(pc, pb))});
  return 0.5 * norm(n) > kFlatTriangle * longest * longest;
}

/// The vertex of `face` to fan from: the first from which no fan triangle is degenerate (a face
/// with a vertex in the middle of an edge, as where a refined cell meets a coarse one), else 0.
std::size_t fanApex(const std::vector<Point>& points, const std::vector<std::int64_t>& face) {
  const std::size_t n = face.size();
  for (std::size_t a = 0; a < n; ++a) {
    bool ok = true;
    for (std::size_t i = 1; ok && i + 1 < n; ++i) {
      ok = fanTriangleOk(points, face[a], face[(a + i) % n], face[(a + i + 1) % n]);
    }
    if (ok) {
      return a;
    }
  }
  return 0;
}

std::string patchList(const std::vector<FoamPatch>& patches) {
  std::string out;
  for (const auto& p : patches) {
    out += fmt::format("{}{} ({}, {} faces)", out.empty() ? "" : ", ", p.name, p.type, p.nFaces);
  }
  return out.empty() ? std::string("none") : out;
}

} // namespace

std::vector<FoamPatch> readFoamBoundary(const fs::path& foamCase) {
  const fs::path file = foamCase / "constant" / "polyMesh" / "boundary";
  if (!fs::is_directory(foamCase / "constant" / "polyMesh")) {
    notMeshed(foamCase, foamCase / "constant" / "polyMesh");
  }
  FoamParser p(readMeshFile(foamCase, "boundary"), file, foamCase);
  (void)p.header();
  std::vector<FoamPatch> patches;
  const std::int64_t n = p.listStart();
  while (!p.listEnd(n, std::int64_t(patches.size()))) {
    FoamPatch patch;
    patch.name = p.word();
    p.expect('{');
    const auto entries = p.dictionary();
    auto entry = [&](const char* key) {
      const auto e = entries.find(key);
      if (e == entries.end()) {
        p.fail(fmt::format("patch '{}' has no '{}' entry", patch.name, key));
      }
      return e->second;
    };
    patch.type = entry("type");
    for (auto [key, value] :
         {std::pair{"nFaces", &patch.nFaces}, std::pair{"startFace", &patch.startFace}}) {
      const std::string text = entry(key);
      char* end = nullptr;
      *value = std::strtoll(text.c_str(), &end, 10);
      if (text.empty() || *end != '\0' || *value < 0) {
        p.fail(fmt::format("patch '{}': {} '{}' is not a count", patch.name, key, text));
      }
    }
    patches.push_back(std::move(patch));
  }
  return patches;
}

FoamPatchSurface readFoamPatches(const fs::path& foamCase,
                                 const std::vector<std::string>& patches) {
  const fs::path boundaryFile = foamCase / "constant" / "polyMesh" / "boundary";
  const std::vector<FoamPatch> boundary = readFoamBoundary(foamCase);
  std::vector<const FoamPatch*> chosen;
  std::set<std::string> seen;
  std::int64_t needed = 0;
  for (const auto& name : patches) {
    if (!seen.insert(name).second) {
      throw FoamMeshError(fmt::format("patch '{}' is listed twice", name));
    }
    const auto it = std::find_if(boundary.begin(), boundary.end(),
                                 [&](const FoamPatch& b) { return b.name == name; });
    if (it == boundary.end()) {
      throw FoamMeshError(fmt::format("no patch '{}' in {}; its patches: {}", name,
                                      boundaryFile.string(), patchList(boundary)));
    }
    if (it->type != "wall" && it->type != "patch") {
      throw FoamMeshError(fmt::format(
          "patch '{}' of {} is of type {}: only patches of type wall or patch are surfaces the "
          "particles can touch; its patches: {}",
          name, boundaryFile.string(), it->type, patchList(boundary)));
    }
    if (it->nFaces == 0) {
      throw FoamMeshError(fmt::format("patch '{}' of {} has no faces (nFaces 0); name patches "
                                      "with faces: {}",
                                      name, boundaryFile.string(), patchList(boundary)));
    }
    chosen.push_back(&*it);
    needed = std::max(needed, it->startFace + it->nFaces);
  }
  const std::vector<Point> points = readPoints(foamCase);
  const std::vector<std::vector<std::int64_t>> faces = readFaces(foamCase, needed);
  if (std::int64_t(faces.size()) < needed) {
    throw FoamMeshError(fmt::format("{}: {} faces, but {} says patches end at face {}; the mesh "
                                    "files do not belong together: mesh the case again",
                                    (foamCase / "constant" / "polyMesh" / "faces").string(),
                                    faces.size(), boundaryFile.string(), needed));
  }

  FoamPatchSurface s;
  std::vector<std::int32_t> local(points.size(), -1);
  auto vertex = [&](std::int64_t point) {
    std::int32_t& v = local[std::size_t(point)];
    if (v < 0) {
      v = std::int32_t(s.pointIndex.size());
      s.pointIndex.push_back(point);
      s.vertices.insert(s.vertices.end(), points[std::size_t(point)].begin(),
                        points[std::size_t(point)].end());
    }
    return v;
  };
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    const FoamPatch& patch = *chosen[k];
    for (std::int64_t f = patch.startFace; f < patch.startFace + patch.nFaces; ++f) {
      const auto& face = faces[std::size_t(f)];
      if (face.size() < 3) {
        throw FoamMeshError(fmt::format(
            "{}: face {} (patch '{}') has {} vertices, a face needs 3 or more; check the mesh "
            "(checkMesh)",
            (foamCase / "constant" / "polyMesh" / "faces").string(), f, patch.name, face.size()));
      }
      for (const std::int64_t v : face) {
        if (v < 0 || v >= std::int64_t(points.size())) {
          throw FoamMeshError(fmt::format(
              "{}: face {} (patch '{}') refers to point {}, but points holds {}; the mesh files "
              "do not belong together: mesh the case again",
              (foamCase / "constant" / "polyMesh" / "faces").string(), f, patch.name, v,
              points.size()));
        }
      }
      const std::size_t n = face.size();
      const std::size_t a = fanApex(points, face);
      for (std::size_t i = 1; i + 1 < n; ++i) {
        for (const std::size_t corner : {a, (a + i) % n, (a + i + 1) % n}) {
          s.triangles.push_back(vertex(face[corner]));
        }
        s.sourceFace.push_back(f);
        s.sourcePatch.push_back(k);
      }
      ++s.faces;
    }
  }
  return s;
}

} // namespace coredem::orchestrator
