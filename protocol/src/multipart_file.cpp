#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>

#include <coredem/common/check.h>
#include <coredem/protocol/multipart_file.h>

namespace coredem::protocol {

namespace {
constexpr std::array<char, 4> kMagic{'C', 'D', 'M', 'F'};
constexpr std::uint32_t kFormatVersion = 1;

template <class T>
void putLE(std::string& out, T value) {
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    out.push_back(static_cast<char>((static_cast<std::uint64_t>(value) >> (8 * i)) & 0xffu));
  }
}

template <class T>
T getLE(const std::string& in, std::size_t& pos, const std::filesystem::path& path) {
  COREDEM_CHECK(pos + sizeof(T) <= in.size(),
                "{}: truncated multipart file (needed {} more bytes at offset {}); regenerate it "
                "with coredem-golden-gen",
                path.string(), sizeof(T), pos);
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    v |= static_cast<std::uint64_t>(static_cast<unsigned char>(in[pos + i])) << (8 * i);
  }
  pos += sizeof(T);
  return static_cast<T>(v);
}
} // namespace

void writeMultipartFile(const std::filesystem::path& path, const Frames& frames) {
  std::string out(kMagic.begin(), kMagic.end());
  putLE<std::uint32_t>(out, kFormatVersion);
  putLE<std::uint32_t>(out, static_cast<std::uint32_t>(frames.size()));
  for (const auto& f : frames) {
    putLE<std::uint64_t>(out, f.size());
    out += f;
  }
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  COREDEM_CHECK(file.good(), "cannot write {}: check that the directory exists and is writable",
                path.string());
  file.write(out.data(), static_cast<std::streamsize>(out.size()));
  COREDEM_CHECK(file.good(), "writing {} failed", path.string());
}

Frames readMultipartFile(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  COREDEM_CHECK(file.good(), "cannot open multipart file {}", path.string());
  std::string in((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  COREDEM_CHECK(in.size() >= 12 && std::memcmp(in.data(), kMagic.data(), 4) == 0,
                "{} is not a CoReDEM multipart file (magic 'CDMF' missing)", path.string());
  std::size_t pos = 4;
  auto version = getLE<std::uint32_t>(in, pos, path);
  COREDEM_CHECK(version == kFormatVersion,
                "{}: multipart file format version {} is not supported (this build reads {})",
                path.string(), version, kFormatVersion);
  auto count = getLE<std::uint32_t>(in, pos, path);
  Frames frames;
  for (std::uint32_t i = 0; i < count; ++i) {
    auto len = getLE<std::uint64_t>(in, pos, path);
    COREDEM_CHECK(len <= in.size() - pos,
                  "{}: truncated multipart file (frame {} declares {} bytes, {} left)",
                  path.string(), i, len, in.size() - pos);
    frames.emplace_back(in, pos, len);
    pos += len;
  }
  COREDEM_CHECK(pos == in.size(), "{}: {} trailing bytes after the last frame", path.string(),
                in.size() - pos);
  return frames;
}

} // namespace coredem::protocol
