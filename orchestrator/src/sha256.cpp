#include <cstring>
#include <fstream>
#include <vector>

#include <coredem/common/check.h>
#include <coredem/orchestrator/sha256.h>

namespace coredem::orchestrator {
namespace {

constexpr std::array<std::uint32_t, 64> kRound = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

constexpr std::uint32_t rotr(std::uint32_t x, int n) {
  return (x >> n) | (x << (32 - n));
}

} // namespace

struct Sha256::Impl {
  std::array<std::uint32_t, 8> h = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                    0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  std::array<std::uint8_t, 64> block{};
  std::size_t blockLen = 0;
  std::uint64_t totalBytes = 0;
  bool finished = false;

  void compress(const std::uint8_t* p) {
    std::array<std::uint32_t, 64> w{};
    for (int t = 0; t < 16; ++t) {
      w[t] = (std::uint32_t(p[4 * t]) << 24) | (std::uint32_t(p[4 * t + 1]) << 16) |
             (std::uint32_t(p[4 * t + 2]) << 8) | std::uint32_t(p[4 * t + 3]);
    }
    for (int t = 16; t < 64; ++t) {
      const std::uint32_t s0 = rotr(w[t - 15], 7) ^ rotr(w[t - 15], 18) ^ (w[t - 15] >> 3);
      const std::uint32_t s1 = rotr(w[t - 2], 17) ^ rotr(w[t - 2], 19) ^ (w[t - 2] >> 10);
      w[t] = w[t - 16] + s0 + w[t - 7] + s1;
    }
    std::uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5], g = h[6], k = h[7];
    for (int t = 0; t < 64; ++t) {
      const std::uint32_t S1 = rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25);
      const std::uint32_t ch = (e & f) ^ (~e & g);
      const std::uint32_t t1 = k + S1 + ch + kRound[t] + w[t];
      const std::uint32_t S0 = rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22);
      const std::uint32_t maj = (a & b) ^ (a & c) ^ (b & c);
      const std::uint32_t t2 = S0 + maj;
      k = g;
      g = f;
      f = e;
      e = d + t1;
      d = c;
      c = b;
      b = a;
      a = t1 + t2;
    }
    h[0] += a;
    h[1] += b;
    h[2] += c;
    h[3] += d;
    h[4] += e;
    h[5] += f;
    h[6] += g;
    h[7] += k;
  }

  void update(const std::uint8_t* p, std::size_t n) {
    COREDEM_ASSERT(!finished);
    totalBytes += n;
    while (n > 0) {
      if (blockLen == 0 && n >= 64) {
        compress(p);
        p += 64;
        n -= 64;
        continue;
      }
      const std::size_t take = std::min<std::size_t>(64 - blockLen, n);
      std::memcpy(block.data() + blockLen, p, take);
      blockLen += take;
      p += take;
      n -= take;
      if (blockLen == 64) {
        compress(block.data());
        blockLen = 0;
      }
    }
  }

  std::array<std::uint8_t, 32> finish() {
    COREDEM_ASSERT(!finished);
    const std::uint64_t bits = totalBytes * 8;
    const std::uint8_t one = 0x80;
    update(&one, 1);
    const std::uint8_t zero = 0;
    while (blockLen != 56) {
      update(&zero, 1);
    }
    std::array<std::uint8_t, 8> len{};
    for (int i = 0; i < 8; ++i) {
      len[i] = std::uint8_t(bits >> (56 - 8 * i));
    }
    update(len.data(), 8);
    COREDEM_ASSERT(blockLen == 0);
    finished = true;
    std::array<std::uint8_t, 32> out{};
    for (int i = 0; i < 8; ++i) {
      out[4 * i] = std::uint8_t(h[i] >> 24);
      out[4 * i + 1] = std::uint8_t(h[i] >> 16);
      out[4 * i + 2] = std::uint8_t(h[i] >> 8);
      out[4 * i + 3] = std::uint8_t(h[i]);
    }
    return out;
  }
};

Sha256::Sha256()
    : _impl(std::make_unique<Impl>()) {}
Sha256::~Sha256() = default;

void Sha256::update(std::span<const std::byte> bytes) {
  _impl->update(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
}

void Sha256::update(std::string_view text) {
  _impl->update(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
}

std::array<std::uint8_t, 32> Sha256::digest() {
  return _impl->finish();
}

std::string Sha256::hexDigest() {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (std::uint8_t b : digest()) {
    out.push_back(kHex[b >> 4]);
    out.push_back(kHex[b & 15]);
  }
  return out;
}

std::string sha256Hex(std::string_view text) {
  Sha256 h;
  h.update(text);
  return h.hexDigest();
}

std::string sha256File(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  COREDEM_CHECK(in.good(), "cannot read '{}' to hash it", file.string());
  Sha256 h;
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), std::streamsize(buf.size()));
    const auto got = in.gcount();
    if (got > 0) {
      h.update(std::string_view(buf.data(), std::size_t(got)));
    }
  }
  COREDEM_CHECK(in.eof(), "error while reading '{}' to hash it", file.string());
  return h.hexDigest();
}

} // namespace coredem::orchestrator
