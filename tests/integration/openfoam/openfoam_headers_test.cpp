// scripts/openfoam-headers.sh on the cache this build was configured with: a second run is a
// no-op that keeps the prepared tree, and bad invocations fail with a message saying what to do.
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <sys/wait.h>

namespace fs = std::filesystem;

namespace {

struct Result {
  int code;
  std::string output;
};

// Runs a shell command with a 120 s deadline and returns its exit code and stdout + stderr.
Result runShell(const std::string& command) {
  const std::string cmd = "timeout 120 " + command + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) {
    return {-1, "popen failed"};
  }
  std::string out;
  std::array<char, 4096> buf{};
  size_t n = 0;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) {
    out.append(buf.data(), n);
  }
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

const std::string kScript = std::string("bash '") + COREDEM_OPENFOAM_HEADERS_SCRIPT + "'";

} // namespace

TEST(OpenFoamHeaders, SecondRunIsANoOpAndKeepsTheTree) {
  const fs::path cache = COREDEM_OPENFOAM_HEADERS_DIR;
  const fs::path stamp = cache / "openfoam-headers.stamp";
  ASSERT_TRUE(fs::exists(stamp)) << "configure should have prepared " << cache;
  const auto fvCFD = cache / "src/finiteVolume/lnInclude/fvCFD.H";
  ASSERT_TRUE(fs::exists(fvCFD)) << fvCFD; // follows the link: the target is there too

  const Result r = runShell(kScript + " '" + cache.string() + "'");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("nothing to do"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("apt-get"), std::string::npos) << "a no-op run must not download\n"
                                                         << r.output;
  EXPECT_TRUE(fs::exists(fvCFD));

  std::ifstream in(stamp);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("components=src/OpenFOAM src/OSspecific/POSIX src/finiteVolume"),
            std::string::npos)
      << text.str();
}

TEST(OpenFoamHeaders, BadInvocationsSayWhatIsWrong) {
  Result r = runShell(kScript);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("missing CACHE_DIR"), std::string::npos) << r.output;

  r = runShell(kScript + " --frobnicate /tmp/x");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("unknown option '--frobnicate'"), std::string::npos) << r.output;

  r = runShell(kScript + " /tmp/a /tmp/b");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("only one CACHE_DIR"), std::string::npos) << r.output;
}
