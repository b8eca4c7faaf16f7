// coredem-bench protocol --cells N --fields F [--json] [--seconds S] [--transports tcp,ipc]
//
// Round trip of N cells x F float64 arrays through the protocol transport (a Client sends a
// message with F arrays of N doubles, an echo Server in a child process - or, with
// --same-process, in a thread - sends the same arrays back) over tcp loopback and over ipc,
// compared with a plain memcpy of the same bytes measured in the same run. Transport
// "tcp-raw" (opt-in: --transports tcp,ipc,tcp-raw) does the same exchange with bare cppzmq
// sockets, bypassing the library, to show the library's own overhead. Figures:
//   gbps          = 2 * N*F*8 bytes / median round-trip time   (bytes moved per second)
//   memcpy_gbps   = N*F*8 bytes / median memcpy time
//   memcpy_ratio  = gbps / memcpy_gbps
//   validate_gbps = N*F*8 bytes / median time of validate() on such a message (structure
//                   and NaN/Inf scan: the receiver-side check every message gets)
// Both sides use the library's zero-copy paths (addArrayShared on send, frame views on
// receive), so the figure is the cost of the transport itself (no validation).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <thread>
#include <vector>

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zmq.hpp>

#include <coredem/protocol/message.h>
#include <coredem/protocol/transport.h>
#include <coredem/protocol/validate.h>

#include "commands.h"
#include "options.h"

