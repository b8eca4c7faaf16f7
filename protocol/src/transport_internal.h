// What the ZeroMQ transport's translation units share (transport.cpp: Server and Client;
// transport_curve.cpp: CURVE keys and the ZAP handler). Private to the protocol library.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <zmq.hpp>

#include <coredem/common/log.h>

namespace coredem::protocol::detail {

std::shared_ptr<spdlog::logger> transportLog();

[[noreturn]] void rethrowZmq(const zmq::error_t& e, const std::string& what);

/// One ZeroMQ context (one I/O thread) per process, shared by every Server and Client and
/// destroyed with the last of them. Measured: a client and a server in one process move data
/// about twice as fast through one shared I/O thread as through two contexts.
std::shared_ptr<zmq::context_t> sharedContext();

/// Sets the CURVE key `option` of `socket`; `which` names the key in the error.
void setKey(zmq::socket_t& socket, int option, const std::string& key, const char* which);

/// ZAP handler (ZeroMQ RFC 27) on inproc://zeromq.zap.01 of the shared context: CURVE clients
/// are admitted when their public key is in the allow-list of the ZAP domain of the socket
/// they connect to (one domain per Server with an allow-list). One per process, alive while a
/// Server uses it; its thread polls with a short timeout so that it stops promptly.
class ZapHandler {
public:
  static std::shared_ptr<ZapHandler> instance();
  ~ZapHandler();
  ZapHandler(const ZapHandler&) = delete;
  ZapHandler& operator=(const ZapHandler&) = delete;

  std::string addDomain(const std::vector<std::string>& keys);
  void removeDomain(const std::string& domain);

private:
  ZapHandler();
  void run();
  /// Request: version, request id, domain, address, routing id, mechanism, credentials.
  void answer(const std::vector<zmq::message_t>& r);

  std::shared_ptr<zmq::context_t> _context = sharedContext(); // outlives the socket
  zmq::socket_t _socket{*_context, zmq::socket_type::rep};
  std::mutex _mutex;
  std::map<std::string, std::set<std::string>> _domains;
  std::map<std::string, std::uint64_t> _refusals; ///< per refused key (log rate limit)
  std::atomic<bool> _stop{false};
  std::thread _thread;
};

} // namespace coredem::protocol::detail
