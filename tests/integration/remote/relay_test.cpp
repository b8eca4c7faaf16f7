// coredem-relay (bench/remote/relay.cpp), the delaying TCP relay of the emulated remote link:
// bytes through it arrive identical and in order both ways, a half-close is passed on after the
// bytes before it, each crossing is held for the configured one-way delay, a bandwidth limit
// spaces the chunks by their transmission time, an unreachable target closes only that
// connection, and SIGTERM ends it with exit 0. The delay and the bandwidth are checked from what
// the relay logs (--trace-chunks: each chunk's read, due and written times on its own clock) and
// from the order of those events, not by timing the test: no assertion depends on how fast the
// machine is.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <coredem/common/process.h>

#include "relay_trace.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

const fs::path kRelay = fs::path(COREDEM_BIN_DIR) / "coredem-relay";

/// A listening socket on 127.0.0.1:any; returns the fd and sets `port`.
int listenLoopback(int& port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  EXPECT_EQ(::listen(fd, 8), 0);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  port = ntohs(a.sin_port);
  return fd;
}

int connectTo(const std::string& hostPort) {
  const auto colon = hostPort.rfind(':');
  sockaddr_in a{};
  a.sin_family = AF_INET;
  ::inet_pton(AF_INET, hostPort.substr(0, colon).c_str(), &a.sin_addr);
  a.sin_port = htons(static_cast<std::uint16_t>(std::stoi(hostPort.substr(colon + 1))));
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

bool sendAll(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t k = ::send(fd, p, n, MSG_NOSIGNAL);
    if (k <= 0) {
      return false;
    }
    p += k;
    n -= static_cast<std::size_t>(k);
  }
  return true;
}

/// Reads exactly n bytes (false on EOF or error before that).
bool recvAll(int fd, char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t k = ::recv(fd, p, n, 0);
    if (k <= 0) {
      return false;
    }
    p += k;
    n -= static_cast<std::size_t>(k);
  }
  return true;
}

/// An echo server on 127.0.0.1: each accepted connection gets back what it sends, then a
/// half-close when the client half-closes.
class EchoServer {
public:
  EchoServer() {
    _fd = listenLoopback(_port);
    _thread = std::thread([this] {
      while (!_stop) {
        const int c = ::accept(_fd, nullptr, nullptr);
        if (c < 0) {
          return;
        }
        std::thread([c] {
          std::vector<char> buf(1 << 16);
          for (;;) {
            const ssize_t k = ::recv(c, buf.data(), buf.size(), 0);
            if (k <= 0 || !sendAll(c, buf.data(), static_cast<std::size_t>(k))) {
              break;
            }
          }
          ::shutdown(c, SHUT_WR);
          ::close(c);
        }).detach();
      }
    });
  }
  ~EchoServer() {
    _stop = true;
    ::shutdown(_fd, SHUT_RDWR);
    ::close(_fd);
    _thread.join();
  }
  std::string address() const { return "127.0.0.1:" + std::to_string(_port); }

private:
  int _fd = -1;
  int _port = 0;
  std::atomic<bool> _stop{false};
  std::thread _thread;
};

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) {
    s.pop_back();
  }
  return s;
}

/// A coredem-relay process on 127.0.0.1:any in front of `target`.
class Relay {
public:
  Relay(const std::string& target, double delayMs, double mbit = 0.0, bool trace = false) {
    _dir = fs::temp_directory_path() /
           ("coredem-relay-test-" + std::to_string(::getpid()) + "-" + std::to_string(_count++));
    fs::remove_all(_dir);
    fs::create_directories(_dir);
    std::vector<std::string> argv = {kRelay.string(),
                                     "--listen",
                                     "127.0.0.1:0",
                                     "--target",
                                     target,
                                     "--delay-ms",
                                     std::to_string(delayMs),
                                     "--mbit",
                                     std::to_string(mbit),
                                     "--port-file",
                                     (_dir / "port").string()};
    if (trace) {
      argv.push_back("--trace-chunks");
    }
    coredem::SpawnOptions o;
    o.ownProcessGroup = false;
    _pid = coredem::spawnProcess("coredem-relay", argv, _dir / "relay.log", o);
    const auto end = Clock::now() + 20s;
    while (!fs::exists(_dir / "port") && Clock::now() < end) {
      std::this_thread::sleep_for(5ms);
    }
    _address = readFile(_dir / "port");
  }
  ~Relay() {
    if (_pid > 0) {
      ::kill(_pid, SIGKILL);
      ::waitpid(_pid, nullptr, 0);
    }
    fs::remove_all(_dir);
  }
  const std::string& address() const { return _address; }
  std::string log() const { return readFile(_dir / "relay.log"); }
  /// SIGTERM and the exit code (−signal when killed; −1000 when it did not end in 20 s).
  int terminate() {
    ::kill(_pid, SIGTERM);
    const auto end = Clock::now() + 20s;
    int status = 0;
    while (::waitpid(_pid, &status, WNOHANG) == 0) {
      if (Clock::now() > end) {
        return -1000;
      }
      std::this_thread::sleep_for(5ms);
    }
    _pid = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  }

private:
  static inline int _count = 0;
  fs::path _dir;
  int _pid = -1;
  std::string _address;
};

