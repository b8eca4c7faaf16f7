// SHA-256 against the FIPS 180-2 example vectors (Appendix B) and the empty string.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include <coredem/orchestrator/sha256.h>

using namespace coredem::orchestrator;

TEST(Sha256, Fips180_2_OneBlockMessage) {
  EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Sha256, Fips180_2_MultiBlockMessage) {
  EXPECT_EQ(sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256, Fips180_2_OneMillionA_FedInOddChunks) {
  Sha256 h;
  const std::string chunk(997, 'a'); // not a multiple of the 64-byte block
  std::size_t left = 1000000;
  while (left > 0) {
    const std::size_t n = std::min(left, chunk.size());
    h.update(std::string_view(chunk.data(), n));
    left -= n;
  }
  EXPECT_EQ(h.hexDigest(), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, EmptyAndPaddingBoundaries) {
  EXPECT_EQ(sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  // 55 and 56 bytes straddle the length-field boundary of the padding.
  EXPECT_EQ(sha256Hex(std::string(55, 'a')),
            "9f4390f8d30c2dd92ec9f095b65e2b9ae9b0a925a5258e241c9f1e910f734318");
  EXPECT_EQ(sha256Hex(std::string(56, 'a')),
            "b35439a4ac6f0948b6d6f9e3c6af0f5f590ce20f1bde7090ef7970686ec6738a");
}

TEST(Sha256, FileMatchesString) {
  const auto p = std::filesystem::temp_directory_path() / "coredem_sha256_test.bin";
  std::string data;
  for (int i = 0; i < 200000; ++i) {
    data += char(i * 7 + 3);
  }
  std::ofstream(p, std::ios::binary) << data;
  EXPECT_EQ(sha256File(p), sha256Hex(data));
  std::filesystem::remove(p);
}
