// coredem-relay: a delaying TCP relay that emulates a remote link (bench/remote/README.md).
//
// Listens on HOST:PORT and forwards every accepted connection to a target HOST:PORT, full
// duplex. Every chunk of bytes read from one side is written to the other side `--delay-ms`
// after it was read (one-way delay; a request and its reply cross the relay twice, so the round
// trip grows by twice the delay). With `--mbit R` each direction of a connection is also a link
// of R Mbit/s: a chunk leaves after the chunks before it have been sent at that rate, then
// travels the delay. Bytes keep their order; a half-close (EOF) is passed on after the bytes
// before it; a reset or error on one side closes both. At most `--max-queued-mb` are held per
// direction (then the relay stops reading that side, which TCP turns into back-pressure).
// SIGTERM or SIGINT closes every connection and exits 0. `--trace-chunks` logs every chunk once
// it is written on: its connection, direction, size and when it was read, due and written (ns on
// the relay's steady clock), so that tests check the delay and the bandwidth from the log.
//
// Used where the kernel has no `tc qdisc netem` (tests/e2e/remote, bench/remote/link.sh). Plain
// POSIX sockets and poll(); no CoReDEM library.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <list>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

namespace {

using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t gStop = 0;

void onSignal(int) {
  gStop = 1;
}

void logLine(const std::string& text) {
  std::fprintf(stderr, "coredem-relay: %s\n", text.c_str());
  std::fflush(stderr);
}

/// "host:port" -> sockaddr (numeric hosts, or names resolved by getaddrinfo).
bool resolve(const std::string& hostPort, sockaddr_storage& out, socklen_t& len) {
  const auto colon = hostPort.rfind(':');
  if (colon == std::string::npos) {
    return false;
  }
  std::string host = hostPort.substr(0, colon);
  const std::string port = hostPort.substr(colon + 1);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* res = nullptr;
  if (::getaddrinfo(host.empty() ? nullptr : host.c_str(), port.c_str(), &hints, &res) != 0 ||
      res == nullptr) {
    return false;
  }
  std::memcpy(&out, res->ai_addr, res->ai_addrlen);
  len = res->ai_addrlen;
  ::freeaddrinfo(res);
  return true;
}

std::string describe(const sockaddr_storage& a) {
  char host[INET6_ADDRSTRLEN] = "?";
  int port = 0;
  if (a.ss_family == AF_INET) {
    const auto* in = reinterpret_cast<const sockaddr_in*>(&a);
    ::inet_ntop(AF_INET, &in->sin_addr, host, sizeof host);
    port = ntohs(in->sin_port);
  } else if (a.ss_family == AF_INET6) {
    const auto* in = reinterpret_cast<const sockaddr_in6*>(&a);
    ::inet_ntop(AF_INET6, &in->sin6_addr, host, sizeof host);
    port = ntohs(in->sin6_port);
  }
  return std::string(host) + ":" + std::to_string(port);
}

void setNonBlocking(int fd) {
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
}

void setNoDelay(int fd) {
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

struct Chunk {
  Clock::time_point read; ///< when it was read from its side
  Clock::time_point due;  ///< when it may be written to the other side
  std::vector<char> bytes;
  std::size_t offset = 0; ///< bytes of it already written
};

/// One direction of a relayed connection: bytes read from `from`, written to `to`.
struct Direction {
  int from = -1;
  int to = -1;
  std::deque<Chunk> queue;
  std::size_t queued = 0;      ///< bytes in `queue` not yet written
  bool eof = false;            ///< `from` sent EOF
  bool shutDown = false;       ///< EOF passed on to `to`
  Clock::time_point linkFree;  ///< with a bandwidth limit: when the link is free again
  std::uint64_t forwarded = 0; ///< bytes written to `to`
  std::string trace;           ///< with --trace-chunks: "<connection> up|down", else empty
  bool done() const { return shutDown; }
};

struct Connection {
  int client = -1;
  int target = -1;
  std::string name;
  Direction up;   ///< client -> target
  Direction down; ///< target -> client
  bool failed = false;
};

struct Settings {
  Clock::duration delay{};
  double bytesPerSecond = 0.0; ///< 0: no bandwidth limit
  std::size_t maxQueued = 0;
};

constexpr std::size_t kChunk = 64 * 1024;

/// Reads what `d.from` has (one chunk) and queues it with its due time. False on a reset.
bool readSide(Direction& d, const Settings& s) {
  Chunk c;
  c.bytes.resize(kChunk);
  const ssize_t n = ::recv(d.from, c.bytes.data(), c.bytes.size(), 0);
  if (n < 0) {
    return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
  }
  if (n == 0) {
    d.eof = true;
    return true;
  }
  c.bytes.resize(static_cast<std::size_t>(n));
  const auto now = Clock::now();
  c.read = now;
  if (s.bytesPerSecond > 0.0) {
    const auto tx = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(double(n) / s.bytesPerSecond));
    d.linkFree = std::max(d.linkFree, now) + tx;
    c.due = d.linkFree + s.delay;
  } else {
    c.due = now + s.delay;
  }
  d.queued += c.bytes.size();
  d.queue.push_back(std::move(c));
  return true;
}

/// Writes the due chunks of `d`; passes EOF on once the queue is empty. False on an error.
bool writeSide(Direction& d) {
  const auto now = Clock::now();
  while (!d.queue.empty() && d.queue.front().due <= now) {
    Chunk& c = d.queue.front();
    const ssize_t n =
        ::send(d.to, c.bytes.data() + c.offset, c.bytes.size() - c.offset, MSG_NOSIGNAL);
    if (n < 0) {
      return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
    }
    c.offset += static_cast<std::size_t>(n);
    d.queued -= static_cast<std::size_t>(n);
    d.forwarded += static_cast<std::uint64_t>(n);
    if (c.offset < c.bytes.size()) {
      return true; // the socket buffer is full: wait for POLLOUT
    }
    if (!d.trace.empty()) {
      auto ns = [](Clock::time_point t) {
        return std::to_string(
            std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
      };
      logLine("chunk " + d.trace + " " + std::to_string(c.bytes.size()) + " bytes read_ns " +
              ns(c.read) + " due_ns " + ns(c.due) + " written_ns " + ns(Clock::now()));
    }
    d.queue.pop_front();
  }
  if (d.eof && d.queue.empty() && !d.shutDown) {
    ::shutdown(d.to, SHUT_WR);
    d.shutDown = true;
  }
  return true;
}

bool wantsWrite(const Direction& d, Clock::time_point now) {
  return !d.queue.empty() && d.queue.front().due <= now;
}

/// Accepts a client on the listener lfd and connects it to the target: a new connection in
/// conns, or (when the target cannot be reached) the client closed again.
void acceptConnection(int lfd, const sockaddr_storage& targetAddr, socklen_t targetLen,
                      bool traceChunks, std::list<Connection>& conns) {
  sockaddr_storage peer{};
  socklen_t peerLen = sizeof peer;
  const int cfd = ::accept4(lfd, reinterpret_cast<sockaddr*>(&peer), &peerLen, SOCK_CLOEXEC);
  if (cfd >= 0) {
    const int tfd = ::socket(targetAddr.ss_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
    // A blocking connect (the target is meant to be near: the same host or namespace),
    // bounded so that a target that does not answer cannot stall the other connections.
    const timeval connectTimeout{5, 0};
    if (tfd >= 0) {
      ::setsockopt(tfd, SOL_SOCKET, SO_SNDTIMEO, &connectTimeout, sizeof connectTimeout);
    }
    if (tfd < 0 || ::connect(tfd, reinterpret_cast<const sockaddr*>(&targetAddr), targetLen) != 0) {
      logLine("connection from " + describe(peer) + ": cannot connect to " + describe(targetAddr) +
              ": " + std::strerror(errno) + "; closed");
      if (tfd >= 0) {
        ::close(tfd);
      }
      ::close(cfd);
    } else {
      const timeval none{0, 0};
      ::setsockopt(tfd, SOL_SOCKET, SO_SNDTIMEO, &none, sizeof none);
      setNonBlocking(cfd);
      setNonBlocking(tfd);
      setNoDelay(cfd);
      setNoDelay(tfd);
      Connection& c = conns.emplace_back();
      c.client = cfd;
      c.target = tfd;
      c.name = describe(peer);
      c.up.from = cfd;
      c.up.to = tfd;
      c.down.from = tfd;
      c.down.to = cfd;
      if (traceChunks) {
        c.up.trace = c.name + " up";
        c.down.trace = c.name + " down";
      }
      logLine("connection from " + c.name + " relayed to " + describe(targetAddr));
    }
  }
}

/// Closes (both sides of) the connections that failed or are done in both directions.
void closeFinished(std::list<Connection>& conns) {
  for (auto it = conns.begin(); it != conns.end();) {
    if (it->failed || (it->up.done() && it->down.done())) {
      logLine("connection from " + it->name + " closed (" +
              (it->failed ? std::string("reset or error") : std::string("both sides done")) + ", " +
              std::to_string(it->up.forwarded) + " bytes up, " +
              std::to_string(it->down.forwarded) + " bytes down)");
      ::close(it->client);
      ::close(it->target);
      it = conns.erase(it);
    } else {
      ++it;
    }
  }
}

int run(const std::string& listenAt, const std::string& targetAt, double delayMs, double mbit,
        double maxQueuedMb, const std::string& portFile, bool traceChunks) {
  Settings s;
  s.delay = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double, std::milli>(delayMs));
  s.bytesPerSecond = mbit * 1e6 / 8.0;
  s.maxQueued = static_cast<std::size_t>(maxQueuedMb * 1024.0 * 1024.0);

  sockaddr_storage listenAddr{}, targetAddr{};
  socklen_t listenLen = 0, targetLen = 0;
  if (!resolve(listenAt, listenAddr, listenLen)) {
    logLine("error: cannot resolve --listen " + listenAt + " (HOST:PORT)");
    return 2;
  }
  if (!resolve(targetAt, targetAddr, targetLen)) {
    logLine("error: cannot resolve --target " + targetAt + " (HOST:PORT)");
    return 2;
  }
  const int lfd = ::socket(listenAddr.ss_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int one = 1;
  ::setsockopt(lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (lfd < 0 || ::bind(lfd, reinterpret_cast<sockaddr*>(&listenAddr), listenLen) != 0 ||
      ::listen(lfd, 64) != 0) {
    logLine("error: cannot listen on " + listenAt + ": " + std::strerror(errno));
    return 1;
  }
  setNonBlocking(lfd);
  sockaddr_storage bound{};
  socklen_t boundLen = sizeof bound;
  ::getsockname(lfd, reinterpret_cast<sockaddr*>(&bound), &boundLen);
  if (!portFile.empty()) {
    const std::string tmp = portFile + ".tmp";
    std::ofstream(tmp) << describe(bound) << "\n";
    std::rename(tmp.c_str(), portFile.c_str());
  }
  char settings[160];
  if (mbit > 0) {
    std::snprintf(settings, sizeof settings, "one-way delay %g ms, %g Mbit/s each way", delayMs,
                  mbit);
  } else {
    std::snprintf(settings, sizeof settings, "one-way delay %g ms, bandwidth unlimited", delayMs);
  }
  logLine("listening on " + describe(bound) + ", forwarding to " + describe(targetAddr) + " (" +
          settings + ")");

  std::list<Connection> conns;
  std::vector<pollfd> fds;
  std::vector<Connection*> owner; // fds[i] belongs to owner[i] (nullptr: the listener)
  while (!gStop) {
    const auto now = Clock::now();
    fds.clear();
    owner.clear();
    fds.push_back({lfd, POLLIN, 0});
    owner.push_back(nullptr);
    auto nextDue = now + std::chrono::milliseconds(200); // wake up to look at the stop flag
    for (Connection& c : conns) {
      short ev[2] = {0, 0}; // client, target
      auto side = [&](Direction& d, int fromIdx, int toIdx) {
        if (!d.eof && d.queued < s.maxQueued) {
          ev[fromIdx] |= POLLIN;
        }
        if (wantsWrite(d, now)) {
          ev[toIdx] |= POLLOUT;
        } else if (!d.queue.empty()) {
          nextDue = std::min(nextDue, d.queue.front().due);
        }
      };
      side(c.up, 0, 1);
      side(c.down, 1, 0);
      // A side with nothing left to read or write is left out (a negative fd), so that a
      // hang-up reported on it does not spin the loop while the other direction drains.
      const bool clientActive = !c.up.eof || wantsWrite(c.down, now);
      const bool targetActive = !c.down.eof || wantsWrite(c.up, now);
      fds.push_back({clientActive ? c.client : -1, ev[0], 0});
      owner.push_back(&c);
      fds.push_back({targetActive ? c.target : -1, ev[1], 0});
      owner.push_back(&c);
    }
    // ppoll() with a nanosecond timeout: sub-millisecond delays stay sub-millisecond (poll()'s
    // milliseconds would round a 50 us delay up to 1 ms).
    const auto wait = std::max(std::chrono::nanoseconds(0),
                               std::chrono::duration_cast<std::chrono::nanoseconds>(nextDue - now));
    timespec timeout{};
    timeout.tv_sec = static_cast<time_t>(wait.count() / 1000000000);
    timeout.tv_nsec = static_cast<long>(wait.count() % 1000000000);
    const int r = ::ppoll(fds.data(), fds.size(), &timeout, nullptr);
    if (r < 0 && errno != EINTR) {
      logLine(std::string("error: poll: ") + std::strerror(errno));
      break;
    }
    if (r > 0 && (fds[0].revents & POLLIN)) {
      acceptConnection(lfd, targetAddr, targetLen, traceChunks, conns);
    }
    // Reads and writes; a connection with a reset or an error is closed on both sides.
    for (std::size_t i = 1; i + 1 < fds.size(); i += 2) {
      Connection& c = *owner[i];
      const short cev = fds[i].revents, tev = fds[i + 1].revents;
      bool ok = true;
      if (cev & (POLLIN | POLLHUP | POLLERR)) {
        ok = ok && (c.up.eof || readSide(c.up, s));
      }
      if (tev & (POLLIN | POLLHUP | POLLERR)) {
        ok = ok && (c.down.eof || readSide(c.down, s));
      }
      ok = ok && writeSide(c.up) && writeSide(c.down);
      c.failed = !ok;
    }
    for (Connection& c : conns) {
      if (!c.failed) {
        c.failed = !(writeSide(c.up) && writeSide(c.down)); // chunks that fell due meanwhile
      }
    }
    closeFinished(conns);
  }
  for (Connection& c : conns) {
    ::close(c.client);
    ::close(c.target);
  }
  ::close(lfd);
  logLine("stopped (" + std::to_string(conns.size()) + " open connections closed)");
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"coredem-relay: a TCP relay that delays every byte by a one-way delay (and "
               "optionally limits the bandwidth), emulating a remote link"};
  std::string listenAt, targetAt, portFile;
  double delayMs = 0.0, mbit = 0.0, maxQueuedMb = 256.0;
  app.add_option("--listen", listenAt, "HOST:PORT to listen on (PORT 0: any free port)")
      ->required();
  app.add_option("--target", targetAt, "HOST:PORT every connection is forwarded to")->required();
  app.add_option("--delay-ms", delayMs, "one-way delay in ms (round trip = 2 x delay)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--mbit", mbit, "bandwidth of each direction in Mbit/s (0: unlimited)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--max-queued-mb", maxQueuedMb,
                 "bytes held per direction before reading pauses, MiB")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--port-file", portFile, "write the HOST:PORT listened on to this file");
  bool traceChunks = false;
  app.add_flag("--trace-chunks", traceChunks,
               "log each chunk when written on: size and read/due/written times (ns)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  ::sigaction(SIGTERM, &sa, nullptr);
  ::sigaction(SIGINT, &sa, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  ::prctl(PR_SET_TIMERSLACK, 1UL); // wake up on time (the default slack is 50 us)
  return run(listenAt, targetAt, delayMs, mbit, maxQueuedMb, portFile, traceChunks);
}
