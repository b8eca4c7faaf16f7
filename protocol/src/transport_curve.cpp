// CURVE security of the ZeroMQ transport: key files, key checks and the ZAP handler that
// admits clients by their public key (docs/protocol.md).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <sys/stat.h>

#include <coredem/protocol/transport.h>

#include "message_impl.h"
#include "transport_internal.h"

namespace coredem::protocol {

namespace detail {

void setKey(zmq::socket_t& socket, int option, const std::string& key, const char* which) {
  if (key.size() != 40) {
    throw ProtocolError(v1::ERROR_CODE_SECURITY,
                        std::string("CURVE ") + which +
                            " must be a 40-character Z85 key (see generateCurveKeyPair), got " +
                            std::to_string(key.size()) + " characters");
  }
  if (zmq_setsockopt(socket.handle(), option, key.c_str(), 41) != 0) {
    throw ProtocolError(v1::ERROR_CODE_SECURITY,
                        std::string("setting the CURVE ") + which +
                            " failed: " + zmq_strerror(zmq_errno()) +
                            (zmq_has("curve") ? "" : " (libzmq was built without CURVE)"));
  }
}

std::shared_ptr<ZapHandler> ZapHandler::instance() {
  static std::mutex mutex;
  static std::weak_ptr<ZapHandler> weak;
  std::lock_guard lock(mutex);
  auto h = weak.lock();
  if (!h) {
    h = std::shared_ptr<ZapHandler>(new ZapHandler());
    weak = h;
  }
  return h;
}

ZapHandler::~ZapHandler() {
  _stop = true;
  _thread.join();
}

std::string ZapHandler::addDomain(const std::vector<std::string>& keys) {
  static std::atomic<std::uint64_t> counter{0};
  const std::string domain = "coredem-" + std::to_string(++counter);
  std::lock_guard lock(_mutex);
  _domains[domain] = std::set<std::string>(keys.begin(), keys.end());
  return domain;
}

void ZapHandler::removeDomain(const std::string& domain) {
  std::lock_guard lock(_mutex);
  _domains.erase(domain);
}

ZapHandler::ZapHandler() {
  _socket.set(zmq::sockopt::linger, 0);
  // Before any CURVE socket of ours accepts. A previous handler's endpoint may take a
  // moment to be released after its socket closed.
  for (int attempt = 0;; ++attempt) {
    try {
      _socket.bind("inproc://zeromq.zap.01");
      break;
    } catch (const zmq::error_t& e) {
      if (e.num() != EADDRINUSE || attempt >= 50) {
        rethrowZmq(e, "starting the ZAP handler (client key allow-list)");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  _thread = std::thread([this] { run(); });
}

void ZapHandler::run() {
  while (!_stop) {
    zmq::pollitem_t item{_socket.handle(), 0, ZMQ_POLLIN, 0};
    try {
      if (zmq::poll(&item, 1, std::chrono::milliseconds(100)) <= 0) {
        continue;
      }
      std::vector<zmq::message_t> request;
      for (;;) {
        zmq::message_t f;
        if (!_socket.recv(f, zmq::recv_flags::dontwait)) {
          break;
        }
        const bool more = f.more();
        request.push_back(std::move(f));
        if (!more) {
          break;
        }
      }
      answer(request);
    } catch (const zmq::error_t& e) {
      transportLog()->warn("ZAP handler: ZeroMQ error {} ({})", e.num(), e.what());
    }
  }
}

void ZapHandler::answer(const std::vector<zmq::message_t>& r) {
  std::string status = "400", text = "malformed ZAP request", user;
  if (r.size() >= 6) {
    const std::string domain = r[2].to_string(), address = r[3].to_string();
    const std::string mechanism = r[5].to_string();
    if (mechanism == "CURVE" && r.size() >= 7 && r[6].size() == 32) {
      char z85[41] = {};
      zmq_z85_encode(z85, static_cast<const std::uint8_t*>(r[6].data()), 32);
      std::lock_guard lock(_mutex);
      const auto d = _domains.find(domain);
      if (d == _domains.end()) {
        status = "200"; // a socket without an allow-list: CURVE alone decides
        text = "OK";
      } else if (d->second.count(z85) != 0) {
        status = "200";
        text = "OK";
        user = z85;
      } else {
        text = "client key not allowed";
        // A refused client reconnects every 100 ms: log its 1st, 2nd, 4th, 8th... refusal.
        if (_refusals.size() > 1024) {
          _refusals.clear();
        }
        const std::uint64_t n = ++_refusals[z85];
        if ((n & (n - 1)) == 0) {
          transportLog()->warn("refused CURVE client {} from {} ({} times): its key is not in "
                               "the allow-list",
                               z85, printable(address, 64), n);
        }
      }
    } else {
      std::lock_guard lock(_mutex);
      const bool guarded = _domains.count(domain) != 0;
      status = guarded ? "400" : "200";
      text = guarded ? "CURVE with an allowed client key required" : "OK";
    }
  }
  const std::string version = "1.0";
  const std::string id = r.size() > 1 ? r[1].to_string() : std::string();
  const std::string parts[] = {version, id, status, text, user, std::string()};
  for (std::size_t i = 0; i < 6; ++i) {
    _socket.send(zmq::buffer(parts[i]),
                 i + 1 < 6 ? zmq::send_flags::sndmore : zmq::send_flags::none);
  }
}

} // namespace detail

std::vector<std::string> readAllowedClientKeys(const std::string& path) {
  std::ifstream in(path);
  if (!in.good()) {
    throw ProtocolError(v1::ERROR_CODE_SECURITY,
                        "cannot read the client key allow-list " + path +
                            " (one Z85 public key per line; `coredem-dem --generate-client-key "
                            "DIR` writes a key pair)");
  }
  std::vector<std::string> keys;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::istringstream words(line);
    std::string key;
    if (!(words >> key) || key.starts_with("#")) {
      continue;
    }
    char binary[32];
    if (key.size() != 40 ||
        zmq_z85_decode(reinterpret_cast<std::uint8_t*>(binary), key.c_str()) == nullptr) {
      throw ProtocolError(v1::ERROR_CODE_SECURITY,
                          path + " line " + std::to_string(n) + ": '" + printable(key, 60) +
                              "' is not a 40-character Z85 CURVE public key");
    }
    keys.push_back(key);
  }
  return keys;
}

bool isLoopbackEndpoint(std::string_view endpoint) {
  if (endpoint.starts_with("ipc://") || endpoint.starts_with("inproc://")) {
    return true;
  }
  if (!endpoint.starts_with("tcp://")) {
    return false;
  }
  std::string_view rest = endpoint.substr(6);
  std::string_view host;
  if (rest.starts_with("[")) {
    auto close = rest.find(']');
    if (close == std::string_view::npos) {
      return false;
    }
    host = rest.substr(1, close - 1);
    return host == "::1";
  }
  auto colon = rest.rfind(':');
  host = colon == std::string_view::npos ? rest : rest.substr(0, colon);
  if (host == "localhost") {
    return true;
  }
  static const std::regex ipv4Loopback(R"(127\.\d{1,3}\.\d{1,3}\.\d{1,3})");
  return std::regex_match(host.begin(), host.end(), ipv4Loopback);
}

std::pair<std::string, std::string> readClientKeyPair(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path secretFile = path;
  if (fs::is_directory(secretFile, ec)) {
    secretFile /= "client.secret";
  }
  const std::string hint = " (a client key pair is written by `coredem-dem --generate-client-key "
                           "DIR`; give DIR/client.secret or DIR)";
  struct stat st {};
  if (::stat(secretFile.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
    throw ProtocolError(v1::ERROR_CODE_SECURITY,
                        "cannot read the client secret key " + secretFile.string() + hint);
  }
  if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    throw ProtocolError(v1::ERROR_CODE_SECURITY,
                        "the client secret key " + secretFile.string() + " has mode " + mode +
                            ": others may read it; make it private with `chmod 600 " +
                            secretFile.string() + "`");
  }
  std::ifstream in(secretFile);
  std::string secret;
  in >> secret;
  char binary[32];
  if (!in.good() && !in.eof()) {
    throw ProtocolError(v1::ERROR_CODE_SECURITY,
                        "cannot read the client secret key " + secretFile.string() + hint);
  }
  if (secret.size() != 40 ||
      zmq_z85_decode(reinterpret_cast<std::uint8_t*>(binary), secret.c_str()) == nullptr) {
    throw ProtocolError(v1::ERROR_CODE_SECURITY,
                        secretFile.string() + " does not hold a 40-character Z85 CURVE key" + hint);
  }
  char pub[41] = {};
  if (!zmq_has("curve") || zmq_curve_public(pub, secret.c_str()) != 0) {
    throw ProtocolError(v1::ERROR_CODE_UNSUPPORTED,
                        "this libzmq has no CURVE support; install libzmq built with libsodium");
  }
  const fs::path publicFile = secretFile.parent_path() / "client.public";
  if (secretFile.filename() == "client.secret" && fs::exists(publicFile, ec)) {
    std::string listed;
    std::ifstream(publicFile) >> listed;
    if (listed != pub) {
      throw ProtocolError(v1::ERROR_CODE_SECURITY,
                          publicFile.string() + " is not the public key of " + secretFile.string() +
                              " (the pair was mixed up)");
    }
  }
  return {pub, secret};
}

std::pair<std::string, std::string> generateCurveKeyPair() {
  char pub[41] = {};
  char sec[41] = {};
  if (!zmq_has("curve") || zmq_curve_keypair(pub, sec) != 0) {
    throw ProtocolError(v1::ERROR_CODE_UNSUPPORTED,
                        "this libzmq has no CURVE support; install libzmq built with libsodium");
  }
  return {pub, sec};
}

} // namespace coredem::protocol