namespace {

using namespace coredem::protocol;
namespace v1 = coredem::v1;
using Clock = std::chrono::steady_clock;

struct Result {
  std::string transport;
  double medianSeconds = 0;
  double minSeconds = 0;
  std::size_t iterations = 0;
};

std::string arrayName(std::size_t f) {
  std::string name = std::to_string(f);
  name.insert(name.begin(), 'f');
  return name;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// Echo server: answers every message with the same arrays (no copy: the reply's arrays
/// keep the received message alive). Returns on Shutdown, on `stop`, or after 60 s idle.
void echo(Server& server, const std::atomic<bool>* stop) {
  auto lastRequest = Clock::now();
  while (!(stop && *stop)) {
    auto req = server.receive(std::chrono::milliseconds(50));
    if (!req) {
      if (Clock::now() - lastRequest > std::chrono::seconds(60)) {
        return;
      }
      continue;
    }
    lastRequest = Clock::now();
    auto keep = std::make_shared<Message>(std::move(req->message));
    if (keep->type() == v1::MESSAGE_TYPE_SHUTDOWN) {
      server.reply(req->peer, std::move(makeAck().setSequence(keep->envelope().sequence())));
      return;
    }
    Message reply(v1::MESSAGE_TYPE_ACK);
    reply.envelope().mutable_ack();
    reply.setSequence(keep->envelope().sequence());
    for (std::size_t i = 0; i < keep->arrayCount(); ++i) {
      ArrayView v = keep->array(i);
      reply.addArraySharedBytes(v.name(), v.dtype(), v.shape(), keep, v.bytes);
    }
    server.reply(req->peer, std::move(reply));
  }
}

/// The echo server in a child process (as in a real coupling: two processes, each with its
/// own ZeroMQ I/O thread). Returns the child's pid; the bound endpoint comes through a pipe.
pid_t startEchoProcess(const std::string& bindEndpoint, std::string* endpoint) {
  int fds[2];
  if (::pipe(fds) != 0) {
    throw coredem::UserError("pipe() failed");
  }
  pid_t pid = ::fork();
  if (pid < 0) {
    throw coredem::UserError("fork() failed");
  }
  if (pid == 0) {
    ::close(fds[0]);
    int rc = 0;
    try {
      Server server;
      std::string ep = server.bind(bindEndpoint) + "\n";
      if (::write(fds[1], ep.data(), ep.size()) != static_cast<ssize_t>(ep.size())) {
        rc = 1;
      }
      ::close(fds[1]);
      if (rc == 0) {
        echo(server, nullptr);
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "echo server: %s\n", e.what());
      rc = 1;
    }
    std::fflush(stderr);
    ::_exit(rc);
  }
  ::close(fds[1]);
  std::string ep;
  char c = 0;
  pollfd pfd{fds[0], POLLIN, 0};
  while (::poll(&pfd, 1, 10000) > 0 && ::read(fds[0], &c, 1) == 1 && c != '\n') {
    ep.push_back(c);
  }
  ::close(fds[0]);
  if (ep.empty()) {
    ::kill(pid, SIGTERM);
    ::waitpid(pid, nullptr, 0);
    throw coredem::UserError("the echo server process did not report its endpoint");
  }
  *endpoint = ep;
  return pid;
}

Result measureTransport(const std::string& name, const std::string& bindEndpoint,
                        const std::vector<std::shared_ptr<std::vector<double>>>& arrays,
                        std::uint64_t cells, double minSeconds, bool sameProcess) {
  std::vector<double> times;
  std::string endpoint;
  pid_t child = -1;
  std::unique_ptr<Server> server;
  std::atomic<bool> stop{false};
  std::thread thread;
  if (sameProcess) {
    server = std::make_unique<Server>();
    endpoint = server->bind(bindEndpoint);
    thread = std::thread([&] { echo(*server, &stop); });
  } else {
    child = startEchoProcess(bindEndpoint, &endpoint);
  }
  {
    Client client;
    client.connect(endpoint);
    auto start = Clock::now();
    const std::size_t warmup = 2;
    for (std::size_t it = 0;; ++it) {
      Message m(v1::MESSAGE_TYPE_ACK);
      m.envelope().mutable_ack();
      for (std::size_t f = 0; f < arrays.size(); ++f) {
        m.addArrayShared<double>(arrayName(f), arrays[f], std::span<const double>(*arrays[f]),
                                 {cells});
      }
      auto t0 = Clock::now();
      Message reply = client.request(std::move(m), std::chrono::seconds(60));
      auto t1 = Clock::now();
      if (reply.arrayCount() != arrays.size() ||
          reply.array(arrays.size() - 1).bytes.size() != cells * sizeof(double)) {
        throw coredem::UserError("echo reply is incomplete");
      }
      if (it >= warmup) {
        times.push_back(std::chrono::duration<double>(t1 - t0).count());
      }
      double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      if (times.size() >= 5 && elapsed >= minSeconds) {
        break;
      }
    }
    if (!sameProcess) {
      (void)client.request(makeShutdown("bench done"), std::chrono::seconds(10));
    }
  }
  if (sameProcess) {
    stop = true;
    thread.join();
  } else {
    ::waitpid(child, nullptr, 0);
  }
  return Result{name, median(times), *std::min_element(times.begin(), times.end()), times.size()};
}

/// The same round trip with bare cppzmq (DEALER -> ROUTER echo in a child process): no
/// envelope, no Message, no validation - the floor set by ZeroMQ and the kernel.
Result measureRawZmq(const std::vector<std::shared_ptr<std::vector<double>>>& arrays,
                     std::uint64_t cells, double minSeconds) {
  int fds[2];
  if (::pipe(fds) != 0) {
    throw coredem::UserError("pipe() failed");
  }
  pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    try {
      zmq::context_t ctx(1);
      zmq::socket_t router(ctx, zmq::socket_type::router);
      router.bind("tcp://127.0.0.1:*");
      std::string ep = router.get(zmq::sockopt::last_endpoint) + "\n";
      (void)!::write(fds[1], ep.data(), ep.size());
      ::close(fds[1]);
      for (;;) {
        zmq::pollitem_t item{router.handle(), 0, ZMQ_POLLIN, 0};
        if (zmq::poll(&item, 1, std::chrono::milliseconds(60000)) == 0) {
          break;
        }
        std::vector<zmq::message_t> frames;
        do {
          frames.emplace_back();
          (void)router.recv(frames.back());
        } while (frames.back().more());
        bool stop = frames.size() == 2 && frames[1].to_string_view() == "stop";
        for (std::size_t i = 0; i < frames.size(); ++i) {
          router.send(std::move(frames[i]),
                      i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
        }
        if (stop) {
          break;
        }
      }
      router.set(zmq::sockopt::linger, 1000);
    } catch (const zmq::error_t& e) {
      std::fprintf(stderr, "raw echo: %s\n", e.what());
      ::_exit(1);
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string ep;
  char c = 0;
  pollfd pfd{fds[0], POLLIN, 0};
  while (::poll(&pfd, 1, 10000) > 0 && ::read(fds[0], &c, 1) == 1 && c != '\n') {
    ep.push_back(c);
  }
  ::close(fds[0]);
  std::vector<double> times;
  try {
    zmq::context_t ctx(1);
    zmq::socket_t dealer(ctx, zmq::socket_type::dealer);
    dealer.set(zmq::sockopt::linger, 1000);
    dealer.connect(ep);
    auto start = Clock::now();
    for (std::size_t it = 0;; ++it) {
      auto t0 = Clock::now();
      dealer.send(zmq::str_buffer("x"), zmq::send_flags::sndmore);
      for (std::size_t f = 0; f < arrays.size(); ++f) {
        zmq::message_t m(arrays[f]->data(), cells * sizeof(double), nullptr, nullptr);
        dealer.send(std::move(m),
                    f + 1 < arrays.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
      }
      zmq::pollitem_t item{dealer.handle(), 0, ZMQ_POLLIN, 0};
      if (zmq::poll(&item, 1, std::chrono::milliseconds(60000)) == 0) {
        throw coredem::UserError("raw echo did not answer within 60 s");
      }
      std::vector<zmq::message_t> frames;
      do {
        frames.emplace_back();
        (void)dealer.recv(frames.back());
      } while (frames.back().more());
      auto t1 = Clock::now();
      if (it >= 2) {
        times.push_back(std::chrono::duration<double>(t1 - t0).count());
      }
      if (times.size() >= 5 &&
          std::chrono::duration<double>(Clock::now() - start).count() >= minSeconds) {
        break;
      }
    }
    dealer.send(zmq::str_buffer("stop"), zmq::send_flags::none);
    zmq::message_t reply;
    zmq::pollitem_t item{dealer.handle(), 0, ZMQ_POLLIN, 0};
    if (zmq::poll(&item, 1, std::chrono::milliseconds(10000)) > 0) {
      (void)dealer.recv(reply);
    }
  } catch (const zmq::error_t& e) {
    ::kill(pid, SIGTERM);
    ::waitpid(pid, nullptr, 0);
    throw coredem::UserError(std::string("raw zmq: ") + e.what());
  }
  ::waitpid(pid, nullptr, 0);
  return Result{"tcp-raw", median(times), *std::min_element(times.begin(), times.end()),
                times.size()};
}

double measureMemcpy(std::size_t bytes, double minSeconds) {
  std::vector<char> src(bytes, 1), dst(bytes, 0);
  std::vector<double> times;
  auto start = Clock::now();
  for (int it = 0;; ++it) {
    auto t0 = Clock::now();
    std::memcpy(dst.data(), src.data(), bytes);
    auto t1 = Clock::now();
    src[static_cast<std::size_t>(it) % bytes] = dst[(static_cast<std::size_t>(it) * 7) % bytes];
    if (it >= 2) {
      times.push_back(std::chrono::duration<double>(t1 - t0).count());
    }
    if (times.size() >= 5 &&
        std::chrono::duration<double>(Clock::now() - start).count() >= minSeconds) {
      break;
    }
  }
  return median(times);
}

double measureValidate(const std::vector<std::shared_ptr<std::vector<double>>>& arrays,
                       std::uint64_t cells, double minSeconds) {
  Message m(v1::MESSAGE_TYPE_ACK);
  m.envelope().mutable_ack();
  for (std::size_t f = 0; f < arrays.size(); ++f) {
    m.addArrayShared<double>(arrayName(f), arrays[f], std::span<const double>(*arrays[f]), {cells});
  }
  std::vector<double> times;
  auto start = Clock::now();
  for (int it = 0;; ++it) {
    auto t0 = Clock::now();
    Status s = validate(m, Expectation{});
    auto t1 = Clock::now();
    if (!s.ok()) {
      throw coredem::UserError("validate failed: " + s.toString());
    }
    if (it >= 1) {
      times.push_back(std::chrono::duration<double>(t1 - t0).count());
    }
    if (times.size() >= 5 &&
        std::chrono::duration<double>(Clock::now() - start).count() >= minSeconds) {
      break;
    }
  }
  return median(times);
}

int runProtocolBench(int argc, char** argv) {
  coredem::bench::Args app{"Round-trip throughput of the coupling transport vs memcpy", "protocol"};
  std::uint64_t cells = 100000;
  std::size_t nFields = 16;
  bool json = false;
  double seconds = 1.0;
  std::vector<std::string> transports{"tcp", "ipc"};
  bool sameProcess = false;
  app.option("--cells", cells, "cells N (doubles per array)").positive();
  app.option("--fields", nFields, "arrays F per message").positive();
  app.flag("--json", json, "print one JSON object");
  app.option("--seconds", seconds, "minimum measuring time per transport");
  app.option("--transports", transports, "tcp, ipc, tcp-raw (bare cppzmq)");
  app.flag("--same-process", sameProcess,
           "run the echo server as a thread of this process (default: a child process)");
  if (const int rc = app.parse(argc, argv); rc >= 0)
    return rc;

  std::vector<std::shared_ptr<std::vector<double>>> arrays;
  for (std::size_t f = 0; f < nFields; ++f) {
    auto a = std::make_shared<std::vector<double>>(cells);
    for (std::uint64_t i = 0; i < cells; ++i) {
      (*a)[i] = static_cast<double>(f) + 1e-6 * static_cast<double>(i);
    }
    arrays.push_back(std::move(a));
  }
  const std::size_t bytes = cells * nFields * sizeof(double);

  std::vector<Result> results;
  const std::string ipcPath = (std::filesystem::temp_directory_path() /
                               ("coredem-bench-" + std::to_string(::getpid()) + ".sock"))
                                  .string();
  try {
    for (const auto& t : transports) {
      if (t == "tcp") {
        results.push_back(
            measureTransport("tcp", "tcp://127.0.0.1:*", arrays, cells, seconds, sameProcess));
      } else if (t == "ipc") {
        results.push_back(
            measureTransport("ipc", "ipc://" + ipcPath, arrays, cells, seconds, sameProcess));
        std::filesystem::remove(ipcPath);
      } else if (t == "tcp-raw") {
        results.push_back(measureRawZmq(arrays, cells, seconds));
      } else {
        std::fprintf(stderr, "coredem-bench protocol: unknown transport '%s' (tcp, ipc, tcp-raw)\n",
                     t.c_str());
        return 2;
      }
    }
  } catch (const coredem::UserError& e) {
    std::fprintf(stderr, "coredem-bench protocol: %s\n", e.what());
    return 1;
  }
  const double memcpySeconds = measureMemcpy(bytes, std::min(seconds, 0.5));
  const double memcpyGbps = static_cast<double>(bytes) / memcpySeconds / 1e9;
  const double validateGbps =
      static_cast<double>(bytes) / measureValidate(arrays, cells, std::min(seconds, 0.5)) / 1e9;

  if (json) {
    std::ostringstream os;
    os.precision(6);
    os << "{\"benchmark\": \"protocol\", \"cells\": " << cells << ", \"fields\": " << nFields
       << ", \"bytes_per_direction\": " << bytes << ", \"memcpy_gbps\": " << memcpyGbps
       << ", \"validate_gbps\": " << validateGbps
       << ", \"hardware_threads\": " << std::thread::hardware_concurrency()
       << ", \"echo_server\": \"" << (sameProcess ? "thread" : "process") << "\""
       << ", \"transports\": {";
    for (std::size_t i = 0; i < results.size(); ++i) {
      const auto& r = results[i];
      double gbps = 2.0 * static_cast<double>(bytes) / r.medianSeconds / 1e9;
      os << (i ? ", " : "") << "\"" << r.transport << "\": {\"gbps\": " << gbps
         << ", \"memcpy_ratio\": " << gbps / memcpyGbps
         << ", \"round_trip_ms\": " << r.medianSeconds * 1e3
         << ", \"round_trip_min_ms\": " << r.minSeconds * 1e3
         << ", \"iterations\": " << r.iterations << "}";
    }
    os << "}}";
    std::printf("%s\n", os.str().c_str());
    return 0;
  }
  std::printf("protocol round trip: %llu cells x %zu float64 arrays = %.2f MB each way, echo "
              "server in %s\n",
              static_cast<unsigned long long>(cells), nFields, static_cast<double>(bytes) / 1e6,
              sameProcess ? "a thread of this process" : "a child process");
  std::printf("memcpy of the same bytes: %.3f ms = %.2f GB/s\n", memcpySeconds * 1e3, memcpyGbps);
  std::printf("validate() of such a message (structure + NaN/Inf scan): %.2f GB/s\n", validateGbps);
  std::printf("%-9s %14s %10s %14s %12s\n", "transport", "round trip ms", "GB/s", "memcpy ratio",
              "iterations");
  for (const auto& r : results) {
    double gbps = 2.0 * static_cast<double>(bytes) / r.medianSeconds / 1e9;
    std::printf("%-9s %14.3f %10.3f %14.3f %12zu\n", r.transport.c_str(), r.medianSeconds * 1e3,
                gbps, gbps / memcpyGbps, r.iterations);
  }
  std::printf("(GB/s = 2 x bytes each way / median round trip; ratio = GB/s / memcpy GB/s)\n");
  return 0;
}

} // namespace

COREDEM_BENCH_COMMAND("protocol", "round trip of N cells x F doubles over tcp and ipc vs memcpy",
                      runProtocolBench);