using coredem::relay::TracedChunk;
using coredem::relay::tracedChunks;

} // namespace

TEST(Relay, BytesArriveIdenticalAndInOrderBothWaysAndAHalfCloseFollowsThem) {
  EchoServer echo;
  Relay relay(echo.address(), 2.0);
  ASSERT_FALSE(relay.address().empty()) << relay.log();
  const int fd = connectTo(relay.address());
  ASSERT_GE(fd, 0) << relay.log();
  std::vector<char> sent(4 << 20);
  std::mt19937 rng(7);
  for (auto& b : sent) {
    b = static_cast<char>(rng());
  }
  // Writes in odd-sized pieces from a thread while the reply is read (full duplex).
  std::thread writer([&] {
    std::size_t off = 0, piece = 1;
    while (off < sent.size()) {
      const std::size_t n = std::min(piece, sent.size() - off);
      ASSERT_TRUE(sendAll(fd, sent.data() + off, n));
      off += n;
      piece = piece * 3 + 7;
      if (piece > 300000) {
        piece = 1;
      }
    }
    ::shutdown(fd, SHUT_WR);
  });
  std::vector<char> got(sent.size());
  const bool complete = recvAll(fd, got.data(), got.size());
  writer.join();
  ASSERT_TRUE(complete) << relay.log();
  EXPECT_TRUE(got == sent) << "the bytes through the relay differ";
  char extra = 0;
  EXPECT_EQ(::recv(fd, &extra, 1, 0), 0) << "expected the echo's half-close (EOF) after the bytes";
  ::close(fd);
  EXPECT_EQ(relay.terminate(), 0) << relay.log();
}

// Every chunk is due exactly the one-way delay after it was read and is written no earlier; and
// since the echo can answer only what the relay wrote, each message's reply leaves the relay at
// least twice the delay after the request came in (read -> due -> written -> echoed -> read ->
// due -> written, all on the relay's clock).
TEST(Relay, EachCrossingIsHeldForTheOneWayDelay) {
  EchoServer echo;
  constexpr double kDelayMs = 5.0;
  constexpr long long kDelayNs = 5'000'000;
  constexpr int kMessages = 20;
  constexpr std::size_t kSize = 100;
  Relay relay(echo.address(), kDelayMs, 0.0, true);
  const int fd = connectTo(relay.address());
  ASSERT_GE(fd, 0) << relay.log();
  char msg[kSize] = {};
  for (int i = 0; i < kMessages; ++i) {
    std::memset(msg, 'a' + i, sizeof msg);
    ASSERT_TRUE(sendAll(fd, msg, sizeof msg));
    char back[sizeof msg];
    ASSERT_TRUE(recvAll(fd, back, sizeof back));
    EXPECT_EQ(std::memcmp(msg, back, sizeof msg), 0);
  }
  ::close(fd);
  EXPECT_EQ(relay.terminate(), 0) << relay.log();
  const std::string log = relay.log();
  const auto up = tracedChunks(log, "up");
  const auto down = tracedChunks(log, "down");
  ASSERT_FALSE(up.empty()) << log;
  ASSERT_FALSE(down.empty()) << log;
  long long upBytes = 0, downBytes = 0;
  for (const auto* list : {&up, &down}) {
    for (const TracedChunk& c : *list) {
      EXPECT_EQ(c.due - c.read, kDelayNs) << c.direction << " chunk read at " << c.read;
      EXPECT_GE(c.written, c.due) << c.direction << " chunk read at " << c.read;
      (list == &up ? upBytes : downBytes) += c.bytes;
    }
  }
  EXPECT_EQ(upBytes, kMessages * kSize);
  EXPECT_EQ(downBytes, kMessages * kSize);
  // Message i is bytes [i kSize, (i + 1) kSize) both ways: the up chunk holding its first byte
  // was read before the down chunk holding its last byte was written, by at least 2 delays.
  auto chunkOf = [](const std::vector<TracedChunk>& list, long long byte) {
    long long end = 0;
    for (const TracedChunk& c : list) {
      end += c.bytes;
      if (byte < end) {
        return c;
      }
    }
    return TracedChunk{};
  };
  for (int i = 0; i < kMessages; ++i) {
    const TracedChunk request = chunkOf(up, i * static_cast<long long>(kSize));
    const TracedChunk reply = chunkOf(down, (i + 1) * static_cast<long long>(kSize) - 1);
    EXPECT_GE(reply.written - request.read, 2 * kDelayNs) << "message " << i;
  }
}

