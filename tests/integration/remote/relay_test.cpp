// coredem-relay (bench/remote/relay.cpp), the delaying TCP relay of the emulated remote link:
// bytes through it arrive identical and in order both ways, a half-close is passed on after the
// bytes before it, each crossing adds at least the configured one-way delay, a bandwidth limit
// is a lower bound on the transfer time, an unreachable target closes only that connection, and
// SIGTERM ends it with exit 0. Lower bounds only: no timing upper bound is asserted.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
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
  Relay(const std::string& target, double delayMs, double mbit = 0.0) {
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

TEST(Relay, EachRoundTripTakesAtLeastTwiceTheOneWayDelay) {
  EchoServer echo;
  constexpr double kDelayMs = 5.0;
  Relay relay(echo.address(), kDelayMs);
  const int fd = connectTo(relay.address());
  ASSERT_GE(fd, 0) << relay.log();
  char msg[100] = {};
  for (int i = 0; i < 20; ++i) {
    std::memset(msg, 'a' + i, sizeof msg);
    const auto t0 = Clock::now();
    ASSERT_TRUE(sendAll(fd, msg, sizeof msg));
    char back[sizeof msg];
    ASSERT_TRUE(recvAll(fd, back, sizeof back));
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    EXPECT_EQ(std::memcmp(msg, back, sizeof msg), 0);
    EXPECT_GE(ms, 2.0 * kDelayMs) << "round trip " << i;
  }
  ::close(fd);
  EXPECT_EQ(relay.terminate(), 0) << relay.log();
}

TEST(Relay, ABandwidthLimitIsALowerBoundOnTheTransferTime) {
  EchoServer echo;
  constexpr double kMbit = 40.0;
  Relay relay(echo.address(), 0.0, kMbit);
  const int fd = connectTo(relay.address());
  ASSERT_GE(fd, 0) << relay.log();
  std::vector<char> sent(1 << 20, 'x'), got(sent.size());
  const auto t0 = Clock::now();
  std::thread writer([&] { ASSERT_TRUE(sendAll(fd, sent.data(), sent.size())); });
  ASSERT_TRUE(recvAll(fd, got.data(), got.size())) << relay.log();
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  writer.join();
  EXPECT_TRUE(got == sent);
  // Each direction is a 40 Mbit/s link: 1 MiB needs 0.21 s to cross it (the two directions
  // overlap, so once is the bound).
  EXPECT_GE(s, double(sent.size()) * 8.0 / (kMbit * 1e6));
  ::close(fd);
  EXPECT_EQ(relay.terminate(), 0) << relay.log();
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
