// Child processes: spawn with a log, exit reasons, stop with SIGTERM then SIGKILL.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <coredem/common/check.h>
#include <coredem/common/process.h>

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

fs::path tempLog(const char* name) {
  const fs::path dir =
      fs::temp_directory_path() / ("coredem-common-proc-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::remove(dir / name);
  return dir / name;
}

TEST(Process, OutputEnvironmentAndExitCodeAreReported) {
  const fs::path log = tempLog("echo.log");
  coredem::ChildProcess p("echo test",
                          {"/bin/sh", "-c", "echo out-$COREDEM_T; echo err >&2; exit 3"},
                          {{"COREDEM_T", "42"}}, log);
  ASSERT_TRUE(p.waitFor(10s));
  EXPECT_EQ(p.exitReason(), "exited with code 3");
  EXPECT_EQ(p.exitCode(), 3);
  std::stringstream s;
  s << std::ifstream(log).rdbuf();
  EXPECT_EQ(s.str(), "out-42\nerr\n");
  EXPECT_NE(p.logTail(1).find("| err"), std::string::npos);
}

TEST(Process, StopEscalatesToSigkill) {
  const fs::path log = tempLog("trap.log");
  coredem::ChildProcess p(
      "stubborn", {"/bin/sh", "-c", "trap '' TERM; echo ready; while :; do sleep 0.05; done"}, {},
      log);
  // Wait until the trap is set, else SIGTERM may still end the shell.
  for (int i = 0; i < 1000 && p.logTail(1).find("ready") == std::string::npos; ++i) {
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_FALSE(p.exitReason().has_value());
  p.stop(300ms);
  ASSERT_TRUE(p.exitReason().has_value());
  EXPECT_EQ(*p.exitReason(), "killed by signal 9 (SIGKILL)");
}

TEST(Process, SpawnReturnsAPidAndFailsClearly) {
  const int pid = coredem::spawnProcess("true", {"/bin/true"}, tempLog("true.log"));
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_EQ(coredem::describeWaitStatus(status), "exited with code 0");
  try {
    (void)coredem::spawnProcess("missing program", {"/nonexistent/prog"}, tempLog("x.log"));
    FAIL();
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot start the missing program ('/nonexistent/prog')"),
              std::string::npos);
  }
}

} // namespace

// writeFileAtomic (files.h): the whole content or the old file, never a temporary left behind.
#include <coredem/common/files.h>

namespace {

TEST(Files, WriteFileAtomicReplacesWholeAndLeavesNoTemporary) {
  const fs::path dir = tempLog("atomic").parent_path() / "atomic-dir";
  fs::remove_all(dir);
  fs::create_directories(dir);
  coredem::writeFileAtomic(dir / "a.json", "old\n");
  coredem::writeFileAtomic(dir / "a.json", std::string(100000, 'x'));
  std::stringstream s;
  s << std::ifstream(dir / "a.json").rdbuf();
  EXPECT_EQ(s.str(), std::string(100000, 'x'));
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) {
    ++files;
  }
  EXPECT_EQ(files, 1);
  EXPECT_THROW(coredem::writeFileAtomic(dir / "missing" / "b.json", "x"), coredem::UserError);
}

} // namespace