// With --mbit each direction is a link of that rate: from the logged read times the test
// recomputes when the link is free again (max(free, read) + bytes/rate, as
// bench/remote/relay.cpp defines it) and finds every chunk due exactly then; no chunk is written
// before it is due, so the transfer spans at least bytes/rate on the relay's clock.
TEST(Relay, ABandwidthLimitSpacesTheChunksByTheirTransmissionTime) {
  EchoServer echo;
  constexpr double kMbit = 40.0;
  Relay relay(echo.address(), 0.0, kMbit, true);
  const int fd = connectTo(relay.address());
  ASSERT_GE(fd, 0) << relay.log();
  std::vector<char> sent(1 << 20, 'x'), got(sent.size());
  std::thread writer([&] { ASSERT_TRUE(sendAll(fd, sent.data(), sent.size())); });
  ASSERT_TRUE(recvAll(fd, got.data(), got.size())) << relay.log();
  writer.join();
  EXPECT_TRUE(got == sent);
  ::close(fd);
  EXPECT_EQ(relay.terminate(), 0) << relay.log();
  const std::string log = relay.log();
  const double bytesPerSecond = kMbit * 1e6 / 8.0;
  for (const char* direction : {"up", "down"}) {
    SCOPED_TRACE(direction);
    const auto chunks = tracedChunks(log, direction);
    ASSERT_GE(chunks.size(), 2u) << log;
    long long linkFree = 0, bytes = 0, transmission = 0;
    for (const TracedChunk& c : chunks) {
      const long long tx = std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::duration<double>(double(c.bytes) / bytesPerSecond))
                               .count();
      linkFree = std::max(linkFree, c.read) + tx;
      EXPECT_EQ(c.due, linkFree) << "chunk read at " << c.read;
      EXPECT_GE(c.written, c.due) << "chunk read at " << c.read;
      bytes += c.bytes;
      transmission += tx;
    }
    EXPECT_EQ(bytes, static_cast<long long>(sent.size()));
    // 1 MiB at 40 Mbit/s: 0.21 s of transmission (each chunk's time truncated to the ns).
    EXPECT_GE(transmission,
              static_cast<long long>(double(sent.size()) * 8.0 / (kMbit * 1e6) * 1e9) -
                  static_cast<long long>(chunks.size()));
    EXPECT_GE(chunks.back().written - chunks.front().read, transmission);
  }
}

TEST(Relay, AnUnreachableTargetClosesThatConnectionAndTheRelayKeepsServing) {
  int port = 0;
  const int unused = listenLoopback(port);
  ::close(unused); // nothing listens on `port` any more
  Relay relay("127.0.0.1:" + std::to_string(port), 1.0);
  for (int i = 0; i < 2; ++i) {
    const int fd = connectTo(relay.address());
    ASSERT_GE(fd, 0) << relay.log();
    char c = 0;
    EXPECT_LE(::recv(fd, &c, 1, 0), 0) << "expected the connection to be closed";
    ::close(fd);
  }
  EXPECT_NE(relay.log().find("cannot connect to"), std::string::npos) << relay.log();
  EXPECT_EQ(relay.terminate(), 0) << relay.log();
}

TEST(Relay, SigtermWithOpenConnectionsExitsZero) {
  EchoServer echo;
  Relay relay(echo.address(), 1.0);
  const int fd = connectTo(relay.address());
  ASSERT_GE(fd, 0) << relay.log();
  ASSERT_TRUE(sendAll(fd, "ping", 4));
  char back[4];
  ASSERT_TRUE(recvAll(fd, back, 4));
  EXPECT_EQ(relay.terminate(), 0) << relay.log();
  char c = 0;
  EXPECT_LE(::recv(fd, &c, 1, 0), 0) << "the relay's end of the connection should be closed";
  ::close(fd);
  EXPECT_NE(relay.log().find("stopped (1 open connections closed)"), std::string::npos)
      << relay.log();
}
