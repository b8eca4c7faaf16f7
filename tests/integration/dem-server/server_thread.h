#pragma once
// An in-process coredem-dem server (cpu backend, one thread) on an ephemeral loopback port,
// serving from a background thread for the lifetime of the object.
#include <memory>
#include <string>
#include <thread>

#include "coredem/server/dem_server.h"

class ServerThread {
public:
  explicit ServerThread(double sessionTimeout = 600.0, double grantWait = 5.0) {
    coredem::server::ServerOptions o;
    o.bind = "tcp://127.0.0.1:*";
    o.backend = "cpu";
    o.threads = 1;
    o.grantWaitSeconds = grantWait;
    o.sessionTimeoutSeconds = sessionTimeout;
    _server = std::make_unique<coredem::server::DemServer>(o);
    _thread = std::thread([this] { _server->run(); });
  }
  /// A server with these options (bind, backend and threads as above unless set).
  explicit ServerThread(coredem::server::ServerOptions o) {
    o.bind = "tcp://127.0.0.1:*";
    o.backend = "cpu";
    o.threads = 1;
    _server = std::make_unique<coredem::server::DemServer>(o);
    _thread = std::thread([this] { _server->run(); });
  }
  ~ServerThread() {
    _server->stop();
    _thread.join();
  }
  ServerThread(const ServerThread&) = delete;
  ServerThread& operator=(const ServerThread&) = delete;
  std::string endpoint() const { return _server->endpoint(); }

private:
  std::unique_ptr<coredem::server::DemServer> _server;
  std::thread _thread;
};
